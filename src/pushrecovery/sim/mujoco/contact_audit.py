"""The physical checks of a MuJoCo run, physics step by physics step.

:class:`ContactAudit` watches every physics step of a run (:meth:`ContactAudit.after_step`, called
by the plant right after ``mj_step``, when MuJoCo's contacts, constraint forces and body
velocities are those of the same instant) and :meth:`ContactAudit.result` sums it up as
:class:`~pushrecovery.sim.physical_checks.PhysicalChecks` (that module's docstring defines each
check).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, positive_float
from pushrecovery.kernels.contact_audit import audit_step
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
        If ``weight`` or ``slip_limit`` is out of range, a foot is not a body of the model or
        ``qpos`` is not ``model.nq`` finite numbers.
    ParameterTypeError
        If ``model`` or ``data`` is not MuJoCo's.
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

        from pushrecovery.control.wbc.bodies import (
            body_names,
            check_data,
            check_model,
            check_qpos,
            sole_points,
        )

        check_model(model)
        check_data(model, data)
        self.model, self.data = model, data
        self.weight = positive_float("weight", weight, "N")
        self.slip_limit = bounded_float("slip_limit", slip_limit, 1e-6, 1.0, "m")
        self.feet = body_names(model, feet, "feet")
        qpos = check_qpos(model, qpos)
        foot_ids = [model.body(name).id for name in self.feet]
        self._foot_ids = np.array(foot_ids, dtype=np.int64)
        pose = mujoco.MjData(model)
        pose.qpos[:] = qpos
        mujoco.mj_kinematics(model, pose)
        # Each foot's sole points in its body frame, R^T (c - o) in the standing pose, padded
        # to the most points of a foot.
        soles = [
            (sole_points(model, pose, body) - pose.xpos[body]) @ pose.xmat[body].reshape(3, 3)
            for body in foot_ids
        ]
        most = max(len(sole) for sole in soles)
        self._soles = np.zeros((len(soles), most, 3))
        for index, sole in enumerate(soles):
            self._soles[index, : len(sole)] = sole
        self._sole_counts = np.array([len(sole) for sole in soles], dtype=np.int64)
        self._slip = np.zeros((len(soles), most, 2))
        self._pending = np.zeros((len(soles), most, 2))
        self._cop = np.zeros((len(soles), 2))
        self._unloaded = np.zeros(len(soles), dtype=np.int64)
        self._loads, self._moments = np.zeros(len(soles)), np.zeros((len(soles), 2))
        # Each geom's foot (index into feet) or -1; floor geoms are the world body's.
        owner = np.full(model.nbody, -1, dtype=np.intp)
        for index, body in enumerate(foot_ids):
            owner[body] = index
        for body in range(1, model.nbody):  # parents come before children
            if owner[body] < 0:
                owner[body] = owner[model.body_parentid[body]]
        bodies = np.asarray(model.geom_bodyid)
        self._geom_foot = np.ascontiguousarray(owner[bodies], dtype=np.int64)
        self._floor = np.ascontiguousarray(bodies == 0)
        self._limits = _torque_limits(model)
        self._torque_use = np.zeros(model.nu)
        groups = [joint_group(model.actuator(i).name) for i in range(model.nu)]
        order = [group for group, _ in JOINT_GROUPS] + ["other"]
        self._groups = [
            (group, np.array([i for i, g in enumerate(groups) if g == group], dtype=np.intp))
            for group in order
            if group in groups
        ]
        self._limit_type = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT)
        self._pyramidal = int(model.opt.cone) == int(mujoco.mjtCone.mjCONE_PYRAMIDAL)
        self._roots = np.asarray(model.body_rootid, dtype=np.int64)
        self._h = float(model.opt.timestep)
        self._light = 1e-3 * LOAD_FRACTION * self.weight
        self._threshold = LOAD_FRACTION * self.weight
        self._lift_steps = max(1, round(LIFT_TIME / float(model.opt.timestep)))
        self.reset()
        # The kernel's arguments after the step's contacts and constraints: MuJoCo's arrays of
        # fixed size (views of ``data``'s arena, valid while it lives) and the audit's state.
        self._kernel_arguments = (
            data.xpos, data.xmat, data.cvel, data.subtree_com, data.actuator_force,
            self._pyramidal, self._floor, self._geom_foot, self._light, self._threshold,
            self._lift_steps, self._h, self._foot_ids, self._roots, self._soles,
            self._sole_counts, self._slip, self._pending, self._unloaded, self._cop,
            self._loads, self._moments, self._limits, self._torque_use, self._limit_type,
        )  # fmt: skip

    def reset(self) -> None:
        """Start a new run's audit."""
        # The current stance interval's travel of each sole point, and a bounce's (pending).
        self._slip[:] = 0.0
        self._pending[:] = 0.0
        self._cop[:] = 0.0  # each foot's last CoP (world xy) [m]
        # Physics steps each foot has carried less than the load threshold (a new interval
        # starts at the next load only after LIFT_TIME of them: a bounce is not a step).
        self._unloaded[:] = self._lift_steps
        self.foot_slip, self.slip_foot = 0.0, ""
        self.peak_ground_force = self.max_penetration = self.friction_use = 0.0
        self._torque_use[:] = 0.0
        self.joint_limit_steps = self.physics_steps = 0

    def after_step(self) -> None:
        """Audit the physics step MuJoCo just took (its contacts, forces and velocities).

        It runs at every physics step: one compiled kernel on MuJoCo's arrays
        (:func:`~pushrecovery.kernels.contact_audit.audit_step`).
        """
        data = self.data
        contact = data.contact
        total, depth, use, moved, foot, on_limit = audit_step(
            contact.geom, contact.dist, contact.frame, contact.pos, contact.friction,
            contact.efc_address, contact.dim, data.efc_force, data.efc_type, data.nefc,
            *self._kernel_arguments,
        )  # fmt: skip
        if total > self.peak_ground_force:
            self.peak_ground_force = total
        if depth > self.max_penetration:
            self.max_penetration = depth
        if use > self.friction_use:
            self.friction_use = use
        if moved > self.foot_slip:
            self.foot_slip, self.slip_foot = moved, self.feet[foot]
        self.joint_limit_steps += on_limit
        self.physics_steps += 1

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
