"""The MuJoCo ``foot`` model behind the :class:`~pushrecovery.sim.plants.Plant` protocol.

State handed to controllers: ``[x, xdot]``, the CoM position relative to the ankle and its
velocity, estimated from MuJoCo's data (subtree CoM of the body above the ankle). A CoP command δ
becomes the ankle torque that puts the CoP there on the pendulum, τ(δ) = δ A / (1 − δ sinθ / L)
with A = m g cos²θ − m L cosθ θ̇² (errata E3), from the estimated lean and rate (plantar flexion
positive; MuJoCo's hinge is positive leaning forward, hence the sign). Closing the loop on the
*measured* normal force instead is unstable at the foot edge: a slight tip raises F_z, which
raises the torque, which tips the foot further.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.pendulum import ankle_torque_for_cop, lean_from_com
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT, foot_model

__all__ = ["MujocoFootPlant"]

#: Time the foot settles on the floor before a run starts [s].
SETTLE_TIME = 0.3
#: Default CoP margin inside the foot edges [m].
DEFAULT_COP_MARGIN = 0.002
#: Default duration of a force push [s].
PUSH_DURATION = 0.01

FloatArray = NDArray[np.float64]


class MujocoFootPlant:
    """Rigid body on a tipping foot, in MuJoCo (model ``foot``).

    The CoP command is clipped to the foot shortened by ``cop_margin`` [m] (default 2 mm): on
    a real (soft-contact) foot the CoP can reach an edge only as the other edge lifts, i.e. as
    the foot starts to tip (docs/validation.md). A push can be a velocity jump
    (:meth:`initial_state`) or a real force: :meth:`schedule_push` applies an impulse [N s]
    at the CoM over a short duration at the start of the run.

    Fall: anything but the foot touches the floor, or the CoM drops below half its standing
    height, or the foot tips by more than 0.2 rad. The rest criterion of the simulator
    (CoM at rest over the foot, unsaturated command) decides recovery, as for the analytic
    models.
    """

    name: ClassVar[str] = "mujoco-foot"

    def __init__(self, params: BodyParams, cop_margin: float = DEFAULT_COP_MARGIN) -> None:
        import mujoco

        self._mj = mujoco
        self.params = params
        self.cop_margin = cop_margin
        self.model = mujoco.MjModel.from_xml_string(foot_model(params))
        self.data = mujoco.MjData(self.model)
        self.fall_limits = (params.heel, params.toe)
        self.stop_impacts = 0
        self._body = self.model.body("body").id
        self._foot = self.model.body("foot").id
        self._floor = self.model.geom("floor").id
        self._sole = self.model.geom("sole").id
        self._pitch = self.model.joint("foot_pitch").qposadr[0]
        self._ankle = self.model.joint("ankle").id
        self._force = np.zeros(6)
        self._mass_body = self.model.body("body").id
        self._push_force = 0.0
        self._push_left = 0.0

    def schedule_push(self, impulse: float, duration: float = PUSH_DURATION) -> None:
        """Push the body at its CoM with ``impulse`` [N s] spread over ``duration`` [s].

        Applied from the next :meth:`step` on (call after :meth:`initial_state`).
        """
        if not (math.isfinite(impulse) and math.isfinite(duration) and duration > 0.0):
            raise InvalidParameterError(
                f"impulse must be finite and duration > 0 s, got {impulse:g}, {duration:g}"
            )
        self._push_force, self._push_left = impulse / duration, duration

    # --- state ---------------------------------------------------------------------------
    def _settle(self) -> None:
        self._mj.mj_forward(self.model, self.data)

    def com_state(self) -> FloatArray:
        """``[x, xdot]`` of the CoM above the ankle, relative to the ankle [m, m/s]."""
        mj, d = self._mj, self.data
        mj.mj_subtreeVel(self.model, d)
        ankle = d.xanchor[self._ankle]
        com = d.subtree_com[self._body]
        return np.array([com[0] - ankle[0], d.subtree_linvel[self._body][0]])

    def initial_state(self, x: float, xdot: float) -> FloatArray:
        """Lean the body so the CoM is x ahead of the ankle, moving at ẋ; foot flat at rest.

        The body first stands upright (an exact balance, no torque) for ``SETTLE_TIME`` so
        that the foot's contact is at equilibrium when the lean and the push are applied.
        """
        d, length = self.data, self.params.com_height
        self._mj.mj_resetData(self.model, d)
        self._push_left = 0.0
        lean = math.asin(max(-0.99, min(0.99, x / length)))
        ankle_q = self.model.joint("ankle").qposadr[0]
        ankle_v = self.model.joint("ankle").dofadr[0]
        d.ctrl[0] = 0.0
        for _ in range(round(SETTLE_TIME / self.model.opt.timestep)):
            self._mj.mj_step(self.model, d)
        d.qpos[ankle_q] = lean
        d.qvel[:] = 0.0
        d.qvel[ankle_v] = xdot / (length * math.cos(lean))
        self._settle()
        return self.com_state()

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, xdot]`` (set with :meth:`initial_state`)."""
        if state.shape != (2,):
            raise InvalidParameterError(f"state must be [x, xdot], got shape {state.shape}")

    # --- dynamics --------------------------------------------------------------------------
    def measured_cop(self) -> float:
        """CoP of the floor's normal forces on the sole, relative to the ankle [m]."""
        moment = total = 0.0
        ankle_x = self.data.xanchor[self._ankle][0]
        for i in range(self.data.ncon):
            contact = self.data.contact[i]
            if {contact.geom1, contact.geom2} == {self._floor, self._sole}:
                self._mj.mj_contactForce(self.model, self.data, i, self._force)
                moment += self._force[0] * (contact.pos[0] - ankle_x)
                total += self._force[0]
        return moment / total if total > 0.0 else math.nan

    def step(
        self, state: FloatArray, command: Command, dt: float
    ) -> tuple[FloatArray, float, float]:
        """Hold the ankle torque for the CoP command over dt; return the estimated state."""
        if command.flywheel_torque != 0.0 or command.step_length is not None:
            raise InvalidParameterError("the mujoco foot model has only an ankle")
        p = self.params
        cop = min(p.toe - self.cop_margin, max(p.heel + self.cop_margin, command.cop))
        steps = max(1, round(dt / self.model.opt.timestep))
        for _ in range(steps):
            x, xdot = self.com_state()
            lean, rate = lean_from_com(
                max(-0.99, min(0.99, x / p.com_height)) * p.com_height, xdot, p.com_height
            )
            torque = ankle_torque_for_cop(lean, rate, cop, p.mass, p.com_height, p.gravity)
            self.data.ctrl[0] = -torque
            pushing = self._push_left > 0.0
            # The push acts at the subtree CoM (xfrc_applied acts at the body's CoM).
            self.data.xfrc_applied[self._mass_body, 0] = self._push_force if pushing else 0.0
            self._push_left -= self.model.opt.timestep
            self._mj.mj_step(self.model, self.data)
        return self.com_state(), cop, 0.0

    def falling(self, state: FloatArray) -> bool:
        """Anything but the sole on the floor, the CoM below half height, or a tipped foot."""
        d = self.data
        for i in range(d.ncon):
            contact = d.contact[i]
            geoms = {contact.geom1, contact.geom2}
            if self._floor in geoms and self._sole not in geoms:
                return True
        com_height = d.subtree_com[self._body][2]
        return bool(
            com_height < 0.5 * (self.params.com_height + ANKLE_HEIGHT)
            or abs(d.qpos[self._pitch]) > 0.2
        )
