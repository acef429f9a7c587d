r"""CMP-balancing (hip strategy) decision surface, Eq. (15) as corrected (errata E11).

With the ankle saturated and the flywheel driven bang-bang for T = T_max from rest
(Eqs. 8-12), a state is recoverable when

.. math:: \delta^- - a (1 - e^{-\omega T_{max}})^2 < x + \frac{\dot x}{\omega}
          < \delta^+ + a (1 - e^{-\omega T_{max}})^2, \qquad a = \tau_{max} / (m g).

The printed Eq. (15) has (e^{ωT} − 1)² in place of (1 − e^{−ωT})², a factor e^{2ωT} (7.2 for
the paper preset) too optimistic (docs/errata.md, E11); the bound is also the supremum over
every flywheel controller within abs(τ) ≤ τmax and abs(θ) ≤ θmax from rest (E12).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.models.flywheel import max_spin_up_time
from pushrecovery.params import LIMITS, OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.cop import CaptureInterval, capture_margin

__all__ = ["cmp_margin", "cmp_offset", "cmp_offset_roll", "cmp_region", "flywheel_offset"]


#: m g over the bodies :data:`~pushrecovery.params.LIMITS` admits [N].
_WEIGHT_RANGE = (
    LIMITS["mass"][0] * LIMITS["gravity"][0],
    LIMITS["mass"][1] * LIMITS["gravity"][1],
)


def flywheel_offset(
    torque_max: float, inertia: float, angle_max: float, weight: float, omega: float
) -> float:
    """How far one flywheel axis moves the capturable capture point past the CoP region [m].

    a (1 − e^{−ω T_max})², a = τmax / (m g), T_max = sqrt(I θmax / τmax) (Eq. 12): corrected
    Eq. (15) for an axis with torque limit τmax [N m], inertia I [kg m²] and joint limit θmax
    [rad], for a body of weight m g [N] and ω = sqrt(g/L) [1/s]. Zero when τmax = 0.

    Raises
    ------
    InvalidParameterError
        If an argument is outside the range of the bodies
        :data:`~pushrecovery.params.LIMITS` admits: τmax in [0, 1e5] N m, I in [1e-6, 1e4]
        kg m², θmax in [1e-3, π] rad, m g in [1e-3, 1e6] N (mass times gravity) and ω in
        [0.1, 100] 1/s.
    """
    torque_max = bounded_float("torque_max", torque_max, *LIMITS["torque_max"])
    inertia = bounded_float("inertia", inertia, *LIMITS["flywheel_inertia"])
    angle_max = bounded_float("angle_max", angle_max, *LIMITS["flywheel_angle_max"])
    weight = bounded_float("weight", weight, *_WEIGHT_RANGE, "N")
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    return _flywheel_offset(torque_max, inertia, angle_max, weight, omega)


def _flywheel_offset(
    torque_max: float, inertia: float, angle_max: float, weight: float, omega: float
) -> float:
    """:func:`flywheel_offset` of a checked body's values (a planar controller's tick)."""
    if torque_max == 0.0:
        return 0.0
    spin_up = math.sqrt(inertia * angle_max / torque_max)
    return torque_max / weight * (1.0 - math.exp(-omega * spin_up)) ** 2


def cmp_offset(params: BodyParams) -> float:
    """How far the hip strategy extends the capture region past each foot edge [m].

    a (1 − e^{−ω T_max})², a = τmax / (m g), corrected Eq. (15), for the pitch axis (x).
    Zero when τmax = 0.
    """
    require_type("params", params, BodyParams)
    if params.torque_max == 0.0:
        return 0.0
    spin_up = max_spin_up_time(params)
    return params.torque_max / params.weight * (1.0 - math.exp(-params.omega * spin_up)) ** 2


def cmp_offset_roll(params: BodyParams) -> float:
    """:func:`cmp_offset` for the roll axis (the CMP moved sideways, y) [m]."""
    require_type("params", params, BodyParams)
    return _flywheel_offset(
        params.torque_max_roll,
        params.flywheel_inertia_roll,
        params.flywheel_angle_max_roll,
        params.weight,
        params.omega,
    )


def cmp_region(params: BodyParams) -> CaptureInterval:
    """Capture-point bounds of CMP balancing, corrected Eq. (15) [m]."""
    require_type("params", params, BodyParams)
    offset = cmp_offset(params)
    return CaptureInterval(params.heel - offset, params.toe + offset)


def cmp_margin(
    x: ArrayLike, xdot: ArrayLike, params: BodyParams, *, out: NDArray[np.float64] | None = None
) -> NDArray[np.float64]:
    """Signed margin of the states to the CMP-balancing surface [m], positive inside.

    Vectorised like :func:`pushrecovery.surfaces.cop.cop_margin`.
    """
    region = cmp_region(params)  # checks params first
    return capture_margin(x, xdot, params.omega, region, out=out)
