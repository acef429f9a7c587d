"""Plants: the models behind one small stepping protocol the simulator drives.

A plant advances a state by one control period with the command held (zero-order hold), and
returns the CoP and hip torque it actually applied (commands are clipped to the foot and the
torque limit: physics, not politeness). ``fall_limits`` are the CoM positions beyond which a CoM
moving outward can no longer be stopped by any admissible input (docs/conventions.md).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.models.pendulum import com_from_lean, lean_from_com, pendulum_step
from pushrecovery.params import BodyParams
from pushrecovery.sim.result import is_falling

__all__ = [
    "FlywheelPlant",
    "LipmPlant",
    "PendulumPlant",
    "Plant",
    "SteppingPlant",
]

FloatArray = NDArray[np.float64]


class Plant(Protocol):
    """What the simulator needs of a model."""

    name: ClassVar[str]
    params: BodyParams
    fall_limits: tuple[float, float]
    #: Times the flywheel hit its joint stop at speed (always 0 for models without one).
    stop_impacts: int
    #: Applied inputs per tick that :meth:`step` returns (CoP then torque entries).
    input_size: ClassVar[int]
    #: Labels of the state entries; ``None`` on the sagittal models (told apart by length).
    state_labels: ClassVar[tuple[str, ...] | None]

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """Whether the CoM moves at most ``speed`` [m/s] and stands over the support."""
        ...

    def falling(self, state: FloatArray) -> bool:
        """Whether ``state`` is in the plant's absorbing fall set (docs/conventions.md)."""
        ...

    def initial_state(self, x: float, xdot: float) -> FloatArray:
        """State with the CoM at x [m] moving at ẋ [m/s], everything else at rest."""
        ...

    def check_state(self, state: FloatArray) -> None:
        """Raise :class:`InvalidParameterError` if the model cannot start from ``state``."""

    def step(self, state: FloatArray, command: Command, dt: float) -> tuple[FloatArray, Any, Any]:
        """Advance ``state`` by ``dt`` [s]; return it, the applied CoP [m] and torque [N m].

        CoP and torque are floats on the sagittal models, arrays of ``input_size // 2`` on
        the plane.
        """
        ...


def over_foot_at_rest(state: FloatArray, params: BodyParams, speed: float) -> bool:
    """Sagittal rest: |ẋ| <= ``speed`` [m/s] and the CoM strictly over the foot (heel, toe)."""
    x, xdot = float(state[0]), float(state[len(state) // 2])
    return abs(xdot) <= speed and params.heel < x < params.toe


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
    input_size: ClassVar[int] = 2
    state_labels: ClassVar[tuple[str, ...] | None] = None

    def __init__(self, params: BodyParams) -> None:
        self.params = params
        # Beyond a foot edge, moving outward: lost for any CoP (docs/conventions.md).
        self.fall_limits = (params.heel, params.toe)
        self.stop_impacts = 0

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """:func:`over_foot_at_rest`."""
        return over_foot_at_rest(state, self.params, speed)

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
        if command.step_length is not None:
            raise InvalidParameterError(f"the {self.name} model has no legs to step with")
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
    input_size: ClassVar[int] = 2
    state_labels: ClassVar[tuple[str, ...] | None] = None

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
        if command.step_length is not None:
            raise InvalidParameterError("the flywheel model has no legs to step with")
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

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """:func:`over_foot_at_rest`."""
        return over_foot_at_rest(state, self.params, speed)

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


class SteppingPlant:
    """LIPM + flywheel in stance, Hofmann's pendulum in swing, and the impact of Sec. IV.

    State ``[x, theta, z, xdot, theta_dot, zdot]``: CoM relative to the *current* stance ankle
    [m], flywheel angle [rad], CoM height [m] and their rates. Phases:

    - **stance**: the flywheel model (Eqs. 6, 7, 16) at the current height z (ω = sqrt(g/z)),
      exact ZOH, joint stop as in :class:`FlywheelPlant`; ż = 0.
    - **swing**, started by a command with ``step_length`` d: the stance leg locks at its current
      length l = sqrt(x² + z²) (the radial velocity is absorbed) and the CoM falls as a pendulum
      about the ankle, no ankle or hip torque (RK4, 0.1 ms substeps). The swing foot lands,
      symmetric to the stance foot (Hofmann), when the lean reaches asin(d / 2l).
    - **impact** (Eqs. 18-20): v_z → 0 through an impulse along the new leg; the new stance
      starts L sin θ behind the new ankle at height l cos θ.

    A swing that never reaches its landing angle (the CoM falls back) ends the run as a fall.
    ``footholds`` lists the world x of every stance foot [m].
    """

    name: ClassVar[str] = "stepping"
    substep: ClassVar[float] = 1e-4
    input_size: ClassVar[int] = 2
    state_labels: ClassVar[tuple[str, ...] | None] = None

    def __init__(self, params: BodyParams) -> None:
        self.params = params
        reach = params.torque_max / params.weight
        self.fall_limits = (params.heel - reach, params.toe + reach)
        self.stop_impacts = 0
        self.footholds: list[float] = [0.0]
        self._swing: tuple[float, float, float] | None = None  # (length, landing lean, sign)
        self._stance: dict[float, FlywheelPlant] = {}

    def initial_state(self, x: float, xdot: float) -> FloatArray:
        """``[x, 0, L, xdot, 0, 0]``: standing at the CoM height, upper body upright."""
        return np.array([x, 0.0, self.params.com_height, xdot, 0.0, 0.0])

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, theta, z, xdot, theta_dot, zdot]`` standing (ż = 0, 0 < z).

        Called by the simulator before every run, it also starts a new record of footholds.
        """
        if state.shape != (6,):
            raise InvalidParameterError(
                f"state must be [x, theta, z, xdot, theta_dot, zdot], got shape {state.shape}"
            )
        if not (float(state[2]) > 0.0 and float(state[5]) == 0.0):
            raise InvalidParameterError("the stepping model starts standing: z > 0, zdot = 0")
        check_com_state(float(state[0]), float(state[3]), self.params)
        self.footholds = [0.0]
        self._swing = None

    def _stance_plant(self, height: float) -> FlywheelPlant:
        plant = self._stance.get(height)
        if plant is None:
            import dataclasses

            body = dataclasses.replace(
                self.params,
                com_height=height,
                leg_length=self.params.leg_length,
                max_step_length=self.params.max_step_length,
            )
            plant = self._stance[height] = FlywheelPlant(body)
        return plant

    def step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Advance by dt in the current phase; a step command starts a swing."""
        if self._swing is None and command.step_length is not None:
            state = self._start_swing(state, command.step_length)
        if self._swing is None:
            plant = self._stance_plant(float(state[2]))
            plant.stop_impacts = 0
            inner, cop, torque = plant.step(state[[0, 1, 3, 4]], command, dt)
            self.stop_impacts += plant.stop_impacts
            return np.array([inner[0], inner[1], state[2], inner[2], inner[3], 0.0]), cop, torque
        torque = min(self.params.torque_max, max(-self.params.torque_max, command.flywheel_torque))
        return self._swing_step(state, dt, torque), 0.0, torque

    def _start_swing(self, state: FloatArray, step_length: float) -> FloatArray:
        x, z, xdot = float(state[0]), float(state[2]), float(state[3])
        length = math.hypot(x, z)
        sign = 1.0 if step_length > 0.0 else -1.0
        lean = math.atan2(x, z)
        # The foot cannot land behind the current lean: at the earliest it lands right away.
        landing = max(math.asin(min(1.0, abs(step_length) / (2.0 * length))), sign * lean)
        self._swing = (length, landing, sign)
        # The locked leg keeps only the tangential part of the CoM velocity.
        rate = xdot * math.cos(lean) / length
        state = state.copy()
        state[0], state[2] = length * math.sin(lean), length * math.cos(lean)
        state[3], state[5] = length * math.cos(lean) * rate, -length * math.sin(lean) * rate
        return state

    def _swing_step(self, state: FloatArray, dt: float, torque: float) -> FloatArray:
        assert self._swing is not None
        length, landing, sign = self._swing
        g = self.params.gravity
        lean = math.atan2(float(state[0]), float(state[2]))
        rate = (float(state[3]) * math.cos(lean) - float(state[5]) * math.sin(lean)) / length
        left = dt
        while left > 1e-15:
            h = min(self.substep, left)
            new_lean, new_rate = pendulum_step(lean, rate, 0.0, h, 1.0, length, g)
            if sign * new_lean >= landing:
                # Land exactly at the landing lean; its rate follows from energy.
                impact = sign * landing
                rate = math.copysign(
                    math.sqrt(
                        max(0.0, rate * rate + 2 * g / length * (math.cos(lean) - math.cos(impact)))
                    ),
                    rate,
                )
                fraction = (impact - lean) / (new_lean - lean) if new_lean != lean else 1.0
                return self._impact(state, length, impact, rate, left - fraction * h)
            lean, rate = new_lean, new_rate
            left -= h
            if sign * rate <= 0.0 or abs(lean) >= 0.5 * math.pi:
                break  # falls back (or flat): never lands
        state = state.copy()
        state[0], state[2] = length * math.sin(lean), length * math.cos(lean)
        state[3], state[5] = length * math.cos(lean) * rate, -length * math.sin(lean) * rate
        # The upper body is not coupled to the point-mass swing (Hofmann): I θ̈ = τ alone.
        state[4] += torque / self.params.flywheel_inertia * dt
        state[1] += state[4] * dt
        limit = self.params.flywheel_angle_max
        if abs(state[1]) > limit:
            state[1], state[4] = math.copysign(limit, state[1]), 0.0
            self.stop_impacts += 1
        return state

    def _impact(
        self, state: FloatArray, length: float, lean: float, rate: float, remaining: float
    ) -> FloatArray:
        # Eqs. (18)-(20): v_x⁺ = L θ̇ cos 2θ / cos θ, v_z⁺ = 0, new stance behind the new foot.
        after = length * rate * math.cos(2.0 * lean) / math.cos(lean)
        height = length * math.cos(lean)
        self.footholds.append(self.footholds[-1] + 2.0 * length * math.sin(lean))
        self._swing = None
        new = np.array([-length * math.sin(lean), state[1], height, after, state[4], 0.0])
        if remaining > 1e-12:
            new, _, _ = self.step(new, Command(0.0), remaining)
        return new

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """:func:`over_foot_at_rest` on the current stance foot."""
        return over_foot_at_rest(state, self.params, speed)

    def falling(self, state: FloatArray) -> bool:
        """Tell whether the body is lost.

        In stance, the flywheel model's fall set; in swing, a CoM falling back or flat, or a
        stance leg that would have to pull (L θ̇² > g cos θ: the foot would leave the floor).
        """
        if self._swing is not None:
            length = self._swing[0]
            lean = math.atan2(float(state[0]), float(state[2]))
            rate = (float(state[3]) * math.cos(lean) - float(state[5]) * math.sin(lean)) / length
            pulls = length * rate * rate > self.params.gravity * math.cos(lean)
            return self._swing[2] * rate <= 0.0 or abs(lean) >= 0.5 * math.pi - 1e-9 or pulls
        return self._stance_plant(float(state[2])).falling(state[[0, 1, 3, 4]])
