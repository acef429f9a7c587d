"""The whole-body balance controller: the ankle strategy's tasks for :class:`~.qp.WholeBodyQP`.

Each tick the laws ask for accelerations (world frame, x forward, y left, z up, SI): the CoM
under the DCM law p_des = clip_P(ξ + (k_ξ/ω)(ξ − ξ₀)), c̈_xy = ω²(c_xy − p_des) (CoP balancing,
Eq. 3; weight 10), the torso upright (1), the pelvis height (1) and the posture (0.01), gains
and weights in :class:`WbcGains`; with ``hip=params`` the CMP law of :mod:`.hip`, with
``stepping=True`` the stepper of :mod:`.stepper.stepper`, without stepping the joint guard of
:mod:`.limits.joint_guard`. docs/humanoid3d_wbc.md, "The tasks" and "The contract", gives each
law and the contract: a :class:`~pushrecovery.control.base.Controller` over the
:class:`~.observation.HumanoidObservation` the plant hands it (views of the physics' arrays),
``compute`` returning a :class:`~.observation.HumanoidCommand`.

Over 400 lines on purpose: the task laws share the controller's state (the reset pose, the
support, the stepper's phase) tick by tick; the tasks' rows and the QP are in :mod:`.tasks` and
:mod:`~pushrecovery.control.wbc.qp`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Controller
from pushrecovery.control.wbc.bodies import body_id, body_names, sole_points
from pushrecovery.control.wbc.foot_contact import FootContact, foot_contact
from pushrecovery.control.wbc.gains import WbcGains
from pushrecovery.control.wbc.hip import UPRIGHT, HipLaw
from pushrecovery.control.wbc.limits.joint_guard import GuardSettings, JointGuard
from pushrecovery.control.wbc.observation import (
    HUMANOID_STATE,
    HumanoidCommand,
    HumanoidObservation,
)
from pushrecovery.control.wbc.qp import WbcSolution, WholeBodyQP
from pushrecovery.control.wbc.stepper.settings import StepSettings
from pushrecovery.control.wbc.stepper.stepper import Stepper
from pushrecovery.control.wbc.tasks.momentum import momentum_rows
from pushrecovery.control.wbc.tasks.stack import TaskStack
from pushrecovery.control.wbc.tasks.task import Task
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon, convex_hull
from pushrecovery.kernels.wbc import ankle_targets, balance_point
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cop import capture_point

FloatArray = NDArray[np.float64]

__all__ = ["WholeBodyController"]

#: The torso's spin where no hip law reads it (the ankles' kernel computes its own).
_NO_SPIN = np.zeros(3)
_NO_SPIN.flags.writeable = False


class WholeBodyController(Controller):
    """Ankle-strategy whole-body control of a floating-base humanoid (module docstring).

    Parameters
    ----------
    model : mujoco.MjModel
        The humanoid (free joint first, torque motors on joints).
    observation : HumanoidObservation
        What the laws read at every tick: the plant's (:func:`~.observation.mujoco_observation`
        of the ``MjData`` the physics steps).
    feet : sequence of str
        Names of the foot bodies, all on the floor at reset and kept there.
    torso : str
        Name of the body held upright (its origin's height is the pelvis task).
    gains : WbcGains, optional
        Task gains and weights.
    hip : BodyParams, optional
        The flywheel limits (τmax, I, θmax per axis) of the hip (CMP) task, :mod:`.hip`;
        None (the default) balances with the ankles only.
    stepping : bool
        Step when the ankles (and hip) cannot recover (:mod:`.stepper.stepper`); needs two feet.
    params : BodyParams, optional
        The body the step plans are for (default ``hip``); required with ``stepping``.
    step_settings : StepSettings, optional
        The stepping task's settings.
    guard : GuardSettings, optional
        The joint-range guard's settings (:mod:`.limits.joint_guard`).

    Raises
    ------
    InvalidParameterError
        If a name is not a body of ``model``, ``feet`` is empty or repeats a body, the model
        has joints other than the free root and hinges or slides, ``gains`` is not a
        :class:`WbcGains` or ``observation`` not a :class:`HumanoidObservation`.
    """

    name: ClassVar[str] = "wbc"
    state_labels: ClassVar[tuple[str, ...]] = HUMANOID_STATE
    #: The period the gains are meant for [s] (500 Hz).
    control_period = 0.002

    def __init__(
        self,
        model: Any,
        feet: Sequence[str] = ("left_foot", "right_foot"),
        torso: str = "torso",
        gains: WbcGains | None = None,
        *,
        observation: HumanoidObservation,
        hip: BodyParams | None = None,
        stepping: bool = False,
        params: BodyParams | None = None,
        step_settings: StepSettings | None = None,
        guard: GuardSettings | None = None,
    ) -> None:
        if not isinstance(observation, HumanoidObservation):
            raise InvalidParameterError(
                f"observation must be a HumanoidObservation, got {type(observation).__name__}"
            )
        feet = body_names(model, feet, "feet")
        body_id(model, torso)
        if observation.qpos.shape != (model.nq,) or observation.xpos.shape[0] != model.nbody:
            raise InvalidParameterError("observation must be of model's MjData (nq, nbody)")
        if int(model.nq) - 7 != int(model.nv) - 6:
            raise InvalidParameterError(
                "model must have a free joint and hinge or slide joints only (nq − 7 = nv − 6)"
            )
        gains = WbcGains() if gains is None else gains
        if not isinstance(gains, WbcGains):
            raise InvalidParameterError(f"gains must be a WbcGains, got {type(gains).__name__}")
        self.model, self.gains, self.observation = model, gains, observation
        self.foot_names, self.torso = tuple(feet), body_id(model, torso)
        self.mass = float(model.body_subtreemass[0])
        self.gravity = np.array(model.opt.gravity, dtype=float)
        self._weight = self.mass * float(np.linalg.norm(self.gravity))  # m g [N]
        self.qp: WholeBodyQP | None = None
        self.feet: tuple[FootContact, ...] = ()
        self.support: ConvexPolygon | None = None
        self.last: WbcSolution | None = None
        self.desired_cop, self.cmp_offset = np.zeros(2), np.zeros(2)
        if hip is not None and not isinstance(hip, BodyParams):
            raise InvalidParameterError(f"hip must be a BodyParams, got {type(hip).__name__}")
        self.hip_params = hip
        self.hip: HipLaw | None = None
        self.capture_point, self.cmp_target, self.returning = np.zeros(2), np.zeros(2), False
        if not isinstance(stepping, bool):
            raise InvalidParameterError(f"stepping must be a bool, got {stepping!r}")
        if params is not None and not isinstance(params, BodyParams):
            raise InvalidParameterError(f"params must be a BodyParams, got {type(params).__name__}")
        params = hip if params is None else params
        if stepping and (not isinstance(params, BodyParams) or len(feet) != 2):
            raise InvalidParameterError("stepping needs params (a BodyParams) and two feet")
        if not isinstance(step_settings, StepSettings | None):
            raise InvalidParameterError(f"step_settings must be StepSettings: {step_settings!r}")
        self.stepping, self.step_params, self.step_settings = stepping, params, step_settings
        self.stepper: Stepper | None = None
        self.guard = JointGuard(model, guard)  # with stepping, the stepper guards the knees
        self._data: Any = None  # the observation whose array views cop_target keeps

    def reset(self, state: FloatArray) -> None:
        """Take the reference posture, feet and balance point from the observation now.

        ``state`` is the plant's CoM state (:data:`~.observation.HUMANOID_STATE`); the laws
        read the observation, which must hold ``mj_forward``'s results, the feet on the floor.
        """
        model, data = self.model, self.observation
        self.feet = tuple(foot_contact(model, data, name) for name in self.foot_names)
        self.qp = WholeBodyQP(model, self.feet)
        soles = np.vstack([sole_points(model, data, foot.body) for foot in self.feet])
        self.support = convex_hull(soles[:, :2])
        com = np.array(data.subtree_com[0], dtype=float)
        self.rest = com[:2].copy()
        floor = float(soles[:, 2].mean())
        self.omega = math.sqrt(float(np.linalg.norm(self.gravity)) / (com[2] - floor))
        self.posture = np.array(data.qpos[7:], dtype=float)
        self.height = float(data.xpos[self.torso][2])
        self.guard.set_posture(data.qpos)
        self.upright = np.array(data.xmat[self.torso], dtype=float).reshape(3, 3)
        self._upright = self.upright.ravel()
        capture_point(0.0, 0.0, self.omega)  # ω's range checked once (the tick's kernel cannot)
        # balance_point's results, read through fixed views: e (3), ξ (2), the DCM CoP (2).
        self._balance = np.zeros(7)
        self._error, self._xi, self._cop = self._balance[:3], self._balance[3:5], self._balance[5:7]
        self._omega2 = self.omega**2
        self._torso_weight = math.nan  # the stack's torso weights are to be written
        self.last = None
        self._bodies = np.array([foot.body for foot in self.feet], dtype=np.intp)
        self._origins = np.array([foot.origin for foot in self.feet])
        nv, size = int(model.nv), self.qp.size
        self._dots = np.zeros((6, nv))  # the torso's J̇ (linear, angular), overwritten each tick
        self._dots_p, self._dots_r = self._dots[:3], self._dots[3:]
        self._jacp, self._jacr = np.zeros((3, nv)), np.zeros((3, nv))  # its J (each tick)
        self._stack = TaskStack(nv, size, self.gains)  # the tasks as rows (tasks.stack)
        self._stack.reserve(nv + 2 + self.guard.qpos.size)  # the hip's 2 rows, the guard's
        self.hip = None
        if self.hip_params is not None:
            self.hip = HipLaw(self.hip_params, self.support, self._weight, self.omega,
                              self.control_period)  # fmt: skip
        self.returning, self.stepper = False, None
        self._soles = {  # each sole's points in its foot's frame, for the supports of steps
            f.body: (sole_points(model, data, f.body) - np.asarray(data.xpos[f.body]))
            @ np.asarray(data.xmat[f.body]).reshape(3, 3) for f in self.feet
        }  # fmt: skip
        if self.stepping:
            assert self.step_params is not None
            lateral = np.asarray(data.xpos)[self._bodies] - np.asarray(data.xpos[self.torso])
            left = int(np.argmax(lateral @ self.upright[:, 1]))
            self.stepper = Stepper(model, self.step_params, self.feet, left, floor,
                                   com[2] - floor, self.step_settings,
                                   hip=self.hip_params is not None)  # fmt: skip
            self.qp.contact_damping = self.stepper.settings.contact_damping

    def _set_support(self, data: HumanoidObservation, contacts: list[bool]) -> None:
        """Set the feet in contact, re-measure the support polygon and rebuild the hip law."""
        assert self.qp is not None
        self.qp.set_contacts(contacts)
        on = [foot for foot, c in zip(self.feet, contacts, strict=True) if c]
        soles = [np.asarray(data.xpos[f.body]) + self._soles[f.body]
                 @ np.asarray(data.xmat[f.body]).reshape(3, 3).T for f in on]  # fmt: skip
        self.support = convex_hull(np.vstack(soles)[:, :2])
        if self.hip_params is not None:
            self.hip = HipLaw(self.hip_params, self.support, self._weight, self.omega,
                              self.control_period)  # fmt: skip

    def _step(self, data: HumanoidObservation) -> bool:
        """Run the stepping decision, lift-off, re-plan and touchdown; True if contacts changed."""
        stepper = self.stepper
        assert stepper is not None and self.support is not None
        if stepper.swing is None:
            region = self.hip.cmp_region if self.hip is not None else self.support
            if not stepper.decide(self.capture_point, region):
                return False
            swing = stepper.lift_off(data)
            self._set_support(data, [i != swing for i in range(len(self.feet))])
            return True
        if not stepper.landed(data):
            stepper.replan(data)
            return False
        self._set_support(data, [True] * len(self.feet))
        ankles = np.array([stepper.sole(data, i)[0][:2] for i in range(len(self.feet))])
        self.rest = ankles.mean(axis=0)
        self.posture = np.array(data.qpos[7:], dtype=float)
        return True

    def cop_target(self) -> FloatArray:
        """Return the DCM law's CoP p_des clipped to the support polygon [m] (world xy).

        Computes the CoM velocity (``mj_subtreeVel``, which ``mj_forward`` leaves stale).
        """
        data = self.observation
        if data is not self._data:  # views of the arrays a tick reads, once (a fixed arena)
            self._data, self._views = data, (
                data.xmat, data.subtree_com, data.subtree_linvel, data.subtree_com[0],
                data.xpos[self.torso], data.qvel, data.qpos)  # fmt: skip
        data.subtree_vel()
        support, out, views = self.support, self._balance, self._views
        assert support is not None
        # One kernel: the torso's error (kept for _update), ξ = c + ċ/ω and the DCM law's CoP.
        inside = balance_point(views[0], self.torso, self._upright, views[1], views[2],
                               self.omega, self.gains.dcm / self.omega, self.rest,
                               support.normals, support.offsets, out)  # fmt: skip
        self.capture_point = self._xi.copy()
        self.cmp_target = self._cop.copy()
        if inside:
            return self._cop.copy()
        return np.array(support.nearest_point(float(out[5]), float(out[6])))

    def tasks(self) -> list[Task]:
        """Return the QP's tasks at the observed state (module docstring, :mod:`.hip`)."""
        data = self.observation
        momentum = self._update(data)
        assert self.qp is not None
        if self.stepper is not None:  # the swing foot (while it swings), the knee guard
            return self._stack.tasks(momentum, self.stepper.tasks(data, self.qp.size, self.qp.nv))
        return self._stack.tasks(momentum, self.guard.tasks(data.qpos, data.qvel, self.qp.nv))

    def _update(self, data: HumanoidObservation) -> Task | None:
        """Run the tick's laws; write the CoM, torso, pelvis and posture rows (:meth:`compute`).

        Returns the hip's momentum task (None when the hip is idle).
        """
        assert self.qp is not None
        gains, nv, size = self.gains, self.qp.nv, self.qp.size
        # The DCM law's CoP (also ξ, the torso's orientation error, mj_subtreeVel, the views).
        self.desired_cop = self.cop_target()
        stepper = self.stepper
        if stepper is not None and self._step(data):
            self.desired_cop = self.cop_target()  # the new support polygon
        xmat, _, _, com, point, qvel, qpos = self._views
        error, hip, torso = self._error, self.hip, self.torso  # the hip law after _step's
        # Torso orientation and pelvis height: J q̈ + J̇ q̇ = a_des (matrices over q̈ only).
        jacp, jacr = self._jacp, self._jacr
        data.jac(jacp, jacr, point, torso)
        data.jac_dot(self._dots_p, self._dots_r, point, torso)
        # The torso's angular velocity [rad/s], world: the hip law's (ankle_targets has its own).
        spin = jacr @ qvel if hip is not None else _NO_SPIN
        hip_active = False
        # No hip task while a foot swings: the step owns the recovery (the confusion matrix's
        # steps that failed fell from 10 to 2 of 60 pushes; docs/validation3d.md, "The confusion
        # matrix: predicted against used strategy"); the torso's
        # paced return goes on.
        if stepper is not None and stepper.swing is not None:
            self.cmp_offset = np.zeros(2)
        elif hip is not None:
            momentum = np.asarray(data.subtree_angmom[0])
            self.cmp_offset = hip.update(
                self.capture_point, np.array([momentum[1], -momentum[0]]),
                np.array([error[1], -error[0]]), np.array([spin[1], -spin[0]]),
            )  # fmt: skip
            hip_active = hip.active
            if hip_active:
                self.desired_cop = hip.saturate(self.desired_cop)
            self.returning = self.returning or hip_active
        stiffness, damping = gains.torso_stiffness, gains.torso_damping
        torso_weight = gains.hip_torso_weight if hip_active else gains.torso_weight
        returning = self.returning and not hip_active  # gently back upright, then as usual
        paced = None  # the paced return's change of the torso's α_x, α_y (hip)
        if returning:
            assert hip is not None
            stiffness, damping = gains.return_stiffness, gains.return_damping
            accel = -stiffness * error[:2] - damping * spin[:2]
            self.cmp_offset, self.desired_cop, paced = hip.paced_return(self.cmp_target, accel)
            paced -= accel
        rows = self._stack
        rows.pd_gains[0], rows.pd_gains[1] = stiffness, damping
        # All targets and rows at once (kernels.wbc.ankle_targets): CoM (m c̈ = m g +
        # Σ R_i F_i, rows x and y; c̈ = ω² (c − p_des − δ)), torso, pelvis height, posture.
        stack, targets = rows.matrix, rows.targets
        height = self.height  # the stepper lowers it for long steps
        height = height if stepper is None else stepper.pelvis_height(data, height)
        upright = ankle_targets(
            xmat, self._bodies, self.mass, com, self.desired_cop, self.cmp_offset, self._omega2,
            self.gravity, error, jacp, jacr, self._dots, qvel, qpos, self.posture, height,
            float(point[2]), rows.pd_gains, UPRIGHT, stack, targets,
        )  # fmt: skip
        if paced is not None:
            targets[2:4] += paced
        if hip_active or returning:  # yaw keeps the usual gains and weight (legs untwisted)
            targets[4] -= (gains.torso_stiffness - stiffness) * error[2] + (
                gains.torso_damping - damping) * spin[2]  # fmt: skip
            scale = math.sqrt(gains.torso_weight / torso_weight)
            stack[4, :nv] *= scale
            targets[4] *= scale
        if returning and upright:
            self.returning = False
        if torso_weight != self._torso_weight:  # the weights stay in the stack between ticks
            rows.weights[2:5] = self._torso_weight = torso_weight
        if not hip_active:
            return None
        # L̇_x = −m g δ_y, L̇_y = m g δ_x
        matrix = momentum_rows(data, self._bodies, size, nv, com, self._origins)[:2]
        rate = self._weight * np.array([-self.cmp_offset[1], self.cmp_offset[0]])
        return Task("momentum", matrix, rate, gains.hip_weight)

    def compute(self, t: float, state: FloatArray) -> HumanoidCommand:
        """Return the command for the observed state: motor commands ``ctrl`` [N m] and more.

        ``t`` [s] is the time since reset and ``state`` the plant's CoM state (both unused:
        the laws are time-invariant and read the observation). The command's ``motors`` is
        the QP's ``ctrl``; ``cop``, ``cop_y`` the desired CoP [m] (world); with stepping its
        ``support`` is the polygon of the feet in contact and ``stance`` False while a foot
        swings. Never raises inside the loop: a tick DAQP cannot solve repeats the last
        command (``last.ok``).
        """
        if self.qp is None:
            raise InvalidParameterError("call reset(state) before compute(t, state)")
        data, stepper = self.observation, self.stepper
        # The tasks() as stacked rows (TaskStack), the QP's fast path.
        momentum, stack, qp = self._update(data), self._stack, self.qp
        count = stack.nv if momentum is None else stack.extend([momentum])
        if stepper is not None:
            count = stack.extend(stepper.tasks(data, qp.size, qp.nv), count)
        else:  # the guard's rows, no Task (the G1's knees are within their margins at each tick)
            count = self.guard._stack_rows(data.qpos, data.qvel, stack.matrix, stack.targets,
                                           stack.weights, count)  # fmt: skip
        self.last = last = qp._solve_rows(data, stack.matrix, stack.targets, stack.weights, count)
        cop = self.desired_cop
        if stepper is None:
            return HumanoidCommand(float(cop[0]), cop_y=float(cop[1]), motors=last.ctrl)
        return HumanoidCommand(float(cop[0]), cop_y=float(cop[1]), motors=last.ctrl,
                               support=self.support, stance=stepper.swing is None)  # fmt: skip
