"""Plans that capture a state with N steps: footholds, touchdown times, CoPs, the hip's share.

The plan decomposes the capture point in the Minkowski sum (S1) of
:mod:`pushrecovery.surfaces.n_step` (docs/steps.md, "Plans").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import (
    Shape,
    decompose,
    minkowski_sum,
    stacked_shapes,
    sum_loop,
)
from pushrecovery.ground.support import Stance
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.n_step import (
    StepOption,
    check_touchdowns,
    hip_box,
    landing_foot,
    landing_viable,
    sum_terms,
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
    """
    from pushrecovery.surfaces.capture_region import foothold_and_centre

    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= 50:
        raise InvalidParameterError(f"steps must be a whole number in [1, 50], got {steps!r}")
    first = params.min_step_time if first_touchdown is None else first_touchdown
    if not 0.0 <= first <= 5.0:  # NaN fails too
        raise InvalidParameterError(f"first_touchdown must be in [0, 5] s, got {first!r}")
    times = tuple(first + params.min_step_time * k for k in range(steps))
    check_touchdowns(params, times)
    if margin is None:
        from pushrecovery.ground._kernels import loop_signed_distance

        terms, offset, _ = sum_terms(params, option, times, hip)
        margin = float(loop_signed_distance(sum_loop(terms, offset), xi[0], xi[1]))
    _, foothold = foothold_and_centre(
        np.asarray(xi), params, option, first, steps, hip, polygon=False
    )
    if foothold is None:
        return _decomposed(xi, params, option, steps, times, hip, margin)
    scale = math.exp(params.omega * first)
    box = hip_box(params, option.yaw) if hip else None
    landing = landing_viable(params, option.swing, option.yaw, steps - 1)
    split: list[tuple[float, Shape]] = [
        (scale, box if box is not None else np.zeros((1, 2))),
        (scale - 1.0, option.stance),
        (1.0, landing),
    ]
    target = scale * np.asarray(xi) - foothold
    share, cop, arrival = _split(target, split)
    hip_share = share if box is not None else np.zeros(2)
    if steps == 1:
        rest_footholds, rest_times, rest_cops = np.zeros((0, 2)), np.zeros(0), arrival[None, :]
        rest_sides: tuple[Stance, ...] = ()
        rest_cops = rest_cops + foothold
    else:
        following = StepOption(
            Stance.RIGHT if option.swing is Stance.LEFT else Stance.LEFT,
            landing_foot(params, option.swing, option.yaw).transformed(
                float(foothold[0]), float(foothold[1]), 0.0
            ),
            np.asarray(foothold, dtype=np.float64),
            option.yaw,
        )
        rest = capture_plan(
            foothold + arrival, params, following, steps - 1, hip=False, margin=margin
        )
        rest_footholds, rest_times, rest_cops = rest.footholds, rest.touchdowns, rest.cops
        rest_sides = rest.swings
    return CapturePlan(
        steps,
        (option.swing, *rest_sides),
        np.vstack([foothold[None, :], rest_footholds]),
        np.concatenate([[first], first + rest_times]),
        np.vstack([cop[None, :], rest_cops]),
        np.asarray(hip_share, dtype=np.float64),
        margin,
        np.array(option.ankle, dtype=np.float64),
    )


def _split(
    target: FloatArray, split: list[tuple[float, Shape]]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Decompose ``target`` in the sum of ``split`` (compiled: a plan does it at every step)."""
    from pushrecovery.ground._kernels import decompose_loop, minkowski_loop

    stacked, counts, weights = stacked_shapes(split)
    origin = np.zeros(2)
    total = minkowski_loop(stacked, counts, weights, origin)
    points, _ = decompose_loop(target, stacked, counts, weights, origin, total)
    return points[0], points[1], points[2]


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
    terms, offset, sides = sum_terms(params, option, times, hip)
    total = minkowski_sum(terms, offset)
    points, _ = decompose(xi, terms, offset, total)
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
