"""The analytic plants of the sagittal plane: LIPM, pendulum and flywheel models.

Each implements the backend contract (:mod:`pushrecovery.sim.backend`): the command held over
a step (zero-order hold), clipped to the foot and the torque limit (physics, not politeness).
``fall_limits`` are the CoM positions beyond which a CoM moving outward can no longer be
stopped by any admissible input (docs/conventions.md). The stepping models are in
:mod:`pushrecovery.sim.stepping_plant` and :mod:`pushrecovery.sim.plane_stepping`.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import FLYWHEEL_STATE, flywheel_discrete
from pushrecovery.models.lipm import ANKLE_STATE
from pushrecovery.models.pendulum import (
    com_from_lean_unchecked,
    lean_from_com_unchecked,
    pendulum_step_unchecked,
)
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import Backend, PlantBase, check_com_state, over_foot_at_rest
from pushrecovery.sim.result import is_falling

__all__ = ["FlywheelPlant", "LipmPlant", "PendulumPlant", "Plant", "check_com_state"]

FloatArray = NDArray[np.float64]

#: The contract every plant implements (the name the simulator's signatures use).
Plant = Backend


class _AnklePlant(PlantBase):
    """Shared parts of the ankle-only plants (state ``[x, xdot]``)."""

    state_labels: ClassVar[tuple[str, ...]] = ANKLE_STATE

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        # Beyond a foot edge, moving outward: lost for any CoP (docs/conventions.md).
        self.fall_limits = (params.heel, params.toe)

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """:func:`over_foot_at_rest`."""
        return over_foot_at_rest(state, self.params, speed)

    def falling(self, state: FloatArray) -> bool:
        """Beyond a foot edge and moving outward (absorbing for every CoP on the foot)."""
        return is_falling(float(state[0]), float(state[1]), *self.fall_limits)

    def _start(self, x: float, xdot: float) -> FloatArray:
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
        return self.params.clip_cop(command.cop)


class LipmPlant(_AnklePlant):
    """LIPM (Eq. 3) advanced exactly with Eq. (24)."""

    name = "lipm"

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        self._dt = -1.0
        self._cosh = self._sinh = 1.0

    def _advance(self, command: Command, dt: float) -> tuple[FloatArray, tuple[float, ...]]:
        """Advance exactly by dt with the CoP held (Eq. 24)."""
        state = self.state
        cop = self.applied_cop(command)
        if dt != self._dt:
            omega = self.params.omega
            self._dt, self._cosh, self._sinh = dt, math.cosh(omega * dt), math.sinh(omega * dt)
        omega, c, s = self.params.omega, self._cosh, self._sinh
        offset, xdot = float(state[0]) - cop, float(state[1])
        # Eq. (24) at t = dt, and its derivative.
        state = np.array([cop + offset * c + xdot / omega * s, omega * offset * s + xdot * c])
        return state, (cop, 0.0)


class PendulumPlant(_AnklePlant):
    """Nonlinear inverted pendulum with the exact CoP-limited ankle torque (RK4)."""

    name = "pendulum"

    #: Largest RK4 substep [s]; ω h ≈ 0.003 keeps the local error far below 1e-12.
    max_substep: ClassVar[float] = 1e-3

    def _advance(self, command: Command, dt: float) -> tuple[FloatArray, tuple[float, ...]]:
        """Advance by dt with RK4 (substeps <= ``max_substep``)."""
        cop = self.applied_cop(command)
        p, state = self.params, self.state
        theta, rate = lean_from_com_unchecked(float(state[0]), float(state[1]), p.com_height)
        substeps = max(1, math.ceil(dt / self.max_substep - 1e-9))
        theta, rate = pendulum_step_unchecked(
            theta, rate, cop, dt, p.mass, p.com_height, p.gravity, substeps=substeps
        )
        if abs(theta) >= 0.5 * math.pi:
            # Lying on the floor: x = ±L, at rest. (x, ẋ) cannot describe θ past horizontal.
            theta, rate = math.copysign(0.5 * math.pi, theta), 0.0
        return np.array(com_from_lean_unchecked(theta, rate, p.com_height)), (cop, 0.0)


class FlywheelPlant(PlantBase):
    """LIPM plus flywheel (Eqs. 6, 7, 16), advanced exactly with the ZOH transition.

    State ``[x, theta, xdot, theta_dot]``. The hip joint limit abs(θ) ≤ θmax is a hard stop: a
    step that ends past it puts the flywheel on the stop, at rest, and the stopping torque
    impulse P = −I θ̇ reacts on the CoM (Δẋ = −P / (m L), from Eqs. 6-7; m L ẋ + I θ̇ is
    conserved). The stop is checked at the end of each step with the end-of-step rate, an
    approximation of order dt. An impact is a torque far beyond τmax, outside the model of
    Sec. III (errata E12): each one is counted in ``stop_impacts`` and reported with the run.
    Controllers that respect the limit (bang-bang with T ≤ T_max, the MPC) never touch it.
    """

    name: ClassVar[str] = "flywheel"
    state_labels: ClassVar[tuple[str, ...]] = FLYWHEEL_STATE

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        # Beyond δ± ± τmax/(m g), moving outward, no CMP on offer can stop the CoM.
        self.fall_limits = params.hip_fall_limits
        self._momentum = (params.mass * params.com_height, params.flywheel_inertia)
        self._dt = -1.0
        self._a = self._b = np.empty(0)
        self._rows: tuple[tuple[float, ...], ...] = ()

    def _start(self, x: float, xdot: float) -> FloatArray:
        return np.array([x, 0.0, xdot, 0.0])

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, theta, xdot, theta_dot]`` with abs(θ) ≤ θmax."""
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

    def _advance(self, command: Command, dt: float) -> tuple[FloatArray, tuple[float, ...]]:
        state, cop, torque = self.advance(self.state, command, dt)
        return state, (cop, torque)

    def advance(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Advance ``state`` exactly by dt with (δ, τ) held; return it, the CoP and torque.

        The stateless core of :meth:`step` (the stepping model's stance uses it); a stop
        impact adds to ``stop_impacts``.
        """
        p = self.params
        cop, torque = p.clip_cop(command.cop), p.clip_hip_torque(command.flywheel_torque)
        if command.step_length is not None:
            raise InvalidParameterError("the flywheel model has no legs to step with")
        if dt != self._dt:
            self._dt = dt
            self._a, self._b = flywheel_discrete(p, dt)
            rows: list[list[float]] = np.hstack([self._a, self._b]).tolist()
            self._rows = tuple(tuple(row) for row in rows)
        new = _held_step(self._rows, state, cop, torque)
        limit = p.flywheel_angle_max
        if abs(new[1]) > limit:
            new[1] = math.copysign(limit, new[1])
            new[2] += p.flywheel_inertia * new[3] / (p.mass * p.com_height)
            new[3] = 0.0
            self.stop_impacts += 1
        return np.array(new), cop, torque

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """:func:`over_foot_at_rest`."""
        return over_foot_at_rest(state, self.params, speed)

    def falling(self, state: FloatArray) -> bool:
        """Beyond δ± ± τmax/(m g), moving outward, with H = m L ẋ + I θ̇ outward too.

        dH/dt = m g (x − δ) > 0 there whatever the hip torque, and a stop impact conserves H,
        so ẋ can never turn back: the set is absorbing even with the joint stop.
        """
        x, xdot = float(state[0]), float(state[2])
        # m L ẋ + I θ̇, in this order (the compiled batch repeats it: kernels/batched/stepping.py)
        momentum = self._momentum[0] * xdot + self._momentum[1] * float(state[3])
        lower, upper = self.fall_limits
        return (x > upper and xdot >= 0.0 and momentum >= 0.0) or (
            x < lower and xdot <= 0.0 and momentum <= 0.0
        )


def _held_step(
    rows: tuple[tuple[float, ...], ...], state: FloatArray, cop: float, torque: float
) -> list[float]:
    """X' = A X + B U for rows (A_i0..A_i3, B_i0, B_i1), summed left to right in floats.

    One fixed order of operations (numpy's mat-vec may take another, e.g. fused multiply-adds),
    so that the compiled batch of :mod:`pushrecovery.kernels.batched.stepping` gives the same bits.
    """
    s0, s1, s2, s3 = (float(v) for v in state)
    return [
        a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3 + (b0 * cop + b1 * torque)
        for a0, a1, a2, a3, b0, b1 in rows
    ]
