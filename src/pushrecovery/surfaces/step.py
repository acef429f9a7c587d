"""Stepping decision surface (Sec. IV): a single step within reach that recovers, or none.

For a CoM state (x, ẋ) beyond the balancing regions the body steps in the direction of its
capture point. The stance leg (length ``leg_length``) then falls as Hofmann's pendulum. A state
with the CoM at lean θ0 = asin(x/L) and rate θ̇0 lies on the same energy orbit as a start above
the ankle with

    v0² = L² θ̇0² + 2 g L (cos θ0 − 1),

so :mod:`pushrecovery.models.stepping` applies with that v0, the step being taken at an angle
θ ≥ θ0. A step at θ recovers when the post-impact capture point lies inside the new foot
(θ_low < θ < θ_high), the foot lands within reach (2 L sin θ ≤ max_step_length) and the stance
leg is still in compression at the landing (L θ̇² ≤ g cos θ). The recommended step is
Eq. (21)'s θ*, moved into that feasible interval if needed. Backward steps are the mirror
image (heel and toe swapped).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.models.stepping import MAX_STEP_ANGLE, solve_step_angle
from pushrecovery.params import BodyParams

__all__ = ["StepPlan", "plan_steps", "step_critical_velocity", "step_thresholds"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class StepPlan:
    """Step decision for arrays of CoM states; all fields have the states' shape.

    Attributes
    ----------
    direction : ndarray
        +1 step forward, −1 backward (the side of the capture point).
    feasible : ndarray of bool
        A single step within reach recovers the state.
    theta : ndarray
        Recommended stance-leg angle at impact [rad] (NaN where infeasible).
    step_length : ndarray
        Recommended step, foot to foot, signed like ``direction`` [m] (NaN where infeasible).
    shortest, longest : ndarray
        Shortest and longest recovering step within reach, foot to foot, unsigned [m].
    margin : ndarray
        max_step_length minus the shortest recovering step [m]: positive when a step within
        reach exists (−inf when no step length recovers at all).
    """

    direction: FloatArray
    feasible: NDArray[np.bool_]
    theta: FloatArray
    step_length: FloatArray
    shortest: FloatArray
    longest: FloatArray
    margin: FloatArray


def plan_steps(x: ArrayLike, xdot: ArrayLike, params: BodyParams) -> StepPlan:
    """Plan the recovering step for arrays of CoM states (module docstring).

    Parameters
    ----------
    x : array_like
        CoM position relative to the stance ankle [m], |x| < leg_length.
    xdot : array_like
        CoM velocity [m/s].
    params : BodyParams
        Body parameters (leg_length, max_step_length, g, foot edges).

    Returns
    -------
    StepPlan
    """
    x, xdot = np.broadcast_arrays(
        np.asarray(x, dtype=np.float64), np.asarray(xdot, dtype=np.float64)
    )
    length, gravity = params.leg_length, params.gravity
    omega = params.omega
    direction = np.where(x + xdot / omega >= 0.5 * (params.heel + params.toe), 1.0, -1.0)
    # Mirror backward steps: lean and rate positive, heel and toe swapped.
    lean = np.arcsin(np.clip(direction * x / length, -1.0, 1.0))
    lean_rate = direction * xdot / (length * np.cos(lean))
    v0_squared = length**2 * lean_rate**2 + 2.0 * gravity * length * (np.cos(lean) - 1.0)
    moving_on = (lean_rate > 0.0) & (v0_squared > 0.0)
    v0 = np.sqrt(np.where(moving_on, v0_squared, 1.0))
    toe = np.where(direction > 0.0, params.toe, -params.heel)
    heel = np.where(direction > 0.0, params.heel, -params.toe)
    targets = np.stack([np.zeros_like(v0), toe, heel])
    best, low, high = solve_step_angle(v0[None], targets, length, gravity)
    reach = math.asin(min(1.0, params.max_step_length / (2.0 * length)))
    # The stance leg stays in compression up to the angle where L θ̇² = g cos θ, i.e.
    # cos θ_c = (v0²/L + 2g) / (3g); beyond it the foot would have to be pulled down.
    cos_limit = (v0**2 / length + 2.0 * gravity) / (3.0 * gravity)
    compression_limit = np.arccos(np.clip(cos_limit, -1.0, 1.0))
    low = np.maximum(low, lean)
    high = np.minimum(np.minimum(high, min(reach, MAX_STEP_ANGLE)), compression_limit)
    in_compression = (cos_limit < 1.0) & (low <= compression_limit)
    feasible = moving_on & (low < high) & in_compression
    theta = np.where(feasible, np.clip(best, low, high), np.nan)
    shortest = np.where(moving_on, 2.0 * length * np.sin(low), np.nan)
    longest = np.where(feasible, 2.0 * length * np.sin(high), np.nan)
    margin = np.where(moving_on & in_compression, params.max_step_length - shortest, -np.inf)
    return StepPlan(
        direction=direction,
        feasible=feasible,
        theta=theta,
        step_length=direction * 2.0 * length * np.sin(theta),
        shortest=shortest,
        longest=longest,
        margin=margin,
    )


def step_critical_velocity(
    x: float, direction: float, params: BodyParams, *, tolerance: float = 1e-9
) -> float:
    """Largest CoM velocity from position x [m] that one step recovers, signed [m/s].

    Found by bisection on :func:`plan_steps` (feasibility is monotone in the push: a harder push
    needs a longer step and loads the stance leg less).
    """
    sign = 1.0 if direction > 0.0 else -1.0
    low, high = 0.0, math.sqrt(params.gravity * params.leg_length)
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        if bool(plan_steps(x, sign * middle, params).feasible):
            low = middle
        else:
            high = middle
    return sign * low


def step_thresholds(params: BodyParams, *, tolerance: float = 1e-9) -> tuple[float, float]:
    """Largest backward and forward CoM velocity from x = 0 that one step recovers [m/s].

    Returns
    -------
    (v_back, v_fwd) : tuple of float
        Signed: v_back < 0 < v_fwd.
    """
    return (
        step_critical_velocity(0.0, -1.0, params, tolerance=tolerance),
        step_critical_velocity(0.0, 1.0, params, tolerance=tolerance),
    )
