r"""Capture regions of one and several steps: the LIPM with feet, a reach and a step time.

The model is that of :mod:`pushrecovery.surfaces.plane` (ξ̇ = ω (ξ − p − c): the CoP p in the
current support, the CMP offset c of the upper body) with steps: at touchdown times
t_1 < t_2 < ... the landing foot F_k, its ankle at q_k, becomes the support and the previous
stance foot lifts. A foothold lies in the reach polygon R_k about the stance ankle,
q_k − q_{k−1} ∈ R_k, and touchdowns are at least Δt_s apart (``min_step_time``); the first
comes no sooner than Δt_s after deciding to step (or after the remaining swing time).

**Derivation** (``docs/steps.md``). ξ stays bounded if and only if
ξ_0 = ω∫_0^∞ e^{−ωs} (p(s) + c(s)) ds. Split the CoP integral at the touchdowns, with
a_k = e^{−ω t_k} and a_{N+1} = 0: over each phase it is a weighted mean of points of that
phase's support, so it ranges over (1 − a_1) S ⊕ Σ_k (a_k − a_{k+1}) (q_k + F_k), each point
reached with a CoP held still. With q_k = q_0 + r_1 + ... + r_k,
Σ_k (a_k − a_{k+1}) q_k = a_1 q_0 + Σ_j a_j r_j. The hip's term ranges over the box H of
:func:`~pushrecovery.surfaces.plane.cmp_polygon` whatever the touchdowns (the flywheel keeps
turning through them). So the capture points captured by N steps at these times are

.. math:: C_N = H \oplus (1 - a_1) S \oplus \{a_1 q_0\}
          \oplus \bigoplus_{k=1}^N (a_k - a_{k+1}) F_k \oplus \bigoplus_{j=1}^N a_j R_j,
          \qquad (S1)

a convex polygon (a Minkowski sum, :mod:`pushrecovery.ground.minkowski`), with support function
h(d) = h_H + (1 − a_1) h_S + a_1 d·q_0 + Σ (a_k − a_{k+1}) h_{F_k} + Σ a_j h_{R_j}  (S2).
Along one direction with point feet (h_F = 0), a disc reach l, touchdowns Δt_s apart from Δt_s
(a_k = β^k, β = e^{−ωΔt_s}) and no hip, (S2) is Koolen et al. (2012)'s
d_N = l Σ_{k=1}^N β^k = (d_{N−1} + l) β; a disc foot of radius r adds r (their finite-foot
d_N); the hip adds its offset. (S1) is exact under the independence conditions of
:mod:`pushrecovery.surfaces.plane` and with the landing foot alone supporting after each
touchdown (the double support of a touchdown, a hull, is not used: conservative).

**Footholds.** For a landing at time t (T = e^{ωt}) followed by N − 1 further steps, (S1)
solved for q_1 gives the first footholds

.. math:: Q_T = T\xi_0 \oplus T(-H) \oplus (T - 1)(-S) \oplus (-V_{N-1}), \qquad (S3)

V_{N−1} the capture points captured, relative to the landing ankle, by the landing foot and
N − 1 more steps (V_0 = F), intersected with the reach a_0 + R_1. That is the region for a
touchdown *exactly* at t. For a touchdown at *any* time from t on, Q_T = Q_{T_0} ⊕ (T − T_0) A
with A = ξ_0 ⊕ (−H) ⊕ (−S), whose union over T >= T_0 is the convex set
Q_{T_0} ⊕ cone(A) (the whole reach when 0 is inside A: the body is already captured without
a step and may put its foot anywhere later).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from pushrecovery._validate import finite_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import (
    Shape,
    clip,
    clip_halfplanes,
    decompose,
    minkowski_sum,
    regular_polygon,
)
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance, Support, foot_shape
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll

__all__ = [
    "REACH_SIDES",
    "CaptureRegion",
    "StepOption",
    "StepPlan",
    "capturability_distance",
    "capture_region",
    "default_max_steps",
    "hip_box",
    "landing_foot",
    "landing_viable",
    "plan_steps_xy",
    "reach_polygon",
    "step_options",
    "viable_region",
]

FloatArray = NDArray[np.float64]

#: Sides of the regular polygon inscribed in the reach disc: its edges come within
#: max_step_length (1 − cos(π/64)) = 0.12 % of the circle (1.2 mm for a 1 m reach).
REACH_SIDES = 64
#: Growth of the region below which one more step does not count [m] (``max_steps``).
GROWTH_TOLERANCE = 1e-3


def default_max_steps(params: BodyParams) -> int:
    """Smallest N whose next step grows every N-step region by less than 1 mm.

    From (S2), one more step moves the support function by a_{N+1} (h_R + h_{F_{N+1}} −
    h_{F_N}) <= β^{N+1} (l + 2 ρ_F), β = e^{−ωΔt_s}, l the reach and ρ_F the foot's farthest
    vertex from its ankle: N is the smallest with that bound under 1 mm. With Δt_s = 0 (the
    paper's instantaneous step) the regions never stop growing: N = 1, the paper's one step.
    """
    beta = math.exp(-params.omega * params.min_step_time)
    foot = foot_shape(params)
    size = params.max_step_length + 2.0 * float(np.hypot(*foot.vertices.T).max())
    if beta >= 1.0:
        return 1
    for steps in range(1, 51):
        if beta ** (steps + 1) * size < GROWTH_TOLERANCE:
            return steps
    return 50


def capturability_distance(
    steps: float,
    omega: float,
    step_time: float,
    reach: float,
    foot_radius: float = 0.0,
    hip: float = 0.0,
) -> float:
    """d_N: the farthest capture point from the stance ankle that N steps capture [m].

    (S2) along one direction for a point (``foot_radius`` 0) or disc foot, a reach ``reach``
    [m] along that direction, touchdowns every ``step_time`` Δt_s [s] from Δt_s on and a hip
    offset ``hip`` [m]: d_N = hip + r + l β (1 − β^N)/(1 − β), β = e^{−ωΔt_s} (Koolen et al.
    2012, with the hip added); ``steps`` may be ``math.inf``. Δt_s = 0 gives hip + r + N l.
    """
    beta = math.exp(-omega * step_time)
    if steps == 0:
        return hip + foot_radius
    if beta >= 1.0:
        return hip + foot_radius + steps * reach
    geometric = beta / (1.0 - beta) if math.isinf(steps) else beta * (1 - beta**steps) / (1 - beta)
    return hip + foot_radius + reach * geometric


def hip_box(params: BodyParams, yaw: float) -> FloatArray | None:
    """Return the hip's box H: ±(pitch, roll) corrected Eq. 15 offsets, heading-aligned [m].

    Counter-clockwise corners (a segment when one axis has no torque), or None when neither.
    """
    half_x, half_y = cmp_offset(params), cmp_offset_roll(params)
    if half_x == 0.0 and half_y == 0.0:
        return None
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([[-half_x, -half_y], [half_x, -half_y], [half_x, half_y], [-half_x, half_y]])
    if half_x == 0.0 or half_y == 0.0:
        local = np.array([[-half_x, -half_y], [half_x, half_y]])
    return np.asarray(local @ np.array([[c, s], [-s, c]]), dtype=np.float64)


@functools.lru_cache(maxsize=64)
def landing_foot(params: BodyParams, side: Stance, yaw: float) -> ConvexPolygon:
    """Return the ``side`` foot (LEFT or RIGHT), its ankle at the origin, turned by yaw [m]."""
    foot = foot_shape(params)
    return (foot if side is Stance.LEFT else foot.mirrored()).transformed(0.0, 0.0, yaw)


@functools.lru_cache(maxsize=32)
def reach_polygon(params: BodyParams, side: Stance, yaw: float) -> ConvexPolygon:
    """Footholds of the ``side`` foot relative to the stance ankle: R [m].

    The regular polygon of :data:`REACH_SIDES` sides inscribed in the disc of radius
    ``max_step_length`` (so no foothold beyond the reach is ever proposed), cut, when
    ``min_step_width`` is set, to the half-plane at least that far out on the landing foot's
    side of the stance ankle (a left foot lands on the left of a right stance foot), in the
    frame turned by the stance's yaw.
    """
    disc = regular_polygon(params.max_step_length, REACH_SIDES, phase=yaw)
    if params.min_step_width is None:
        return disc
    outward = 1.0 if side is Stance.LEFT else -1.0
    normal = -outward * np.array([[-math.sin(yaw), math.cos(yaw)]])  # −(lateral, outward)
    cut = clip_halfplanes(disc, normal, np.array([-params.min_step_width]))
    if cut is None:  # pragma: no cover - min_step_width < max_step_length is validated
        raise InvalidParameterError("min_step_width leaves no foothold within the reach")
    return cut


def _other(side: Stance) -> Stance:
    return Stance.RIGHT if side is Stance.LEFT else Stance.LEFT


@dataclass(frozen=True, slots=True, eq=False)
class StepOption:
    """One way to start stepping from a support: which foot lands first, on what it stands.

    Attributes
    ----------
    swing : Stance
        The foot that lands first (LEFT or RIGHT).
    stance : ConvexPolygon
        The support while it swings: the other foot [m].
    ankle : ndarray, shape (2,)
        The stance ankle q_0 [m].
    yaw : float
        The stance foot's yaw, kept by every landing foot [rad].
    """

    swing: Stance
    stance: ConvexPolygon
    ankle: FloatArray
    yaw: float


def step_options(
    params: BodyParams, support: Support, swing: Stance | str | None = None
) -> list[StepOption]:
    """List the ways to step from ``support``: the free foot, or either one from double.

    ``swing`` picks one foot from double support (it must be the free foot otherwise).
    """
    if swing is not None:
        try:
            swing = Stance(swing)
        except ValueError:
            raise InvalidParameterError(f"swing must be 'left' or 'right', got {swing!r}") from None
        if swing is Stance.DOUBLE:
            raise InvalidParameterError("swing must be 'left' or 'right', got 'double'")
        if support.stance is not Stance.DOUBLE and swing is support.stance:
            raise InvalidParameterError(
                f"swing must be the free foot: the {support.stance.value} foot carries the body"
            )
    if support.stance is Stance.DOUBLE:
        sides = [Stance.LEFT, Stance.RIGHT] if swing is None else [swing]
    else:
        sides = [_other(support.stance)]
    options = []
    for side in sides:
        stance = _other(side)
        pose = support.left if stance is Stance.LEFT else support.right
        single = Support.from_params(params, stance, left=support.left, right=support.right)
        options.append(StepOption(side, single.polygon, np.array([pose.x, pose.y]), pose.yaw))
    return options


def _terms(
    params: BodyParams, option: StepOption, touchdowns: tuple[float, ...], hip: bool
) -> tuple[list[tuple[float, Shape]], FloatArray, list[Stance]]:
    """Return the weighted shapes and the offset of (S1), and the landing sides."""
    omega = params.omega
    a = [math.exp(-omega * t) for t in touchdowns] + [0.0]
    terms: list[tuple[float, Shape]] = []
    box = hip_box(params, option.yaw) if hip else None
    terms.append((1.0 if box is not None else 0.0, box if box is not None else np.zeros((1, 2))))
    terms.append((1.0 - a[0], option.stance))
    sides = []
    side = option.swing
    for k in range(len(touchdowns)):
        sides.append(side)
        terms.append((a[k] - a[k + 1], landing_foot(params, side, option.yaw)))
        side = _other(side)
    for k in range(len(touchdowns)):
        terms.append((a[k], reach_polygon(params, sides[k], option.yaw)))
    return terms, a[0] * option.ankle, sides


def _check_touchdowns(params: BodyParams, touchdowns: tuple[float, ...]) -> None:
    previous = 0.0
    for k, t in enumerate(touchdowns):
        finite_float("touchdown", t, "s")
        gap = params.min_step_time if k else 0.0
        if t < previous + gap - 1e-12:
            raise InvalidParameterError(
                f"touchdown {k + 1} at {t:g} s comes sooner than min_step_time "
                f"{params.min_step_time:g} s after the previous one"
            )
        previous = t


def viable_region(
    params: BodyParams,
    option: StepOption,
    touchdowns: tuple[float, ...],
    *,
    hip: bool = True,
) -> ConvexPolygon:
    """C_N of (S1): the capture points that N steps at these touchdown times capture [m].

    Parameters
    ----------
    params : BodyParams
        Body parameters (ω, feet, reach, hip).
    option : StepOption
        Which foot lands first and the stance it leaves (:func:`step_options`).
    touchdowns : tuple of float
        t_1 < ... < t_N [s] from now, at least ``min_step_time`` apart; () gives S ⊕ H.
    hip : bool
        Include the upper body's box H.
    """
    _check_touchdowns(params, touchdowns)
    terms, offset, _ = _terms(params, option, tuple(touchdowns), hip)
    return minkowski_sum(terms, offset)


def landing_viable(params: BodyParams, side: Stance, yaw: float, more: int) -> ConvexPolygon:
    """Return V_more: what the landed ``side`` foot and ``more`` steps capture [m].

    Capture points relative to the landing ankle, touchdowns every Δt_s, without the hip.
    """
    foot = landing_foot(params, side, yaw)
    if more == 0:
        return foot
    option = StepOption(_other(side), foot, np.zeros(2), yaw)
    times = tuple(params.min_step_time * (k + 1) for k in range(more))
    return viable_region(params, option, times, hip=False)


@dataclass(frozen=True, slots=True, eq=False)
class CaptureRegion:
    """Footholds of the first landing foot from which ``steps`` steps capture a state.

    Attributes
    ----------
    polygon : ConvexPolygon or None
        The region of ankle positions of the landing foot [m]; None when empty.
    swing : Stance
        The landing foot.
    touchdown : float
        The (earliest) touchdown time [s] from now.
    timing : str
        ``"exact"``: the foot lands at ``touchdown``; ``"after"``: at any time from then on.
    steps : int
        Steps of the capture, this one included (1: captured on the landing foot).
    foothold : ndarray of shape (2,) or None
        The recommended foothold: the region's Chebyshev centre, the foothold farthest from
        its boundary (the largest margin for a misplaced foot) [m].
    """

    polygon: ConvexPolygon | None
    swing: Stance
    touchdown: float
    timing: str
    steps: int
    foothold: FloatArray | None = field(default=None)

    @property
    def area(self) -> float:
        """Area of the region [m²] (0 when empty)."""
        return 0.0 if self.polygon is None else self.polygon.area

    def margin(self, x: NDArray[np.float64] | float, y: NDArray[np.float64] | float) -> FloatArray:
        """Signed distance of footholds (x, y) to the region [m], + inside, −inf if empty."""
        if self.polygon is None:
            return np.full(np.broadcast(np.asarray(x), np.asarray(y)).shape, -np.inf)
        return self.polygon.signed_distance(x, y)


def capture_region(
    x: float,
    y: float,
    xdot: float,
    ydot: float,
    params: BodyParams,
    support: Support,
    swing_time: float | None = None,
    *,
    steps: int = 1,
    timing: Literal["exact", "after"] = "exact",
    swing: Stance | str | None = None,
    hip: bool = True,
) -> CaptureRegion:
    """Footholds that capture a state with ``steps`` steps, the first landing after swing_time.

    (S3) of the module docstring, intersected with the reach about the stance ankle.

    Parameters
    ----------
    x, y, xdot, ydot : float
        CoM position [m] and velocity [m/s] now, world frame.
    params : BodyParams
        Body parameters.
    support : Support
        The support now; in single support the free foot lands, in double support ``swing``
        or, by default, the foot on the side of the capture point from the ankles' midpoint.
    swing_time : float, optional
        Remaining time to touchdown t >= 0 [s] (mid-swing included); default
        ``min_step_time``.
    steps : int
        1: captured on the landing foot; N: with N − 1 more steps every Δt_s after it.
    timing : {"exact", "after"}
        Touchdown exactly at ``swing_time``, or at any time from then on.
    swing : {"left", "right"}, optional
        The landing foot.
    hip : bool
        Let the upper body help (its box H).

    Returns
    -------
    CaptureRegion
    """
    t = params.min_step_time if swing_time is None else finite_float("swing_time", swing_time, "s")
    if not 0.0 <= t <= 5.0:
        raise InvalidParameterError(f"swing_time must be in [0, 5] s, got {t:g}")
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= 50:
        raise InvalidParameterError(f"steps must be a whole number in [1, 50], got {steps!r}")
    if timing not in ("exact", "after"):
        raise InvalidParameterError(f"timing must be 'exact' or 'after', got {timing!r}")
    xi = _capture_point(x, y, xdot, ydot, params)
    if swing is None and support.stance is Stance.DOUBLE:
        centre = support.ankle
        lateral = -math.sin(support.yaw) * (xi[0] - centre[0]) + math.cos(support.yaw) * (
            xi[1] - centre[1]
        )
        swing = Stance.LEFT if lateral >= 0.0 else Stance.RIGHT
    option = step_options(params, support, swing)[0]
    landing = landing_viable(params, option.swing, option.yaw, steps - 1)
    box = hip_box(params, option.yaw) if hip else None
    boxes: list[tuple[float, Shape]] = [] if box is None else [(1.0, box)]
    ankle_x, ankle_y = (float(v) for v in option.ankle)
    window = reach_polygon(params, option.swing, option.yaw).transformed(ankle_x, ankle_y, 0.0)
    scale = math.exp(params.omega * t)
    at = minkowski_sum(
        [(-scale * w, b) for w, b in boxes] + [(1.0 - scale, option.stance), (-1.0, landing)],
        scale * xi,
    )
    if timing == "exact":
        polygon = clip(at, window)
    else:
        polygon = _after(at, xi, boxes, option.stance, window)
    foothold = None if polygon is None else _chebyshev_centre(polygon)
    return CaptureRegion(polygon, option.swing, t, timing, steps, foothold)


def _capture_point(x: float, y: float, xdot: float, ydot: float, params: BodyParams) -> FloatArray:
    values = [
        finite_float(n, v, u)
        for n, v, u in zip(
            ("x", "y", "xdot", "ydot"), (x, y, xdot, ydot), ("m", "m", "m/s", "m/s"), strict=True
        )
    ]
    for name, value, bound in zip(
        ("x", "y", "xdot", "ydot"), values, (1e3, 1e3, 1e2, 1e2), strict=True
    ):
        if abs(value) > bound:
            raise InvalidParameterError(f"{name} must be in [-{bound:g}, {bound:g}], got {value:g}")
    return np.array([values[0] + values[2] / params.omega, values[1] + values[3] / params.omega])


def _after(
    at: ConvexPolygon,
    xi: FloatArray,
    boxes: list[tuple[float, Shape]],
    stance: ConvexPolygon,
    window: ConvexPolygon,
) -> ConvexPolygon | None:
    """(Q_{T0} ⊕ cone(A)) ∩ window, A = ξ0 ⊕ (−H) ⊕ (−S) (module docstring)."""
    growth = minkowski_sum([(-w, b) for w, b in boxes] + [(-1.0, stance)], xi)
    if float(growth.signed_distance(0.0, 0.0)) > 0.0:
        return window  # already captured without a step: any later foothold
    # The cone's edges: the extreme directions of A's vertices seen from the origin.
    centre = growth.vertices.mean(axis=0)
    base = math.atan2(centre[1], centre[0])
    angles = np.arctan2(growth.vertices[:, 1], growth.vertices[:, 0]) - base
    angles = (angles + math.pi) % (2.0 * math.pi) - math.pi
    rays = growth.vertices[[int(np.argmin(angles)), int(np.argmax(angles))]]
    rays = rays / np.hypot(rays[:, 0], rays[:, 1])[:, None]
    tolerance = 1e-12
    keep = np.all(at.normals @ rays.T <= tolerance, axis=1)
    # Normals of the cone's own edges: perpendicular to a ray, pointing away from the other.
    sides = np.array([[rays[0, 1], -rays[0, 0]], [-rays[1, 1], rays[1, 0]]])
    sides = np.where((np.sum(sides * rays[::-1], axis=1) > 0.0)[:, None], -sides, sides)
    normals = np.vstack([at.normals[keep], sides])
    offsets = np.concatenate([at.offsets[keep], (at.vertices @ sides.T).max(axis=0)])
    return clip_halfplanes(window, normals, offsets)


def _chebyshev_centre(polygon: ConvexPolygon) -> FloatArray:
    """Return the centre of the largest disc in a convex polygon [m].

    The LP max r subject to n_i · q + r <= b_i, solved by a small compiled dual simplex
    (``surfaces._kernels.chebyshev_centre``; scipy's HiGHS if it fails). When the largest disc
    can slide (two parallel edges hold it) the centres form a segment and its midpoint is
    returned: unique, and mirrored with the polygon.
    """
    from pushrecovery.surfaces._kernels import chebyshev_centre

    normals, offsets = polygon.normals, polygon.offsets
    qx, qy, radius, ok = chebyshev_centre(normals, offsets)
    if not ok:  # pragma: no cover - the compiled simplex found no start or did not converge
        from scipy.optimize import linprog

        a_ub = np.column_stack([normals, np.ones(len(offsets))])
        bounds = [(None, None), (None, None), (0.0, None)]
        qx, qy, radius = linprog([0.0, 0.0, -1.0], A_ub=a_ub, b_ub=offsets, bounds=bounds).x
    centre = np.array([qx, qy])
    slack = offsets - normals @ centre - radius
    scale = max(1.0, float(np.abs(polygon.vertices).max()))
    touching = normals[slack < 1e-9 * scale]
    opposite = touching @ touching.T < -1.0 + 1e-9
    if not opposite.any():
        return centre
    # Held by two parallel edges: slide along them as far as the other edges allow.
    i = int(np.argwhere(opposite)[0, 0])
    along = np.array([-touching[i, 1], touching[i, 0]])
    rate = normals @ along
    room = offsets - normals @ centre - radius
    moving = np.abs(rate) > 1e-12
    ends = room[moving] / rate[moving]
    low = float(ends[rate[moving] < 0.0].max(initial=-np.inf))
    high = float(ends[rate[moving] > 0.0].min(initial=np.inf))
    return centre + 0.5 * (low + high) * along


@dataclass(frozen=True, slots=True, eq=False)
class StepPlan:
    """A capturing sequence of steps for one state (:func:`plan_steps_xy`).

    Attributes
    ----------
    steps : int
        Number of steps N (>= 1).
    swings : tuple of Stance
        The landing foot of each step.
    footholds : ndarray, shape (N, 2)
        Ankle positions of the landing feet [m], world frame.
    touchdowns : ndarray, shape (N,)
        Touchdown times from now [s].
    cops : ndarray, shape (N + 1, 2)
        The CoP to hold on each support, the current one first [m].
    hip : ndarray, shape (2,)
        The hip's share of the capture point, ω∫e^{−ωs} c ds [m] (0 without hip).
    margin : float
        Signed distance of the capture point to the region C_N of the plan's timing [m].
    ankle : ndarray, shape (2,)
        The stance ankle the first step leaves [m].
    """

    steps: int
    swings: tuple[Stance, ...]
    footholds: FloatArray
    touchdowns: FloatArray
    cops: FloatArray
    hip: FloatArray
    margin: float
    ankle: FloatArray = field(default_factory=lambda: np.zeros(2))

    def to_dict(self) -> dict[str, object]:
        """JSON form: footholds, touchdown times, landing feet and the CoPs [m, s]."""
        return {
            "steps": self.steps,
            "swing": [side.value for side in self.swings],
            "footholds": self.footholds.tolist(),
            "touchdowns": self.touchdowns.tolist(),
            "cops": self.cops.tolist(),
            "hip": self.hip.tolist(),
            "margin": self.margin,
            "ankle": self.ankle.tolist(),
        }


def plan_steps_xy(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    steps: int,
    *,
    first_touchdown: float | None = None,
    hip: bool = True,
) -> StepPlan:
    """Footholds, touchdowns and CoPs that capture the capture point ξ0 with ``steps`` steps.

    The decomposition of ξ0 in the Minkowski sum (S1) that keeps every term equally deep
    (:func:`~pushrecovery.ground.minkowski.decompose`): when ξ0 ∈ C_N the plan captures the
    LIPM exactly (hold each CoP until the next touchdown, then the last one); outside, it is
    the plan of the nearest boundary point along the ray from C_N's centre and ``margin`` < 0.
    Touchdowns every ``min_step_time`` from ``first_touchdown`` (default: min_step_time).
    """
    first = params.min_step_time if first_touchdown is None else first_touchdown
    times = tuple(first + params.min_step_time * k for k in range(steps))
    _check_touchdowns(params, times)
    terms, offset, sides = _terms(params, option, times, hip)
    total = minkowski_sum(terms, offset)
    points, _ = decompose(xi, terms, offset, total)
    reach = np.cumsum(np.array(points[2 + steps :]), axis=0) + option.ankle
    feet = np.array(points[2 : 2 + steps]) + reach
    cops = np.vstack([points[1], feet])
    return StepPlan(
        steps,
        tuple(sides),
        reach,
        np.array(times),
        cops,
        np.asarray(points[0]) if hip and hip_box(params, option.yaw) is not None else np.zeros(2),
        float(total.signed_distance(xi[0], xi[1])),
        np.array(option.ankle, dtype=np.float64),
    )
