"""A balance monitor for a 500 Hz – 1 kHz loop: one state in, a verdict out.

:class:`BalanceMonitor` is built once from the body and its support (and rebuilt with
:meth:`BalanceMonitor.set_support` when a foot lands or lifts). Every query then runs on Python
floats and tuples prepared at construction: no arrays, no thread pool, no compilation. The
step decision (Sec. IV) calls the compiled scalar planner of
:func:`pushrecovery.surfaces.step.compiled_plan_step`, loaded from numba's on-disk cache and
called once in the constructor, so the first query of a process pays nothing either.

The verdicts, capture point and margins are those of
:func:`pushrecovery.surfaces.classify.classify` on the ground plane (tested to 1e-12).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify import Strategy
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.step import compiled_plan_step

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
        Reach left beyond the shortest recovering single step [m]; −inf when none recovers.
    """

    strategy: Strategy
    capture_point_x: float
    capture_point_y: float
    cop_margin: float
    cmp_margin: float
    step_margin: float


def _edges(polygon: ConvexPolygon) -> _Edges:
    """Per edge: normal, offset, start vertex, edge vector, 1/|edge|² as Python floats."""
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

    __slots__ = (
        "_ankle",
        "_cmp",
        "_cop",
        "_feet",
        "_heading",
        "_inv_omega",
        "_plan",
        "_plan_args",
        "_reach",
        "_swing",
        "params",
        "support",
    )

    def __init__(self, params: BodyParams, support: Support | None = None) -> None:
        self.params = params
        self._inv_omega = 1.0 / params.omega
        self._reach = params.leg_length
        self._plan_args = (params.com_height, params.gravity, params.max_step_length)
        self._plan: Callable[..., tuple[float, bool, bool, float, float, float, float, float]]
        self._plan = compiled_plan_step()
        self.set_support(Support.from_params(params) if support is None else support)
        self.query(0.0, 0.0, 10.0, 0.0)  # loads every compiled path before the first tick

    def set_support(self, support: Support) -> None:
        """Use another stance or foot placement (a few µs of set-up; not for every tick)."""
        self.support = support
        self._cop = _edges(support.polygon)
        self._cmp = _edges(cmp_polygon(support, self.params))
        self._ankle = support.ankle
        self._heading = (math.cos(support.yaw), math.sin(support.yaw))
        self._feet = tuple((float(x), float(y)) for x, y in support.foot.vertices)
        # Which foot lands (Support.landing_foot): -1 mirrors the left shape into the right.
        self._swing = {Stance.LEFT: -1.0, Stance.RIGHT: 1.0, Stance.DOUBLE: 0.0}[support.stance]

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
        px = x + xdot * self._inv_omega
        py = y + ydot * self._inv_omega
        if not (math.isfinite(px) and math.isfinite(py) and math.isfinite(x + y)):
            raise InvalidParameterError(
                f"x, y, xdot, ydot must be finite, got {x!r}, {y!r}, {xdot!r}, {ydot!r}"
            )
        cop = _signed_distance(self._cop, px, py)
        cmp = _signed_distance(self._cmp, px, py)
        step = self._step_margin_and_feasible(x, y, xdot, ydot, px, py)
        if cop > 0.0:
            strategy = Strategy.ANKLE
        elif cmp > 0.0:
            strategy = Strategy.HIP
        elif step[1]:
            strategy = Strategy.STEP
        else:
            strategy = Strategy.FALL
        return Verdict(strategy, px, py, cop, cmp, step[0])

    def _step_margin_and_feasible(
        self, x: float, y: float, xdot: float, ydot: float, px: float, py: float
    ) -> tuple[float, bool]:
        """Sec. IV's step on the line of the excursion (as :func:`.plane.plan_step_xy`)."""
        ex, ey = px - self._ankle[0], py - self._ankle[1]
        norm = math.hypot(ex, ey)
        hx, hy = self._heading
        if norm == 0.0:
            ex, ey = hx, hy
        else:
            ex, ey = ex / norm, ey / norm
            if ex * hx + ey * hy < 0.0:
                ex, ey = -ex, -ey
        along = (x - self._ankle[0]) * ex + (y - self._ankle[1]) * ey
        if abs(along) >= self._reach:
            return -math.inf, False
        fx, fy = hx * ex + hy * ey, -hy * ex + hx * ey  # the line in the foot's frame
        fy = abs(fy) if self._swing == 0.0 else self._swing * fy
        toe = -math.inf
        heel = math.inf
        for vx, vy in self._feet:
            reach = vx * fx + vy * fy
            if reach > toe:
                toe = reach
            if reach < heel:
                heel = reach
        plan = self._plan(along, xdot * ex + ydot * ey, heel, toe, *self._plan_args)
        return plan[7], plan[2]
