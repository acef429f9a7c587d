"""Compiled closed loops of the ankle PD on the pendulum and the LIPM, many pushes per call.

Each function repeats, operation for operation, what :func:`~pushrecovery.sim.simulate.simulate`
does for one push with :class:`~pushrecovery.control.ankle.AnklePD` on
:class:`~pushrecovery.sim.plants.PendulumPlant` (RK4, one substep per 1 ms tick) or
:class:`~pushrecovery.sim.plants.LipmPlant` (Eq. 24): the PD's CoP, its clipping and saturation
flag, the plant's step, then the fall test and the rest test at the end of each tick. The same
IEEE operations in the same order give the same numbers; ``tests/test_batched.py`` checks every
row against the one-push loop. Compiled by numba on first use and cached on disk.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.kernels.jit import njit

FloatArray = NDArray[np.float64]

#: Outcome codes of the kernels.
UNDECIDED, RECOVERED, FELL = 0, 1, 2


@njit(cache=True)
def _pd_cop(x: float, xdot: float, length: float, kp: float, kd: float, inv_weight: float) -> float:
    """AnklePD.compute before clipping: τ / (m g) of τ = k_p θ + k_d θ̇."""
    lean = math.asin(max(-1.0, min(1.0, x / length)))
    cos = math.cos(lean)
    lean_rate = xdot / (length * cos) if cos > 0.0 else 0.0
    torque = kp * lean + kd * lean_rate
    return torque * inv_weight


@njit(cache=True)
def _acceleration(
    theta: float, rate: float, cop: float, mass: float, length: float, gravity: float
) -> float:
    """models.pendulum._pendulum_acceleration (its hot path, no hip, no push)."""
    cos, sin = math.cos(theta), math.sin(theta)
    spin = length * rate * rate
    load = mass * cos * (gravity * cos - spin)
    torque = cop * load / (1.0 - cop * sin / length) if load > 0.0 else 0.0
    return gravity * math.sin(theta) / length - torque / (mass * length * length)


@njit(cache=True)
def ankle_pd_pushes(
    pendulum: bool,
    x0: FloatArray,
    xdot0: FloatArray,
    mass: FloatArray,
    length: FloatArray,
    gravity: FloatArray,
    heel: FloatArray,
    toe: FloatArray,
    kp: FloatArray,
    kd: FloatArray,
    dt: float,
    ticks: int,
    rest_ticks: int,
    rest_speed: float,
    code: NDArray[np.int64],
    end: NDArray[np.int64],
    cop_min: FloatArray,
    cop_max: FloatArray,
) -> None:
    """Simulate every push i from (x0[i], xdot0[i]); write its outcome, end step and CoPs.

    ``pendulum``: the pendulum plant (RK4), else the LIPM (Eq. 24). Per push the body (mass,
    length = CoM height, gravity, foot edges) and the PD gains; for all of them the control
    period ``dt`` [s], the ``ticks`` of the run, the rest criterion (``rest_ticks`` ticks at
    |ẋ| <= ``rest_speed``, over the foot, unsaturated). ``end[i]`` is the plant step at which
    the run ended (its time is end * dt).
    """
    half_pi = 0.5 * math.pi
    for i in range(x0.shape[0]):
        m, length_i, g = mass[i], length[i], gravity[i]
        back, front = heel[i], toe[i]
        inv_weight = 1.0 / (m * g)
        omega = math.sqrt(g / length_i)
        cosh, sinh = math.cosh(omega * dt), math.sinh(omega * dt)
        x, xdot = x0[i], xdot0[i]
        low, high = math.inf, -math.inf
        outcome, at_rest, k = UNDECIDED, 0, 0
        while k < ticks:
            raw = _pd_cop(x, xdot, length_i, kp[i], kd[i], inv_weight)
            saturated = raw > front or raw < back
            cop = front if raw > front else (back if raw < back else raw)
            low, high = min(low, cop), max(high, cop)
            if pendulum:
                theta = math.asin(x / length_i)
                rate = xdot / (length_i * math.cos(theta))
                h = dt / 1  # one RK4 substep of at most 1 ms (the plant's max_substep)
                k1a = _acceleration(theta, rate, cop, m, length_i, g)
                k2q = rate + 0.5 * h * k1a
                k2a = _acceleration(theta + 0.5 * h * rate, k2q, cop, m, length_i, g)
                k3q = rate + 0.5 * h * k2a
                k3a = _acceleration(theta + 0.5 * h * k2q, k3q, cop, m, length_i, g)
                k4q = rate + h * k3a
                k4a = _acceleration(theta + h * k3q, k4q, cop, m, length_i, g)
                theta += h / 6.0 * (rate + 2.0 * k2q + 2.0 * k3q + k4q)
                rate += h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a)
                if abs(theta) >= half_pi:
                    theta, rate = math.copysign(half_pi, theta), 0.0
                x, xdot = length_i * math.sin(theta), length_i * math.cos(theta) * rate
            else:
                offset = x - cop
                x, xdot = (
                    cop + offset * cosh + xdot / omega * sinh,
                    omega * offset * sinh + xdot * cosh,
                )
            k += 1
            if (x > front and xdot >= 0.0) or (x < back and xdot <= 0.0):
                outcome = FELL
                break
            resting = not saturated and abs(xdot) <= rest_speed and back < x < front
            at_rest = at_rest + 1 if resting else 0
            if at_rest >= rest_ticks:
                outcome = RECOVERED
                break
        code[i], end[i], cop_min[i], cop_max[i] = outcome, k, low, high
