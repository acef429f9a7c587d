"""Sec. IV's stepping model as a plant: the flywheel model in stance, Hofmann's legs in swing."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.pendulum import pendulum_step_unchecked
from pushrecovery.models.stepping import STEPPING_STATE
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import PlantBase, check_com_state, over_foot_at_rest
from pushrecovery.sim.plants import FlywheelPlant

__all__ = ["SteppingPlant"]

FloatArray = NDArray[np.float64]


class SteppingPlant(PlantBase):
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
    state_labels: ClassVar[tuple[str, ...]] = STEPPING_STATE

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        self.fall_limits = params.hip_fall_limits
        self._swing: tuple[float, float, float] | None = None  # (length, landing lean, sign)
        self._stance: dict[float, FlywheelPlant] = {}

    def _start(self, x: float, xdot: float) -> FloatArray:
        """``[x, 0, L, xdot, 0, 0]``: standing at the CoM height, upper body upright."""
        return np.array([x, 0.0, self.params.com_height, xdot, 0.0, 0.0])

    def _restart_records(self) -> None:
        super()._restart_records()
        self._swing = None

    def _in_stance(self) -> bool:
        """Stance unless a foot swings toward its landing."""
        return self._swing is None

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, theta, z, xdot, theta_dot, zdot]`` standing (ż = 0, 0 < z)."""
        if state.shape != (6,):
            raise InvalidParameterError(
                f"state must be [x, theta, z, xdot, theta_dot, zdot], got shape {state.shape}"
            )
        if not (float(state[2]) > 0.0 and float(state[5]) == 0.0):
            raise InvalidParameterError("the stepping model starts standing: z > 0, zdot = 0")
        check_com_state(float(state[0]), float(state[3]), self.params)

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

    def _advance(self, command: Command, dt: float) -> tuple[FloatArray, tuple[float, ...]]:
        """Advance by dt in the current phase; a step command starts a swing."""
        state, cop, torque = self._phase_step(self.state, command, dt)
        return state, (cop, torque)

    def _phase_step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        if self._swing is None and command.step_length is not None:
            state = self._start_swing(state, command.step_length)
        if self._swing is None:
            plant = self._stance_plant(float(state[2]))
            before = plant.stop_impacts
            inner, cop, torque = plant.advance(state[[0, 1, 3, 4]], command, dt)
            self.stop_impacts += plant.stop_impacts - before
            return np.array([inner[0], inner[1], state[2], inner[2], inner[3], 0.0]), cop, torque
        torque = self.params.clip_hip_torque(command.flywheel_torque)
        return self._swing_step(state, dt, torque), 0.0, torque

    def _start_swing(self, state: FloatArray, step_length: float) -> FloatArray:
        x, z, xdot = float(state[0]), float(state[2]), float(state[3])
        # sqrt(x² + z²) as written (math.hypot's algorithm varies between libraries; the
        # compiled batch, kernels/batched/stepping.py, computes the same bits).
        length = math.sqrt(x * x + z * z)
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
            new_lean, new_rate = pendulum_step_unchecked(lean, rate, 0.0, h, 1.0, length, g)
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
            new, _, _ = self._phase_step(new, Command(0.0), remaining)
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
