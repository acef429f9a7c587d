r"""Stepping model of Sec. IV (Hofmann): a point mass on massless legs of length L.

The CoM starts above the stance ankle moving forward at v0 and falls as an inverted pendulum
about it, with no ankle torque. Our angle θ is the stance leg's lean from vertical, **positive
forward** (CoM ahead of the stance foot), like the pendulum of Sec. II; the paper's θ in
Eqs. (18)-(22) is the opposite, −θ (docs/errata.md, E14). The swing leg lands symmetrically, at
L sin θ ahead of the CoM, so the step is 2 L sin θ foot to foot.

Energy gives the fall rate in closed form:

.. math:: \dot\theta(\theta)^2 = \frac{v_0^2}{L^2} + 2\omega^2 (1 - \cos\theta),
          \qquad \omega^2 = g / L.

Velocities before impact (Eq. 18, our sign): v_x = L cos θ θ̇, v_z = −L sin θ θ̇. The impact
impulse acts along the new leg and removes v_z (Eqs. 19-20), so

.. math:: v_x^+ = L\dot\theta\,\frac{\cos 2\theta}{\cos\theta}, \qquad v_z^+ = 0,

and the CoM then moves as a LIPM at height z = L cos θ, with ω⁺ = sqrt(g/z), starting
L sin θ *behind* the new ankle. Its capture point relative to the new ankle is

.. math:: \xi^+(\theta) = -L\sin\theta + \frac{v_x^+}{\omega^+}
          = L\left(-\sin\theta + \frac{\dot\theta}{\omega}
            \frac{\cos 2\theta}{\sqrt{\cos\theta}}\right),

which decreases monotonically from v0/ω at θ = 0 to −L/√2 at θ = π/4 (checked on a dense grid,
``tests/test_stepping.py``). Eq. (21) asks for ξ⁺ = 0 (Eq. 22 is the same condition written as
θ̇(θ)); any θ with δ⁻ < ξ⁺ < δ⁺ leaves the body recoverable by the new foot's ankle (Eq. 4).
Every such condition is therefore a 1-D root of ξ⁺(θ) = target on (0, π/4), solved with a
safeguarded Newton iteration written once, in pure Python
(:func:`pushrecovery.kernels.step_scalar.step_angle`), and compiled by numba into cached,
vectorised loops (:mod:`pushrecovery.kernels.stepping`) for arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import bounded_float, broadcast, finite_array, finite_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.kernels.step_scalar import MAX_STEP_ANGLE as MAX_STEP_ANGLE
from pushrecovery.kernels.step_scalar import step_angle
from pushrecovery.params import LIMITS

__all__ = [
    "STEPPING_STATE",
    "StepSolution",
    "fall_rate",
    "impact_velocities",
    "post_impact_capture_point",
    "solve_step_angle",
    "step_solution",
    "time_to_angle",
]

#: Slowest push a step is solved for [m/s]: at rest over the ankle nothing falls.
MIN_V0 = 1e-6

FloatArray = NDArray[np.float64]

#: The stepping model's state: CoM relative to the stance ankle, flywheel angle, CoM height
#: and their rates [m, rad, m, m/s, rad/s, m/s].
STEPPING_STATE = ("x", "theta", "z", "xdot", "theta_dot", "zdot")
#: Up to this many angles, :func:`solve_step_angle` runs the pure-Python solver (a few µs an
#: angle) instead of loading numba (0.4 s, once per process) and its compiled loops.
_PYTHON_MAX_SIZE = 32


def _leg(length: object, gravity: object) -> tuple[float, float]:
    """L [m] and g [m/s²] checked against :data:`~pushrecovery.params.LIMITS`."""
    return (
        bounded_float("length", length, *LIMITS["leg_length"]),
        bounded_float("gravity", gravity, *LIMITS["gravity"]),
    )


def _angles(name: str, theta: ArrayLike) -> FloatArray:
    """Stance-leg angles [rad] in [0, π/2): finite, leaning forward, the foot below the hip."""
    values = finite_array(name, theta)
    if values.size and not (float(values.min()) >= 0.0 and float(values.max()) < 0.5 * math.pi):
        raise InvalidParameterError(f"{name} must lie in [0, pi/2) rad")
    return values


def _speeds(v0: ArrayLike, length: float, gravity: float, least: float = 0.0) -> FloatArray:
    """CoM speeds [m/s] in [least, 10 sqrt(g L)): the models' validity (check_com_state)."""
    values = finite_array("v0", v0)
    limit = 10.0 * math.sqrt(gravity * length)
    if values.size and not (float(values.min()) >= least and float(values.max()) < limit):
        raise InvalidParameterError(f"v0 must lie in [{least:g}, 10 sqrt(g L) = {limit:g}) m/s")
    return values


def fall_rate(theta: ArrayLike, v0: ArrayLike, length: float, gravity: float) -> FloatArray:
    """Stance-leg rate θ̇ [rad/s] at lean θ [rad], from energy, starting at θ = 0 with v0 [m/s]."""
    length, gravity = _leg(length, gravity)
    theta, v0 = broadcast(theta=_angles("theta", theta), v0=_speeds(v0, length, gravity))
    return np.sqrt((v0 / length) ** 2 + 2.0 * gravity / length * (1.0 - np.cos(theta)))


def time_to_angle(theta: ArrayLike, v0: ArrayLike, length: float, gravity: float) -> FloatArray:
    """Time [s] for the stance leg to lean from 0 to θ, in closed form.

    t = ∫₀^θ dφ / θ̇(φ) = (2 / √a) F(θ/2 | −4ω²/a), a = v0²/L², with F the incomplete elliptic
    integral of the first kind (``scipy.special.ellipkinc``). Needs v0 > 0.
    """
    from scipy.special import ellipkinc

    length, gravity = _leg(length, gravity)
    theta, v0 = broadcast(theta=_angles("theta", theta), v0=_speeds(v0, length, gravity, MIN_V0))
    a = (v0 / length) ** 2
    return 2.0 / np.sqrt(a) * ellipkinc(0.5 * theta, -4.0 * gravity / length / a)


def impact_velocities(
    theta: ArrayLike, theta_rate: ArrayLike, length: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """CoM velocities at impact: before (v_x, v_z), Eq. (18), and after v_x⁺, Eqs. (19)-(20).

    Returns
    -------
    vx_before, vz_before, vx_after : ndarray
        [m/s]; v_z after the impact is 0 by assumption.
    """
    length = bounded_float("length", length, *LIMITS["leg_length"])
    theta = _angles("theta", theta)
    theta_rate = finite_array("theta_rate", theta_rate)
    cos = np.cos(theta)
    return (
        length * cos * theta_rate,
        -length * np.sin(theta) * theta_rate,
        length * theta_rate * np.cos(2.0 * theta) / cos,
    )


def post_impact_capture_point(
    theta: ArrayLike, v0: ArrayLike, length: float, gravity: float
) -> FloatArray:
    """Capture point after landing at step angle θ, relative to the new ankle, ξ⁺(θ) [m]."""
    length, gravity = _leg(length, gravity)
    theta = _angles("theta", theta)
    rate = fall_rate(theta, v0, length, gravity)
    omega = math.sqrt(gravity / length)
    return length * (-np.sin(theta) + rate / omega * np.cos(2.0 * theta) / np.sqrt(np.cos(theta)))


def solve_step_angle(
    v0: ArrayLike,
    target: ArrayLike,
    length: float,
    gravity: float,
    *,
    lean: ArrayLike = 0.0,
    lean_rate: ArrayLike | None = None,
) -> FloatArray:
    """Step angle θ in [lean, π/4] whose post-impact capture point is ``target`` [rad].

    Solves ξ⁺(θ) = target (module docstring) for arrays of v0 [m/s] and targets [m]
    (broadcast). By default the fall starts upright with v0; with ``lean`` [rad] and
    ``lean_rate`` [rad/s] it starts from that lean instead (v0 is then ignored), which covers
    slow falls whose energy is below the top of the pendulum. Returns ``lean`` when even an
    immediate step leaves the capture point behind the target, and π/4 when the target lies
    below −L/√2 (unreachable).

    Raises
    ------
    InvalidParameterError
        A value that is not finite, a length or gravity out of
        :data:`~pushrecovery.params.LIMITS`, a lean outside [0, π/2), abs(v0) >= 10 sqrt(g L)
        or abs(lean_rate) >= 10 sqrt(g / L) (the models' validity, as :func:`step_solution`;
        the squares overflow beyond), or shapes that do not broadcast.
    """
    length, gravity = _leg(length, gravity)
    v0 = finite_array("v0", v0)
    limit = 10.0 * math.sqrt(gravity * length)
    if v0.size and float(np.max(np.abs(v0))) >= limit:
        raise InvalidParameterError(
            f"v0 must satisfy |v0| < 10 sqrt(g L) = {limit:g} m/s, "
            f"got {float(np.max(np.abs(v0))):g}"
        )
    target = finite_array("target", target)
    lean = _angles("lean", lean)
    lean_rate = None if lean_rate is None else finite_array("lean_rate", lean_rate)
    if lean_rate is not None and lean_rate.size:
        largest = float(np.max(np.abs(lean_rate)))
        if largest >= limit / length:
            raise InvalidParameterError(
                f"lean_rate must satisfy |lean_rate| < 10 sqrt(g / L) = {limit / length:g} "
                f"rad/s, got {largest:g}"
            )
    speeds = ("v0", v0) if lean_rate is None else ("lean_rate", lean_rate)
    try:
        np.broadcast_shapes(speeds[1].shape, target.shape, lean.shape)
    except ValueError:
        raise InvalidParameterError(
            f"{speeds[0]} {speeds[1].shape}, target {target.shape} and lean {lean.shape} "
            "must broadcast"
        ) from None
    omega2 = gravity / length
    lean = np.asarray(lean, dtype=np.float64)
    if lean_rate is None:
        energy = (np.asarray(v0, dtype=np.float64) / length) ** 2  # θ̇² at θ = 0
    else:
        rate = np.asarray(lean_rate, dtype=np.float64)
        energy = rate**2 - 2.0 * omega2 * (1.0 - np.cos(lean))
    energy, lean, target = np.broadcast_arrays(energy, lean, np.asarray(target, dtype=np.float64))
    if energy.size <= _PYTHON_MAX_SIZE:
        rows = zip(energy.flat, lean.flat, target.flat, strict=True)
        angles = [step_angle(float(a), float(b), float(c), length, gravity) for a, b, c in rows]
        out = np.array(angles, dtype=np.float64)
    else:
        from pushrecovery.kernels.stepping import solve

        out = solve(energy, lean, target, length, gravity)
    return out.reshape(energy.shape)


@dataclass(frozen=True, slots=True)
class StepSolution:
    """Steps for arrays of initial CoM velocities v0 (module docstring); all arrays broadcast.

    Attributes
    ----------
    v0 : ndarray
        Initial CoM velocity, CoM above the stance ankle [m/s], > 0.
    theta, theta_rate : ndarray
        Eq. (21) step: stance-leg angle [rad] and rate [rad/s] at impact.
    time_to_impact : ndarray
        [s].
    step_length, com_to_foot : ndarray
        2 L sin θ (foot to foot) and L sin θ (CoM to new foot) [m].
    velocity_before_x, velocity_before_z, velocity_after, height_after : ndarray
        Eq. (18) velocities before impact, Eq. (20) after [m/s]; CoM height after [m].
    theta_low, theta_high : ndarray
        Step angles whose post-impact capture point is on the new foot's toe / heel edge: every
        angle strictly between them leaves a state inside Eq. (4) on the new foot [rad].
    centred_theta : ndarray
        Step angle that puts the capture point at the middle of the new foot [rad].
    stance_leg_in_compression : ndarray of bool
        False where the stance leg would have to pull to keep the mass on its circle before
        impact (L θ̇² > g cos θ): the model is no longer physical there.
    """

    v0: FloatArray
    theta: FloatArray
    theta_rate: FloatArray
    time_to_impact: FloatArray
    step_length: FloatArray
    com_to_foot: FloatArray
    velocity_before_x: FloatArray
    velocity_before_z: FloatArray
    velocity_after: FloatArray
    height_after: FloatArray
    theta_low: FloatArray
    theta_high: FloatArray
    centred_theta: FloatArray
    length: float
    stance_leg_in_compression: NDArray[np.bool_]

    def step_length_of(self, theta: ArrayLike) -> FloatArray:
        """Foot-to-foot step length 2 L sin θ [m] of step angles θ [rad]."""
        return 2.0 * self.length * np.sin(np.asarray(theta, dtype=np.float64))


def step_solution(
    v0: ArrayLike, length: float, gravity: float, heel: float, toe: float
) -> StepSolution:
    """Optimal (Eq. 21), centred and admissible steps for initial velocities v0 [m/s].

    Parameters
    ----------
    v0 : array_like
        CoM velocity with the CoM above the stance ankle [m/s], > 0 (forward; mirror the foot
        for backward pushes).
    length : float
        Leg length L [m].
    gravity : float
        g [m/s²].
    heel, toe : float
        Edges of the new foot relative to its ankle [m].

    Returns
    -------
    StepSolution

    Raises
    ------
    InvalidParameterError
        On a non-finite value, a length or gravity out of :data:`~pushrecovery.params.LIMITS`,
        v0 < 1e-6 m/s, or abs(v0) >= 10 sqrt(g L) (ten times the speed at which the stance
        foot leaves the floor: no step of this model, and float64 overflow beyond).
    """
    length, gravity = _leg(length, gravity)
    heel, toe = finite_float("heel", heel, "m"), finite_float("toe", toe, "m")
    v0 = finite_array("v0", v0)
    if v0.size and float(np.min(v0)) < MIN_V0:
        raise InvalidParameterError(
            "v0 must be >= 1e-6 m/s (a forward push; backward steps are the mirror "
            f"image), got {float(np.min(v0)):g}"
        )
    # solve_step_angle refuses abs(v0) >= 10 sqrt(g L).
    targets = np.stack(np.broadcast_arrays(0.0, toe, heel, 0.5 * (heel + toe)))
    angles = solve_step_angle(
        v0[None, ...], targets.reshape((4,) + (1,) * v0.ndim), length, gravity
    )
    theta, low, high, centred = angles
    rate = fall_rate(theta, v0, length, gravity)
    vx, vz, after = impact_velocities(theta, rate, length)
    return StepSolution(
        v0=v0,
        theta=theta,
        theta_rate=rate,
        time_to_impact=time_to_angle(theta, v0, length, gravity),
        step_length=2.0 * length * np.sin(theta),
        com_to_foot=length * np.sin(theta),
        velocity_before_x=vx,
        velocity_before_z=vz,
        velocity_after=after,
        height_after=length * np.cos(theta),
        theta_low=low,
        theta_high=high,
        centred_theta=centred,
        length=length,
        stance_leg_in_compression=length * rate**2 <= gravity * np.cos(theta),
    )
