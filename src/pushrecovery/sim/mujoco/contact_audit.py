"""The physical checks of a MuJoCo run, physics step by physics step.

:class:`ContactAudit` watches every physics step of a run (:meth:`ContactAudit.after_step`, called
by the plant right after ``mj_step``, when MuJoCo's contacts, constraint forces and body
velocities are those of the same instant) and :meth:`ContactAudit.result` sums it up as
:class:`~pushrecovery.sim.physical_checks.PhysicalChecks` (that module's docstring defines each
check).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, positive_float
from pushrecovery.sim.physical_checks import (
    DEFAULT_SLIP_LIMIT,
    JOINT_GROUPS,
    LIFT_TIME,
    LOAD_FRACTION,
    PhysicalChecks,
    joint_group,
)

__all__ = ["ContactAudit"]


class ContactAudit:
    """Watch the physics steps of a MuJoCo run and sum them up (module docstring).

    Parameters
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
        The run's model and data (the floor: geoms of the world body).
    feet : sequence of str
        The foot bodies; a geom of a foot's subtree belongs to the foot.
    qpos : float array
        A pose with the soles flat on the floor (the standing posture), where the sole points
        are found: [m] for slide and free-joint positions, [-] for the free joint's unit
        quaternion, [rad] for hinges.
    weight : float
        The body weight m g [N], > 0.
    slip_limit : float
        Largest slip that may count as recovered [m], in (0, 1].

    Raises
    ------
    InvalidParameterError
        If ``weight`` or ``slip_limit`` is out of range.
    KeyError
        If a foot is not a body of the model.
    """

    def __init__(
        self,
        model: Any,
        data: Any,
        feet: Sequence[str],
        qpos: NDArray[np.float64],
        weight: float,
        slip_limit: float = DEFAULT_SLIP_LIMIT,
    ) -> None:
        import mujoco

        from pushrecovery.control.wbc.bodies import sole_points

        self.model, self.data = model, data
        self.weight = positive_float("weight", weight, "N")
        self.slip_limit = bounded_float("slip_limit", slip_limit, 1e-6, 1.0, "m")
        self.feet = tuple(feet)
        foot_ids = [model.body(name).id for name in self.feet]
        self._foot_ids = foot_ids
        pose = mujoco.MjData(model)
        pose.qpos[:] = qpos
        mujoco.mj_kinematics(model, pose)
        # Each foot's sole points in its body frame: R^T (c - o) in the standing pose.
        self._soles = [
            (sole_points(model, pose, body) - pose.xpos[body]) @ pose.xmat[body].reshape(3, 3)
            for body in foot_ids
        ]
        # Each geom's foot (index into feet) or -1; floor geoms are the world body's.
        owner = np.full(model.nbody, -1, dtype=np.intp)
        for index, body in enumerate(foot_ids):
            owner[body] = index
        for body in range(1, model.nbody):  # parents come before children
            if owner[body] < 0:
                owner[body] = owner[model.body_parentid[body]]
        bodies = np.asarray(model.geom_bodyid)
        self._geom_foot = owner[bodies].tolist()
        self._floor = (bodies == 0).tolist()
        self._limits = _torque_limits(model)
        groups = [joint_group(model.actuator(i).name) for i in range(model.nu)]
        order = [group for group, _ in JOINT_GROUPS] + ["other"]
        self._groups = [
            (group, np.array([i for i, g in enumerate(groups) if g == group], dtype=np.intp))
            for group in order
            if group in groups
        ]
        self._limit_type = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT)
        self._xbody = int(mujoco.mjtObj.mjOBJ_XBODY)
        self._contact_force = mujoco.mj_contactForce
        self._object_velocity = mujoco.mj_objectVelocity
        self._force, self._velocity = np.zeros(6), np.zeros(6)
        self._lift_steps = max(1, round(LIFT_TIME / float(model.opt.timestep)))
        self.reset()

    def reset(self) -> None:
        """Start a new run's audit."""
        count = len(self.feet)
        # The current loaded interval's displacement of each sole point.
        self._slip = [np.zeros((len(sole), 2)) for sole in self._soles]
        self._pending = [np.zeros((len(sole), 2)) for sole in self._soles]
        self._cop = [(0.0, 0.0)] * count  # each foot's last CoP (world xy) [m]
        # Physics steps each foot has carried less than the load threshold (a new interval
        # starts at the next load only after LIFT_TIME of them: a bounce is not a step).
        self._unloaded = [self._lift_steps] * count
        self.foot_slip, self.slip_foot = 0.0, ""
        self.peak_ground_force = self.max_penetration = self.friction_use = 0.0
        self._torque_use = np.zeros(self.model.nu)
        self.joint_limit_steps = self.physics_steps = 0

    def after_step(self) -> None:
        """Audit the physics step MuJoCo just took (its contacts, forces and velocities)."""
        model, data, force = self.model, self.data, self._force
        floor, geom_foot = self._floor, self._geom_foot
        count = len(self.feet)
        loads = [0.0] * count
        moments = [[0.0, 0.0] for _ in range(count)]
        total = 0.0
        light = 1e-3 * LOAD_FRACTION * self.weight
        for i in range(data.ncon):
            contact = data.contact[i]
            g1, g2 = int(contact.geom1), int(contact.geom2)
            if floor[g1] == floor[g2]:
                continue  # not a contact of the body with the floor
            self._contact_force(model, data, i, force)
            frame = contact.frame
            # The force of geom1 on geom2 along the normal (geom1 → geom2): on the body as is
            # when the floor is geom1, reversed when it is geom2.
            sign = 1.0 if floor[g1] else -1.0
            fz = sign * (force[0] * frame[2] + force[1] * frame[5] + force[2] * frame[8])
            total += fz
            depth = -float(contact.dist)
            if depth > self.max_penetration:
                self.max_penetration = depth
            if force[0] > light and contact.friction[0] > 0.0:
                use = math.hypot(force[1], force[2]) / (contact.friction[0] * force[0])
                if use > self.friction_use:
                    self.friction_use = use
            foot = geom_foot[g2 if floor[g1] else g1]
            if foot >= 0:
                loads[foot] += fz
                moments[foot][0] += fz * contact.pos[0]
                moments[foot][1] += fz * contact.pos[1]
        if total > self.peak_ground_force:
            self.peak_ground_force = total
        self._slide(loads, moments)
        np.maximum(self._torque_use, np.abs(data.actuator_force) / self._limits,
                   out=self._torque_use)  # fmt: skip
        if data.nefc and np.any(data.efc_type[: data.nefc] == self._limit_type):
            self.joint_limit_steps += 1
        self.physics_steps += 1

    def _slide(self, loads: list[float], moments: list[list[float]]) -> None:
        """Integrate each foot's sole travel over this step (module docstring).

        A foot below the load threshold for less than ``LIFT_TIME`` (a bounce) keeps its
        interval: its travel meanwhile, about its last CoP, is kept aside and counts once the
        foot is loaded again (a foot that chatters while it slides); a lift drops it.
        """
        threshold = LOAD_FRACTION * self.weight
        for foot, body in enumerate(self._foot_ids):
            load = loads[foot]
            slip, pending = self._slip[foot], self._pending[foot]
            if load < threshold:
                self._unloaded[foot] += 1
                if self._unloaded[foot] < self._lift_steps:
                    self._travel(body, foot, pending)
                continue
            if self._unloaded[foot] >= self._lift_steps:
                slip[:] = 0.0  # a new stance: its slip counts from here
            else:
                slip += pending  # a bounce: the travel while unloaded counts
            pending[:] = 0.0
            self._unloaded[foot] = 0
            self._cop[foot] = (moments[foot][0] / load, moments[foot][1] / load)
            self._travel(body, foot, slip)
            moved = float(np.sqrt((slip * slip).sum(axis=1)).max())
            if moved > self.foot_slip:
                self.foot_slip, self.slip_foot = moved, self.feet[foot]

    def _travel(self, body: int, foot: int, into: NDArray[np.float64]) -> None:
        """Add this step's horizontal travel of the foot's sole points to ``into`` [m]."""
        model, data, velocity = self.model, self.data, self._velocity
        h = float(model.opt.timestep)
        cop_x, cop_y = self._cop[foot]
        self._object_velocity(model, data, self._xbody, body, velocity, 0)
        origin = data.xpos[body]
        rx, ry, rz = cop_x - origin[0], cop_y - origin[1], -origin[2]
        wx, wy, wz = velocity[0], velocity[1], velocity[2]
        # v_p = v_o + ω × (p − o), horizontal part, p on the floor (z = 0).
        vx = velocity[3] + wy * rz - wz * ry
        vy = velocity[4] + wz * rx - wx * rz
        # The sole points now (world xy) relative to the CoP, turned by ω_z about it.
        points = origin[:2] + self._soles[foot] @ data.xmat[body].reshape(3, 3)[:2].T
        into[:, 0] += (vx - wz * (points[:, 1] - cop_y)) * h
        into[:, 1] += (vy + wz * (points[:, 0] - cop_x)) * h

    def result(self) -> PhysicalChecks:
        """Return the checks of the run so far."""
        use = self._torque_use
        return PhysicalChecks(
            foot_slip=float(self.foot_slip),
            slip_foot=self.slip_foot,
            peak_ground_force=float(self.peak_ground_force),
            peak_force_ratio=float(self.peak_ground_force) / self.weight,
            max_penetration=float(self.max_penetration),
            friction_use=float(self.friction_use),
            torque_use=tuple((group, float(use[index].max())) for group, index in self._groups),
            joint_limit_steps=self.joint_limit_steps,
            physics_steps=self.physics_steps,
            slip_limit=self.slip_limit,
        )


def _torque_limits(model: Any) -> NDArray[np.float64]:
    """Return each actuator's largest ‖τ‖ (module docstring; inf: unlimited) [N m or N]."""
    limits = np.full(model.nu, np.inf)
    for i in range(model.nu):
        gear = abs(float(model.actuator_gear[i, 0]))
        joint = int(model.actuator_trnid[i, 0])
        if model.actuator_forcelimited[i]:
            limits[i] = float(np.abs(model.actuator_forcerange[i]).max())
        elif model.actuator_ctrllimited[i]:
            limits[i] = float(np.abs(model.actuator_ctrlrange[i]).max()) * gear
        elif joint >= 0 and model.jnt_actfrclimited[joint]:
            limits[i] = float(np.abs(model.jnt_actfrcrange[joint]).max())
    return limits
