"""The exact capture region of the discretised flywheel model, as a linear program.

The dynamics (Eq. 16, exact zero-order hold) and every constraint (CoP on the foot, abs(τ) ≤ τmax,
abs(θ) ≤ θmax) are linear, so the largest capture point from which *some* admissible input sequence
reaches a captured state is a linear program. This is an independent check of the bang-bang
bound (corrected Eq. 15) that assumes nothing about the shape of the optimal input.

Captured state at the horizon: capture point on the foot (CoP balancing takes over, Eq. 4) and
the flywheel at rest within its limit. The LP restricts inputs to piecewise constants on a grid
of ``dt`` (a subset of all inputs) and checks abs(θ) ≤ θmax at the samples and at three interior
points of each step, where θ is a parabola. Between check points the parabola can exceed θmax
by at most u h²/8 (u = τmax/I, h = dt/4): 8e-6 rad at dt = 0.01 s for the paper preset. So the
LP value is below the supremum for a limit θmax + u h²/8, and it approaches the continuous-time
supremum as dt → 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, positive_float, require_type
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.lp.plane import grid_steps
from pushrecovery.surfaces.cop import capture_point

__all__ = ["CaptureLP", "largest_capture_point"]


@dataclass(frozen=True, slots=True)
class CaptureLP:
    """Solution of the capture LP.

    Attributes
    ----------
    capture_point : float
        Largest capturable capture point in the push direction [m] (signed).
    cops, torques : ndarray, shape (N,)
        The optimal inputs [m], [N m].
    states : ndarray, shape (N + 1, 4)
        The optimal trajectory ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s].
    dt : float
        Grid step [s].
    """

    capture_point: float
    cops: NDArray[np.float64]
    torques: NDArray[np.float64]
    states: NDArray[np.float64]
    dt: float


def largest_capture_point(
    params: BodyParams, *, direction: float = 1.0, dt: float = 0.01, horizon: float = 3.0
) -> CaptureLP:
    """Largest capture point the flywheel model can capture, by linear programming.

    Starts from x = 0 with the flywheel at rest and maximises direction · ẋ(0) (so the capture
    point ẋ(0)/ω) subject to the exact discrete dynamics, δ⁻ ≤ δ_k ≤ δ⁺, abs(τ_k) ≤ τmax,
    abs(θ_k) ≤ θmax, and at the horizon δ⁻ ≤ ξ_N ≤ δ⁺, θ̇_N = 0. Only the capture point matters
    (the bound is on ξ), so starting at x = 0 loses no generality.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    direction : float
        +1 for forward pushes (upper bound), −1 for backward (lower bound).
    dt : float
        Input grid step [s].
    horizon : float
        Time allowed to reach a captured state [s].

    Returns
    -------
    CaptureLP
    """
    require_type("params", params, BodyParams)
    from scipy.optimize import linprog

    direction = finite_float("direction", direction)
    if direction not in (1.0, -1.0):
        raise InvalidParameterError(f"direction must be +1 or -1, got {direction!r}")
    dt = positive_float("dt", dt, "s")
    steps = grid_steps(positive_float("horizon", horizon, "s"), dt)
    a, b = flywheel_discrete(params, dt)
    # State k is affine in the decision vector z = (ẋ0, δ_0, τ_0, ..., δ_{N-1}, τ_{N-1}):
    # X_k = S_k z. Build S_k forward with the dynamics.
    size = 1 + 2 * steps
    s = np.zeros((steps + 1, 4, size))
    s[0, 2, 0] = 1.0  # X_0 = (0, 0, ẋ0, 0)
    for k in range(steps):
        s[k + 1] = a @ s[k]
        s[k + 1][:, 1 + 2 * k : 3 + 2 * k] += b
    omega = params.omega
    # θ inside step k at offset h: θ_k + θ̇_k h + τ_k h² / (2 I), linear in z.
    inside = []
    for fraction in (0.25, 0.5, 0.75):
        h = fraction * dt
        rows = s[:-1, 1, :] + h * s[:-1, 3, :]
        rows[np.arange(steps), 2 + 2 * np.arange(steps)] += h * h / (2 * params.flywheel_inertia)
        inside.append(rows)
    theta_rows = np.vstack([s[1:, 1, :], *inside])
    capture_end = capture_point(s[steps, 0, :], s[steps, 2, :], omega)
    a_ub = np.vstack([theta_rows, -theta_rows, capture_end, -capture_end])
    b_ub = np.concatenate(
        [np.full(2 * len(theta_rows), params.flywheel_angle_max), [params.toe, -params.heel]]
    )
    bounds = [(None, None)] + [
        pair
        for _ in range(steps)
        for pair in ((params.heel, params.toe), (-params.torque_max, params.torque_max))
    ]
    cost = np.zeros(size)
    cost[0] = -np.sign(direction)
    result = linprog(
        cost,
        A_ub=a_ub,
        b_ub=b_ub,
        A_eq=s[steps, 3, :][None, :],
        b_eq=[0.0],
        bounds=bounds,
        method="highs",
    )
    if result.status != 0:  # pragma: no cover - the LP is always feasible (z = 0)
        raise PushRecoveryError(f"capture LP failed: {result.message}")
    z = result.x
    states = s @ z
    return CaptureLP(float(z[0] / omega), z[1::2], z[2::2], states, dt)
