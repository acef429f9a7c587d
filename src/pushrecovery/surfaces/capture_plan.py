"""Plans that capture a state with N steps: footholds, touchdown times, CoPs, the hip's share.

The plan decomposes the capture point in the Minkowski sum (S1) of
:mod:`pushrecovery.surfaces.n_step` (docs/steps.md, "Plans").
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_float, finite_vector, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import (
    decompose_unchecked,
    minkowski_sum_loop,
    minkowski_sum_unchecked,
)
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture_region import MAX_CAPTURE_POINT, ORIGIN, step_terms
from pushrecovery.surfaces.n_step import (
    StepOption,
    _check_touchdowns,
    _sum_terms,
    hip_box,
    landing_foot,
)

__all__ = ["CapturePlan", "capture_plan"]

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


def capture_plan(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    steps: int,
    *,
    first_touchdown: float | None = None,
    hip: bool = True,
    margin: float | None = None,
) -> CapturePlan:
    """Footholds, touchdowns and CoPs that capture the capture point ξ0 with ``steps`` steps.

    Step by step, as a controller re-planning at each touchdown would: the first foothold is
    the recommended one of the ``steps``-step foothold region (S3) at the first touchdown (the
    farthest from the region's edges,
    :func:`~pushrecovery.surfaces.capture_region.chebyshev_centre`); the CoP to hold until
    then and the hip's share come from splitting T ξ0 − q_1 over T H ⊕ (T − 1) S ⊕ V_{N−1}
    with every term equally deep (:func:`~pushrecovery.ground.minkowski.decompose`), which
    also gives the capture point at the touchdown; the landing foot is then the stance of a
    plan of N − 1 steps without the hip (its share is spent), every Δt_s. When ξ0 lies in C_N
    the plan captures the LIPM exactly (each CoP held until the next touchdown, then the
    last); when the region is empty, the plan of (S1)'s decomposition along the ray from C_N's
    centre is returned, with ``margin`` < 0. Touchdowns every ``min_step_time`` from
    ``first_touchdown`` (default: min_step_time). ``margin``, when known, skips computing the
    signed distance of ξ0 to C_N (the recursion knows it is inside).

    Raises
    ------
    ParameterTypeError
        If ``params``, ``option`` or ``hip`` has the wrong type.
    InvalidParameterError
        A ξ0 that is not a finite (x, y) within ±``MAX_CAPTURE_POINT`` of the stance ankle
        (:mod:`~pushrecovery.surfaces.capture_region`), ``steps`` not a whole number in
        [1, 50], ``first_touchdown`` outside [0, 5] s, or a non-finite ``margin``.
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
    times = tuple(first + params.min_step_time * k for k in range(steps))
    _check_touchdowns(params, times)
    from pushrecovery.kernels.polygons import decompose_loop, foothold_kernel, loop_signed_distance

    # Everything relative to the stance ankle a: the shapes then repeat from call to call and
    # from step to step, so their stacked forms and sums are kept (_PlanTerms).
    ankle = np.array(option.ankle, dtype=np.float64)
    stance_key = (option.stance.vertices - ankle).tobytes()
    relative = np.asarray(xi, dtype=np.float64) - ankle
    if margin is None:
        loop = _viable_loop(params, option.swing, option.yaw, times, hip, stance_key)
        margin = float(loop_signed_distance(loop, relative[0], relative[1]))
    swing, use_hip, touchdown = option.swing, hip, first
    footholds: list[FloatArray] = []
    cops: list[FloatArray] = []
    sides: list[Stance] = []
    hip_share = np.zeros(2)
    for level in range(steps):
        more = steps - level
        terms = step_terms(params, swing, option.yaw, more, touchdown, use_hip, stance_key)
        vertices, qx, qy, ok = foothold_kernel(
            terms.foot_shapes,
            terms.foot_counts,
            terms.foot_weights,
            terms.scale * relative,
            terms.window_normals,
            terms.window_offsets,
        )
        foothold: FloatArray | None = np.array([qx, qy]) if len(vertices) >= 3 else None
        if not ok:  # pragma: no cover - the compiled simplex found no start: the numpy path
            foothold = _numpy_foothold(
                relative, params, swing, option.yaw, stance_key, more, touchdown, use_hip
            )
        if foothold is None:  # no foothold: (S1)'s decomposition for the rest
            rest = _decomposed(
                relative + ankle,
                params,
                _world_option(swing, option.yaw, stance_key, ankle),
                more,
                tuple(touchdown + params.min_step_time * k for k in range(more)),
                use_hip,
                margin,
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
        stance_key = landing_foot(params, swing, option.yaw).vertices.tobytes()
        swing = Stance.RIGHT if swing is Stance.LEFT else Stance.LEFT
        touchdown, use_hip = params.min_step_time, False
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
    )


@functools.lru_cache(maxsize=256)
def _viable_loop(
    params: BodyParams,
    swing: Stance,
    yaw: float,
    touchdowns: tuple[float, ...],
    hip: bool,
    stance_key: bytes,
) -> FloatArray:
    """C_N's vertex loop relative to the stance ankle (read-only, kept)."""
    stance = np.frombuffer(stance_key, dtype=np.float64).reshape(-1, 2)
    option = StepOption(swing, ConvexPolygon._from_ccw(stance), ORIGIN, yaw)
    terms, offset, _ = _sum_terms(params, option, touchdowns, hip)
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
    from pushrecovery.surfaces.capture_region import _region_loop

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
) -> CapturePlan:
    """Return the plan of (S1)'s decomposition (every term equally deep), for ξ0 outside C_N."""
    terms, offset, sides = _sum_terms(params, option, times, hip)
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
    )
