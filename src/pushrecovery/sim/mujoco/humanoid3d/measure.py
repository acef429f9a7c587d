"""Measurements of a compiled 3-D humanoid: joints by name, subtrees, standing pose, inertia.

Shared by the generated biped (:mod:`.biped3d`), the robots (:mod:`.robots`) and the standing
controller (:mod:`.standing`); bodies by name and the soles' points are the whole-body
controller's (:mod:`pushrecovery.control.wbc.bodies`). World frame: x forward, y left, z up,
the floor at z = 0 [m]. MuJoCo's types appear as ``Any``: its bindings ship no type
information.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_array
from pushrecovery.control.wbc.bodies import sole_points
from pushrecovery.errors import InvalidParameterError

FloatArray = NDArray[np.float64]

__all__ = []


def joint_id(model: Any, name: str) -> int:
    """Return the id of joint ``name`` (a KeyError naming it if the model has none)."""
    import mujoco

    index = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name))
    if index < 0:
        raise KeyError(f"the model has no joint {name!r}")
    return index


def body_origins(model: Any, qpos: FloatArray, names: tuple[str, ...]) -> dict[str, FloatArray]:
    """Return the world origin of each named body in pose ``qpos`` (forward kinematics) [m].

    Raises
    ------
    InvalidParameterError
        If ``qpos`` is not finite of shape (nq,), or the model has no body of a name.
    """
    import mujoco

    qpos = finite_array("qpos", qpos)
    if qpos.shape != (model.nq,):
        raise InvalidParameterError(f"qpos must have shape ({model.nq},), got {qpos.shape}")
    ids = {}
    for name in names:
        index = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))
        if index < 0:
            raise InvalidParameterError(f"the model has no body {name!r}")
        ids[name] = index
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    return {name: np.array(data.xpos[index]) for name, index in ids.items()}


def subtree(model: Any, root: int) -> list[int]:
    """Return the ids of ``root`` and every body below it in the kinematic tree."""
    inside = []
    for body in range(model.nbody):
        walk = body
        while walk > 0 and walk != root:
            walk = int(model.body_parentid[walk])
        if walk == root:
            inside.append(body)
    return inside


def standing_qpos(model: Any, qpos: FloatArray, feet: list[int]) -> FloatArray:
    """Return ``qpos`` with the free root lifted or lowered so the lowest sole touches z = 0.

    ``qpos`` is a standing posture (a keyframe or the model's ``qpos0``); the root's height is
    the only entry changed (the free joint must be the model's first joint).
    """
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    lowest = min(float(sole_points(model, data, foot)[:, 2].min()) for foot in feet)
    standing = np.array(qpos, dtype=float)
    standing[2] -= lowest
    return standing


def inertia_about_axis(
    model: Any, data: Any, bodies: list[int], point: FloatArray, axis: FloatArray
) -> float:
    """Return the inertia of ``bodies`` about the line through ``point`` along ``axis`` [kg m^2].

    Σ_b m_b ‖a × (c_b − p)‖² + aᵀ R_b diag(I_b) R_bᵀ a with each body's centre of mass c_b and
    principal frame R_b (``data.xipos``, ``data.ximat`` after ``mj_kinematics``), ``a`` the unit
    axis: the composite inertia the bodies present to a hinge along that line.
    """
    unit = np.asarray(axis, dtype=float) / float(np.linalg.norm(axis))
    total = 0.0
    for body in bodies:
        lever = np.cross(unit, np.asarray(data.xipos[body]) - np.asarray(point, dtype=float))
        rot = np.array(data.ximat[body], dtype=float).reshape(3, 3)
        local = rot.T @ unit
        total += float(model.body_mass[body]) * float(lever @ lever)
        total += float(local @ (np.asarray(model.body_inertia[body], dtype=float) * local))
    return total
