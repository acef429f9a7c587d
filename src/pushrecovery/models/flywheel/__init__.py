r"""LIPM plus flywheel (upper body), Sec. III: Eqs. (6), (7) and (16) as corrected.

State ``[x, theta, xdot, theta_dot]``: CoM position relative to the ankle [m], flywheel
(upper-body pitch) angle [rad], and their rates. Input ``[cop, torque]``: the CoP δ [m] and the
hip torque τ on the flywheel [N m], positive pitching the upper body forward. The reaction of τ
on the legs moves the centroidal moment pivot (CMP) to δ + τ/(m g):

.. math:: \ddot x = \omega^2 \left(x - \delta - \frac{\tau}{m g}\right), \qquad
          I \ddot\theta = \tau,

which is Eq. (6) (ω²/(m g) = 1/(m L)) and Eq. (7). The state derivative on the left of the
printed Eq. (16) repeats (ẋ, θ̇); it is (ẋ, θ̇, ẍ, θ̈) (docs/errata.md, E10).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    float_array,
    non_negative_float,
    positive_float,
    require_type,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import LIMITS, BodyParams

__all__ = [
    "FLYWHEEL_STATE",
    "bang_bang_end_state",
    "bang_bang_switch_time",
    "bang_bang_torque",
    "flywheel_continuous",
    "flywheel_discrete",
    "flywheel_propagate",
    "max_spin_up_time",
]

#: Largest ω dt of one discrete step: cosh(50) = 2.6e21, far from float64 overflow (ω dt ≈ 710).
MAX_OMEGA_DT = 50.0

FloatArray = NDArray[np.float64]

#: The state X of Eq. (16): CoM position, flywheel angle and their rates [m, rad, m/s, rad/s].
FLYWHEEL_STATE = ("x", "theta", "xdot", "theta_dot")


def max_spin_up_time(params: BodyParams) -> float:
    """T_max = sqrt(I θmax / τmax), Eq. (12) [s]: the longest bang-bang half period.

    Returns ``inf`` when τmax = 0 (no hip torque: the flywheel never reaches its limit).
    """
    require_type("params", params, BodyParams)
    if params.torque_max == 0.0:
        return math.inf
    return math.sqrt(params.flywheel_inertia * params.flywheel_angle_max / params.torque_max)


def flywheel_continuous(params: BodyParams) -> tuple[FloatArray, FloatArray]:
    """Continuous-time matrices (A, B) of Eq. (16): Ẋ = A X + B U, X = (x, θ, ẋ, θ̇), U = (δ, τ)."""
    require_type("params", params, BodyParams)
    w2 = params.omega**2
    a = np.zeros((4, 4))
    a[0, 2] = a[1, 3] = 1.0
    a[2, 0] = w2
    b = np.zeros((4, 2))
    b[2, 0] = -w2
    b[2, 1] = -1.0 / (params.mass * params.com_height)
    b[3, 1] = 1.0 / params.flywheel_inertia
    return a, b


def flywheel_discrete(params: BodyParams, dt: float) -> tuple[FloatArray, FloatArray]:
    r"""Exact zero-order-hold discretisation X[k+1] = A X[k] + B U[k] of Eq. (16).

    The CoM part is Eq. (24) with the CMP c = δ + τ/(m g) held; the flywheel is a double
    integrator. With ch = cosh ω dt, sh = sinh ω dt:

    .. math::
        A = \begin{bmatrix} ch & 0 & sh/\omega & 0 \\ 0 & 1 & 0 & dt \\
                            \omega sh & 0 & ch & 0 \\ 0 & 0 & 0 & 1 \end{bmatrix},\quad
        B = \begin{bmatrix} 1 - ch & (1 - ch)/(m g) \\ 0 & dt^2/(2I) \\
                            -\omega sh & -\omega sh/(m g) \\ 0 & dt/I \end{bmatrix}.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    dt : float
        Step [s], in (0, 50/ω] (beyond, cosh ω dt leaves any useful precision).

    Returns
    -------
    A : ndarray, shape (4, 4)
    B : ndarray, shape (4, 2)

    Raises
    ------
    InvalidParameterError
        If ``dt`` is not in (0, 50/ω].
    """
    require_type("params", params, BodyParams)
    omega, weight, inertia = params.omega, params.weight, params.flywheel_inertia
    dt = positive_float("dt", dt, "s")
    if omega * dt > MAX_OMEGA_DT:
        raise InvalidParameterError(
            f"dt must be in (0, {MAX_OMEGA_DT:g}/omega = {MAX_OMEGA_DT / omega:g}] s, got dt={dt:g}"
        )
    ch, sh = math.cosh(omega * dt), math.sinh(omega * dt)
    a = np.array(
        [
            [ch, 0.0, sh / omega, 0.0],
            [0.0, 1.0, 0.0, dt],
            [omega * sh, 0.0, ch, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
    b = np.array(
        [
            [1.0 - ch, (1.0 - ch) / weight],
            [0.0, 0.5 * dt * dt / inertia],
            [-omega * sh, -omega * sh / weight],
            [0.0, dt / inertia],
        ]
    )
    return a, b


def flywheel_propagate(
    states: ArrayLike, inputs: ArrayLike, params: BodyParams, dt: float
) -> FloatArray:
    """Advance arrays of states (..., 4) with inputs (..., 2) held for dt (exact, vectorised).

    Raises
    ------
    InvalidParameterError
        States or inputs that are not finite or not of shape (..., 4) and (..., 2) with
        leading shapes that broadcast, ``dt`` as in :func:`flywheel_discrete`, or states so
        large that the result overflows.
    """
    a, b = flywheel_discrete(params, dt)
    return _propagated(states, inputs, a, b)


def _propagated(states: ArrayLike, inputs: ArrayLike, a: FloatArray, b: FloatArray) -> FloatArray:
    """Return states @ A.T + inputs @ B.T for checked (..., n) states and (..., m) inputs."""
    x = float_array("states", states)
    u = float_array("inputs", inputs)
    for name, array, size in (("states", x, a.shape[0]), ("inputs", u, b.shape[1])):
        if array.ndim == 0 or array.shape[-1] != size:
            raise InvalidParameterError(f"{name} must have shape (..., {size}), got {array.shape}")
    try:
        np.broadcast_shapes(x.shape[:-1], u.shape[:-1])
    except ValueError:
        raise InvalidParameterError(
            f"states {x.shape} and inputs {u.shape} must have leading shapes that broadcast"
        ) from None
    with np.errstate(over="ignore", invalid="ignore"):  # reported below, as one error
        result = x @ a.T + u @ b.T
    if not np.isfinite(result).all():
        finite_array("states", x)
        finite_array("inputs", u)
        raise InvalidParameterError("states or inputs are too large: the result overflows")
    return np.asarray(result, dtype=np.float64)


def bang_bang_torque(t: ArrayLike, switch_time: float, torque_max: float) -> FloatArray:
    """Bang-bang flywheel torque, Eq. (8) as corrected (errata E8) [N m].

    τ = +τmax on [0, T), −τmax on [T, 2T), 0 afterwards, i.e.
    τ(t) = τmax (1 − 2 u(t − T) + u(t − 2T)) with u the unit step.

    Raises
    ------
    InvalidParameterError
        If a time is not finite, ``switch_time`` T is negative or not finite, or
        ``torque_max`` is outside [0, 1e5] N m (:data:`~pushrecovery.params.LIMITS`).
    """
    t = finite_array("t", t)
    switch_time = non_negative_float("switch_time", switch_time, "s")
    torque_max = bounded_float("torque_max", torque_max, *LIMITS["torque_max"])
    return torque_max * np.where(t < switch_time, 1.0, np.where(t < 2.0 * switch_time, -1.0, 0.0))


def bang_bang_end_state(
    x0: ArrayLike,
    xdot0: ArrayLike,
    params: BodyParams,
    *,
    switch_time: float,
    cop: float,
    direction: float = 1.0,
) -> tuple[FloatArray, FloatArray, float, float]:
    r"""State at t = 2T under bang-bang torque and a constant CoP, from θ(0) = θ̇(0) = 0.

    With a = direction · τmax/(m g) the CMP offset and T the switch time (errata E10):

    .. math::
        x(2T) = \delta + (x_0 - \delta)\cosh 2\omega T + \frac{\dot x_0}{\omega}\sinh 2\omega T
                + a(-\cosh 2\omega T + 2\cosh\omega T - 1),

        \dot x(2T) = \omega(x_0 - \delta)\sinh 2\omega T + \dot x_0\cosh 2\omega T
                + a\omega(-\sinh 2\omega T + 2\sinh\omega T),

    θ(2T) = direction · τmax T² / I (Eq. 11) and θ̇(2T) = 0 (Eq. 10).

    Parameters
    ----------
    x0, xdot0 : array_like
        CoM state at t = 0 [m, m/s].
    params : BodyParams
        Body parameters.
    switch_time : float
        T [s], at most :func:`max_spin_up_time` to respect the joint limit.
    cop : float
        CoP δ held on [0, 2T] [m].
    direction : float
        +1 spins the flywheel forward first (for a forward push), −1 backward.

    Returns
    -------
    x, xdot : ndarray
        CoM position [m] and velocity [m/s] at 2T.
    theta, theta_dot : float
        Flywheel angle [rad] and rate [rad/s] at 2T.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        A state or ``cop`` that is not finite, ``direction`` other than ±1, a negative
        ``switch_time`` or one with 2 ω T above 50 (:data:`MAX_OMEGA_DT`: cosh 2ωT leaves any
        useful precision), or a state so large that the result overflows.
    """
    require_type("params", params, BodyParams)
    x0 = finite_array("x0", x0)
    xdot0 = finite_array("xdot0", xdot0)
    switch_time = non_negative_float("switch_time", switch_time, "s")
    if 2.0 * params.omega * switch_time > MAX_OMEGA_DT:
        raise InvalidParameterError(
            f"switch_time must be in [0, {MAX_OMEGA_DT:g}/(2 omega) = "
            f"{MAX_OMEGA_DT / (2.0 * params.omega):g}] s, got {switch_time:g}"
        )
    cop = finite_float("cop", cop, "m")
    direction = _direction(direction)
    with np.errstate(over="ignore", invalid="ignore"):  # reported below, as one error
        x, xdot, theta, rate = _end_state(x0, xdot0, params, switch_time, cop, direction)
    if not (np.isfinite(x).all() and np.isfinite(xdot).all()):
        raise InvalidParameterError("x0, xdot0 or cop are too large: the end state overflows")
    return x, xdot, theta, rate


def _direction(value: float) -> float:
    direction = finite_float("direction", value, allowed="+1 or -1")
    if direction not in (1.0, -1.0):
        raise InvalidParameterError(f"direction must be +1 or -1, got {direction!r}")
    return direction


def _end_state(
    x0: FloatArray,
    xdot0: FloatArray,
    params: BodyParams,
    switch_time: float,
    cop: float,
    direction: float,
) -> tuple[FloatArray, FloatArray, float, float]:
    """:func:`bang_bang_end_state` of checked arguments."""
    omega, t = params.omega, switch_time
    a = direction * params.torque_max / params.weight
    offset = np.asarray(x0, dtype=np.float64) - cop
    xdot0 = np.asarray(xdot0, dtype=np.float64)
    c1, s1 = math.cosh(omega * t), math.sinh(omega * t)
    c2, s2 = math.cosh(2.0 * omega * t), math.sinh(2.0 * omega * t)
    x = cop + offset * c2 + xdot0 / omega * s2 + a * (-c2 + 2.0 * c1 - 1.0)
    xdot = omega * offset * s2 + xdot0 * c2 + a * omega * (-s2 + 2.0 * s1)
    theta = direction * params.torque_max * t * t / params.flywheel_inertia
    return x, xdot, theta, 0.0


def bang_bang_switch_time(
    capture_point: float, target: float, params: BodyParams, *, cop: float, direction: float
) -> float:
    """Shortest bang-bang half period T that moves the capture point to ``target`` at 2T [s].

    From Eq. (13): with y = e^{ωT} and a = direction · τmax/(m g), the capture point at 2T is
    ξ(2T) = δ + y² (ξ0 − δ) − a (y − 1)². Setting ξ(2T) = target gives the quadratic
    (ξ0 − δ − a) y² + 2 a y − (a + target − δ) = 0, whose root y ≥ 1 nearest 1 is used.
    Returns T_max (Eq. 12) when the target cannot be reached within the joint limit, and 0
    when no spin-up is needed.

    Parameters
    ----------
    capture_point : float
        ξ0 [m].
    target : float
        Wanted capture point at 2T [m].
    params : BodyParams
        Body parameters.
    cop : float
        CoP δ held meanwhile [m].
    direction : float
        +1 or −1, sign of the first torque pulse.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        If a position is not finite or ``direction`` is not ±1.
    """
    capture_point = finite_float("capture_point", capture_point, "m")
    target = finite_float("target", target, "m")
    cop = finite_float("cop", cop, "m")
    direction = _direction(direction)
    spin_up = max_spin_up_time(params)
    a = direction * params.torque_max / params.weight
    if a == 0.0:
        return spin_up
    quad, lin, const = capture_point - cop - a, 2.0 * a, -(a + target - cop)
    if abs(quad) < 1e-15:
        roots = [-const / lin]
    else:
        disc = lin * lin - 4.0 * quad * const
        if disc < 0.0:
            return spin_up
        sq = math.sqrt(disc)
        roots = [(-lin - sq) / (2.0 * quad), (-lin + sq) / (2.0 * quad)]
    feasible = [y for y in roots if y >= 1.0]
    if not feasible:
        return 0.0 if (capture_point - target) * direction <= 0.0 else spin_up
    return min(spin_up, math.log(min(feasible)) / params.omega)
