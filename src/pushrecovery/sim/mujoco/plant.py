"""MuJoCo plants behind the backend contract (:mod:`pushrecovery.sim.backend`): the shared base.

The controllers see the same state as on the analytic models and send the same commands; the
plants turn them into joint torques (refreshed at every control tick and at least every
``torque_hold``: 1 ms, the physics step, or 10 ms for ``foot`` and ``torso``) and estimate the
state from MuJoCo's joints:

- ``foot`` (:class:`~pushrecovery.sim.mujoco.pendulums.MujocoFootPlant`): state
  ``[x, xdot]``, the CoM (the mass at the top of the rod) relative to the ankle, x = L sinφ
  with φ the body's absolute pitch (foot pitch + ankle).
- ``torso`` (:class:`~pushrecovery.sim.mujoco.pendulums.MujocoTorsoPlant`): state
  ``[x, theta, xdot, theta_dot]`` as the flywheel model, with θ the upper body's absolute
  pitch (the flywheel angle of Eq. 7).

A CoP command δ becomes the ankle torque that puts the CoP there on a pendulum whose hip carries
the commanded hip torque τ_h, τ(δ) = δ (A + τ_h sinφ/L) / (1 − δ sinφ/L) with
A = m g cos²φ − m L cosφ φ̇² (errata E3), from the current lean and rate. Plantar flexion is
positive in the paper and negative about MuJoCo's +y hinge, hence the sign. Closing the loop on
the *measured* normal force instead is unstable at the foot edge: a slight tip raises F_z, which
raises the torque, which tips the foot further.

Over 400 lines on purpose: one class, what every planar MuJoCo plant shares (the model, pushes,
the physics loop and its audit, the measured CoP, falls, recording).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.control.base import Command, StepInfo
from pushrecovery.errors import InvalidParameterError, SimulationDiverged
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import RecordedFrame, Step, check_com_state, over_foot_at_rest
from pushrecovery.sim.mujoco.contact_audit import ContactAudit
from pushrecovery.sim.mujoco.engine import (
    floor_cop_world,
    settle,
    touches_floor,
    unstable_warnings,
)
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT, MODEL_BUILDERS, TIMESTEP
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.push import PUSH_DURATION, Push

__all__ = [
    "DEFAULT_COP_MARGIN",
    "FOOT_TIP_LIMIT",
    "PUSH_DURATION",
    "SETTLE_TIME",
    "TORQUE_HOLD",
    "MujocoPlant",
    "RecordedFrame",
]

#: Time the feet settle on the floor before a run starts [s].
SETTLE_TIME = 0.3
#: Default CoP margin inside the foot edges [m].
DEFAULT_COP_MARGIN = 0.002
#: Foot pitch beyond which a foot counts as tipped over [rad].
FOOT_TIP_LIMIT = 0.2
#: Longest hold of the ankle and hip torques of ``foot`` and ``torso`` [s].
TORQUE_HOLD = 0.01

FloatArray = NDArray[np.float64]


class MujocoPlant(ABC):
    """What every MuJoCo plant shares: the model, pushes, measured CoP, falls, recording.

    Subclasses set ``model_name`` and the names of the pushed body and of the CoM body, and
    implement :meth:`read_state` (joint readings → the controller's state) and
    :meth:`actuate` (command → ``data.ctrl``, called at every torque refresh).

    Parameters
    ----------
    params : BodyParams
        The body; the model is generated from it (:mod:`pushrecovery.sim.mujoco.models`).
    cop_margin : float
        The CoP command is clipped to the foot shortened by this much at each edge [m],
        in [0, (toe − heel)/4]: with soft contacts the CoP reaches an edge only as the other
        edge lifts, i.e. as the foot starts to tip (docs/validation.md, "From the paper's commands
        to joint torques").
    """

    name: ClassVar[str]
    model_name: ClassVar[str]
    #: Body the push force acts on (at its centre of mass).
    pushed_body: ClassVar[str]
    #: The foot bodies whose contacts the audit checks (:meth:`physical_checks`).
    feet: ClassVar[tuple[str, ...]] = ("foot",)
    #: Longest time the joint torques are held between two refreshes [s]; they are also
    #: refreshed at every control tick and at every step of a push. One physics step (the
    #: default) for plants with joint servos; longer for open-loop torque maps of a slowly
    #: changing state.
    torque_hold: ClassVar[float] = TIMESTEP
    state_labels: ClassVar[tuple[str, ...]]
    input_labels: ClassVar[tuple[str, ...]] = ("cop", "hip_torque")

    def __init__(self, params: BodyParams, cop_margin: float = DEFAULT_COP_MARGIN) -> None:
        import mujoco

        require_type("params", params, BodyParams)
        cop_margin = bounded_float(
            "cop_margin", cop_margin, 0.0, 0.25 * (params.toe - params.heel), "m"
        )
        self._mj: Any = mujoco
        self.params = params
        self.cop_margin = cop_margin
        self.model = self.build(params).compile()
        self.data = mujoco.MjData(self.model)
        self.fall_limits = (params.heel, params.toe)
        self.stop_impacts = 0
        self._first_ankle = 0.0
        self.time = 0.0
        #: Frames recorded by :meth:`step` after :meth:`record` (for rendering), else None.
        self.frames: list[RecordedFrame] | None = None
        #: CoP measured from the contact forces at each recorded step, relative to the stance
        #: ankle [m] (NaN while no sole touches the floor).
        self.measured_cops: list[float] = []
        model = self.model
        self._floor = model.geom("floor").id
        self._soles = frozenset(
            i for i in range(model.ngeom) if model.geom(i).name.endswith("sole")
        )
        self._pushed = model.body(self.pushed_body).id
        self._push_target = -1
        self._qpos: FloatArray = self.data.qpos
        self._qvel: FloatArray = self.data.qvel
        self._ctrl: FloatArray = self.data.ctrl
        self._xfrc: FloatArray = self.data.xfrc_applied
        # Read at every control tick, as Python numbers: memoryviews of the data's buffers
        # (fixed for its life) read twice as fast as NumPy's indexing or ``item``.
        self._subtree_com = memoryview(self.data.subtree_com)
        #: Height of the CoM below which the body counts as fallen (:meth:`falling`) [m].
        self._fall_height = 0.5 * (params.com_height + ANKLE_HEIGHT)
        self._force = np.zeros(6)
        self._push_force = 0.0
        self._push_steps = 0
        #: Horizontal force on the pushed body during this physics step [N].
        self.push_now = 0.0
        self._substep = model.opt.timestep
        self._hold_steps = max(1, round(self.torque_hold / self._substep))
        self._steps_done = 0
        self._measuring = False
        # Counts of the warnings after which MuJoCo resets (a view of the data's: no copies;
        # a memoryview, read after every step).
        self._warnings = memoryview(self.data.warning.number)
        self._unstable = unstable_warnings()
        #: The physical checks of every physics step since :meth:`reset` (the model's pose
        #: qpos0 stands on flat soles).
        self.audit = ContactAudit(model, self.data, self.feet, model.qpos0, params.weight)
        #: The state after settling (:meth:`reset`), kept: settling is the same every time.
        self._settled: FloatArray | None = None
        self._info_key: tuple[int, float] | None = None
        self._info = StepInfo()

    @classmethod
    def build(cls, params: BodyParams) -> Any:
        """Return the model's ``mujoco.MjSpec`` for ``params`` (:data:`~.models.MODEL_BUILDERS`)."""
        return MODEL_BUILDERS[cls.model_name](params)

    @classmethod
    def xml(cls, params: BodyParams) -> str:
        """Return the model as MJCF text (from :meth:`build`), e.g. to inspect or save it."""
        text: str = cls.build(params).to_xml()
        return text

    # --- pushes and recording ------------------------------------------------------------
    def apply_push(self, push: Push) -> FloatArray:
        """Push (contract item 4) and return the state after it (scheduled: the state now).

        A ``"velocity"`` push adds Δẋ [m/s] to the CoM velocity now, the pose kept. A
        ``"force"`` push acts with J = m Δẋ [N s] (+x forward) on ``push.body`` (default the
        pushed body) at that body's centre of mass, over the whole physics steps nearest to
        ``push.duration`` (at least one) with the force that makes their total exactly J;
        :attr:`push_left` is how long it still acts. On another body the CoP map does not
        know the push, so the CoP wanders during it.

        Scheduled (``push.scheduled``), the force acts from the next :meth:`step` on (call
        after :meth:`reset` or :meth:`begin`). Otherwise it acts now while the body holds
        still (the CoP under the CoM, no hip torque), and the state returned is the state
        just after the push, the moment the paper's velocity jump stands for; the clock
        restarts there, so a controller started on it sees the push as it ends.

        Raises
        ------
        InvalidParameterError
            If ``push.duration`` is shorter than the MuJoCo step, ``push.body`` is not a body
            of the model, or the CoM velocity it stands for leaves abs(ẋ) < 10 sqrt(g L).
        """
        require_type("push", push, Push)
        delta = push.delta_velocity
        if push.kind == "velocity":
            state = self.read_state()
            if delta == 0.0:
                return state
            x, xdot = float(state[0]), float(state[len(state) // 2]) + delta
            check_com_state(x, xdot, self.params)
            self.pose(x, xdot)
            self._mj.mj_forward(self.model, self.data)
            return self.read_state()
        if push.duration < self._substep:
            raise InvalidParameterError(
                f"duration must be >= the MuJoCo step {self._substep:g} s, got {push.duration:g}"
            )
        check_com_state(0.0, delta, self.params)
        target = self.pushed_body if push.body is None else push.body
        try:
            self._push_target = self.model.body(target).id
        except KeyError:
            names = [self.model.body(i).name for i in range(1, self.model.nbody)]
            raise InvalidParameterError(f"body must be one of {names}, got {push.body!r}") from None
        self._push_steps = round(push.duration / self._substep)
        self._push_force = push.impulse(self.params.mass) / (self._push_steps * self._substep)
        state = self.read_state()
        if push.scheduled:
            return state
        while self._push_steps > 0:
            state, _, _ = self._hold(Command(float(state[0])), self._substep)
        self._start_clock()
        return state

    @property
    def push_left(self) -> float:
        """How long the force of the push still acts [s] (0: no push)."""
        return self._push_steps * self._substep

    def record(self) -> None:
        """Record a frame at every :meth:`step` from now on (see :attr:`frames`)."""
        self.frames, self.measured_cops, self._measuring = [], [], True

    def measure(self) -> None:
        """Record only the measured CoP at every :meth:`step` (:attr:`measured_cops`)."""
        self.frames, self.measured_cops, self._measuring = None, [], True

    def _start_clock(self) -> None:
        self.time, self._steps_done = 0.0, 0
        self.measured_cops = []
        if self.frames is not None:
            self.frames = []
            self._record(None)

    # --- state ---------------------------------------------------------------------------
    @abstractmethod
    def read_state(self) -> FloatArray:
        """Return the controller's state from the current joint positions and velocities."""

    @abstractmethod
    def actuate(self, cop: float, command: Command) -> float:
        """Set ``data.ctrl`` until the next torque refresh; return the applied hip torque [N m]."""

    @abstractmethod
    def pose(self, x: float, xdot: float) -> None:
        """Set the joints for a CoM at x [m] moving at ẋ [m/s] after settling (subclasses)."""

    @abstractmethod
    def ankle_x(self) -> float:
        """World x of the stance ankle [m]."""

    def reset(self, x: float, xdot: float) -> FloatArray:
        """Lean so the CoM is x ahead of the ankle, moving at ẋ; feet flat, upper body upright.

        The body first stands upright (an exact balance, no torque) for ``SETTLE_TIME`` so
        that the contacts are at equilibrium when the lean and the push are applied (contract
        item 2).
        """
        check_com_state(x, xdot, self.params)
        mj, d = self._mj, self.data
        self._push_steps, self.push_now, self.stop_impacts = 0, 0.0, 0
        self._push_target = -1
        steps = round(SETTLE_TIME / self._substep)
        self._settled = settle(self.model, d, steps, self._settled)  # once, then restored
        d.qvel[:] = 0.0
        self.pose(x, xdot)
        mj.mj_forward(self.model, d)
        self._start_clock()
        self._restart_records()
        self.audit.reset()
        return self.read_state()

    def check_state(self, state: FloatArray) -> None:
        """Require the state shape of the model (set it with :meth:`reset`)."""
        size = len(self.state_labels)
        if state.shape != (size,):
            raise InvalidParameterError(
                f"state must be {list(self.state_labels)} for {self.name}, got shape {state.shape}"
            )

    def begin(self, state: FloatArray) -> FloatArray:
        """Start a run from the body as it is now (after :meth:`reset` or a push; item 3).

        MuJoCo's state is its joints: ``state`` must have the model's shape; the run's
        records (stop impacts, footholds) start here.
        """
        state = np.array(state, dtype=np.float64)
        self.check_state(state)
        self._restart_records()
        return state

    def _restart_records(self) -> None:
        self.stop_impacts = 0
        self._first_ankle = self.ankle_x()

    def info(self) -> StepInfo:
        """Return the report of the run so far (contract item 5): stance, footholds, CoP."""
        if self._measuring:
            measured = self.measured_cops[-1] if self.measured_cops else None
            return StepInfo(True, (self._first_ankle,), self.stop_impacts, measured)
        key = (self.stop_impacts, self._first_ankle)  # kept while it stays the same
        if key != self._info_key:
            self._info_key, self._info = key, StepInfo(True, (key[1],), key[0], None)
        return self._info

    def physical_checks(self) -> PhysicalChecks:
        """Return the checks of every physics step since :meth:`reset` (contact_audit)."""
        return self.audit.result()

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """:func:`~pushrecovery.sim.plants.over_foot_at_rest` on the stance foot."""
        return over_foot_at_rest(state, self.params, speed)

    # --- dynamics ------------------------------------------------------------------------
    def measured_cop_world(self) -> float:
        """World x of the CoP of the floor's normal forces on the soles [m]; NaN if airborne."""
        return floor_cop_world(self.model, self.data, self._floor, self._soles, self._force)

    def measured_cop(self) -> float:
        """CoP of the floor's normal forces on the soles, relative to the stance ankle [m]."""
        return self.measured_cop_world() - self.ankle_x()

    def step(self, command: Command, dt: float) -> Step:
        """Hold ``command`` over dt, torques refreshed every ``torque_hold`` (contract item 5).

        The applied inputs are the commanded CoP after clipping [m] and the hip torque [N m].
        """
        state, cop, torque = self._hold(command, dt)
        return Step(state, (cop, torque), self.info())

    def _hold(self, command: Command, dt: float) -> tuple[FloatArray, float, float]:
        p, margin = self.params, self.cop_margin
        cop = min(p.toe - margin, max(p.heel + margin, command.cop))
        mj_step, model, d, h = self._mj.mj_step, self.model, self.data, self._substep
        if dt < 0.5 * h:
            raise InvalidParameterError(
                f"control_period must be >= half the MuJoCo step, {0.5 * h:g} s, got {dt:g}"
            )
        actuate, audit, torque = self.actuate, self.audit.after_step, 0.0
        # Whole physics steps that keep the physics clock on the control clock (a period
        # that is not a multiple of the step, e.g. bang-bang's, is rounded per tick).
        self.time += dt
        steps = round(self.time / h) - self._steps_done
        self._steps_done += steps
        while steps and self._push_steps:
            self._xfrc[self._push_target, 0] = self._push_force
            # The CoP map accounts for a push at the CoM only.
            self.push_now = self._push_force if self._push_target == self._pushed else 0.0
            torque = actuate(cop, command)
            mj_step(model, d)
            audit()
            self._push_steps -= 1
            steps -= 1
        if self._push_target >= 0 and not self._push_steps:
            self.push_now = self._xfrc[self._push_target, 0] = 0.0
            self._push_target = -1
        # The hot loop: the torques are refreshed every `torque_hold` steps (about 1 µs of
        # Python each); the audit sees every physics step.
        hold = self._hold_steps
        while steps > 0:
            torque = actuate(cop, command)
            for _ in range(min(hold, steps)):
                mj_step(model, d)
                audit()
            steps -= hold
        counts, (a, b, c) = self._warnings, self._unstable
        if counts[a] or counts[b] or counts[c]:
            raise SimulationDiverged(
                "MuJoCo's simulation became unstable (accelerations blew up); "
                "the push or the state is beyond what the model can simulate"
            )
        if self._measuring:
            self._record(cop)
        return self.read_state(), cop, torque

    def _record(self, cop: float | None) -> None:
        d = self.data
        if self.frames is None:  # the CoP only, from the last step's contacts
            self.measured_cops.append(self.measured_cop_world() - self.ankle_x())
            return
        self._mj.mj_forward(self.model, d)
        state = self.read_state()
        half = len(state) // 2
        com = d.subtree_com[0]
        capture = self.ankle_x() + state[0] + state[half] / self.params.omega
        measured = self.measured_cop_world() if cop is not None else math.nan
        self.frames.append((self.time, d.qpos.copy(), (com[0], com[2]), capture, measured))
        if cop is not None:
            self.measured_cops.append(measured - self.ankle_x())

    def falling(self, state: FloatArray) -> bool:
        """Anything but a sole on the floor, the CoM below half height, or a tipped foot."""
        if touches_floor(self.data, self._floor, self._soles):
            return True
        return self._subtree_com[0, 2] < self._fall_height or self.foot_tipped()

    @abstractmethod
    def foot_tipped(self) -> bool:
        """Whether the stance foot has tipped beyond ``FOOT_TIP_LIMIT``."""
