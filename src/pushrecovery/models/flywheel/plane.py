r"""LIPM plus two flywheels (upper-body pitch and roll) on the ground plane: Sec. III in 2-D.

State ``X = (x, y, θp, θr, ẋ, ẏ, θ̇p, θ̇r)``: CoM position in the world frame [m] (x forward,
y left), the upper body's pitch and roll angles [rad] and their rates. Input
``U = (px, py, τp, τr)``: the CoP p in the world frame [m] and the hip torques [N m] about the
upper body's pitch and roll axes. The body's axes are turned by ``yaw`` [rad] (counter-clockwise)
from the world's: e_p = (cos ψ, sin ψ), e_r = (−sin ψ, cos ψ). A positive pitch torque moves the
CMP along +e_p (as in the sagittal model, ``docs/conventions.md``), a positive roll torque along
+e_r (leaning the upper body toward its left):

.. math:: \ddot{\mathbf r} = \omega^2\Big(\mathbf r - \mathbf p
          - \frac{\tau_p \mathbf e_p + \tau_r \mathbf e_r}{m g}\Big), \qquad
          I_p \ddot\theta_p = \tau_p, \qquad I_r \ddot\theta_r = \tau_r .

Each body axis is the sagittal model of Eq. (16) (:mod:`pushrecovery.models.flywheel`) with that
axis's inertia; the LIPM is isotropic, so the two axes are coupled only through the constraint
on the CoP (the support polygon), never through the dynamics.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import finite_float, require_type
from pushrecovery.models.flywheel import _propagated, flywheel_discrete
from pushrecovery.params import BodyParams

__all__ = [
    "PLANE_STATE_LABELS",
    "plane_continuous",
    "plane_discrete",
    "plane_propagate",
    "roll_axis",
]

FloatArray = NDArray[np.float64]

#: The state X, in order (module docstring).
PLANE_STATE_LABELS = (
    "x",
    "y",
    "theta_pitch",
    "theta_roll",
    "xdot",
    "ydot",
    "theta_pitch_dot",
    "theta_roll_dot",
)


def roll_axis(params: BodyParams) -> BodyParams:
    """``params`` with the roll axis's inertia, torque and joint limits in the pitch fields.

    The 1-D flywheel functions (:func:`~pushrecovery.models.flywheel.max_spin_up_time`,
    :func:`~pushrecovery.models.flywheel.flywheel_discrete`, ...) then describe the roll axis.
    """
    require_type("params", params, BodyParams)
    return dataclasses.replace(
        params,
        flywheel_inertia=params.flywheel_inertia_roll,
        torque_max=params.torque_max_roll,
        flywheel_angle_max=params.flywheel_angle_max_roll,
    )


def _axes(yaw: float) -> FloatArray:
    """Columns e_p, e_r: the body's pitch (forward) and roll (left) axes in the world frame.

    Checks ``yaw`` [rad] (finite), for the public functions that take it.
    """
    yaw = finite_float("yaw", yaw, "rad")
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s], [s, c]])


def plane_continuous(params: BodyParams, yaw: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """Continuous-time matrices (A, B) of the planar model: Ẋ = A X + B U (module docstring)."""
    require_type("params", params, BodyParams)
    w2 = params.omega**2
    a = np.zeros((8, 8))
    a[0:4, 4:8] = np.eye(4)
    a[4, 0] = a[5, 1] = w2
    b = np.zeros((8, 4))
    b[4:6, 0:2] = -w2 * np.eye(2)
    b[4:6, 2:4] = -w2 / params.weight * _axes(yaw)
    b[6, 2] = 1.0 / params.flywheel_inertia
    b[7, 3] = 1.0 / params.flywheel_inertia_roll
    return a, b


def plane_discrete(
    params: BodyParams, dt: float, yaw: float = 0.0
) -> tuple[FloatArray, FloatArray]:
    """Exact zero-order-hold discretisation X[k+1] = A X[k] + B U[k] of the planar model.

    Built from the sagittal ZOH (:func:`~pushrecovery.models.flywheel.flywheel_discrete`) of
    each axis: the CoM rows are the same in x and y (isotropic LIPM) and the torque columns
    are turned into the world frame by the body's axes.

    Parameters
    ----------
    params : BodyParams
        Body parameters (pitch and roll axes).
    dt : float
        Step [s].
    yaw : float
        Heading of the body's pitch axis [rad], counter-clockwise from the world's x.

    Returns
    -------
    A : ndarray, shape (8, 8)
    B : ndarray, shape (8, 4)
    """
    require_type("params", params, BodyParams)
    pitch_a, pitch_b = flywheel_discrete(params, dt)
    _, roll_b = flywheel_discrete(roll_axis(params), dt)
    axes = _axes(yaw)
    a = np.zeros((8, 8))
    b = np.zeros((8, 4))
    for pos, vel in ((0, 4), (1, 5)):  # CoM x and y: rows (x, ẋ) of the sagittal model
        a[pos, pos], a[pos, vel] = pitch_a[0, 0], pitch_a[0, 2]
        a[vel, pos], a[vel, vel] = pitch_a[2, 0], pitch_a[2, 2]
        b[pos, pos], b[vel, pos] = pitch_b[0, 0], pitch_b[2, 0]  # the CoP on its own axis
        b[pos, 2:4] = pitch_b[0, 1] * axes[pos]  # the CMP offset, turned
        b[vel, 2:4] = pitch_b[2, 1] * axes[pos]
    for angle, rate, column, axis_b in ((2, 6, 2, pitch_b), (3, 7, 3, roll_b)):
        a[angle, angle], a[angle, rate], a[rate, rate] = 1.0, dt, 1.0
        b[angle, column], b[rate, column] = axis_b[1, 1], axis_b[3, 1]
    return a, b


def plane_propagate(
    states: ArrayLike, inputs: ArrayLike, params: BodyParams, dt: float, yaw: float = 0.0
) -> FloatArray:
    """Advance arrays of states (..., 8) with inputs (..., 4) held for dt (exact, vectorised).

    Raises
    ------
    InvalidParameterError
        States or inputs that are not finite or not of shape (..., 8) and (..., 4) with
        leading shapes that broadcast, ``dt`` or ``yaw`` as in :func:`plane_discrete`, or
        states so large that the result overflows.
    """
    a, b = plane_discrete(params, dt, yaw)
    return _propagated(states, inputs, a, b)
