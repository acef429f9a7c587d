r"""Plans that capture a state with N steps: footholds, touchdown times, CoPs, the hip's share.

The plan decomposes the capture point in the Minkowski sum (S1) of
:mod:`pushrecovery.surfaces.n_step` (docs/steps.md, "Plans"). Each plan also says what it
asks of the legs and the ground:

* **crossover** — step k lands on the far side of its stance foot's midline: with the stance
  ankle a_k (a_0 the plan's ``ankle``, then the footholds), its yaw φ_k (the stance yaw, then
  the landing yaw) and the landing ankle q_{k+1}, the lateral offset in the stance foot's frame
  ℓ = −sin φ_k (q − a)_x + cos φ_k (q − a)_y (y left) is negative for a left swing foot or
  positive for a right one, by more than :data:`CROSSOVER_TOLERANCE` (rounding). With
  ``min_step_width`` set the reach excludes such footholds (s ℓ >= min_step_width, s = ±1 for
  a left/right swing foot), so no plan crosses over.
* **ankle torque** — the support's vertical force F_z = m g acts at the CoP p; about the stance
  ankle a (on the ground, as the LIPM places it) its moment is the horizontal vector
  τ = (p − a) × (0, 0, m g) = m g ((p − a)_y, −(p − a)_x, 0), of magnitude m g ‖p − a‖ [N m],
  held through each phase (the horizontal force acts at the ground: no moment about a).
* **friction** — the LIPM's CoM r (height L) obeys m r̈ = F_h with the ground force's line
  through the CoM and the CMP p + c (the hip's CMP offset c): F_h / F_z = (r − p − c) / L,
  so F_h = m ω² (r − p − c), F_z = m g, positive along +x (+y) when the CoM is ahead of
  (left of) the CMP: the ground pushes the body away from the CMP. The force needs
  ‖F_h‖ <= μ F_z, i.e. ‖r − p − c‖ <= μ L. In each phase r − p − c = u cosh ωt + w sinh ωt,
  whose squared norm has the second derivative 2 ‖ṙ‖² + 2 ω² ‖r − p − c‖² >= 0 (convex),
  so its peak over a phase lies at an end: the touchdowns. The CoM follows the plan's CoPs
  with the hip's share delivered as a constant CMP offset until the first touchdown, as
  :func:`~pushrecovery.surfaces.step.impact.plan_impacts` does; the last CoP holds the
  capture point of a plan that captures (``margin`` > 0), where ‖r − p‖ decays as e^{−ωt}
  (a plan with ``margin`` < 0 does not come to rest: its peak covers the touchdowns only).

Over 400 lines on purpose: one concept, a plan, how it is made and what it asks of the robot;
the landing yaw's terms (``_turned_terms``) would shrink to a call if
:func:`~pushrecovery.surfaces.capture.region.step_terms` took a landing yaw.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_float,
    finite_pair,
    finite_vector,
    require_type,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import (
    decompose_unchecked,
    minkowski_sum_loop,
    minkowski_sum_unchecked,
    stacked_shapes,
)
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.region import (
    MAX_CAPTURE_POINT,
    MAX_POSITION,
    MAX_SPEED,
    ORIGIN,
    StepTerms,
    step_terms,
)
from pushrecovery.surfaces.n_step import (
    StepOption,
    _check_touchdowns,
    _sum_terms,
    hip_box,
    landing_foot,
    landing_viable,
    reach_polygon,
)

__all__ = ["CROSSOVER_TOLERANCE", "CapturePlan", "PlanLoads", "capture_plan", "plan_loads"]

#: A landing ankle this close to the stance foot's midline [m] is not a crossover (rounding).
CROSSOVER_TOLERANCE = 1e-9


@dataclass(frozen=True, slots=True)
class PlanLoads:
    """What a plan's CoPs ask of the ankle and the ground (module docstring).

    Attributes
    ----------
    ankle_torques : tuple of float
        m g ‖p_k − a_k‖ of each CoP about its stance ankle, the current support first [N m].
    ankle_torque_peak : float
        Their largest [N m].
    ankle_torque_ok : bool or None
        ``ankle_torque_peak`` <= ``params.ankle_torque_max``; None when not limited.
    horizontal_force_peak : float or None
        Largest ‖F_h‖ = m ω² ‖r − p − c‖ along the plan [N]; None without the CoM.
    friction_ratio_peak : float or None
        ``horizontal_force_peak`` / (μ m g), μ = ``params.friction``; None without μ or CoM.
    friction_ok : bool or None
        ``friction_ratio_peak`` <= 1; None when it is None.
    """

    ankle_torques: tuple[float, ...]
    ankle_torque_peak: float
    ankle_torque_ok: bool | None
    horizontal_force_peak: float | None = None
    friction_ratio_peak: float | None = None
    friction_ok: bool | None = None

    def to_dict(self) -> dict[str, object]:
        """JSON form: every key, null when its limit (or the CoM) is not given."""
        return {
            "ankle_torque_peak": self.ankle_torque_peak,
            "ankle_torque_ok": self.ankle_torque_ok,
            "horizontal_force_peak": self.horizontal_force_peak,
            "friction_ratio_peak": self.friction_ratio_peak,
            "friction_ok": self.friction_ok,
        }


_LOAD_KEYS = tuple(PlanLoads((), 0.0, None).to_dict())

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class CapturePlan:
    """A capturing sequence of steps for one state (:func:`capture_plan`).

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
    yaw : float
        The stance foot's yaw [rad].
    landing_yaw : float
        The yaw of every landing foot [rad] (by default the stance foot's).
    loads : PlanLoads or None
        The ankle torques and ground forces of the CoPs (:func:`plan_loads`).
    """

    steps: int
    swings: tuple[Stance, ...]
    footholds: FloatArray
    touchdowns: FloatArray
    cops: FloatArray
    hip: FloatArray
    margin: float
    ankle: FloatArray = field(default_factory=lambda: np.zeros(2))
    yaw: float = 0.0
    landing_yaw: float = 0.0
    loads: PlanLoads | None = None

    def with_loads(self, loads: PlanLoads | None) -> CapturePlan:
        """Return the same plan with ``loads`` (:func:`plan_loads`)."""
        return CapturePlan(
            self.steps,
            self.swings,
            self.footholds,
            self.touchdowns,
            self.cops,
            self.hip,
            self.margin,
            self.ankle,
            self.yaw,
            self.landing_yaw,
            loads,
        )

    @property
    def ankles(self) -> FloatArray:
        """The stance ankle of each phase, shape (N + 1, 2): ``ankle``, then the footholds [m]."""
        return np.vstack([np.reshape(self.ankle, (1, 2)), self.footholds])

    @property
    def crossovers(self) -> tuple[bool, ...]:
        """Whether each step lands across its stance foot's midline (module docstring)."""
        ankles = self.ankles
        found = []
        for k, side in enumerate(self.swings):
            yaw = self.yaw if k == 0 else self.landing_yaw
            gap = ankles[k + 1] - ankles[k]
            lateral = -math.sin(yaw) * float(gap[0]) + math.cos(yaw) * float(gap[1])
            outward = lateral if side is Stance.LEFT else -lateral
            found.append(outward < -CROSSOVER_TOLERANCE)
        return tuple(found)

    @property
    def crossover(self) -> bool:
        """Whether any step of the plan crosses over (:attr:`crossovers`)."""
        return any(self.crossovers)

    def to_dict(self) -> dict[str, object]:
        """JSON form: footholds, touchdown times, landing feet and the CoPs [m, s].

        Also ``crossover``, ``landing_yaw`` [rad] and the loads of :class:`PlanLoads`
        (``ankle_torque_peak`` [N m], ``ankle_torque_ok``, ``horizontal_force_peak`` [N],
        ``friction_ratio_peak``, ``friction_ok``; null when not known or not limited).
        """
        data: dict[str, object] = {
            "steps": self.steps,
            "swing": [side.value for side in self.swings],
            "footholds": self.footholds.tolist(),
            "touchdowns": self.touchdowns.tolist(),
            "cops": self.cops.tolist(),
            "hip": self.hip.tolist(),
            "margin": self.margin,
            "ankle": self.ankle.tolist(),
            "crossover": self.crossover,
            "landing_yaw": self.landing_yaw,
        }
        data.update(dict.fromkeys(_LOAD_KEYS) if self.loads is None else self.loads.to_dict())
        return data


def plan_loads(
    plan: CapturePlan,
    params: BodyParams,
    position: tuple[float, float] | FloatArray | None = None,
    velocity: tuple[float, float] | FloatArray | None = None,
) -> PlanLoads:
    """Ankle torques and ground forces of a plan's CoPs, checked against the body's limits.

    τ_k = m g ‖p_k − a_k‖ for each CoP p_k about its stance ankle a_k, against
    ``params.ankle_torque_max``; with the CoM state, the largest horizontal ground force
    ‖F_h‖ = m ω² ‖r − p − c‖ along the plan (module docstring: at the touchdowns, the CoM
    following the LIPM with each CoP held) against μ m g, μ = ``params.friction``.

    Parameters
    ----------
    plan : CapturePlan
        The plan (CoPs, footholds, touchdowns, the hip's share).
    params : BodyParams
        The body (m, g, L, the limits).
    position, velocity : (float, float), optional
        The CoM's position [m] and velocity [m/s] now, in the plan's frame; without them
        the forces are not computed (None).

    Raises
    ------
    ParameterTypeError
        If ``plan`` or ``params`` has the wrong type.
    InvalidParameterError
        Only one of ``position`` and ``velocity``, or a position (velocity) that is not a
        finite (x, y) within ±1000 m (±100 m/s).
    """
    require_type("plan", plan, CapturePlan)
    require_type("params", params, BodyParams)
    # On Python floats: a plan has a few phases, and numpy's per-call cost would dominate.
    cops = plan.cops.tolist()
    ankles = [plan.ankle.tolist(), *plan.footholds.tolist()]
    weight = params.weight
    torques = tuple(
        weight * math.hypot(p[0] - a[0], p[1] - a[1]) for p, a in zip(cops, ankles, strict=True)
    )
    peak = max(torques)
    limit = params.ankle_torque_max
    torque_ok = None if limit is None else peak <= limit
    if (position is None) != (velocity is None):
        raise InvalidParameterError("give both position and velocity (the CoM state), or neither")
    if position is None or velocity is None:
        return PlanLoads(torques, peak, torque_ok)
    rx, ry = finite_pair("position", position, MAX_POSITION, "m")
    vx, vy = finite_pair("velocity", velocity, MAX_SPEED, "m/s")
    omega = params.omega
    first = math.exp(-omega * float(plan.touchdowns[0]))
    hx, hy = (h / (1.0 - first) for h in plan.hip.tolist()) if first < 1.0 else (0.0, 0.0)
    start, farthest = 0.0, 0.0
    for k, t in enumerate([*plan.touchdowns.tolist(), None]):
        px, py = cops[k][0] + (hx if k == 0 else 0.0), cops[k][1] + (hy if k == 0 else 0.0)
        farthest = max(farthest, math.hypot(rx - px, ry - py))
        if t is None:  # the last CoP holds the capture point: ‖r − p‖ decays
            break
        c, s = math.cosh(omega * (t - start)), math.sinh(omega * (t - start))
        rx, ry, vx, vy = (
            px + (rx - px) * c + vx / omega * s,
            py + (ry - py) * c + vy / omega * s,
            (rx - px) * omega * s + vx * c,
            (ry - py) * omega * s + vy * c,
        )
        farthest = max(farthest, math.hypot(rx - px, ry - py))
        start = t
    force = params.mass * omega**2 * farthest
    if params.friction is None:
        return PlanLoads(torques, peak, torque_ok, force)
    ratio = force / (params.friction * weight)
    return PlanLoads(torques, peak, torque_ok, force, ratio, ratio <= 1.0)


def capture_plan(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    steps: int,
    *,
    first_touchdown: float | None = None,
    hip: bool = True,
    margin: float | None = None,
    landing_yaw: float | None = None,
    com: tuple[float, float] | FloatArray | None = None,
) -> CapturePlan:
    """Footholds, touchdowns and CoPs that capture the capture point ξ0 with ``steps`` steps.

    Step by step, as a controller re-planning at each touchdown would: the first foothold is
    the recommended one of the ``steps``-step foothold region (S3) at the first touchdown (the
    farthest from the region's edges,
    :func:`~pushrecovery.surfaces.capture.region.chebyshev_centre`); the CoP to hold until
    then and the hip's share come from splitting T ξ0 − q_1 over T H ⊕ (T − 1) S ⊕ V_{N−1}
    with every term equally deep (:func:`~pushrecovery.ground.minkowski.decompose`), which
    also gives the capture point at the touchdown; the landing foot is then the stance of a
    plan of N − 1 steps without the hip (its share is spent), every Δt_s. When ξ0 lies in C_N
    the plan captures the LIPM exactly (each CoP held until the next touchdown, then the
    last); when the region is empty, the plan of (S1)'s decomposition along the ray from C_N's
    centre is returned, with ``margin`` < 0. Touchdowns every ``min_step_time`` from
    ``first_touchdown`` (default: min_step_time). ``margin``, when known, skips computing the
    signed distance of ξ0 to C_N (the recursion knows it is inside).

    Every landing foot takes ``landing_yaw`` [rad] (default: the stance foot's yaw,
    ``option.yaw``): the landing feet F_k of (S1) and the reach of every later step turn with
    it, while the first reach and the hip's box keep the stance's frame. A foot that is not
    rotationally symmetric (every foot here: a rectangle or a polygon) gives a different C_N
    for each landing yaw, so the plan's ``margin`` is that of its landing yaw (the verdicts of
    :class:`~pushrecovery.surfaces.step.regions.StepRegions` assume the stance's yaw). With the
    CoM position ``com`` [m] (its velocity is then ω (ξ0 − com)) the plan's ``loads`` include
    the ground forces (:func:`plan_loads`); the ankle torques need only the CoPs.

    Raises
    ------
    ParameterTypeError
        If ``params``, ``option`` or ``hip`` has the wrong type.
    InvalidParameterError
        A ξ0 that is not a finite (x, y) within ±``MAX_CAPTURE_POINT`` of the stance ankle
        (:mod:`~pushrecovery.surfaces.capture.region`), ``steps`` not a whole number in
        [1, 50], ``first_touchdown`` outside [0, 5] s, a non-finite ``margin``, a
        ``landing_yaw`` outside [−π, π] rad or a ``com`` that is not a finite (x, y) within
        ±1000 m.
    """
    require_type("params", params, BodyParams)
    require_type("option", option, StepOption)
    xi = finite_vector("xi", xi, 2, unit="m")
    if float(np.max(np.abs(xi - option.ankle))) > MAX_CAPTURE_POINT:
        raise InvalidParameterError(
            f"xi must lie within ±{MAX_CAPTURE_POINT:g} m of the stance ankle, got "
            f"{xi.tolist()} (ankle {np.asarray(option.ankle).tolist()})"
        )
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= 50:
        raise InvalidParameterError(f"steps must be a whole number in [1, 50], got {steps!r}")
    first = params.min_step_time if first_touchdown is None else first_touchdown
    first = bounded_float("first_touchdown", first, 0.0, 5.0, "s")
    require_type("hip", hip, (bool, np.bool_))
    hip = bool(hip)
    if margin is not None:
        margin = finite_float("margin", margin, "m")
    landing = option.yaw
    if landing_yaw is not None:
        landing = bounded_float("landing_yaw", landing_yaw, -math.pi, math.pi, "rad")
    if com is not None:
        com = finite_vector("com", com, 2, MAX_POSITION, "m")
    times = tuple(first + params.min_step_time * k for k in range(steps))
    _check_touchdowns(params, times)
    plan = _plan(xi, params, option, steps, times, hip, margin, landing)
    velocity = None if com is None else params.omega * (xi - com)
    return plan.with_loads(plan_loads(plan, params, com, velocity))


def _plan(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    steps: int,
    times: tuple[float, ...],
    hip: bool,
    margin: float | None,
    landing: float,
) -> CapturePlan:
    """:func:`capture_plan` of checked arguments, without the loads."""
    from pushrecovery.kernels.polygons import decompose_loop, foothold_kernel, loop_signed_distance

    # Everything relative to the stance ankle a: the shapes then repeat from call to call and
    # from step to step, so their stacked forms and sums are kept (_PlanTerms).
    ankle = np.array(option.ankle, dtype=np.float64)
    stance_key = (option.stance.vertices - ankle).tobytes()
    relative = np.asarray(xi, dtype=np.float64) - ankle
    if margin is None:
        loop = _viable_loop(params, option.swing, option.yaw, times, hip, stance_key, landing)
        margin = float(loop_signed_distance(loop, relative[0], relative[1]))
    swing, use_hip, touchdown, yaw = option.swing, hip, times[0], option.yaw
    footholds: list[FloatArray] = []
    cops: list[FloatArray] = []
    sides: list[Stance] = []
    hip_share = np.zeros(2)
    for level in range(steps):
        more = steps - level
        if yaw == landing:
            terms = step_terms(params, swing, yaw, more, touchdown, use_hip, stance_key)
        else:
            terms = _turned_terms(params, swing, yaw, landing, more, touchdown, use_hip, stance_key)
        vertices, qx, qy, ok = foothold_kernel(
            terms.foot_shapes,
            terms.foot_counts,
            terms.foot_weights,
            terms.scale * relative,
            terms.window_normals,
            terms.window_offsets,
        )
        foothold: FloatArray | None = np.array([qx, qy]) if len(vertices) >= 3 else None
        if not ok and yaw == landing:  # pragma: no cover - the compiled simplex found no start
            foothold = _numpy_foothold(
                relative, params, swing, yaw, stance_key, more, touchdown, use_hip
            )
        if foothold is None:  # no foothold: (S1)'s decomposition for the rest
            rest = _decomposed(
                relative + ankle,
                params,
                _world_option(swing, yaw, stance_key, ankle),
                more,
                tuple(touchdown + params.min_step_time * k for k in range(more)),
                use_hip,
                margin,
                landing,
            )
            if level == 0:
                return rest
            footholds.extend(rest.footholds)
            cops.extend(rest.cops[:-1])
            sides.extend(rest.swings)
            relative, ankle = rest.cops[-1], np.zeros(2)
            break
        target = terms.scale * relative - foothold
        points, _ = decompose_loop(
            target,
            terms.split_shapes,
            terms.split_counts,
            terms.split_weights,
            ORIGIN,
            terms.split_total,
        )
        if level == 0 and terms.has_box:
            hip_share = points[0].copy()
        cops.append(points[1] + ankle)
        footholds.append(foothold + ankle)
        sides.append(swing)
        # The landed foot is the next stance; its capture point arrives relative to its ankle.
        ankle, relative = ankle + foothold, points[2].copy()
        if more > 1:  # the next step's stance
            stance_key = landing_foot(params, swing, landing).vertices.tobytes()
        swing = Stance.RIGHT if swing is Stance.LEFT else Stance.LEFT
        touchdown, use_hip, yaw = params.min_step_time, False, landing
    cops.append(relative + ankle)  # the last CoP holds the capture point, in the last foot
    return CapturePlan(
        steps,
        tuple(sides),
        np.array(footholds),
        np.array(times),
        np.array(cops),
        hip_share,
        margin,
        np.array(option.ankle, dtype=np.float64),
        option.yaw,
        landing,
    )


@functools.lru_cache(maxsize=64)
def _turned_terms(
    params: BodyParams,
    swing: Stance,
    yaw: float,
    landing: float,
    steps: int,
    touchdown: float,
    hip: bool,
    stance_key: bytes,
) -> StepTerms:
    """Return the terms of :func:`~pushrecovery.surfaces.capture.region.step_terms`, landing turned.

    The landing foot (and V_{N−1}) take the yaw ``landing``; the hip's box and the reach keep
    the stance's ``yaw``. Kept as step_terms' answers are.
    """
    from pushrecovery.kernels.polygons import minkowski_loop

    stance = np.frombuffer(stance_key, dtype=np.float64).reshape(-1, 2)
    remaining = landing_viable(params, swing, landing, steps - 1)
    box = hip_box(params, yaw) if hip else None
    foot: list[tuple[float, object]] = [(1.0, stance), (-1.0, remaining)]
    split: list[tuple[float, object]] = [
        (1.0, box if box is not None else np.zeros((1, 2))),
        (1.0, stance),
        (1.0, remaining),
    ]
    if box is not None:
        foot.append((-1.0, box))
    foot_shapes, foot_counts, _ = stacked_shapes(foot)  # type: ignore[arg-type]
    split_shapes, split_counts, _ = stacked_shapes(split)  # type: ignore[arg-type]
    window = reach_polygon(params, swing, yaw)
    scale = math.exp(params.omega * touchdown)
    weights = (1.0 - scale, -1.0, -scale) if box is not None else (1.0 - scale, -1.0)
    split_weights = np.array((scale, scale - 1.0, 1.0), dtype=np.float64)
    return StepTerms(
        scale,
        box is not None,
        foot_shapes,
        foot_counts,
        np.array(weights, dtype=np.float64),
        window.normals,
        window.offsets,
        split_shapes,
        split_counts,
        split_weights,
        minkowski_loop(split_shapes, split_counts, split_weights, ORIGIN),
    )


@functools.lru_cache(maxsize=256)
def _viable_loop(
    params: BodyParams,
    swing: Stance,
    yaw: float,
    touchdowns: tuple[float, ...],
    hip: bool,
    stance_key: bytes,
    landing: float,
) -> FloatArray:
    """C_N's vertex loop relative to the stance ankle (read-only, kept)."""
    stance = np.frombuffer(stance_key, dtype=np.float64).reshape(-1, 2)
    option = StepOption(swing, ConvexPolygon._from_ccw(stance), ORIGIN, yaw)
    terms, offset, _ = _sum_terms(params, option, touchdowns, hip, landing)
    loop = minkowski_sum_loop(terms, offset)
    loop.flags.writeable = False
    return loop


def _world_option(swing: Stance, yaw: float, stance_key: bytes, ankle: FloatArray) -> StepOption:
    """Return the step option of a relative stance placed at ``ankle``."""
    stance = np.frombuffer(stance_key, dtype=np.float64).reshape(-1, 2) + ankle
    return StepOption(swing, ConvexPolygon._from_ccw(stance), ankle, yaw)


def _numpy_foothold(  # pragma: no cover - only when the compiled simplex fails
    relative: FloatArray,
    params: BodyParams,
    swing: Stance,
    yaw: float,
    stance_key: bytes,
    steps: int,
    touchdown: float,
    hip: bool,
) -> FloatArray | None:
    """Return the recommended foothold relative to the ankle, from the numpy region."""
    from pushrecovery.surfaces.capture.region import _region_loop

    option = _world_option(swing, yaw, stance_key, np.zeros(2))
    _, foothold = _region_loop(
        relative, params, option, np.zeros(2), stance_key, touchdown, steps, hip
    )
    return foothold


def _decomposed(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    steps: int,
    times: tuple[float, ...],
    hip: bool,
    margin: float,
    landing: float,
) -> CapturePlan:
    """Return the plan of (S1)'s decomposition (every term equally deep), for ξ0 outside C_N."""
    terms, offset, sides = _sum_terms(params, option, times, hip, landing)
    total = minkowski_sum_unchecked(terms, offset)
    points, _ = decompose_unchecked(xi, terms, offset, total)
    reach = np.cumsum(np.array(points[2 + steps :]), axis=0) + option.ankle
    feet = np.array(points[2 : 2 + steps]) + reach
    cops = np.vstack([points[1], feet])
    return CapturePlan(
        steps,
        tuple(sides),
        reach,
        np.array(times),
        cops,
        np.asarray(points[0]) if hip and hip_box(params, option.yaw) is not None else np.zeros(2),
        margin,
        np.array(option.ankle, dtype=np.float64),
        option.yaw,
        landing,
    )
