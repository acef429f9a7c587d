"""Stepping decision surface (Sec. IV): a single step within reach that recovers, or none.

For a CoM state (x, ẋ) beyond the balancing regions the body steps in the direction of its
capture point. The stance leg (the ankle-to-CoM segment, l = sqrt(x² + L²)) then falls as
Hofmann's pendulum from its lean θ0 with rate θ̇0; energy gives
θ̇(θ)² = θ̇0² + 2 (g/l)(cos θ0 − cos θ) for θ ≥ θ0, so :mod:`pushrecovery.models.stepping`
applies, with the step taken at an angle θ ≥ θ0 (slow falls below the top of the pendulum
included). A step at θ recovers when the post-impact capture point lies inside the new foot
(θ_low < θ < θ_high), the foot lands within reach (2 l sin θ ≤ max_step_length) and the stance
leg is still in compression at the landing (l θ̇² ≤ g cos θ). The recommended step is Eq. (21)'s
θ*, moved into that feasible interval if needed. Backward steps are the mirror image (heel and
toe swapped).
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

#: Shortest step that counts as a step, foot to foot [m].
MIN_STEP_LENGTH = 0.05


@dataclass(frozen=True, slots=True)
class StepPlan:
    """Step decision for arrays of CoM states; all fields have the states' shape.

    Attributes
    ----------
    direction : ndarray
        +1 step forward, −1 backward (the side of the capture point).
    ready : ndarray of bool
        The CoM falls toward that side, so a step can be taken now.
    feasible : ndarray of bool
        A single step within reach recovers the state.
    theta : ndarray
        Recommended stance-leg angle at impact [rad] (NaN where not ready). Where infeasible it
        is the best effort: the admissible angle whose capture point lands nearest the foot.
    step_length : ndarray
        Recommended step, foot to foot, signed like ``direction`` [m] (NaN where not ready).
    shortest, longest : ndarray
        Shortest and longest recovering step within reach, foot to foot, unsigned [m].
    margin : ndarray
        max_step_length minus the shortest recovering step [m]: positive when a step within
        reach exists (−inf when no step length recovers at all).
    """

    direction: FloatArray
    ready: NDArray[np.bool_]
    feasible: NDArray[np.bool_]
    theta: FloatArray
    step_length: FloatArray
    shortest: FloatArray
    longest: FloatArray
    margin: FloatArray


def plan_steps(x: ArrayLike, xdot: ArrayLike, params: BodyParams) -> StepPlan:
    """Plan the recovering step for arrays of CoM states (module docstring).

    The stance leg is the ankle-to-CoM segment as it stands, l = sqrt(x² + L²) with L =
    ``com_height``, leaning θ0 = atan2(x, L); when it locks to fall as a pendulum only the
    tangential part of the CoM velocity survives, θ̇0 = ẋ cos θ0 / l. This is exactly what
    :class:`~pushrecovery.sim.plants.SteppingPlant` does.

    Parameters
    ----------
    x : array_like
        CoM position relative to the stance ankle [m].
    xdot : array_like
        CoM velocity [m/s].
    params : BodyParams
        Body parameters (com_height, max_step_length, g, foot edges).

    Returns
    -------
    StepPlan
    """
    x, xdot = np.broadcast_arrays(
        np.asarray(x, dtype=np.float64), np.asarray(xdot, dtype=np.float64)
    )
    gravity, height = params.gravity, params.com_height
    direction = np.where(x + xdot / params.omega >= 0.5 * (params.heel + params.toe), 1.0, -1.0)
    # Mirror backward steps: positive lean toward the step, heel and toe swapped.
    length = np.hypot(x, height)
    lean = np.arctan2(direction * x, height)
    lean_rate = direction * xdot * np.cos(lean) / length
    omega2 = gravity / length
    energy = lean_rate**2 - 2.0 * omega2 * (1.0 - np.cos(lean))  # θ̇² at θ = 0, signed
    ready = (lean_rate > 0.0) & ((energy > 0.0) | (lean > 0.0))
    toe = np.where(direction > 0.0, params.toe, -params.heel)
    heel = np.where(direction > 0.0, params.heel, -params.toe)
    # Solve in units of l (ξ⁺/l depends on θ̇/ω_l only), so each state may have its own leg.
    scaled = np.where(ready, energy / omega2, 1.0)
    targets = np.stack([np.zeros_like(x), toe / length, heel / length])
    best, low, high = _solve(scaled, np.maximum(lean, 0.0), targets)
    reach = np.arcsin(np.minimum(1.0, params.max_step_length / (2.0 * length)))
    # The stance leg stays in compression up to the angle where l θ̇² = g cos θ, i.e.
    # cos θ_c = (l θ̇0² + 2 g) / (3 g) with θ̇0 the upright-equivalent rate.
    cos_limit = (length * np.where(ready, energy, 0.0) + 2.0 * gravity) / (3.0 * gravity)
    allowed = np.minimum(
        np.minimum(reach, MAX_STEP_ANGLE), np.arccos(np.clip(cos_limit, -1.0, 1.0))
    )
    # A step needs room: at least MIN_STEP_LENGTH within reach and compression (leaning past
    # the reach, or with a leg about to pull, no step can be placed).
    ready &= (np.maximum(lean, 0.0) <= allowed) & (
        2.0 * length * np.sin(allowed) >= MIN_STEP_LENGTH
    )
    low = np.maximum(low, lean)
    high = np.minimum(high, allowed)
    in_compression = (cos_limit < 1.0) & (low <= allowed)
    feasible = ready & (low < high) & in_compression
    # Best effort where infeasible: the admissible angle nearest Eq. (21)'s.
    lowest = np.maximum(lean, 0.0)
    theta = np.where(ready, np.clip(best, lowest, np.maximum(allowed, lowest)), np.nan)
    theta = np.where(feasible, np.clip(best, low, high), theta)
    shortest = np.where(ready, 2.0 * length * np.sin(low), np.nan)
    longest = np.where(feasible, 2.0 * length * np.sin(high), np.nan)
    margin = np.where(ready & in_compression, params.max_step_length - shortest, -np.inf)
    return StepPlan(
        direction=direction,
        ready=ready,
        feasible=feasible,
        theta=theta,
        step_length=direction * 2.0 * length * np.sin(theta),
        shortest=shortest,
        longest=longest,
        margin=margin,
    )


def _solve(scaled_energy: FloatArray, lean: FloatArray, targets: FloatArray) -> FloatArray:
    """ξ⁺(θ) = target in units of the leg (l = 1, g = 1), from a lean and its energy."""
    rate = np.sqrt(np.maximum(scaled_energy + 2.0 * (1.0 - np.cos(lean)), 0.0))
    return solve_step_angle(0.0, targets, 1.0, 1.0, lean=lean, lean_rate=rate)


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
