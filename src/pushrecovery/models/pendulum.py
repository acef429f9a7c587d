r"""Nonlinear single inverted pendulum on a foot, Fig. 3(b).

A point mass m on a massless rod of length L pivots about the ankle, which sits on the floor
(zero ankle height) on a massless foot spanning [δ⁻, δ⁺]. The lean angle θ is positive
forward, so the CoM is at x = L sin θ, z = L cos θ. The ankle torque τ is the torque the foot
exerts on the body, positive for plantar flexion (it pushes the body backward and moves the
CoP forward). Angular momentum about the ankle gives

.. math:: m L^2 \ddot\theta = m g L \sin\theta - \tau .

A CoP command is clipped to the foot and turned into exactly the torque that puts the CoP
there, τ(δ) = δ A / (1 − δ sinθ / L), A = m g cos²θ − m L cosθ θ̇² (the exact normal force,
including the vertical acceleration the LIPM neglects; τ = 0 when A ≤ 0, the foot unloaded).
docs/errata.md, E3, derives it and its generalisation to a hip torque, an ankle height and a
foot mass (:func:`ankle_torque_for_cop`).
"""

from __future__ import annotations

import math

from pushrecovery.arguments import bounded_float, finite_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import LIMITS

__all__ = [
    "ankle_torque_for_cop",
    "com_from_lean",
    "lean_from_com",
    "pendulum_acceleration",
    "pendulum_step",
]


#: Largest lean rate [rad/s]: a thousand times any body's fall (sqrt(g/L) <= 100 1/s).
MAX_RATE = 1e5


def _state(theta: object, theta_rate: object, cop: object, length: float) -> tuple[float, ...]:
    """Return the lean [rad], its rate [rad/s] and a CoP [m] within the leg's reach, checked."""
    theta, theta_rate, cop = (
        finite_float(name, value)
        for name, value in (("theta", theta), ("theta_rate", theta_rate), ("cop", cop))
    )
    if not abs(cop) < length:
        raise InvalidParameterError(f"cop must satisfy |cop| < length = {length:g} m, got {cop:g}")
    if not abs(theta_rate) < MAX_RATE:  # beyond, L θ̇² overflows
        raise InvalidParameterError(
            f"theta_rate must satisfy |theta_rate| < {MAX_RATE:g} rad/s, got {theta_rate:g}"
        )
    return theta, theta_rate, cop


def _body(mass: object, length: object, gravity: object) -> tuple[float, float, float]:
    """M [kg], L [m] and g [m/s²] checked against :data:`~pushrecovery.params.LIMITS`."""
    return (
        bounded_float("mass", mass, *LIMITS["mass"]),
        bounded_float("length", length, *LIMITS["com_height"]),
        bounded_float("gravity", gravity, *LIMITS["gravity"]),
    )


def ankle_torque_for_cop(
    theta: float,
    theta_rate: float,
    cop: float,
    mass: float,
    length: float,
    gravity: float,
    *,
    hip_torque: float = 0.0,
    push_force: float = 0.0,
    ankle_height: float = 0.0,
    foot_mass: float = 0.0,
    foot_centre: float = 0.0,
) -> float:
    """Exact ankle torque that places the CoP at ``cop`` (module docstring) [N m].

    Parameters
    ----------
    theta : float
        Lean angle, positive forward [rad].
    theta_rate : float
        Lean rate [rad/s].
    cop : float
        Desired CoP relative to the ankle, already on the foot [m]; abs(cop) < length.
    mass, length, gravity : float
        m [kg], L [m] (ankle to CoM), g [m/s²].
    hip_torque : float
        Torque on an upper body whose CoM is at the top of the rod [N m], positive pitching
        it forward; 0 for the plain pendulum; within ±1e7.
    push_force : float
        Horizontal force P pushing the CoM [N], positive forward; within ±1e7.
    ankle_height : float
        Height h of the ankle above the sole [m], in [0, L]; 0 in the paper. The friction
        force then has a lever arm too.
    foot_mass, foot_centre : float
        Mass of the foot [kg], in [0, m] (0 in the paper), and the x of its centre of mass
        relative to the ankle [m], within ±L: its weight loads the floor too.

    Returns
    -------
    float
        With h = P = m_f = 0, τ = δ A' / (1 − δ sinθ / L), A' = A + τ_h sinθ / L; in general
        τ = [B − h P + m_f g (δ − c_f) + k (m g sinθ + P cosθ − τ_h / L)] / (1 + k / L),
        k = h cosθ − δ sinθ, B = δ m (g − L cosθ θ̇²) − h m L sinθ θ̇² (docs/errata.md, E3).
        0 when the foot is unloaded (F_z ≤ 0).
    """
    mass, length, gravity = _body(mass, length, gravity)
    theta, theta_rate, cop = _state(theta, theta_rate, cop, length)
    # Bounds far beyond any body's, within which the products stay finite.
    extras = {
        name: bounded_float(name, value, low, high, unit)
        for name, value, low, high, unit in (
            ("hip_torque", hip_torque, -1e7, 1e7, "N m"),
            ("push_force", push_force, -1e7, 1e7, "N"),
            ("ankle_height", ankle_height, 0.0, length, "m"),
            ("foot_mass", foot_mass, 0.0, mass, "kg"),
            ("foot_centre", foot_centre, -length, length, "m"),
        )
    }
    return ankle_torque_for_cop_unchecked(theta, theta_rate, cop, mass, length, gravity, **extras)


def ankle_torque_for_cop_unchecked(
    theta: float,
    theta_rate: float,
    cop: float,
    mass: float,
    length: float,
    gravity: float,
    hip_torque: float = 0.0,
    push_force: float = 0.0,
    ankle_height: float = 0.0,
    foot_mass: float = 0.0,
    foot_centre: float = 0.0,
) -> float:
    """:func:`ankle_torque_for_cop` unchecked: the kernel of the simulators' ticks.

    Its extras may be passed by position: the MuJoCo plants call it at every torque refresh,
    where keywords cost 0.07 µs of its 0.5 µs.
    """
    cos, sin = math.cos(theta), math.sin(theta)
    spin = length * theta_rate * theta_rate
    if ankle_height == 0.0 and hip_torque == 0.0 and push_force == 0.0 and foot_mass == 0.0:
        # The pendulum of Fig. 3(b) (the simulators' hot path): τ = δ A / (1 − δ sinθ / L).
        load = mass * cos * (gravity * cos - spin)
        return cop * load / (1.0 - cop * sin / length) if load > 0.0 else 0.0
    # Moments about the ankle: m L² θ̈ = m g L sinθ + P L cosθ − τ − τ_h; on the foot,
    # τ = δ F_z + h F_x + m_f g (δ − c_f) with F_z = m (g + z̈), F_x = m ẍ − P.
    lever = ankle_height * cos - cop * sin
    torque = (
        cop * mass * (gravity - cos * spin)
        - ankle_height * (mass * sin * spin + push_force)
        + foot_mass * gravity * (cop - foot_centre)
        + lever * (mass * gravity * sin + push_force * cos - hip_torque / length)
    ) / (1.0 + lever / length)
    # The vertical load this torque implies; none can be transmitted by an unloaded foot.
    accel = (mass * gravity * length * sin + push_force * length * cos - torque - hip_torque) / (
        mass * length * length
    )
    load = mass * (gravity - length * (sin * accel + cos * theta_rate * theta_rate))
    return torque if load > 0.0 else 0.0


def pendulum_acceleration(
    theta: float, theta_rate: float, cop: float, mass: float, length: float, gravity: float
) -> float:
    """Lean acceleration θ̈ = g sinθ / L − τ / (m L²) with τ from the CoP [rad/s²].

    Raises
    ------
    InvalidParameterError
        If a value is not finite, or ``mass``, ``length`` or ``gravity`` is outside
        :data:`~pushrecovery.params.LIMITS` (``length`` as ``com_height``).
    """
    mass, length, gravity = _body(mass, length, gravity)
    theta, theta_rate, cop = _state(theta, theta_rate, cop, length)
    return _pendulum_acceleration(theta, theta_rate, cop, mass, length, gravity)


def _pendulum_acceleration(
    theta: float, theta_rate: float, cop: float, mass: float, length: float, gravity: float
) -> float:
    """:func:`pendulum_acceleration` unchecked: the kernel of :func:`pendulum_step`'s RK4."""
    torque = ankle_torque_for_cop_unchecked(theta, theta_rate, cop, mass, length, gravity)
    return gravity * math.sin(theta) / length - torque / (mass * length * length)


def lean_from_com(x: float, xdot: float, length: float) -> tuple[float, float]:
    """Lean angle and rate (θ, θ̇) from the CoM state (x, ẋ); needs abs(x) < L.

    Raises
    ------
    InvalidParameterError
        If a value is not finite, ``length`` is outside [0.01, 10] m, abs(x) >= length or
        abs(xdot) >= :data:`MAX_RATE` length.
    """
    x, xdot = finite_float("x", x, "m"), finite_float("xdot", xdot, "m/s")
    length = bounded_float("length", length, *LIMITS["com_height"])
    if not abs(x) < length:
        raise InvalidParameterError(f"x must satisfy |x| < length = {length:g} m, got {x:g}")
    if not abs(xdot) < MAX_RATE * length:  # as the lean rate's bound
        raise InvalidParameterError(
            f"xdot must satisfy |xdot| < {MAX_RATE:g} length = {MAX_RATE * length:g} m/s, "
            f"got {xdot:g}"
        )
    return lean_from_com_unchecked(x, xdot, length)


def lean_from_com_unchecked(x: float, xdot: float, length: float) -> tuple[float, float]:
    """:func:`lean_from_com` unchecked (a plant's every step)."""
    theta = math.asin(x / length)
    return theta, xdot / (length * math.cos(theta))


def com_from_lean(theta: float, theta_rate: float, length: float) -> tuple[float, float]:
    """CoM state (x, ẋ) = (L sinθ, L cosθ θ̇) from the lean angle and rate.

    Raises
    ------
    InvalidParameterError
        If a value is not finite or ``length`` is outside [0.01, 10] m.
    """
    theta = finite_float("theta", theta, "rad")
    theta_rate = finite_float("theta_rate", theta_rate, "rad/s")
    length = bounded_float("length", length, *LIMITS["com_height"])
    return com_from_lean_unchecked(theta, theta_rate, length)


def com_from_lean_unchecked(theta: float, theta_rate: float, length: float) -> tuple[float, float]:
    """:func:`com_from_lean` unchecked (a plant's every step)."""
    return length * math.sin(theta), length * math.cos(theta) * theta_rate


def pendulum_step(
    theta: float,
    theta_rate: float,
    cop: float,
    dt: float,
    mass: float,
    length: float,
    gravity: float,
    substeps: int = 1,
) -> tuple[float, float]:
    """Advance (θ, θ̇) by dt with the CoP held, classical Runge-Kutta (RK4).

    Parameters
    ----------
    theta, theta_rate : float
        Lean angle [rad] and rate [rad/s].
    cop : float
        CoP held over the step, on the foot [m].
    dt : float
        Step [s].
    mass, length, gravity : float
        m [kg], L [m], g [m/s²].
    substeps : int
        RK4 substeps per dt.

    Returns
    -------
    theta, theta_rate : float
        The state after dt.

    Raises
    ------
    InvalidParameterError
        If a value is not finite, ``dt`` is not in (0, 1] s, ``substeps`` not a whole number
        in [1, 1000], or the body is outside :data:`~pushrecovery.params.LIMITS`.
    """
    dt = bounded_float("dt", dt, 1e-9, 1.0, "s")
    mass, length, gravity = _body(mass, length, gravity)
    theta, theta_rate, cop = _state(theta, theta_rate, cop, length)
    if isinstance(substeps, bool) or not isinstance(substeps, int) or not 1 <= substeps <= 1000:
        raise InvalidParameterError(
            f"substeps must be a whole number in [1, 1000], got {substeps!r}"
        )
    return pendulum_step_unchecked(theta, theta_rate, cop, dt, mass, length, gravity, substeps)


def pendulum_step_unchecked(
    theta: float,
    theta_rate: float,
    cop: float,
    dt: float,
    mass: float,
    length: float,
    gravity: float,
    substeps: int = 1,
) -> tuple[float, float]:
    """:func:`pendulum_step` unchecked: the kernel of the pendulum plants' ticks."""
    h = dt / substeps
    args = (cop, mass, length, gravity)
    for _ in range(substeps):
        k1a = _pendulum_acceleration(theta, theta_rate, *args)
        k2q = theta_rate + 0.5 * h * k1a
        k2a = _pendulum_acceleration(theta + 0.5 * h * theta_rate, k2q, *args)
        k3q = theta_rate + 0.5 * h * k2a
        k3a = _pendulum_acceleration(theta + 0.5 * h * k2q, k3q, *args)
        k4q = theta_rate + h * k3a
        k4a = _pendulum_acceleration(theta + h * k3q, k4q, *args)
        theta += h / 6.0 * (theta_rate + 2.0 * k2q + 2.0 * k3q + k4q)
        theta_rate += h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a)
    return theta, theta_rate
