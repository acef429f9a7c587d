"""Synthetic measured trials with known truth: 2-D LIPM pushes written as the analysis' CSV.

For testing an analysis pipeline (the project's tests and ``benchmarks/trials.py`` use it) and
for trying ``pushrecovery analyze`` without a gait lab. A body stands still with its CoM
``x0`` [m] ahead of the ankles; at ``push_time`` its CoM velocity jumps by ``push`` [m/s]
toward ``azimuth`` (0 forward, π/2 to the subject's left); the CoP then follows p = x + 2 ẋ/ω
clipped to the foot's rectangle (ahead of the capture point ξ = x + ẋ/ω by ẋ/ω, which brings
the CoM to rest when the foot allows it: ankle strategy, or a fall). The CoM moves
by the exact zero-order hold of the LIPM (Eq. 24, per axis) at ``rate``; the recording ends
when the CoM is 0.6 m from the ankles (a fall). Columns: time, CoM, CoP and the base of
support (the foot's rectangle) in metres, with Gaussian marker noise of ``noise`` [m] on the CoM.
"""

from __future__ import annotations

import math

import numpy as np

from pushrecovery.arguments import bounded_float, finite_float, require_type, whole_number
from pushrecovery.params import BodyParams

__all__ = ["lipm_trial_csv"]


def lipm_trial_csv(
    params: BodyParams,
    push: float,
    azimuth: float,
    *,
    duration: float = 3.0,
    rate: float = 100.0,
    push_time: float = 1.0,
    x0: float = 0.02,
    noise: float = 1e-4,
    seed: int = 0,
) -> str:
    """Return the CSV text of one synthetic trial (module docstring).

    Parameters
    ----------
    params : BodyParams
        The body: ω = sqrt(g/L), the foot (heel, toe, foot_width).
    push : float
        The push's velocity change [m/s], in [0, 5].
    azimuth : float
        Its direction [rad], finite: 0 forward (+ap), π/2 to the left (+ml).
    duration, rate, push_time : float
        Length [s] in (0, 60], frame rate [Hz] in [10, 10000], push time [s] in [0, duration).
    x0 : float
        The CoM ahead of the ankles before the push [m], within the foot.
    noise : float
        SD of the CoM's marker noise [m], in [0, 0.01].
    seed : int
        Seed of the noise, >= 0.

    Raises
    ------
    InvalidParameterError
        An argument out of its range (named).
    """
    require_type("params", params, BodyParams)
    push = bounded_float("push", push, 0.0, 5.0, "m/s")
    azimuth = finite_float("azimuth", azimuth, "rad")
    duration = bounded_float("duration", duration, 1e-3, 60.0, "s")
    rate = bounded_float("rate", rate, 10.0, 1e4, "Hz")
    push_time = bounded_float("push_time", push_time, 0.0, duration, "s")
    x0 = bounded_float("x0", x0, params.heel, params.toe, "m")
    noise = bounded_float("noise", noise, 0.0, 0.01, "m")
    seed = whole_number("seed", seed, 0, 2**32 - 1)
    omega, dt = params.omega, 1.0 / rate
    rng = np.random.default_rng(seed)
    low = np.array([params.heel, -0.5 * params.foot_width])
    high = np.array([params.toe, 0.5 * params.foot_width])
    ch, sh = math.cosh(omega * dt), math.sinh(omega * dt)
    x, v = np.array([x0, 0.0]), np.zeros(2)
    lines = ["time,com_ap,com_ml,cop_ap,cop_ml,base_ap_min,base_ap_max,base_ml_min,base_ml_max"]
    for k in range(max(1, int(duration * rate))):
        if k == int(push_time * rate):
            v = v + push * np.array([math.cos(azimuth), math.sin(azimuth)])
        cop = np.clip(x + 2.0 * v / omega, low, high)
        com = x + rng.normal(0.0, noise, 2)
        lines.append(
            f"{k * dt:.6f},{com[0]:.6f},{com[1]:.6f},{cop[0]:.6f},{cop[1]:.6f},"
            f"{low[0]},{high[0]},{low[1]},{high[1]}"
        )
        offset = x - cop
        x, v = cop + offset * ch + v / omega * sh, omega * offset * sh + v * ch  # Eq. (24)
        if np.any(np.abs(x) > 0.6):
            break
    return "\n".join(lines) + "\n"
