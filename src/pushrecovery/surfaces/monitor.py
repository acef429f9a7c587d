"""A balance monitor for a 500 Hz – 1 kHz loop: one state in, a verdict out.

:class:`BalanceMonitor` is built once from the body (the N-step regions of a stance foot at
the origin, :class:`~pushrecovery.surfaces.step.regions.StepRegions`) and told each support
with :meth:`BalanceMonitor.set_support` when a foot lands or lifts: tens of µs, the regions
turned and moved to the feet, the CMP region one compiled Minkowski sum. Every query then runs
on Python floats and tuples prepared for the support (no arrays allocated, no thread pool, no
compilation) and one call of the compiled N-step region test
(``kernels.plane_codes.locate_steps``). The constructor loads every compiled path from numba's
on-disk cache and calls each once: the first query and the first support change of a process
pay nothing either.

The verdicts, capture point and margins are those of
:func:`pushrecovery.surfaces.classify.classify` on the ground plane (tested to 1e-12).

A query may also give the upper body's current pitch and roll, each (angle [rad], rate
[rad/s]): the CMP margin is then that of the region the hip strategy reaches from that state
(docs/errata.md, E19; :func:`pushrecovery.surfaces.plane.cmp_polygon_from`, tested to 1e-12),
P ⊕ an off-centre box in the support's axes. The sum's edges are ordered per support (P's
edges and the box's four, merged by direction), so a query only moves the box's corners: a
few µs more, no hull built.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.support import MAX_POSE, Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify import Strategy
from pushrecovery.surfaces.cmp import _flywheel_offsets, cmp_offset, cmp_offset_roll
from pushrecovery.surfaces.cop import capture_point
from pushrecovery.surfaces.edge_rows import Edges, cmp_rows, polygon_rows, signed_distance
from pushrecovery.surfaces.step.regions import StepRegions

__all__ = ["BalanceMonitor", "Verdict"]

FloatArray = NDArray[np.float64]
#: Per edge of P ⊕ box, CCW: outward normal, the vertex of P and the box corner it starts from.
_SumEdges = tuple[tuple[float, float, float, float, int], ...]
#: An upper-body axis's (angle [rad], rate [rad/s]).
Axis = tuple[float, float]


@dataclass(frozen=True, slots=True, eq=False)
class _SupportState:
    """Everything a query needs of one support, built whole and never changed."""

    support: Support
    cop: Edges
    cmp: Edges
    torso: tuple[_SumEdges, float, float]  # P ⊕ box's edges, cos and sin of the yaw
    regions: tuple[object, ...]  # locate_steps' table, counts, steps, outer


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


def _sum_edges(polygon: Edges, yaw: float) -> tuple[_SumEdges, float, float]:
    """Return the edges of P ⊕ box for any box [lo_x, hi_x] × [lo_y, hi_y] in the stance axes.

    The sum of a convex polygon and a box has P's edges, each moved by the box corner whose
    normal cone holds the edge's normal, and the box's four edges, each moved by the vertex of
    P where P's normals cross the box's normal: an order that depends on the directions alone,
    so it is fixed per support and only the box's corners change per query. Box corners
    k = 0…3, counter-clockwise: (lo_x, lo_y), (hi_x, lo_y), (hi_x, hi_y), (lo_x, hi_y); an edge
    of P whose normal has stance components (u, w) takes corner 2 if u > 0 < w, 3 if u <= 0 < w,
    0 if u, w <= 0 and 1 if w <= 0 < u (a partition of the directions, turning with them, so
    each box edge is inserted once; a tie gives two collinear edges, one possibly of length 0).

    ``polygon`` is P's rows (:func:`~pushrecovery.surfaces.edge_rows.polygon_rows`), ``yaw``
    the stance's heading [rad]. Each row: the edge's outward normal and its start (a vertex
    of P and a corner), in the world frame; each edge ends where the next starts. Then cos
    and sin of the yaw.
    """
    c, s = math.cos(yaw), math.sin(yaw)
    # The box edge from corner k to k + 1: its outward normal in the world frame.
    box = ((s, -c), (c, s), (-s, c), (-c, -s))
    starts: list[tuple[float, float, float, float, int]] = []
    k = first = -1
    for nx, ny, _, vx, vy, _, _, _ in polygon:
        u, w = c * nx + s * ny, c * ny - s * nx
        corner = (2 if u > 0.0 else 3) if w > 0.0 else (1 if u > 0.0 else 0)
        if k < 0:  # the first vertex: its box edges come last, from the last edge's corner
            first = k = corner
        while k != corner:  # the box's edges between the last edge's corner and this one's
            bx, by = box[k]
            starts.append((bx, by, vx, vy, k))
            k = (k + 1) & 3
        starts.append((nx, ny, vx, vy, corner))
    _, _, _, vx, vy, _, _, _ = polygon[0]
    while k != first:  # the box's edges at the first vertex, closing the loop
        bx, by = box[k]
        starts.append((bx, by, vx, vy, k))
        k = (k + 1) & 3
    return tuple(starts), c, s


def _sum_distance(
    torso: tuple[_SumEdges, float, float],
    box: tuple[float, float, float, float],
    px: float,
    py: float,
) -> float:
    """Signed distance of (px, py) to P ⊕ [lo_x, hi_x] × [lo_y, hi_y] (stance axes), + inside.

    ``box`` is (lo_x, hi_x, lo_y, hi_y) [m], lo <= hi; the edges from :func:`_sum_edges`.
    Outside, the nearest point is on an edge whose line ξ is beyond (positive excess): only
    those are measured.
    """
    rows, c, s = torso
    lo_x, hi_x, lo_y, hi_y = box
    # The box's corners in the world frame, counter-clockwise from (lo_x, lo_y).
    cx = (c * lo_x - s * lo_y, c * hi_x - s * lo_y, c * hi_x - s * hi_y, c * lo_x - s * hi_y)
    cy = (s * lo_x + c * lo_y, s * hi_x + c * lo_y, s * hi_x + c * hi_y, s * lo_x + c * hi_y)
    excess = -math.inf
    for nx, ny, vx, vy, k in rows:
        e = nx * (px - (vx + cx[k])) + ny * (py - (vy + cy[k]))
        if e > excess:
            excess = e
    if excess <= 0.0:
        return -excess
    best = math.inf
    nx, ny, vx, vy, k = rows[-1]  # the last edge: it ends where the first starts
    x0, y0 = vx + cx[k], vy + cy[k]
    for next_nx, next_ny, vx, vy, k in rows:  # the edge (nx, ny) from (x0, y0) to (x1, y1)
        x1, y1 = vx + cx[k], vy + cy[k]
        dx, dy = px - x0, py - y0
        if nx * dx + ny * dy > 0.0:  # ξ is beyond this edge's line
            ex, ey = x1 - x0, y1 - y0
            length2 = ex * ex + ey * ey
            t = (dx * ex + dy * ey) / length2 if length2 > 0.0 else 0.0
            t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
            gap = math.hypot(dx - t * ex, dy - t * ey)
            if gap < best:
                best = gap
        nx, ny, x0, y0 = next_nx, next_ny, x1, y1
    return -best


class BalanceMonitor:
    """Real-time balance verdicts for one body on one support.

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support, optional
        Stance and feet; default double support on the default feet.

    Notes
    -----
    Threads: everything :meth:`query` needs of a support lives in one immutable object,
    which :meth:`set_support` builds whole and then installs with a single attribute
    assignment; :meth:`query` reads that attribute once. So one thread may call
    :meth:`set_support` while others call :meth:`query`: each query answers for the old
    support or the new one, never a mix of both. Two threads calling :meth:`set_support` at
    once leave the support of whichever assigned last. The compiled kernels (numba,
    ``nogil``) release the GIL only while they run, a few µs of a call, and read arrays that
    nothing writes after :meth:`set_support` built them; the rest of a call is Python, which
    holds the GIL, so threads take turns rather than run in parallel. A query allocates no
    arrays (an upper-body state is the caller's, read once); :meth:`set_support` allocates one
    edge table (tens of kB).

    Examples
    --------
    >>> from pushrecovery import load_params
    >>> monitor = BalanceMonitor(load_params())
    >>> monitor.query(0.0, 0.0, 0.0, 0.6).strategy.value
    'hip'
    >>> monitor.query(0.0, 0.0, 0.0, 0.6, roll=(0.9, 0.0)).strategy.value  # leaning left
    'step'
    """

    __slots__ = ("_axes", "_box", "_locate", "_omega", "_state", "params")

    def __init__(self, params: BodyParams, support: Support | None = None) -> None:
        from pushrecovery.kernels.plane_codes import locate_steps

        require_type("params", params, BodyParams)
        if support is not None:
            require_type("support", support, Support)
        self.params = params
        self._omega = params.omega
        self._locate: Callable[..., tuple[int, float]] = locate_steps
        self._box = (cmp_offset(params), cmp_offset_roll(params))
        # Each upper-body axis's τmax, I, θmax, m g and ω, for the offsets from θ0, θ̇0 (E19).
        limits = (
            (params.torque_max, params.flywheel_inertia, params.flywheel_angle_max,
             params.weight, params.omega),
            (params.torque_max_roll, params.flywheel_inertia_roll,
             params.flywheel_angle_max_roll, params.weight, params.omega),
        )  # fmt: skip
        # Per axis: those values and (−Δ⁻, Δ⁺) of the upright body at rest.
        rest = [_flywheel_offsets(*axis, 0.0, 0.0) for axis in limits]
        self._axes = tuple(
            (axis, (-minus, plus)) for axis, (minus, plus) in zip(limits, rest, strict=True)
        )
        first = Support.from_params(params) if support is None else support
        for stance in (Stance.LEFT, Stance.DOUBLE):  # loads every compiled path once
            self.set_support(Support.from_params(params, stance))
            self.query(0.0, 0.0, 10.0, 0.0)
            self.query(0.0, 0.0, 10.0, 0.0, pitch=(0.0, 0.1), roll=(0.0, -0.1))
        self.set_support(first)

    @property
    def support(self) -> Support:
        """The support the queries answer for."""
        return self._state.support

    def set_support(self, support: Support) -> None:
        """Use another stance or foot placement (tens of µs; safe while others query).

        Raises
        ------
        ParameterTypeError
            If ``support`` is not a :class:`~pushrecovery.ground.support.Support`.
        """
        require_type("support", support, Support)
        regions = StepRegions.of(self.params, support)
        cop = polygon_rows(support.polygon)
        self._state = _SupportState(
            support,
            cop,
            cmp_rows(support, *self._box),
            _sum_edges(cop, support.yaw),
            (regions.table, regions.counts, regions.steps_array, regions.outer),
        )

    def query(
        self,
        x: float,
        y: float,
        xdot: float,
        ydot: float,
        pitch: Axis | None = None,
        roll: Axis | None = None,
    ) -> Verdict:
        r"""Classify one CoM state on the ground plane, the upper body upright or as given.

        Parameters
        ----------
        x, y : float
            CoM position in the world frame [m].
        xdot, ydot : float
            CoM velocity [m/s].
        pitch, roll : (float, float), optional
            The upper body's current (angle [rad], rate [rad/s]) about its pitch axis
            (positive forward: toward the support's heading e_p = (cos ψ, sin ψ), ψ =
            ``support.yaw``, the direction in which a positive pitch torque moves the CMP) and
            about its roll axis (positive toward the body's left, e_r = (−sin ψ, cos ψ)): the
            flywheel states of :mod:`pushrecovery.models.flywheel.plane` and
            :func:`~pushrecovery.surfaces.cmp.cmp_offset_from`. None is (0, 0) for that axis;
            both None, or every value 0, answer for the upright body at rest (the same
            verdict, bit for bit, as without them).

        Returns
        -------
        Verdict
            With a torso state, ``cmp_margin`` is the signed distance of ξ to
            P ⊕ [−Δ⁻_p, Δ⁺_p] × [−Δ⁻_r, Δ⁺_r], the box in the support's axes (e_p, e_r) with
            (Δ⁻, Δ⁺) of each axis from
            :func:`~pushrecovery.surfaces.cmp.cmp_offset_from` (docs/errata.md, E19):
            :func:`~pushrecovery.surfaces.plane.cmp_polygon_from`'s region (tested to 1e-12),
            without building it. A side's Δ is smaller when the upper body already leans or
            turns toward it (less room, or a rate to brake first) and negative when it must
            first be braked against the push: the region can then end inside the support
            polygon, so ``ankle`` needs ξ inside both (ξ in P outside the region is not
            balanced without a step). The CoP margin and the step regions do not depend on
            the upper body (they assume it upright and at rest).

        Raises
        ------
        InvalidParameterError
            If a value is NaN or infinite or the capture point is beyond
            ±:data:`~pushrecovery.ground.support.MAX_POSE` m (as a foot pose); if ``pitch``
            or ``roll`` is not a pair, an angle is outside its joint range [−θmax, θmax] or a
            rate is one from which no torque within τmax stops the upper body inside that
            range (the message names the axis and ``theta0`` or ``thetadot0``, as
            :func:`~pushrecovery.surfaces.cmp.cmp_offset_from`).
        """
        if not (type(x) is type(y) is type(xdot) is type(ydot) is float):
            x, y, xdot, ydot = _floats(x, y, xdot, ydot)  # numpy scalars: 5x slower otherwise
        try:
            px = capture_point(x, xdot, self._omega)
            py = capture_point(y, ydot, self._omega)
            # NaN fails the comparisons; beyond MAX_POSE a distance to a foot overflows.
            finite = abs(px) <= MAX_POSE and abs(py) <= MAX_POSE and math.isfinite(x + y)
        except (TypeError, ValueError):  # an array or text where a number belongs: no cost here
            raise ParameterTypeError(
                "x, y, xdot, ydot must be numbers (one state per query; classify_states for "
                f"arrays), got {type(x).__name__}, {type(y).__name__}, {type(xdot).__name__}, "
                f"{type(ydot).__name__}"
            ) from None
        if not finite:
            raise InvalidParameterError(
                f"x, y, xdot, ydot must be finite, with the capture point within "
                f"±{MAX_POSE:g} m, got {x!r}, {y!r}, {xdot!r}, {ydot!r}"
            )
        box = None if pitch is None and roll is None else self._torso_box(pitch, roll)
        state = self._state  # read once: the old support or the new one, never a mix
        cop = signed_distance(state.cop, px, py)
        if box is None:
            cmp = signed_distance(state.cmp, px, py)
        else:
            cmp = _sum_distance(state.torso, box, px, py)
        # The N-step regions (compiled, one call), as StepRegions.locate.
        steps, step_margin = self._locate(*state.regions, px, py)
        if cop > 0.0 and (box is None or cmp > 0.0):
            strategy, steps = Strategy.ANKLE, 0
        elif cmp > 0.0:
            strategy, steps = Strategy.HIP, 0
        elif steps > 0:
            strategy = Strategy.STEP
        else:
            strategy, steps = Strategy.FALL, -1
        return Verdict(strategy, px, py, cop, cmp, step_margin, steps)

    def _torso_box(
        self, pitch: Axis | None, roll: Axis | None
    ) -> tuple[float, float, float, float] | None:
        """(−Δ⁻_p, Δ⁺_p, −Δ⁻_r, Δ⁺_r) [m] of the upper body's state; None if every value is 0."""
        box: list[float] = []
        resting = True
        for name, value, axis in (("pitch", pitch, self._axes[0]), ("roll", roll, self._axes[1])):
            if value is None:  # upright and at rest: (Δ⁻, Δ⁺) computed once, the same numbers
                box += axis[1]
                continue
            angle, rate = _pair(name, value)
            try:
                minus, plus = _flywheel_offsets(*axis[0], angle, rate)
            except InvalidParameterError as error:
                raise InvalidParameterError(f"{name}: {error}") from None
            resting = resting and angle == 0.0 and rate == 0.0
            box += (-minus, plus)
        if resting:  # the at-rest region, as without a torso state
            return None
        return box[0], box[1], box[2], box[3]


def _floats(*values: float) -> tuple[float, ...]:
    """Return numbers (numpy scalars, ints) as Python floats, anything else as it is.

    The same values (IEEE doubles either way); Python floats keep a query's arithmetic off
    numpy's scalar path. Arrays, text and None go on to :meth:`BalanceMonitor.query`'s check.
    """
    return tuple(float(v) if isinstance(v, int | np.floating | np.integer) else v for v in values)


def _pair(name: str, value: Axis) -> Axis:
    """Return an axis's (angle, rate) or raise naming ``name`` (values checked by the caller)."""
    try:
        angle, rate = value
    except (TypeError, ValueError):
        raise InvalidParameterError(
            f"{name} must be an (angle [rad], rate [rad/s]) pair, got {str(value)[:40]!r}"
        ) from None
    return angle, rate
