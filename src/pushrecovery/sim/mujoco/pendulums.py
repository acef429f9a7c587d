"""The ``foot`` and ``torso`` plants: the pendulum and the flywheel model in MuJoCo.

Their model, the CoP → ankle torque map and the hip are described in
:mod:`pushrecovery.sim.mujoco.plant` (the base of every MuJoCo plant).
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import FLYWHEEL_STATE
from pushrecovery.models.lipm import ANKLE_STATE
from pushrecovery.models.pendulum import ankle_torque_for_cop_unchecked
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT, FOOT_MASS
from pushrecovery.sim.mujoco.plant import (
    DEFAULT_COP_MARGIN,
    FOOT_TIP_LIMIT,
    TORQUE_HOLD,
    MujocoPlant,
)

__all__ = ["MujocoFootPlant", "MujocoTorsoPlant"]

FloatArray = NDArray[np.float64]


class MujocoFootPlant(MujocoPlant):
    """Rigid body on a tipping foot, in MuJoCo (model ``foot``): the pendulum of Fig. 3(b).

    A push can be a velocity jump (:meth:`reset`) or a real force: :meth:`apply_push` applies
    an impulse [N s] at the CoM over a short duration. The rest criterion of the simulator
    (CoM at rest over the foot, unsaturated command) decides recovery, as for the analytic
    models.
    """

    name: ClassVar[str] = "mujoco-foot"
    state_labels: ClassVar[tuple[str, ...]] = ANKLE_STATE
    model_name: ClassVar[str] = "foot"
    pushed_body: ClassVar[str] = "body"
    #: The CoP → torque map depends on the lean and its rate only, which change little in
    #: 10 ms: holding its torque that long moves the critical pushes by < 0.1 % against a
    #: refresh at every step, and makes the loop 1.3× faster (CHANGELOG.md; docs/performance.md,
    #: "Simulation", has the loop's speed).
    torque_hold: ClassVar[float] = TORQUE_HOLD

    def __init__(self, params: BodyParams, cop_margin: float = DEFAULT_COP_MARGIN) -> None:
        super().__init__(params, cop_margin)
        model = self.model
        self._pitch = int(model.joint("foot_pitch").qposadr[0])
        self._pitch_v = int(model.joint("foot_pitch").dofadr[0])
        self._ankle = int(model.joint("ankle").qposadr[0])
        self._ankle_v = int(model.joint("ankle").dofadr[0])
        self._ankle_id = model.joint("ankle").id
        self._foot_centre = 0.5 * (params.heel + params.toe)
        # The joints read as Python floats, through memoryviews of the data's buffers (as
        # ``_qpos``: fixed for the data's life): the torque map and the state do their
        # arithmetic on them at every torque refresh, twice as fast as on NumPy scalars (the
        # same IEEE operations: the same bits), and a memoryview reads twice as fast as
        # ``ndarray.item``.
        self._q = memoryview(self.data.qpos)
        self._v = memoryview(self.data.qvel)
        # The torque map's body constants, bound once: read at every torque refresh.
        self._body = (params.mass, params.com_height, params.gravity)

    def lean(self) -> tuple[float, float]:
        """Absolute pitch φ of the body above the ankle and its rate [rad, rad/s]."""
        q, v = self._q, self._v
        return q[self._pitch] + q[self._ankle], v[self._pitch_v] + v[self._ankle_v]

    def read_state(self) -> FloatArray:
        """``[x, xdot]`` = (L sinφ, L cosφ φ̇) of the CoM relative to the ankle [m, m/s]."""
        lean, rate = self.lean()
        length = self.params.com_height
        return np.array([length * math.sin(lean), length * math.cos(lean) * rate])

    def pose(self, x: float, xdot: float) -> None:
        """Lean the body above the ankle; the foot stays as it settled."""
        length = self.params.com_height
        lean = math.asin(x / length)  # |x| < L: checked by reset
        self._qpos[self._ankle] = lean - self._qpos[self._pitch]
        self._qvel[self._ankle_v] = xdot / (length * math.cos(lean))

    def ankle_x(self) -> float:
        """World x of the ankle [m]."""
        return float(self.data.xanchor[self._ankle_id][0])

    def foot_tipped(self) -> bool:
        """Foot pitch beyond ``FOOT_TIP_LIMIT``."""
        return abs(self._q[self._pitch]) > FOOT_TIP_LIMIT

    def ankle_torque(self, cop: float, hip_torque: float = 0.0) -> float:
        """Ankle torque (paper's sign) that puts the CoP at ``cop`` now [N m] (errata E3)."""
        p = self.params
        lean, rate = self.lean()
        return ankle_torque_for_cop_unchecked(  # by position: called at every torque refresh
            lean,
            rate,
            cop,
            p.mass,
            p.com_height,
            p.gravity,
            hip_torque,
            self.push_now,  # push_force
            ANKLE_HEIGHT,
            FOOT_MASS,
            self._foot_centre,
        )

    def actuate(self, cop: float, command: Command) -> float:
        """Ankle torque for the CoP; the model has nothing else to move."""
        if command.flywheel_torque != 0.0 or command.step_length is not None:
            raise InvalidParameterError("the mujoco foot model has only an ankle")
        self._ctrl[0] = -self.ankle_torque(cop)
        return 0.0


class MujocoTorsoPlant(MujocoFootPlant):
    """Pendulum + upper body on a hip limited to ±θmax, in MuJoCo (model ``torso``).

    State ``[x, theta, xdot, theta_dot]`` as :class:`~pushrecovery.sim.plants.FlywheelPlant`:
    θ is the upper body's absolute pitch (I θ̈ = τ_h, Eq. 7). The joint limit acts on the hip
    angle θ − φ; every time the hip reaches the stop counts one ``stop_impacts`` (sampled at
    the torque refreshes, so a touch of the stop shorter than ``torque_hold`` can be missed).
    """

    name: ClassVar[str] = "mujoco-torso"
    state_labels: ClassVar[tuple[str, ...]] = FLYWHEEL_STATE
    model_name: ClassVar[str] = "torso"
    pushed_body: ClassVar[str] = "torso"

    def __init__(self, params: BodyParams, cop_margin: float = DEFAULT_COP_MARGIN) -> None:
        super().__init__(params, cop_margin)
        # As the flywheel model: beyond δ± ± τmax/(m g) no CMP stops an outgoing CoM.
        self.fall_limits = params.hip_fall_limits
        self._hip = int(self.model.joint("hip").qposadr[0])
        self._hip_v = int(self.model.joint("hip").dofadr[0])
        self._at_stop = False
        #: Hip angle from which the hip counts as at its stop [rad].
        self._stop_angle = params.flywheel_angle_max - 1e-3
        self._torque_max = params.torque_max

    def read_state(self) -> FloatArray:
        """``[x, theta, xdot, theta_dot]`` [m, rad, m/s, rad/s]."""
        q, v = self._q, self._v  # lean() inlined: read at every control tick
        lean, rate = q[self._pitch] + q[self._ankle], v[self._pitch_v] + v[self._ankle_v]
        length = self._body[1]
        return np.array(
            [
                length * math.sin(lean),
                lean + q[self._hip],
                length * math.cos(lean) * rate,
                rate + v[self._hip_v],
            ]
        )

    def pose(self, x: float, xdot: float) -> None:
        """Lean the legs; the upper body stays upright and at rest (hip = −lean)."""
        super().pose(x, xdot)
        lean, rate = self.lean()
        self._qpos[self._hip] = -lean
        self._qvel[self._hip_v] = -rate

    def actuate(self, cop: float, command: Command) -> float:
        """Hip torque (clipped to τmax) and the ankle torque for the CoP under it."""
        if command.step_length is not None:
            raise InvalidParameterError("the mujoco torso model has no legs to step with")
        # clip_hip_torque, lean() and ankle_torque() inlined (the same operations): this runs
        # twice per control tick, and each call cost ~0.15 µs of its ~1.1 µs.
        limit = self._torque_max
        torque = min(limit, max(-limit, command.flywheel_torque))
        q, v = self._q, self._v
        mass, length, gravity = self._body
        ctrl = self._ctrl
        ctrl[0] = -ankle_torque_for_cop_unchecked(
            q[self._pitch] + q[self._ankle],
            v[self._pitch_v] + v[self._ankle_v],
            cop,
            mass,
            length,
            gravity,
            torque,
            self.push_now,
            ANKLE_HEIGHT,
            FOOT_MASS,
            self._foot_centre,
        )
        ctrl[1] = torque
        at_stop = abs(q[self._hip]) >= self._stop_angle
        if at_stop and not self._at_stop:
            self.stop_impacts += 1
        self._at_stop = at_stop
        return torque
