"""The swing leg of the whole-body controller's step: its joints, inertia and swing time.

World frame, x forward, y left, z up, SI units. The swing-time bound is derived in
:mod:`~pushrecovery.control.wbc.stepper.plan` (its module docstring); used by
:class:`~.stepper.stepper.Stepper` and the knee and pelvis limits (:mod:`~.height`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.control.wbc.stepper.plan import QUINTIC_PEAK, lipm_com

FloatArray = NDArray[np.float64]

__all__ = ["Leg"]


@dataclass(frozen=True)
class Leg:
    """The hinge joints of one leg that the swing time and the knee guard need (ids or −1).

    Found by name on the bodies from the foot up to the root: ``hip_pitch``, ``hip_roll``,
    ``knee`` (the biped3d's ``left_hip_pitch``, the G1's ``left_hip_pitch_joint``).
    """

    foot: int
    hip_pitch: int = -1
    hip_roll: int = -1
    knee: int = -1


def leg_joints(model: Any, foot: int) -> Leg:
    """Return the :class:`Leg` of foot body ``foot`` in ``model``."""
    import mujoco

    found: dict[str, int] = {}
    body = foot
    while body > 0:
        for joint in range(int(model.njnt)):
            if int(model.jnt_bodyid[joint]) != body:
                continue
            if int(model.jnt_type[joint]) != mujoco.mjtJoint.mjJNT_HINGE:
                continue
            name = model.joint(joint).name
            for key in ("hip_pitch", "hip_roll", "knee"):
                if key in name and key not in found:
                    found[key] = joint
        body = int(model.body_parentid[body])
    return Leg(foot, **found)


def axis_inertia(model: Any, data: HumanoidObservation, joint: int) -> float:
    """Return the inertia of ``joint``'s subtree about its axis [kg m²], armature included.

    I = Σ_b m_b ‖a × (c_b − o)‖² + aᵀ R_b I_b R_bᵀ a over the bodies b below the joint (a its
    unit axis, o its anchor, after ``mj_kinematics``).
    """
    axis = np.asarray(data.xaxis[joint], dtype=float)
    anchor = np.asarray(data.xanchor[joint], dtype=float)
    first = int(model.jnt_bodyid[joint])
    total = float(model.dof_armature[int(model.jnt_dofadr[joint])])
    for body in range(first, int(model.nbody)):
        parent = body
        while parent > first:
            parent = int(model.body_parentid[parent])
        if parent != first:
            continue
        lever = np.cross(axis, np.asarray(data.xipos[body]) - anchor)
        rot = np.asarray(data.ximat[body], dtype=float).reshape(3, 3)
        local = rot.T @ axis
        total += float(model.body_mass[body]) * float(lever @ lever)
        total += float(local @ (np.asarray(model.body_inertia[body]) * local))
    return total


def leg_swing_time(
    model: Any,
    data: HumanoidObservation,
    leg: Leg,
    foothold: FloatArray,
    cop: FloatArray,
    omega: float,
    t: float,
    torque_share: float,
) -> float:
    """Return the shortest swing T [s] the hip of ``leg`` drives to ``foothold`` (module doc).

    ``cop`` is the stance ankle the LIPM turns about [m], ``t`` the swing time the foothold
    was planned for [s] (the hip's displacement is taken over it), ``torque_share`` κ in
    (0, 1]. 0 when the leg has no hip joints named as :func:`leg_joints` finds them.
    """
    if leg.hip_pitch < 0 and leg.hip_roll < 0:
        return 0.0
    data.subtree_vel()
    com = np.asarray(data.subtree_com[0][:2], dtype=float)
    vel = np.asarray(data.subtree_linvel[0][:2], dtype=float)
    hip_joint = leg.hip_pitch if leg.hip_pitch >= 0 else leg.hip_roll
    hip = np.asarray(data.xanchor[hip_joint], dtype=float)
    foot = np.asarray(data.xpos[leg.foot][:2], dtype=float)
    moved = lipm_com(com, vel, cop, omega, t) - com
    change = (foothold - (hip[:2] + moved)) - (foot - hip[:2])
    height = max(float(hip[2]) - float(data.xpos[leg.foot][2]), 0.1)
    # The pelvis' heading: the hip pitch axis is its lateral (y) direction.
    lateral = np.asarray(data.xaxis[hip_joint][:2], dtype=float)
    if leg.hip_pitch < 0 or float(np.linalg.norm(lateral)) < 1e-9:
        lateral = np.array([0.0, 1.0])
    lateral = lateral / float(np.linalg.norm(lateral))
    forward = np.array([lateral[1], -lateral[0]])
    need = 0.0
    for joint, part in ((leg.hip_pitch, forward @ change), (leg.hip_roll, lateral @ change)):
        if joint < 0:
            continue
        actuators = np.flatnonzero(np.asarray(model.actuator_trnid[:, 0]) == joint)
        if actuators.size == 0:
            continue
        limit = float(np.abs(model.actuator_ctrlrange[actuators[0]]).min())
        limit *= abs(float(model.actuator_gear[actuators[0], 0])) * torque_share
        if limit <= 0.0:
            continue
        angle = abs(float(part)) / height
        need = max(need, math.sqrt(QUINTIC_PEAK * angle * axis_inertia(model, data, joint) / limit))
    return need
