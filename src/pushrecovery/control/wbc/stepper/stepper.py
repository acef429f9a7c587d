"""The stepping task of the whole-body controller: decide, plan, swing and land a foot.

A :class:`Stepper` runs inside :class:`~.controller.WholeBodyController` (``stepping=True``) at
every control tick (world frame, x forward, y left, z up, SI units): in double support it steps
when ξ = c + ċ/ω is more than ``margin`` beyond the ankles' (and the hip's) region; the foot is
dropped from the QP's contacts (:meth:`~.qp.WholeBodyQP.set_contacts`) and its sole tracks a
quintic swing to the foothold of :mod:`~pushrecovery.control.wbc.stepper.plan`, re-planned
every ``replan_period`` early in the swing, with the knee guard of :mod:`~.limits.knee_guard`
and the pelvis lowered (:meth:`Stepper.pelvis_height`, :mod:`.height`); it lands when its sole
is within ``contact`` of the floor after half the swing, and the ankles balance about the new
feet (a second step follows if ξ is still beyond the new region). docs/humanoid3d_stepping.md
gives each phase's law and constants.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.bodies import sole_points
from pushrecovery.control.wbc.foot_contact import FootContact
from pushrecovery.control.wbc.limits.knee_guard import knee_guard_tasks
from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.control.wbc.stepper.height import leg_span, pelvis_limit, segment_lengths
from pushrecovery.control.wbc.stepper.leg import leg_joints, leg_swing_time
from pushrecovery.control.wbc.stepper.plan import (
    StepRecord,
    choose_step,
    evaluate,
    lipm_com,
    plan_foothold,
    planning_params,
    quintic,
    yaw_of,
)
from pushrecovery.control.wbc.stepper.settings import StepSettings
from pushrecovery.control.wbc.tasks.swing_foot import swing_foot_task
from pushrecovery.control.wbc.tasks.task import Task
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import FootPose, Stance
from pushrecovery.params import BodyParams

FloatArray = NDArray[np.float64]

__all__ = []


class Stepper:
    """Stepping decisions, plans and the swing-foot task of one two-footed model.

    Parameters
    ----------
    model : mujoco.MjModel
        The humanoid.
    params : BodyParams
        The body the plans are for (foot shape, step length, ``min_step_time``); its
        ``com_height`` is replaced by ``com_height`` here.
    feet : tuple of FootContact
        The two feet, in the controller's order.
    left : int
        Index in ``feet`` of the left foot (+y of the body).
    floor, com_height : float
        The floor's height under the soles [m] and the CoM's above it [m] at reset.
    settings : StepSettings, optional
    hip : bool
        The controller's hip (CMP) task helps: the plans count on the hip's box H.
    """

    def __init__(
        self, model: Any, params: BodyParams, feet: tuple[FootContact, ...], left: int,
        floor: float, com_height: float, settings: StepSettings | None = None, *,
        hip: bool = False,
    ) -> None:  # fmt: skip
        if not isinstance(params, BodyParams):
            raise InvalidParameterError(f"params must be a BodyParams, got {type(params).__name__}")
        if len(feet) != 2:
            raise InvalidParameterError(f"stepping needs two feet, got {len(feet)}")
        settings = StepSettings() if settings is None else settings
        if not isinstance(settings, StepSettings):
            raise InvalidParameterError(
                f"step settings must be a StepSettings, got {type(settings).__name__}"
            )
        if not isinstance(hip, bool):
            raise InvalidParameterError(f"hip must be a bool, got {hip!r}")
        self._model = model
        self.params = replace(params, com_height=com_height)
        clearance = settings.clearance  # the no-crossing plan (plan.planning_params)
        self.cut = None if clearance is None else planning_params(self.params, clearance)
        self.feet, self.left, self.floor, self.settings = feet, left, floor, settings
        self.hip = hip
        self.legs = tuple(leg_joints(model, foot.body) for foot in feet)
        self.swing_time = max(0.05, params.min_step_time if settings.swing_time is None
                              else settings.swing_time)  # fmt: skip
        self.swing: int | None = None
        self._landed: int | None = None  # the foot that landed last, until ξ is captured
        self.steps: list[StepRecord] = []
        self._coeffs = np.zeros((6, 2))
        self._start = self._end = self._planned = 0.0
        self._z = np.zeros(2)
        self._rot = np.eye(3)
        self._spans: tuple[float, ...] | None = None  # ℓ(knee_reach) of each leg [m]
        self._pelvis = 0

    def _side(self, index: int) -> Stance:
        return Stance.LEFT if index == self.left else Stance.RIGHT

    def _pose(self, data: HumanoidObservation, index: int) -> FootPose:
        body = self.feet[index].body
        rot = np.asarray(data.xmat[body]).reshape(3, 3)
        x, y = np.asarray(data.xpos[body])[:2]
        return FootPose(float(x), float(y), yaw_of(rot))

    def _state(self, data: HumanoidObservation) -> tuple[float, float, float, float]:
        com, vel = np.asarray(data.subtree_com[0]), np.asarray(data.subtree_linvel[0])
        return float(com[0]), float(com[1]), float(vel[0]), float(vel[1])

    def _foothold(self, data: HumanoidObservation, swing: int, t: float) -> tuple[FloatArray, int]:
        """Plan the foothold of foot ``swing`` for a touchdown after t [s] (plan)."""
        stance = (self._side(1 - swing), self._pose(data, 1 - swing))
        return plan_foothold(self.params, self._state(data), stance,
                             self._pose(data, swing), t, hip=self.hip, cut=self.cut)  # fmt: skip

    def _choose(self, data: HumanoidObservation, t: float) -> tuple[int, FloatArray, int]:
        """Choose the swing foot and plan its foothold (:func:`~.plan.choose_step`)."""
        poses = (self._pose(data, self.left), self._pose(data, 1 - self.left))
        landed = None
        if self._landed is not None and self.steps[-1].touchdown is not None:
            if float(data.time) - self.steps[-1].touchdown <= self.settings.follow_time:
                landed = self._side(self._landed)
        side, foothold, count = choose_step(self.params, self._state(data), poses, t, cut=self.cut,
                                            hip=self.hip, landed=landed)  # fmt: skip
        return (self.left if side is Stance.LEFT else 1 - self.left), foothold, count

    def decide(self, xi: FloatArray, region: ConvexPolygon) -> bool:
        """Whether ξ [m] is more than ``margin`` outside ``region`` (P or the CMP region)."""
        distance = float(region.signed_distance(float(xi[0]), float(xi[1])))
        return self.swing is None and distance < -self.settings.margin

    def sole(self, data: HumanoidObservation, index: int) -> tuple[FloatArray, FloatArray]:
        """Return the sole frame's origin [m] and orientation of foot ``index``."""
        foot = self.feet[index]
        rot = np.asarray(data.xmat[foot.body], dtype=float).reshape(3, 3)
        return np.asarray(data.xpos[foot.body]) + rot @ foot.origin, rot

    def lift_off(self, data: HumanoidObservation) -> int:
        """Plan a step from double support and start its swing; return the swing foot's index.

        The swing time starts at ``swing_time`` and grows to what the swing hip needs for the
        planned foothold (:func:`~.leg.leg_swing_time`, ``torque_share``), the
        foothold re-planned for it, until the two agree within 10 ms or ``max_swing_time``.
        """
        t0, s = float(data.time), self.settings
        span = self.swing_time
        index, foothold, count = self._choose(data, span)
        cop = np.asarray(data.xpos[self.feet[1 - index].body][:2], dtype=float)
        for _ in range(8 if s.torque_share is not None else 0):
            assert s.torque_share is not None
            need = leg_swing_time(self._model, data, self.legs[index], foothold, cop,
                                  self.params.omega, span, s.torque_share)  # fmt: skip
            if need <= span + 0.01 or span >= s.max_swing_time:
                break
            span = min(s.max_swing_time, need)
            foothold, count = self._foothold(data, index, span)
        point, self._rot = self.sole(data, index)
        self.swing, self._start = index, t0
        self._end = t0 + span
        self._planned = t0
        self._z = np.array([point[2], self.floor - s.sink])
        self._coeffs = quintic(point[:2], np.zeros(2), np.zeros(2), foothold, span)
        record = StepRecord(self.feet[index].name, t0, self._end, count=count)
        record.origin = np.array(data.xpos[self.feet[index].body][:2], dtype=float)
        record.plans.append((t0, float(foothold[0]), float(foothold[1])))
        self.steps.append(record)
        return index

    def reference(self, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Return the swing foot's reference position [m], velocity [m/s], acceleration [m/s²]."""
        span = self._end - self._start
        tau = min(t, self._end) - self._planned
        xy, vxy, axy = evaluate(self._coeffs, tau)
        if t >= self._end:
            z = self._z[1] - self.settings.sink_speed * (t - self._end)
            return (np.array([*xy, z]), np.array([0.0, 0.0, -self.settings.sink_speed]),
                    np.zeros(3))  # fmt: skip
        s = (t - self._start) / span
        drop = self._z[1] - self._z[0]
        lift = 64.0 * self.settings.lift
        z = self._z[0] + drop * (10 * s**3 - 15 * s**4 + 6 * s**5) + lift * s**3 * (1 - s) ** 3
        dz = drop * (30 * s**2 - 60 * s**3 + 30 * s**4) + lift * (
            3 * s**2 * (1 - s) ** 3 - 3 * s**3 * (1 - s) ** 2
        )
        ddz = drop * (60 * s - 180 * s**2 + 120 * s**3) + lift * (
            6 * s * (1 - s) ** 3 - 18 * s**2 * (1 - s) ** 2 + 6 * s**3 * (1 - s)
        )
        return (np.array([*xy, z]), np.array([*vxy, dz / span]),
                np.array([*axy, ddz / span**2]))  # fmt: skip

    def replan(self, data: HumanoidObservation) -> None:
        """Re-plan the foothold from the current state if it is time (module docstring)."""
        t, s = float(data.time), self.settings
        if self.swing is None or t >= self._start + s.replan_fraction * (self._end - self._start):
            return
        record = self.steps[-1]
        if t - record.plans[-1][0] < s.replan_period - 1e-9:
            return
        foothold, _ = self._foothold(data, self.swing, self._end - t)
        xy, vxy, axy = evaluate(self._coeffs, t - self._planned)
        self._coeffs, self._planned = quintic(xy, vxy, axy, foothold, self._end - t), t
        record.plans.append((t, float(foothold[0]), float(foothold[1])))

    def task(self, data: HumanoidObservation, size: int, nv: int) -> Task:
        """Return the swing foot's task now (:func:`~.swing_foot.swing_foot_task`)."""
        assert self.swing is not None
        return swing_foot_task(data, self.feet[self.swing].body,
                               self.sole(data, self.swing), self._rot,
                               self.reference(float(data.time)), self.settings, size,
                               nv)  # fmt: skip

    def knee_guard(self, data: HumanoidObservation, size: int, nv: int) -> list[Task]:
        """Return the knee guard's task (:func:`~.knee_guard.knee_guard_tasks`), if any."""
        s = self.settings
        return knee_guard_tasks(self._model, data, [leg.knee for leg in self.legs], size,
                                knee_min=s.knee_min, stiffness=s.stiffness, damping=s.damping,
                                weight=s.knee_weight)  # fmt: skip

    def pelvis_height(self, data: HumanoidObservation, height: float) -> float:
        """Return the pelvis height task's target [m]: ``height`` lowered for the legs' reach.

        min(height, :func:`~.height.pelvis_limit`) with every knee bent by at least
        ``knee_reach`` (the swinging leg at its foothold, its hip moved with the LIPM's CoM on
        the stance ankle to touchdown), and at least ``height − max_drop``; ``height`` when
        ``knee_reach`` is None or a leg lacks a hip pitch or knee joint.
        """
        s = self.settings
        if s.knee_reach is None or any(leg.knee < 0 or leg.hip_pitch < 0 for leg in self.legs):
            return height
        if self._spans is None:
            lengths = [segment_lengths(data, leg) for leg in self.legs]
            self._spans = tuple(leg_span(*pair, s.knee_reach) for pair in lengths)
            self._pelvis = int(
                self._model.body_parentid[self._model.jnt_bodyid[self.legs[0].hip_pitch]]
            )
        foothold = shift = None
        if self.swing is not None:
            foothold = self.steps[-1].foothold
            com = np.asarray(data.subtree_com[0][:2], dtype=float)
            vel = np.asarray(data.subtree_linvel[0][:2], dtype=float)
            cop = np.asarray(data.xpos[self.feet[1 - self.swing].body][:2], dtype=float)
            remaining = max(self._end - float(data.time), 0.0)
            shift = lipm_com(com, vel, cop, self.params.omega, remaining) - com
        limit = pelvis_limit(data, self.legs, self._spans, self._pelvis, swing=self.swing,
                             foothold=foothold, shift=shift)  # fmt: skip
        return max(height - s.max_drop, min(height, limit))

    def tasks(self, data: HumanoidObservation, size: int, nv: int) -> list[Task]:
        """Return the stepping tasks now: the swing foot's (while it swings), the knee guard."""
        tasks = self.knee_guard(data, size, nv)
        if self.swing is not None:
            tasks.append(self.task(data, size, nv))
        return tasks

    def landed(self, data: HumanoidObservation) -> bool:
        """Detect touchdown (module docstring); on it, record the landing and end the swing."""
        if self.swing is None:
            return False
        t = float(data.time)
        if t < 0.5 * (self._start + self._end):
            return False
        foot = self.feet[self.swing]
        lowest = float(sole_points(self._model, data, foot.body)[:, 2].min())
        if lowest > self.floor + self.settings.contact:
            return False
        record = self.steps[-1]
        record.touchdown = t
        record.landed = np.array(data.xpos[foot.body][:2], dtype=float)
        self._landed, self.swing = self.swing, None
        return True
