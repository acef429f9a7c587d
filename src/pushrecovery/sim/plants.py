"""Plants: the models behind one small stepping protocol the simulator drives.

A plant advances a state by one control period with the command held (zero-order hold), and
returns the CoP and hip torque it actually applied (commands are clipped to the foot and the
torque limit: physics, not politeness). ``fall_limits`` are the CoM positions beyond which a CoM
moving outward can no longer be stopped by any admissible input (docs/conventions.md).
"""

from __future__ import annotations

import math
from typing import ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.models.pendulum import com_from_lean, lean_from_com, pendulum_step
from pushrecovery.params import BodyParams
from pushrecovery.sim.result import is_falling

__all__ = ["MODELS", "FlywheelPlant", "LipmPlant", "PendulumPlant", "Plant", "make_plant"]

FloatArray = NDArray[np.float64]


class Plant(Protocol):
    """What the simulator needs of a model."""

    name: ClassVar[str]
    params: BodyParams
    fall_limits: tuple[float, float]
    #: Times the flywheel hit its joint stop at speed (always 0 for models without one).
    stop_impacts: int

    def falling(self, state: FloatArray) -> bool:
        """Whether ``state`` is in the plant's absorbing fall set (docs/conventions.md)."""
        ...

    def initial_state(self, x: float, xdot: float) -> FloatArray:
        """State with the CoM at x [m] moving at ẋ [m/s], everything else at rest."""
        ...

    def check_state(self, state: FloatArray) -> None:
        """Raise :class:`InvalidParameterError` if the model cannot start from ``state``."""

    def step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Advance ``state`` by ``dt`` [s]; return it, the applied CoP [m] and torque [N m]."""
        ...


def check_com_state(x: float, xdot: float, params: BodyParams) -> None:
    """Reject CoM states outside every model's validity.

    |x| < L (the CoM above the ankle's horizon) and |ẋ| < 10 sqrt(g L): ten times the speed at
    which an upright pendulum's foot unloads (docs/conventions.md).
    """
    if abs(x) >= params.com_height:
        raise InvalidParameterError(
            f"x must satisfy |x| < com_height = {params.com_height:g} m, got x={x:g}"
        )
    speed = 10.0 * math.sqrt(params.gravity * params.com_height)
    if abs(xdot) >= speed:
        raise InvalidParameterError(
            f"xdot must satisfy |xdot| < 10 sqrt(g L) = {speed:g} m/s, got xdot={xdot:g}"
        )


class _AnklePlant:
    """Shared parts of the ankle-only plants (state ``[x, xdot]``)."""

    name: ClassVar[str]

    def __init__(self, params: BodyParams) -> None:
        self.params = params
        # Beyond a foot edge, moving outward: lost for any CoP (docs/conventions.md).
        self.fall_limits = (params.heel, params.toe)
        self.stop_impacts = 0

    def falling(self, state: FloatArray) -> bool:
        """Beyond a foot edge and moving outward (absorbing for every CoP on the foot)."""
        return is_falling(float(state[0]), float(state[1]), *self.fall_limits)

    def initial_state(self, x: float, xdot: float) -> FloatArray:
        """``[x, xdot]``."""
        return np.array([x, xdot], dtype=np.float64)

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, xdot]`` within the models' validity (:func:`check_com_state`)."""
        if state.shape != (2,):
            raise InvalidParameterError(f"state must be [x, xdot], got shape {state.shape}")
        check_com_state(float(state[0]), float(state[1]), self.params)

    def applied_cop(self, command: Command) -> float:
        if command.flywheel_torque != 0.0:
            raise InvalidParameterError(
                f"the {self.name} model has no upper body: flywheel_torque must be 0, "
                f"got {command.flywheel_torque:g} N m"
            )
        return min(self.params.toe, max(self.params.heel, command.cop))


class LipmPlant(_AnklePlant):
    """LIPM (Eq. 3) advanced exactly with Eq. (24)."""

    name = "lipm"

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        self._dt = -1.0
        self._cosh = self._sinh = 1.0

    def step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Advance exactly by dt with the CoP held (Eq. 24); return state, CoP, torque (0)."""
        cop = self.applied_cop(command)
        if dt != self._dt:
            omega = self.params.omega
            self._dt, self._cosh, self._sinh = dt, math.cosh(omega * dt), math.sinh(omega * dt)
        omega, c, s = self.params.omega, self._cosh, self._sinh
        offset, xdot = float(state[0]) - cop, float(state[1])
        # Eq. (24) at t = dt, and its derivative.
        state = np.array([cop + offset * c + xdot / omega * s, omega * offset * s + xdot * c])
        return state, cop, 0.0


class PendulumPlant(_AnklePlant):
    """Nonlinear inverted pendulum with the exact CoP-limited ankle torque (RK4)."""

    name = "pendulum"

    #: Largest RK4 substep [s]; ω h ≈ 0.003 keeps the local error far below 1e-12.
    max_substep: ClassVar[float] = 1e-3

    def step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Advance by dt with RK4 (substeps <= ``max_substep``); return state, CoP, torque (0)."""
        cop = self.applied_cop(command)
        p = self.params
        theta, rate = lean_from_com(float(state[0]), float(state[1]), p.com_height)
        substeps = max(1, math.ceil(dt / self.max_substep - 1e-9))
        theta, rate = pendulum_step(
            theta, rate, cop, dt, p.mass, p.com_height, p.gravity, substeps=substeps
        )
        if abs(theta) >= 0.5 * math.pi:
            # Lying on the floor: x = ±L, at rest. (x, ẋ) cannot describe θ past horizontal.
            theta, rate = math.copysign(0.5 * math.pi, theta), 0.0
        return np.array(com_from_lean(theta, rate, p.com_height)), cop, 0.0


class FlywheelPlant:
    """LIPM plus flywheel (Eqs. 6, 7, 16), advanced exactly with the ZOH transition.

    State ``[x, theta, xdot, theta_dot]``. The hip joint limit |θ| ≤ θmax is a hard stop: a
    step that ends past it puts the flywheel on the stop, at rest, and the stopping torque
    impulse P = −I θ̇ reacts on the CoM (Δẋ = −P / (m L), from Eqs. 6-7; m L ẋ + I θ̇ is
    conserved). The stop is checked at the end of each step with the end-of-step rate, an
    approximation of order dt. An impact is a torque far beyond τmax, outside the model of
    Sec. III (errata E12): each one is counted in ``stop_impacts`` and reported with the run.
    Controllers that respect the limit (bang-bang with T ≤ T_max, the MPC) never touch it.
    """

    name: ClassVar[str] = "flywheel"

    def __init__(self, params: BodyParams) -> None:
        self.params = params
        reach = params.torque_max / params.weight
        # Beyond δ± ± τmax/(m g), moving outward, no CMP on offer can stop the CoM.
        self.fall_limits = (params.heel - reach, params.toe + reach)
        self._momentum = np.array([params.mass * params.com_height, params.flywheel_inertia])
        self.stop_impacts = 0
        self._dt = -1.0
        self._a = self._b = np.empty(0)

    def initial_state(self, x: float, xdot: float) -> FloatArray:
        """``[x, 0, xdot, 0]``: the upper body upright and at rest."""
        return np.array([x, 0.0, xdot, 0.0])

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, theta, xdot, theta_dot]`` with |θ| ≤ θmax."""
        if state.shape != (4,):
            raise InvalidParameterError(
                f"state must be [x, theta, xdot, theta_dot], got shape {state.shape}"
            )
        check_com_state(float(state[0]), float(state[2]), self.params)
        if abs(float(state[1])) > self.params.flywheel_angle_max:
            raise InvalidParameterError(
                f"theta must satisfy |theta| <= flywheel_angle_max = "
                f"{self.params.flywheel_angle_max:g} rad, got {float(state[1]):g}"
            )

    def step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Advance exactly by dt with (δ, τ) held; return state, applied CoP and torque."""
        p = self.params
        cop = min(p.toe, max(p.heel, command.cop))
        torque = min(p.torque_max, max(-p.torque_max, command.flywheel_torque))
        if dt != self._dt:
            self._dt = dt
            self._a, self._b = flywheel_discrete(p, dt)
        new = self._a @ state + self._b @ np.array([cop, torque])
        limit = p.flywheel_angle_max
        if abs(new[1]) > limit:
            new[1] = math.copysign(limit, new[1])
            new[2] += p.flywheel_inertia * new[3] / (p.mass * p.com_height)
            new[3] = 0.0
            self.stop_impacts += 1
        return new, cop, torque

    def falling(self, state: FloatArray) -> bool:
        """Beyond δ± ± τmax/(m g), moving outward, with H = m L ẋ + I θ̇ outward too.

        dH/dt = m g (x − δ) > 0 there whatever the hip torque, and a stop impact conserves H,
        so ẋ can never turn back: the set is absorbing even with the joint stop.
        """
        x, xdot = float(state[0]), float(state[2])
        momentum = float(self._momentum @ state[2:])
        lower, upper = self.fall_limits
        return (x > upper and xdot >= 0.0 and momentum >= 0.0) or (
            x < lower and xdot <= 0.0 and momentum <= 0.0
        )


#: Model name -> plant class.
MODELS: dict[str, type[LipmPlant] | type[PendulumPlant] | type[FlywheelPlant]] = {
    LipmPlant.name: LipmPlant,
    PendulumPlant.name: PendulumPlant,
    FlywheelPlant.name: FlywheelPlant,
}


def make_plant(name: str, params: BodyParams) -> Plant:
    """Build the plant registered as ``name``; unknown names raise."""
    try:
        return MODELS[name](params)
    except KeyError:
        raise InvalidParameterError(
            f"model must be one of {sorted(MODELS)}, got model={name!r}"
        ) from None
