r"""Linear inverted pendulum model (LIPM) with a movable centre of pressure, Sec. II.

The CoM moves at constant height L; with the CoP at δ the horizontal dynamics are

.. math:: \ddot x = \omega^2 (x - \delta), \qquad \omega^2 = g / L,

which is Eq. (3) with the CoP anywhere on the foot and Eq. (23) with f = -ω² δ. All functions
broadcast over arrays of states. State order is ``[x, xdot]``: CoM position relative to the
ankle [m] and CoM velocity [m/s], x forward.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    MAX_MAGNITUDE,
    bounded_float,
    broadcast,
    finite_array,
    finite_float,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN

__all__ = [
    "ANKLE_STATE",
    "lipm_acceleration",
    "lipm_state",
    "lipm_transition",
]

#: Largest ω t the closed forms take: e^50 = 5e21, far from float64 overflow (ω t ≈ 710).
MAX_OMEGA_T = 50.0


FloatArray = NDArray[np.float64]

#: The state of the ankle models (LIPM, pendulum): CoM position and velocity [m, m/s].
ANKLE_STATE = ("x", "xdot")


def lipm_acceleration(x: ArrayLike, cop: ArrayLike, omega: float) -> FloatArray:
    """CoM acceleration of the LIPM, Eq. (3) with the CoP at ``cop``.

    Parameters
    ----------
    x : array_like
        CoM position relative to the ankle [m].
    cop : array_like
        CoP position δ relative to the ankle [m].
    omega : float
        LIPM natural frequency sqrt(g / L) [1/s].

    Returns
    -------
    ndarray
        ẍ = ω² (x − δ) [m/s²]; positive accelerates the CoM forward.
    """
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    big = MAX_MAGNITUDE  # beyond, ω² (x − δ) overflows
    x, cop = broadcast(x=finite_array("x", x, big, "m"), cop=finite_array("cop", cop, big, "m"))
    return omega**2 * (x - cop)


def lipm_state(
    t: ArrayLike, x0: ArrayLike, xdot0: ArrayLike, cop: ArrayLike, omega: float
) -> tuple[FloatArray, FloatArray]:
    r"""Closed-form LIPM state at time t with the CoP held at δ, Eq. (24).

    Eq. (24) with f / ω² = −δ reads

    .. math:: x(t) = \delta + (x_0 - \delta)\cosh\omega t
              + \frac{\dot x_0}{\omega}\sinh\omega t,

    and its derivative gives the velocity
    :math:`\dot x(t) = \omega (x_0 - \delta)\sinh\omega t + \dot x_0\cosh\omega t`.

    Parameters
    ----------
    t : array_like
        Time since (x0, xdot0) [s].
    x0, xdot0 : array_like
        Initial CoM position [m] and velocity [m/s].
    cop : array_like
        Constant CoP δ [m].
    omega : float
        sqrt(g / L) [1/s].

    Returns
    -------
    x, xdot : ndarray
        CoM position [m] and velocity [m/s] at t, broadcast over the inputs.
    """
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    times = finite_array("t", t)
    if times.size and float(np.max(np.abs(times))) > MAX_OMEGA_T / omega:  # before ω t overflows
        raise InvalidParameterError(
            f"|t| must be <= {MAX_OMEGA_T:g}/omega = {MAX_OMEGA_T / omega:g} s, got t={t!r}"
        )
    big = MAX_MAGNITUDE  # beyond, the terms times cosh(ω t) <= e^50 overflow
    start, cop, xdot0, times = broadcast(
        x0=finite_array("x0", x0, big, "m"),
        cop=finite_array("cop", cop, big, "m"),
        xdot0=finite_array("xdot0", xdot0, big, "m/s"),
        t=times,
    )
    wt = omega * times
    offset = start - cop
    cosh, sinh = np.cosh(wt), np.sinh(wt)
    x = cop + offset * cosh + xdot0 / omega * sinh
    xdot = omega * offset * sinh + xdot0 * cosh
    return x, xdot


def lipm_transition(omega: float, dt: float) -> tuple[FloatArray, FloatArray]:
    r"""Exact zero-order-hold discretisation of the LIPM over one step dt.

    With the CoP held constant over the step, Eq. (24) is linear in (x, ẋ, δ):
    ``X[k+1] = A X[k] + B δ[k]`` with

    .. math:: A = \begin{bmatrix} c & s/\omega \\ \omega s & c \end{bmatrix},\quad
              B = \begin{bmatrix} 1 - c \\ -\omega s \end{bmatrix},\quad
              c = \cosh\omega\,dt,\ s = \sinh\omega\,dt.

    Parameters
    ----------
    omega : float
        sqrt(g / L) [1/s].
    dt : float
        Step length [s].

    Returns
    -------
    A : ndarray, shape (2, 2)
    B : ndarray, shape (2,)
    """
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    dt = finite_float("dt", dt, "s")
    if abs(dt) > MAX_OMEGA_T / omega:
        raise InvalidParameterError(
            f"|dt| must be <= {MAX_OMEGA_T:g}/omega = {MAX_OMEGA_T / omega:g} s, got dt={dt:g}"
        )
    c, s = np.cosh(omega * dt), np.sinh(omega * dt)
    return np.array([[c, s / omega], [omega * s, c]]), np.array([1.0 - c, -omega * s])
