r"""The 3-D humanoids as plants: the backend contract where it fits, a 3-D push, the WBC's loop.

:class:`Biped3DPlant` (``biped3d``, the biped of :mod:`.biped3d` with its knees bent,
:func:`~.biped3d.bent_knee_qpos`) and :class:`G1Plant` (``g1``, the Unitree G1 of the
``robots`` extra) keep their state in MuJoCo and report the contract's
(docs/architecture.md) where it is 3-D:

* **State** (:data:`STATE_LABELS`): the whole-body CoM ``x, y, z`` [m] and its velocity
  ``xdot, ydot, zdot`` [m/s], world frame (x forward, y left, z up, the floor at 0):
  positions then velocities, ``x`` first and ``xdot`` at ``len // 2`` as item 1 asks.
* **reset(x, xdot)** stands the body still (``x = xdot = 0`` only: the standing posture puts
  the CoM over the feet; a push is :meth:`~Humanoid3DPlant.apply_push`).
* **begin(state)** starts a run from the plant's own current state only (MuJoCo's state is
  not a function of the CoM's).
* **apply_push(push)** takes a :class:`~pushrecovery.sim.push.Push3D` (or a sagittal force
  :class:`~pushrecovery.sim.push.Push` of the default duration, as J = m Δẋ at azimuth 0 or
  180 on its body) and applies the constant force J/Δ (cos ψ, sin ψ, 0) for Δ =
  :data:`PUSH_DURATION` (10 ms, whole physics steps) at the pushed body's centre of mass
  (``xfrc_applied``): the whole body's momentum gains J, minus what the floor's friction
  takes. Not ``scheduled``: now, the motors holding their last ``ctrl``, with a row after it.
  ``scheduled``: on the physics steps of the next :meth:`~Humanoid3DPlant.step` calls, under
  whatever motor commands they hold (a controller reacting through the push);
  :attr:`~Humanoid3DPlant.push_left` is how long it still acts
  (:class:`~pushrecovery.sim.events.ForcePushing`).
* **step(command, dt)** holds the motor commands of a
  :class:`~pushrecovery.control.wbc.observation.HumanoidCommand` (``motors`` [N m], the
  :class:`~pushrecovery.control.wbc.controller.WholeBodyController`'s output; any other
  ``Command`` holds the last motors: the body holding still), clipped to the motors' ranges,
  for dt (rounded to physics steps); ``applied`` is the clipped ``ctrl`` (``input_labels``:
  the motors' names).
* **observation**: the :class:`~pushrecovery.control.wbc.observation.HumanoidObservation`
  the plant hands its controller (:func:`wbc_for`), views of its ``MjData`` built once.
* **falling(state)**: the capture point ξ = c_xy + ċ_xy/ω (ω = sqrt(g/z₀), z₀ the CoM's
  standing height above the soles) farther than :meth:`~Humanoid3DPlant.fall_margin` =
  2 max(τmax, τmax_roll)/(m g) outside the support polygon P (the hull of both soles at
  reset): beyond what both hips' CMP offsets could bring back, the LIPM with a flywheel
  falls; or the CoM below :data:`FALL_HEIGHT` z₀ (the body is down). Under a controller that
  steps (its command's ``support``, reported in the step's ``StepInfo.support``) a capture
  point beyond the feet is what a step answers: the body down only.
* **at_rest(state, speed)**: ‖ċ_xy‖ <= speed and the CoM's ground point strictly inside P
  (the step's ``StepInfo.support`` when the controller steps, and no foot swinging).
* **Clocked** (:class:`~pushrecovery.sim.backend.Clocked`): ``clock`` is MuJoCo's time and
  ``run_rows()`` the rows since ``reset``/``begin``: one per step and one after a push held
  still (whose 10 ms are physics steps of the plant's own), so the loop's result keeps
  MuJoCo's time and the state on either side of the push. With ``recording`` set, each row
  also keeps ``qpos``, ``qvel`` and ``ctrl`` (``frames``). :attr:`~Humanoid3DPlant.push_row`
  is the row at which the last push's force ended and
  :attr:`~Humanoid3DPlant.max_torso_tilt` the largest torso tilt since then.

* **audit**: a :class:`~pushrecovery.sim.mujoco.contact_audit.ContactAudit` watches every
  physics step since reset/begin (loaded-foot slip, ground force, penetration, friction and
  torque use, joint limits; :mod:`pushrecovery.sim.physical_checks`).

:func:`~pushrecovery.sim.simulate.simulate` is the loop of these plants
(:func:`~.runs3d.run_push3d`: stand, push, run the whole-body controller).

Over 400 lines on purpose: one class and the contract it keeps, item by item; the models are
in :mod:`.biped3d` and :mod:`.robots`, the run in :mod:`.runs3d`.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_float, non_negative_float, require_type
from pushrecovery.control.base import Command, StepInfo
from pushrecovery.control.wbc.bodies import (
    body_id,
    body_names,
    check_model,
    check_qpos,
    sole_points,
)
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.control.wbc.observation import (
    HUMANOID_STATE,
    HumanoidCommand,
    mujoco_observation,
)
from pushrecovery.errors import InvalidParameterError, SimulationDiverged
from pushrecovery.ground.polygon import ConvexPolygon, convex_hull
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import RunRows, Step
from pushrecovery.sim.mujoco.contact_audit import ContactAudit
from pushrecovery.sim.mujoco.humanoid3d.biped3d import SIDES, bent_knee_qpos, biped3d_model
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.push import PUSH_DURATION, Push, Push3D

FloatArray = NDArray[np.float64]

__all__ = [
    "CONTROL_PERIOD",
    "FALL_HEIGHT",
    "PUSH_DURATION",
    "STATE_LABELS",
    "Biped3DPlant",
    "G1Plant",
    "Humanoid3DPlant",
    "wbc_for",
]

#: The 3-D plants' state: the whole-body CoM and its velocity (world frame).
STATE_LABELS = HUMANOID_STATE
#: The WBC's period [s] (500 Hz).
CONTROL_PERIOD = 0.002
#: A CoM below this fraction of its standing height above the soles is down (fallen).
FALL_HEIGHT = 0.7


class Humanoid3DPlant:
    """A 3-D humanoid in MuJoCo behind the backend contract where it fits (module docstring).

    Parameters
    ----------
    params : BodyParams
        The body (its mass, gravity and hip torque limits enter the fall set).
    model : mujoco.MjModel
        The humanoid: a free root joint first, torque motors.
    qpos : float array
        Its standing posture, soles on the floor, in MuJoCo's units: [m] for slide and free-joint
        positions, [-] for the free joint's unit quaternion, [rad] for hinges.
    feet : tuple of str
        The foot bodies (left, right).
    torso : str
        The body a push named ``"torso"`` acts on.
    upright : str
        The body the WBC holds upright (its origin's height is the pelvis task).
    ankle : (float, float)
        The ankles' midpoint at the standing pose, world xy [m]: the origin of the frame of
        ``params``' feet (``Support.from_params``), in which ``standing_origin`` is given.
    """

    name: ClassVar[str] = "humanoid3d"
    state_labels: ClassVar[tuple[str, ...]] = STATE_LABELS
    #: Whether :func:`wbc_for` gives its controller the hip (CMP) task unless told.
    hip_task: ClassVar[bool] = True

    def __init__(
        self,
        params: BodyParams,
        model: Any,
        qpos: FloatArray,
        feet: tuple[str, ...],
        torso: str,
        upright: str,
        ankle: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        import mujoco

        require_type("params", params, BodyParams)
        check_model(model)
        feet = body_names(model, feet, "feet")
        body_id(model, torso)
        self.params, self.model = params, model
        if not (isinstance(ankle, tuple | list) and len(ankle) == 2):
            raise InvalidParameterError(f"ankle must be (x, y) [m], got {ankle!r}")
        self.ankle = (
            finite_float("ankle x", ankle[0], "m"),
            finite_float("ankle y", ankle[1], "m"),
        )
        self.qpos = check_qpos(model, qpos).copy()
        self.feet, self.torso, self.upright = feet, torso, upright
        self.data = mujoco.MjData(model)
        self.observation = mujoco_observation(model, self.data)
        self.input_labels: tuple[str, ...] = tuple(model.actuator(i).name for i in range(model.nu))
        self.ctrl_range = np.array(model.actuator_ctrlrange, dtype=float)
        limited = np.asarray(model.actuator_ctrllimited, dtype=bool)
        self.ctrl_range[~limited] = (-np.inf, np.inf)
        self.hip_motors = [
            i for i, label in enumerate(self.input_labels)
            if "hip_pitch" in label or "hip_roll" in label
        ]  # fmt: skip
        self.steps_per_tick = max(1, round(CONTROL_PERIOD / float(model.opt.timestep)))
        self.state = np.zeros(len(STATE_LABELS))
        self.ctrl = np.zeros(int(model.nu))
        self.support: ConvexPolygon | None = None
        self.info = StepInfo()  # the last step's report (its support: the fall rule's)
        self.floor = 0.0
        self.standing_height = 1.0
        self.omega = 1.0
        #: Standing (at reset): the CoM's ground point r₀ [m] relative to the ankles'
        #: midpoint (``ankle``: the frame of the body's feet, ``Support.from_params``) and the
        #: pushed torso's CoM height above the whole-body CoM d [m], the lever of a push
        #: (docs/validation3d.md).
        self.standing_origin = (0.0, 0.0)
        self.push_lever = 0.0
        #: Keep ``qpos``, ``qvel`` and ``ctrl`` at each row (``frames``) from the next reset.
        self.recording = False
        self.frames: list[FloatArray] = []
        #: The row at which the last push's force ended (None: none since reset/begin).
        self.push_row: int | None = None
        #: The largest tilt of the upright body since the last push ended [rad] (0 before).
        self.max_torso_tilt = 0.0
        # A scheduled push: its body, force [N] and the physics steps it still acts.
        self._push_body, self._push_force, self._push_steps = -1, np.zeros(3), 0
        self._upright_id = body_id(model, upright)
        #: The physical checks of the run since reset/begin (every physics step).
        gravity = float(np.linalg.norm(model.opt.gravity))
        weight = float(np.sum(model.body_mass)) * gravity
        self.audit = ContactAudit(model, self.data, feet, self.qpos, weight)
        self._times: list[float] = []
        self._states: list[FloatArray] = []
        self._inputs: list[tuple[float, ...]] = []
        self.reset()

    # -- contract items 2-3 ----------------------------------------------------------------

    def reset(self, x: float = 0.0, xdot: float = 0.0) -> FloatArray:
        """Stand still in the standing posture (contract item 2, ``x = xdot = 0`` only).

        Raises
        ------
        InvalidParameterError
            If ``x`` or ``xdot`` is not 0 (the posture sets the CoM; push with apply_push).
        """
        import mujoco

        for label, value in (("x", x), ("xdot", xdot)):
            if finite_float(label, value) != 0.0:
                raise InvalidParameterError(
                    f"{label} must be 0 on the 3-D models (the standing posture puts the CoM "
                    f"over the feet; push with apply_push), got {label}={float(value):g}"
                )
        model, data = self.model, self.data
        mujoco.mj_resetData(model, data)
        data.qpos[:] = self.qpos
        mujoco.mj_forward(model, data)
        soles = np.vstack([sole_points(model, data, body_id(model, foot)) for foot in self.feet])
        self.support = convex_hull(soles[:, :2])
        self.floor = float(soles[:, 2].mean())
        self.standing_height = float(data.subtree_com[0][2]) - self.floor
        gravity = float(np.linalg.norm(model.opt.gravity))
        self.omega = math.sqrt(gravity / self.standing_height)
        self.ctrl = np.zeros(int(model.nu))
        self.info = StepInfo()
        self._push_steps = 0
        self.state = self._read()
        self.standing_origin = (
            float(self.state[0]) - self.ankle[0],
            float(self.state[1]) - self.ankle[1],
        )
        torso = body_id(model, self.torso)
        self.push_lever = float(data.xipos[torso][2]) - float(data.subtree_com[0][2])
        self._restart_rows()
        return self.state.copy()

    def check_state(self, state: FloatArray) -> None:
        """Require a finite state of :data:`STATE_LABELS` (contract item 3)."""
        array = np.asarray(state, dtype=float)
        if array.shape != (len(STATE_LABELS),) or not np.all(np.isfinite(array)):
            raise InvalidParameterError(
                f"state must be 6 finite numbers {list(STATE_LABELS)}, got shape {array.shape}"
            )

    def begin(self, state: FloatArray) -> FloatArray:
        """Start a run from the plant's current state (``reset``'s or ``apply_push``'s).

        Raises
        ------
        InvalidParameterError
            If ``state`` is not the plant's current one (MuJoCo's state is not a function of
            the CoM's: a deviation from contract item 3).
        """
        self.check_state(state)
        if not np.allclose(np.asarray(state, dtype=float), self.state, rtol=0.0, atol=1e-12):
            raise InvalidParameterError(
                "state must be the 3-D plant's current state (from reset or apply_push)"
            )
        self._restart_rows()
        return self.state.copy()

    # -- Clocked (contract item 7) -----------------------------------------------------------

    @property
    def clock(self) -> float:
        """MuJoCo's time since reset [s]."""
        return float(self.data.time)

    def run_rows(self) -> RunRows:
        """Return the rows since reset/begin: one per step, one after each push."""
        inputs = np.array(self._inputs, dtype=float).reshape(len(self._inputs), len(self.ctrl))
        return RunRows(np.array(self._times), np.array(self._states), inputs)

    def physical_checks(self) -> PhysicalChecks:
        """Return the checks of every physics step since reset/begin (the :attr:`audit`'s)."""
        return self.audit.result()

    def _restart_rows(self) -> None:
        """Start the rows at the current state (no push yet)."""
        self._times, self._states, self._inputs = [], [], []
        self.frames, self.push_row, self.max_torso_tilt = [], None, 0.0
        self.audit.reset()
        self._add_row()

    def _add_row(self) -> None:
        """Keep the clock, the state and (recording) MuJoCo's ``qpos``, ``qvel`` and ``ctrl``."""
        self._times.append(float(self.data.time))
        self._states.append(self.state)
        if self.recording:
            data = self.data
            self.frames.append(np.concatenate([data.qpos, data.qvel, self.ctrl]))

    # -- contract items 4-6 ----------------------------------------------------------------

    def body_of(self, name: str) -> int:
        """Return the id of the pushed body ``name`` (``"torso"``: the model's torso)."""
        target = self.torso if name == "torso" else name
        try:
            return body_id(self.model, target)
        except InvalidParameterError:
            raise InvalidParameterError(
                f"body must be a body of the {self.name} model, got {name[:40]!r}"
            ) from None

    def apply_push(self, push: Push3D | Push) -> FloatArray:
        """Push (contract item 4; module docstring) and return the state after it (scheduled: now).

        A :class:`~pushrecovery.sim.push.Push` is J = m Δẋ [N s] forward (Δẋ >= 0, azimuth 0)
        or backward (180) on its ``body`` (default the torso), ``scheduled`` as given.

        Raises
        ------
        InvalidParameterError
            If the pushed body is not one of the model, or a ``Push`` is not a force
            (``kind``) or lasts other than :data:`PUSH_DURATION` (``duration``): the 3-D
            push is a 10 ms force.
        """
        import mujoco

        if isinstance(push, Push):
            push = self._as_push3d(push)
        require_type("push", push, Push3D)
        body = self.body_of(push.body)
        force = np.array(push.force(PUSH_DURATION))
        model, data = self.model, self.data
        steps = max(1, round(PUSH_DURATION / float(model.opt.timestep)))
        self._push_body, self._push_force, self._push_steps = body, force, steps
        if push.scheduled:  # from the next step on (step); push_row, max tilt at its end
            self.push_row, self.max_torso_tilt = None, 0.0
            return self.state.copy()
        data.ctrl[:] = self.ctrl
        self._pushed_steps(steps)
        mujoco.mj_step1(model, data)
        self.state = self._read()
        self._inputs.append(tuple(float(v) for v in self.ctrl))  # held during the push
        self._add_row()
        self.push_row, self.max_torso_tilt = len(self._times) - 1, self.torso_tilt()
        return self.state.copy()

    def _as_push3d(self, push: Push) -> Push3D:
        """Return the sagittal force ``push`` as a Push3D; refuse what a Push3D cannot be."""
        if push.kind != "force":
            raise InvalidParameterError(
                f"push kind must be 'force' on the {self.name} model (a 10 ms force at a body), "
                f"got {push.kind!r}"
            )
        if push.duration != PUSH_DURATION:
            raise InvalidParameterError(
                f"push duration must be {PUSH_DURATION:g} s on the {self.name} model, "
                f"got {push.duration:g}"
            )
        size = push.impulse(self.params.mass)
        body = "torso" if push.body is None else push.body
        return Push3D(abs(size), 0.0 if size >= 0.0 else 180.0, body, push.scheduled)

    @property
    def push_left(self) -> float:
        """How long the force of a scheduled push still acts [s] (0: none)."""
        return self._push_steps * float(self.model.opt.timestep)

    def step(self, command: Command, dt: float) -> Step:
        """Hold ``command``'s motor commands [N m] (clipped) for ``dt`` [s] (item 5).

        A :class:`~pushrecovery.control.wbc.observation.HumanoidCommand` sets the motors; any
        other :class:`~pushrecovery.control.base.Command` (or ``motors=None``) holds the last
        ones.

        Raises
        ------
        ParameterTypeError
            If ``command`` is not a Command.
        InvalidParameterError
            If its ``motors`` are not ``nu`` finite numbers or ``dt`` is not in [1e-6, 1] s.
        """
        import mujoco

        require_type("command", command, Command)
        info = self.info
        if isinstance(command, HumanoidCommand):
            if command.motors is not None:
                ctrl = np.asarray(command.motors, dtype=float)
                if ctrl.shape != (self.model.nu,) or not np.all(np.isfinite(ctrl)):
                    raise InvalidParameterError(
                        f"command motors must be {self.model.nu} finite motor commands, "
                        f"got shape {ctrl.shape}"
                    )
                self.ctrl = np.clip(ctrl, self.ctrl_range[:, 0], self.ctrl_range[:, 1])
            if command.stance is not info.stance or command.support is not info.support:
                info = StepInfo(command.stance, (0.0,), 0, None, (), command.support)
        seconds = bounded_float("dt", dt, 1e-6, 1.0, "s")
        model, data = self.model, self.data
        steps = max(1, round(seconds / float(model.opt.timestep)))
        data.ctrl[:] = self.ctrl
        pushing = self._push_steps > 0
        if pushing:
            self._pushed_steps(steps)
        else:
            audit = self.audit.after_step
            mujoco.mj_step2(model, data)
            audit()
            for _ in range(steps - 1):
                mujoco.mj_step(model, data)
                audit()
        mujoco.mj_step1(model, data)
        self.state = self._read()
        self.info = info
        applied = tuple(float(v) for v in self.ctrl)
        self._inputs.append(applied)
        self._add_row()
        if pushing and self._push_steps == 0:  # the scheduled push's force ended in this step
            self.push_row, self.max_torso_tilt = len(self._times) - 1, self.torso_tilt()
        elif self.push_row is not None:
            self.max_torso_tilt = max(self.max_torso_tilt, self.torso_tilt())
        return Step(self.state, applied, info)

    def _pushed_steps(self, steps: int) -> None:
        """Take ``steps`` physics steps, the scheduled force on those it still acts on."""
        import mujoco

        model, data = self.model, self.data
        applied = data.xfrc_applied[self._push_body, :3]
        try:
            for sub in range(steps):
                applied[:] = self._push_force if self._push_steps > 0 else 0.0
                self._push_steps = max(0, self._push_steps - 1)
                if sub == 0:  # mj_step1 ended the last step
                    mujoco.mj_step2(model, data)
                else:
                    mujoco.mj_step(model, data)
                self.audit.after_step()
        finally:
            applied[:] = 0.0

    def fall_margin(self) -> float:
        """Return 2 max(τmax, τmax_roll)/(m g) [m]: both hips' largest CMP offset."""
        p = self.params
        return 2.0 * max(p.torque_max, p.torque_max_roll) / (p.mass * p.gravity)

    def capture_point(self, state: FloatArray) -> tuple[float, float]:
        """Return ξ = c_xy + ċ_xy/ω [m] of ``state`` (world)."""
        return (
            float(state[0]) + float(state[3]) / self.omega,
            float(state[1]) + float(state[4]) / self.omega,
        )

    def xcom_outside(self, state: FloatArray) -> float:
        """Return how far ξ is outside the support polygon [m] (0 inside)."""
        assert self.support is not None
        xi = self.capture_point(state)
        near = self.support.nearest_point(*xi)
        return math.hypot(xi[0] - near[0], xi[1] - near[1])

    def falling(self, state: FloatArray) -> bool:
        """Whether ``state`` is in the fall set (module docstring, contract item 6).

        With the last step's ``StepInfo.support`` (a controller that steps): the body down.
        """
        self.check_state(state)
        if float(state[2]) - self.floor < FALL_HEIGHT * self.standing_height:
            return True
        return self.info.support is None and self.xcom_outside(state) > self.fall_margin()

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """Whether ‖ċ_xy‖ <= ``speed`` [m/s] with the CoM over the support (item 6).

        The support is the last step's ``StepInfo.support`` when the controller steps (no
        foot may swing), else the feet at reset.
        """
        self.check_state(state)
        limit = non_negative_float("speed", speed, "m/s")
        info = self.info
        support = self.support if info.support is None else info.support
        assert support is not None
        inside = info.stance and bool(support.contains(float(state[0]), float(state[1])))
        return inside and math.hypot(float(state[3]), float(state[4])) <= limit

    # -- measurements ----------------------------------------------------------------------

    def _read(self) -> FloatArray:
        """Return the state from ``data`` (after ``mj_step1``: the CoM's velocity computed)."""
        import mujoco

        data = self.data
        if not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
            raise SimulationDiverged(f"the {self.name} physics diverged at t={data.time:.4g} s")
        mujoco.mj_subtreeVel(self.model, data)
        return np.concatenate([data.subtree_com[0], data.subtree_linvel[0]]).astype(float)

    def torso_tilt(self) -> float:
        """Return the angle between the upright body's z axis and the vertical [rad]."""
        upright = self.data.xmat[self._upright_id]
        return math.acos(max(-1.0, min(1.0, float(upright[8]))))


class Biped3DPlant(Humanoid3DPlant):
    """The biped3d of ``params``, its knees bent 0.3 rad (:func:`~.biped3d.bent_knee_qpos`)."""

    name: ClassVar[str] = "biped3d"

    def __init__(self, params: BodyParams) -> None:
        require_type("params", params, BodyParams)
        model = biped3d_model(params)
        super().__init__(
            params,
            model,
            bent_knee_qpos(model),
            tuple(f"{side}_foot" for side in SIDES),
            torso="torso",
            upright="torso",
        )


class G1Plant(Humanoid3DPlant):
    """The Unitree G1 of the ``robots`` extra at its standing pose (``robots.describe_robot``).

    Its body is the robot's: ``params`` must be ``robot_params("g1")`` (the CLI passes it).
    A push named ``"torso"`` acts on ``torso_link``, which the WBC also holds upright (the
    feet and torso of :mod:`.g1`).

    Raises
    ------
    RobotsExtraMissing
        Without the ``robots`` extra (one line saying how to get it).
    InvalidParameterError
        If ``params`` are not the G1's.
    """

    name: ClassVar[str] = "g1"
    #: The hip task lowers the G1's critical push at every azimuth (docs/validation3d.md, "G1:
    #: no hip strategy": 9.3 N s forward against the ankles' 10.3; with stepping it falls at 11-15
    #: N s where stepping alone stands): off unless asked for.
    hip_task: ClassVar[bool] = False

    def __init__(self, params: BodyParams) -> None:
        from pushrecovery.sim.mujoco.humanoid3d.g1 import G1_FEET, G1_TORSO
        from pushrecovery.sim.mujoco.humanoid3d.robots import describe_robot

        require_type("params", params, BodyParams)
        described = describe_robot("g1")
        if params != described.params:
            raise InvalidParameterError(
                "params of the g1 model must be the robot's own (robot_params('g1'))"
            )
        super().__init__(params, described.model, described.qpos, G1_FEET, torso=G1_TORSO,
                         upright=G1_TORSO, ankle=described.ankle)  # fmt: skip


def wbc_for(
    plant: Humanoid3DPlant, *, hip: bool | None = None, stepping: bool = False
) -> WholeBodyController:
    """Return the whole-body controller of ``plant``'s model, feet and upright body.

    With ``hip`` its hip (CMP) task uses the flywheel limits of ``plant.params``
    (:mod:`pushrecovery.control.wbc.hip`); without, it balances with the ankles only; None
    (the default): the plant's own default, ``plant.hip_task`` (the biped3d's on, the G1's
    off). With ``stepping`` it steps, planned for ``plant.params``
    (:mod:`pushrecovery.control.wbc.stepper`), when neither recovers.

    Raises
    ------
    InvalidParameterError
        If ``hip`` is neither a bool nor None.
    """
    require_type("plant", plant, Humanoid3DPlant)
    if hip is None:
        hip = plant.hip_task
    elif not isinstance(hip, bool):
        raise InvalidParameterError(f"hip must be a bool or None, got {hip!r}")
    return WholeBodyController(
        plant.model, feet=plant.feet, torso=plant.upright, observation=plant.observation,
        hip=plant.params if hip else None, stepping=stepping, params=plant.params,
    )  # fmt: skip
