r"""CMP-balancing (hip strategy) decision surface, Eq. (15) as corrected (errata E11).

With the ankle saturated and the flywheel driven bang-bang for T = T_max from rest
(Eqs. 8-12), a state is recoverable when

.. math:: \delta^- - a (1 - e^{-\omega T_{max}})^2 < x + \frac{\dot x}{\omega}
          < \delta^+ + a (1 - e^{-\omega T_{max}})^2, \qquad a = \tau_{max} / (m g).

The printed Eq. (15) has (e^{ωT} − 1)² in place of (1 − e^{−ωT})², a factor e^{2ωT} (7.2 for
the paper preset) too optimistic (docs/errata.md, E11); the bound is also the supremum over
every flywheel controller within abs(τ) ≤ τmax and abs(θ) ≤ θmax from rest (E12).

From a flywheel (upper body) at angle θ0 and rate θ̇0 the two sides differ:
:func:`flywheel_offsets` and :func:`cmp_offset_from` give (Δ⁻, Δ⁺) and :func:`cmp_region_from`
the interval (heel − Δ⁻, toe + Δ⁺) (docs/errata.md, E19).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import bounded_float, finite_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import max_spin_up_time
from pushrecovery.params import LIMITS, OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.cop import CaptureInterval, capture_margin

__all__ = [
    "cmp_margin",
    "cmp_offset",
    "cmp_offset_from",
    "cmp_offset_roll",
    "cmp_region",
    "cmp_region_from",
    "flywheel_offset",
    "flywheel_offsets",
]


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


def flywheel_offsets(
    torque_max: float,
    inertia: float,
    angle_max: float,
    weight: float,
    omega: float,
    theta0: float,
    thetadot0: float,
) -> tuple[float, float]:
    r"""How far one flywheel axis moves the capture point past each edge, from θ0, θ̇0 [m].

    The hip strategy from a flywheel (upper body) at angle θ0 and rate θ̇0 (docs/errata.md,
    E19). The CMP is p = δ + τ/(m g) (positive τ pitches the upper body forward and moves the
    CMP forward) and ξ̇ = ω (ξ − p); with δ held on an edge, the capture point that a torque
    history u = τ/τmax ∈ [−1, 1] brings onto the edge moves by
    a ∫₀^∞ ω e^{−ωt} u(t) dt, a = τmax/(m g). Over every history that keeps abs(θ) ≤ θmax and
    brings the flywheel to rest (θ̇ = 0, the paper's end condition), the largest forward shift
    is reached by full torque forward for t₁⁺, full torque back until t₂⁺ (θ arrives at θmax at
    rest), then holding:

    .. math::
        \Delta^+ = a \left(1 - 2 e^{-\omega t_1^+} + e^{-\omega t_2^+}\right)
                 = a \left[(1 - e^{-\omega t_1^+})^2
                   - e^{-2\omega t_1^+} (1 - e^{-\omega \dot\theta_0/\alpha})\right],

        v^+ = \sqrt{\alpha (\theta_{max} - \theta_0) + \dot\theta_0^2/2}, \quad
        t_1^+ = (v^+ - \dot\theta_0)/\alpha, \quad t_2^+ = (2 v^+ - \dot\theta_0)/\alpha,

    α = τmax/I and v⁺ the peak rate. The backward shift Δ⁻ is the same with (θ0, θ̇0) →
    (−θ0, −θ̇0). Recoverable capture points are δ⁻ − Δ⁻ < ξ < δ⁺ + Δ⁺. At θ0 = θ̇0 = 0,
    t₁ = T_max = sqrt(I θmax/τmax), t₂ = 2 T_max and Δ± = a (1 − e^{−ω T_max})², the corrected
    Eq. (15) (:func:`flywheel_offset`). A shift is negative when the flywheel must first be
    braked against the push (θ̇0 toward the push near the limit); Δ⁻ + Δ⁺ ≥ 0 always.

    Parameters
    ----------
    torque_max, inertia, angle_max : float
        τmax [N m], I [kg m²], θmax [rad] of the axis.
    weight, omega : float
        m g [N] and ω = sqrt(g/L) [1/s].
    theta0 : float
        Flywheel angle [rad], in [−θmax, θmax]; positive forward (the direction of positive τ).
    thetadot0 : float
        Flywheel rate [rad/s], in [−sqrt(2 α (θmax + θ0)), sqrt(2 α (θmax − θ0))]: beyond, no
        torque within τmax stops the flywheel inside its range.

    Returns
    -------
    offset_minus, offset_plus : float
        Δ⁻ (past the heel, backward) and Δ⁺ (past the toe, forward) [m]. (0, 0) when τmax = 0
        (no hip strategy: the flywheel state is then not used, only checked for θ0).

    Raises
    ------
    InvalidParameterError
        A body value outside the ranges of :func:`flywheel_offset`, θ0 outside [−θmax, θmax],
        or θ̇0 not finite or outside its range above (no admissible history exists).
    """
    torque_max = bounded_float("torque_max", torque_max, *LIMITS["torque_max"])
    inertia = bounded_float("inertia", inertia, *LIMITS["flywheel_inertia"])
    angle_max = bounded_float("angle_max", angle_max, *LIMITS["flywheel_angle_max"])
    weight = bounded_float("weight", weight, *_WEIGHT_RANGE, "N")
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    return _flywheel_offsets(torque_max, inertia, angle_max, weight, omega, theta0, thetadot0)


def _flywheel_offsets(
    torque_max: float,
    inertia: float,
    angle_max: float,
    weight: float,
    omega: float,
    theta0: object,
    thetadot0: object,
) -> tuple[float, float]:
    """:func:`flywheel_offsets` of checked body values (θ0, θ̇0 checked here)."""
    theta = bounded_float("theta0", theta0, -angle_max, angle_max, "rad")
    rate = finite_float("thetadot0", thetadot0, "rad/s")
    if torque_max == 0.0:
        return 0.0, 0.0
    accel = torque_max / inertia
    # Largest rates the flywheel can still stop from inside the range: θ0 ± θ̇0²/(2α) ≤ θmax.
    low = -math.sqrt(2.0 * accel * (angle_max + theta))
    high = math.sqrt(2.0 * accel * (angle_max - theta))
    if not low <= rate <= high:
        raise InvalidParameterError(
            f"thetadot0 must be in [{low:g}, {high:g}] rad/s at theta0={theta:g} rad (no torque "
            f"within torque_max={torque_max:g} N m stops the flywheel inside "
            f"[-{angle_max:g}, {angle_max:g}] rad), got thetadot0={rate:g}"
        )
    scale = torque_max / weight
    return (
        scale * _shift(omega, accel, angle_max + theta, -rate),
        scale * _shift(omega, accel, angle_max - theta, rate),
    )


def _shift(omega: float, accel: float, room: float, rate: float) -> float:
    """∫ω e^{−ωt} u dt of the optimal history toward a limit ``room`` [rad] away, at ``rate``."""
    peak = math.sqrt(accel * room + 0.5 * rate * rate)
    first = max(peak - rate, 0.0) / accel  # t₁ ≥ 0 (rounding at the range's edge)
    lead = -math.expm1(-omega * first)  # 1 − e^{−ω t₁}
    return lead * lead + (1.0 - lead) ** 2 * math.expm1(-omega * rate / accel)


def cmp_offset_from(
    params: BodyParams, theta0: float, thetadot0: float, *, axis: str = "pitch"
) -> tuple[float, float]:
    """Hip-strategy offsets past the heel and the toe from the upper body's state [m].

    :func:`flywheel_offsets` for the body's pitch axis (x; θ0, θ̇0 the upper-body pitch [rad],
    [rad/s], positive forward) or, with ``axis="roll"``, its roll axis (y; positive toward the
    left, the CMP moving to +y). Returns (Δ⁻, Δ⁺); the CMP region is
    (heel − Δ⁻, toe + Δ⁺) along the axis. Equals (:func:`cmp_offset`, :func:`cmp_offset`) at
    θ0 = θ̇0 = 0.

    Raises
    ------
    InvalidParameterError
        θ0 outside [−θmax, θmax], θ̇0 outside the rates from which the flywheel can stop inside
        its range (:func:`flywheel_offsets`), non-finite values, or an unknown ``axis``.
    """
    require_type("params", params, BodyParams)
    require_type("axis", axis, str)
    if axis == "pitch":
        limits = (params.torque_max, params.flywheel_inertia, params.flywheel_angle_max)
    elif axis == "roll":
        limits = (
            params.torque_max_roll,
            params.flywheel_inertia_roll,
            params.flywheel_angle_max_roll,
        )
    else:
        raise InvalidParameterError(f"axis must be 'pitch' or 'roll', got {axis!r}")
    return _flywheel_offsets(*limits, params.weight, params.omega, theta0, thetadot0)


def cmp_region_from(params: BodyParams, theta0: float, thetadot0: float) -> CaptureInterval:
    """Capture-point bounds of CMP balancing from the upper body's pitch θ0, θ̇0 [m].

    (heel − Δ⁻, toe + Δ⁺) with :func:`cmp_offset_from`; :func:`cmp_region` at θ0 = θ̇0 = 0.
    """
    minus, plus = cmp_offset_from(params, theta0, thetadot0)
    return CaptureInterval(params.heel - minus, params.toe + plus)


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
