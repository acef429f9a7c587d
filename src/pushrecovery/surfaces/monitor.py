"""A balance monitor for a 500 Hz – 1 kHz loop: one state in, a verdict out.

:class:`BalanceMonitor` is built once from the body and its support (and rebuilt with
:meth:`BalanceMonitor.set_support` when a foot lands or lifts). Every query then runs on Python
floats and tuples prepared at construction (no arrays allocated, no thread pool, no
compilation) and one call of the compiled N-step region test
(``kernels.plane_codes.locate_steps`` over the regions of
:class:`~pushrecovery.surfaces.step_regions.StepRegions`), loaded from numba's on-disk cache
in the constructor, which calls every path once: the first query of a process pays nothing
either.

The verdicts, capture point and margins are those of
:func:`pushrecovery.surfaces.classify.classify` on the ground plane (tested to 1e-12).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify import Strategy
from pushrecovery.surfaces.cop import capture_point
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.step_regions import StepRegions

__all__ = ["BalanceMonitor", "Verdict"]

_Edges = tuple[tuple[float, float, float, float, float, float, float, float], ...]


@dataclass(frozen=True, slots=True)
class Verdict:
    """What one state needs, with its margins.

    Attributes
    ----------
    strategy : Strategy
        ``ankle``, ``hip``, ``step`` or ``fall``.
    capture_point_x, capture_point_y : float
        ξ = r + ṙ/ω in the world frame [m].
    cop_margin, cmp_margin : float
        Signed distances of ξ to the support polygon and to the CMP region [m], + inside.
    step_margin : float
        Largest signed distance of ξ to the N-step regions, N <= max_steps [m]: positive
        exactly when steps capture the state.
    steps : int
        Steps needed: 0 for ``ankle`` and ``hip``, N for ``step``, −1 for ``fall``.
    """

    strategy: Strategy
    capture_point_x: float
    capture_point_y: float
    cop_margin: float
    cmp_margin: float
    step_margin: float
    steps: int


def _edges(polygon: ConvexPolygon) -> _Edges:
    """Per edge: normal, offset, start vertex, edge vector, 1/‖edge‖² as Python floats."""
    v, n, b = polygon.vertices, polygon.normals, polygon.offsets
    rows = []
    for i in range(len(v)):
        j = (i + 1) % len(v)
        ex, ey = float(v[j, 0] - v[i, 0]), float(v[j, 1] - v[i, 1])
        rows.append(
            (
                float(n[i, 0]),
                float(n[i, 1]),
                float(b[i]),
                float(v[i, 0]),
                float(v[i, 1]),
                ex,
                ey,
                1.0 / (ex * ex + ey * ey),
            )
        )
    return tuple(rows)


def _signed_distance(edges: _Edges, px: float, py: float) -> float:
    """Signed distance to a convex polygon, + inside (see :mod:`pushrecovery.ground.polygon`)."""
    excess = -math.inf
    for nx, ny, b, _, _, _, _, _ in edges:
        e = nx * px + ny * py - b
        if e > excess:
            excess = e
    if excess <= 0.0:
        return -excess
    best = math.inf
    for _, _, _, vx, vy, ex, ey, inv in edges:
        dx, dy = px - vx, py - vy
        t = (dx * ex + dy * ey) * inv
        t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
        gap = math.hypot(dx - t * ex, dy - t * ey)
        if gap < best:
            best = gap
    return -best


class BalanceMonitor:
    """Real-time balance verdicts for one body on one support.

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support, optional
        Stance and feet; default double support on the default feet.

    Examples
    --------
    >>> from pushrecovery import load_params
    >>> monitor = BalanceMonitor(load_params())
    >>> monitor.query(0.0, 0.0, 0.0, 0.6).strategy.value
    'hip'
    """

    __slots__ = ("_cmp", "_cop", "_locate", "_omega", "_regions", "params", "support")

    def __init__(self, params: BodyParams, support: Support | None = None) -> None:
        from pushrecovery.kernels.plane_codes import locate_steps

        require_type("params", params, BodyParams)
        if support is not None:
            require_type("support", support, Support)
        self.params = params
        self._omega = params.omega
        self._locate: Callable[..., tuple[int, float]] = locate_steps
        self.set_support(Support.from_params(params) if support is None else support)
        self.query(0.0, 0.0, 10.0, 0.0)  # loads every compiled path before the first tick

    def set_support(self, support: Support) -> None:
        """Use another stance or foot placement (tens of µs of set-up; not for every tick)."""
        self.support = support
        self._cop = _edges(support.polygon)
        self._cmp = _edges(cmp_polygon(support, self.params))
        regions = StepRegions.of(self.params, support)
        steps = np.array(regions.steps, dtype=np.int64)
        self._regions = (regions.table, regions.counts, steps, regions.outer)

    def query(self, x: float, y: float, xdot: float, ydot: float) -> Verdict:
        """Classify one CoM state on the ground plane.

        Parameters
        ----------
        x, y : float
            CoM position in the world frame [m].
        xdot, ydot : float
            CoM velocity [m/s].

        Returns
        -------
        Verdict

        Raises
        ------
        InvalidParameterError
            If a value is NaN or infinite.
        """
        try:
            px = capture_point(x, xdot, self._omega)
            py = capture_point(y, ydot, self._omega)
            finite = math.isfinite(px) and math.isfinite(py) and math.isfinite(x + y)
        except (TypeError, ValueError):  # an array or text where a number belongs: no cost here
            raise ParameterTypeError(
                "x, y, xdot, ydot must be numbers (one state per query; classify_states for "
                f"arrays), got {type(x).__name__}, {type(y).__name__}, {type(xdot).__name__}, "
                f"{type(ydot).__name__}"
            ) from None
        if not finite:
            raise InvalidParameterError(
                f"x, y, xdot, ydot must be finite, got {x!r}, {y!r}, {xdot!r}, {ydot!r}"
            )
        cop = _signed_distance(self._cop, px, py)
        cmp = _signed_distance(self._cmp, px, py)
        # The N-step regions (compiled, one call), as StepRegions.locate.
        steps, step_margin = self._locate(*self._regions, px, py)
        if cop > 0.0:
            strategy, steps = Strategy.ANKLE, 0
        elif cmp > 0.0:
            strategy, steps = Strategy.HIP, 0
        elif steps > 0:
            strategy = Strategy.STEP
        else:
            strategy, steps = Strategy.FALL, -1
        return Verdict(strategy, px, py, cop, cmp, step_margin, steps)
