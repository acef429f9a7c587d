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
from pushrecovery.kernels import contact_audit as kernel
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
        pose = mujoco.MjData(model)
        pose.qpos[:] = qpos
        mujoco.mj_kinematics(model, pose)
        # Each foot's sole points in its body frame, R^T (c - o) in the standing pose, padded
        # to the most points of a foot (the kernel's layouts: kernels.contact_audit).
        soles = [
            (sole_points(model, pose, body) - pose.xpos[body]) @ pose.xmat[body].reshape(3, 3)
            for body in foot_ids
        ]
        most = max(len(sole) for sole in soles)
        self._soles = np.zeros((len(soles), most, 7))
        self._feet_int = np.zeros((len(soles), 4), dtype=np.int64)
        for index, (sole, body) in enumerate(zip(soles, foot_ids, strict=True)):
            self._soles[index, : len(sole), kernel.SOLE : kernel.SOLE + 3] = sole
            self._feet_int[index, [kernel.BODY, kernel.ROOT, kernel.POINTS]] = (
                body, model.body_rootid[body], len(sole),
            )  # fmt: skip
        self._feet_float = np.zeros((len(soles), 5))
        # Each geom's foot (index into feet), NO_FOOT, or FLOOR (the world body's geoms).
        owner = np.full(model.nbody, kernel.NO_FOOT, dtype=np.int64)
        for index, body in enumerate(foot_ids):
            owner[body] = index
        for body in range(1, model.nbody):  # parents come before children
            if owner[body] < 0:
                owner[body] = owner[model.body_parentid[body]]
        owner[0] = kernel.FLOOR
        self._geom_class = np.ascontiguousarray(owner[np.asarray(model.geom_bodyid)])
        self._actuators = np.zeros((model.nu, 2))  # each one's limit and torque use
        self._actuators[:, 0] = _torque_limits(model)
        groups = [joint_group(model.actuator(i).name) for i in range(model.nu)]
        order = [group for group, _ in JOINT_GROUPS] + ["other"]
        self._groups = [
            (group, np.array([i for i, g in enumerate(groups) if g == group], dtype=np.intp))
            for group in order
            if group in groups
        ]
        self._lift_steps = max(1, round(LIFT_TIME / float(model.opt.timestep)))
        settings = np.zeros(6)
        settings[kernel.PYRAMIDAL] = int(model.opt.cone) == int(mujoco.mjtCone.mjCONE_PYRAMIDAL)
        settings[kernel.LIGHT] = 1e-3 * LOAD_FRACTION * self.weight
        settings[kernel.THRESHOLD] = LOAD_FRACTION * self.weight
        settings[kernel.LIFT_STEPS] = self._lift_steps
        settings[kernel.STEP] = float(model.opt.timestep)
        settings[kernel.LIMIT_TYPE] = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT)
        self._totals = np.zeros(7)
        self.reset()
        # The kernel's arguments after the step's contacts and constraints: MuJoCo's arrays of
        # fixed size (views of ``data``'s arena, valid while it lives) and the audit's state.
        self._kernel_arguments = (
            data.xpos, data.xmat, data.cvel, data.subtree_com, data.actuator_force, settings,
            self._geom_class, self._feet_int, self._feet_float, self._soles, self._actuators,
            self._totals,
        )  # fmt: skip

    def reset(self) -> None:
        """Start a new run's audit."""
        # The current stance interval's travel of each sole point, and a bounce's (pending).
        self._soles[:, :, kernel.SLIP :] = 0.0
        self._feet_float[:] = 0.0  # each foot's load, moments and last CoP (world xy) [m]
        # Physics steps each foot has carried less than the load threshold (a new interval
        # starts at the next load only after LIFT_TIME of them: a bounce is not a step).
        self._feet_int[:, kernel.UNLOADED] = self._lift_steps
        self._actuators[:, 1] = 0.0
        self._totals[:] = 0.0
        self._totals[kernel.MOVED_FOOT] = -1.0

    def after_step(self) -> None:
        """Audit the physics step MuJoCo just took (its contacts, forces and velocities).

        It runs at every physics step: one compiled kernel on MuJoCo's arrays
        (:func:`~pushrecovery.kernels.contact_audit.audit_step`).
        """
        data = self.data
        contact = data.contact
        audit_step(
            contact.geom, contact.dist, contact.frame, contact.pos, contact.friction,
            contact.efc_address, contact.dim, data.efc_force, data.efc_type,
            *self._kernel_arguments,
        )  # fmt: skip

    def result(self) -> PhysicalChecks:
        """Return the checks of the run so far."""
        totals, use = self._totals, self._actuators[:, 1]
        foot = int(totals[kernel.MOVED_FOOT])
        peak = float(totals[kernel.PEAK])
        return PhysicalChecks(
            foot_slip=float(totals[kernel.MOVED]),
            slip_foot=self.feet[foot] if foot >= 0 else "",
            peak_ground_force=peak,
            peak_force_ratio=peak / self.weight,
            max_penetration=float(totals[kernel.DEPTH]),
            friction_use=float(totals[kernel.USE]),
            torque_use=tuple((group, float(use[index].max())) for group, index in self._groups),
            joint_limit_steps=int(totals[kernel.LIMIT_STEPS]),
            physics_steps=int(totals[kernel.STEPS]),
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
