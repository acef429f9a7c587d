"""A joint-space PD that holds a 3-D humanoid in a standing posture (docs/humanoid3d.md).

Every motor-driven hinge is pulled to its posture angle: τ_i = K_i (q*_i − q_i) − D_i q̇_i,
clipped to the motor's range. The gains come from the inertia each joint moves while both
feet stand on the floor, J_i: its own entry M_ii of the joint-space inertia (what hangs below
it), plus for a leg joint the inertia of everything *above* it (every body outside the joint's
subtree, which turns about the joint when the foot is fixed) about the joint's axis
(:func:`~.measure.inertia_about_axis`). K_i = J_i ω², D_i = 2 ζ J_i ω with
ω² = :data:`STIFFNESS_RATIO` g / h (h the CoM height): the ankle, whose load J is about
m h², gets K ≈ 4 m g h, four times the gravity stiffness of the inverted pendulum it holds
(the G1's own position servos, kp = 500 N m/rad, are about twice its m g h). ζ =
:data:`DAMPING_RATIO` = 0.5: the damping is applied explicitly at each physics step, and at
ζ = 1 (1 ms steps) the stiff double-support chain (both feet on the floor, the knees at their
stop) chattered between the torque limits and fell; at ζ = 0.5 it stands. This is a
placeholder that stands still; the whole-body controller that recovers from pushes is a
later item of issue 19.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.mujoco.humanoid3d.measure import inertia_about_axis, subtree

FloatArray = NDArray[np.float64]

__all__ = ["DAMPING_RATIO", "STIFFNESS_RATIO", "StandingPD"]

#: Each loop's ω² over g / h, the pendulum's [-] (module docstring).
STIFFNESS_RATIO = 4.0
#: Damping ratio ζ of each joint's loop [-] (module docstring).
DAMPING_RATIO = 0.5


@dataclass(frozen=True)
class StandingPD:
    """Joint-space PD gains and targets for every motor of a model.

    Attributes
    ----------
    qpos_address, dof_address : int arrays
        Each motor's joint entry in ``qpos`` and ``qvel``.
    target : float array
        Posture angle q* of each motor's joint [rad].
    stiffness, damping : float arrays
        K [N m/rad] and D [N m s/rad] of each motor.
    low, high : float arrays
        Each motor's torque range [N m].
    """

    qpos_address: NDArray[np.int64]
    dof_address: NDArray[np.int64]
    target: FloatArray
    stiffness: FloatArray
    damping: FloatArray
    low: FloatArray
    high: FloatArray

    @classmethod
    def for_model(
        cls,
        model: Any,
        qpos: FloatArray,
        legs: list[int],
        stiffness_ratio: float = STIFFNESS_RATIO,
    ) -> StandingPD:
        """Return the PD holding posture ``qpos`` of ``model`` (torque motors on hinges).

        Parameters
        ----------
        model : mujoco.MjModel
            Its actuators must be torque motors (gear 1) on hinge joints.
        qpos : float array
            The standing posture (:func:`~.measure.standing_qpos`), in MuJoCo's units: [m] for slide
            and free-joint positions, [-] for the free joint's unit quaternion, [rad] for hinges.
        legs : list of int
            Body ids at the top of each leg (the hip's first body): joints in their subtrees
            also move the body above them (module docstring).
        stiffness_ratio : float
            ω² over g / h [-], > 0 (:data:`STIFFNESS_RATIO`).
        """
        import mujoco

        if not (math.isfinite(stiffness_ratio) and stiffness_ratio > 0.0):
            raise InvalidParameterError(f"stiffness_ratio must be > 0, got {stiffness_ratio!r}")
        data = mujoco.MjData(model)
        data.qpos[:] = qpos
        mujoco.mj_forward(model, data)
        in_leg = {b for leg in legs for b in subtree(model, leg)}
        joints = np.array([int(model.actuator_trnid[a, 0]) for a in range(model.nu)])
        inertia = np.empty(model.nu)
        for a, joint in enumerate(joints):
            dof, body = int(model.jnt_dofadr[joint]), int(model.jnt_bodyid[joint])
            unit, column = np.zeros(model.nv), np.zeros(model.nv)
            unit[dof] = 1.0
            mujoco.mj_mulM(model, data, column, unit)  # M e_i (the same call in MuJoCo 3 and 4)
            inertia[a] = column[dof]
            if body in in_leg:
                above = sorted(set(range(1, model.nbody)) - set(subtree(model, body)))
                inertia[a] += inertia_about_axis(
                    model, data, above, data.xanchor[joint], data.xaxis[joint]
                )
        gravity = float(np.linalg.norm(model.opt.gravity))
        omega = math.sqrt(stiffness_ratio * gravity / float(data.subtree_com[0][2]))
        ranges = np.array(model.actuator_ctrlrange, dtype=float)
        limited = np.array(model.actuator_ctrllimited, dtype=bool)
        return cls(
            qpos_address=np.array(model.jnt_qposadr[joints], dtype=np.int64),
            dof_address=np.array(model.jnt_dofadr[joints], dtype=np.int64),
            target=np.array(qpos, dtype=float)[model.jnt_qposadr[joints]],
            stiffness=inertia * omega**2,
            damping=2.0 * DAMPING_RATIO * inertia * omega,
            low=np.where(limited, ranges[:, 0], -np.inf),
            high=np.where(limited, ranges[:, 1], np.inf),
        )

    def torques(self, data: Any) -> FloatArray:
        """Return the motor torques for the state in ``data`` [N m], within each motor's range."""
        error = self.target - np.asarray(data.qpos)[self.qpos_address]
        rate = np.asarray(data.qvel)[self.dof_address]
        return np.clip(self.stiffness * error - self.damping * rate, self.low, self.high)


def hold_standing(
    model: Any, qpos: FloatArray, legs: list[int], duration: float
) -> tuple[Any, FloatArray]:
    """Simulate ``duration`` seconds from rest at ``qpos`` under :class:`StandingPD`.

    Returns
    -------
    data : mujoco.MjData
        The final state.
    root : float array, shape (n, 3)
        The free root's position after every physics step [m] (world frame).
    """
    import mujoco

    if not (math.isfinite(duration) and 0.0 <= duration <= 60.0):
        raise InvalidParameterError(f"duration must be in [0, 60] s, got {duration!r}")
    controller = StandingPD.for_model(model, qpos, legs)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    steps = round(float(duration) / float(model.opt.timestep))
    root = np.empty((steps, 3))
    for step in range(steps):
        data.ctrl[:] = controller.torques(data)
        mujoco.mj_step(model, data)
        root[step] = data.qpos[:3]
    return data, root
