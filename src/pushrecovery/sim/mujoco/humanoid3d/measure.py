"""Measurements of a compiled 3-D humanoid: standing pose, sole points, inertia about an axis.

Shared by the generated biped (:mod:`.biped3d`), the robots (:mod:`.robots`) and the standing
controller (:mod:`.standing`). World frame: x forward, y left, z up, the floor at z = 0 [m].
MuJoCo's types appear as ``Any``: its bindings ship no type information.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = [
    "SOLE_TOLERANCE",
    "body_id",
    "colliding_geoms",
    "inertia_about_axis",
    "joint_id",
    "sole_points",
    "standing_qpos",
    "subtree",
]

#: Points of a foot's colliding geoms within this height of its lowest one form its sole [m].
SOLE_TOLERANCE = 1e-3


def body_id(model: Any, name: str) -> int:
    """Return the id of body ``name`` (a KeyError naming it if the model has none)."""
    import mujoco

    index = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))
    if index < 0:
        raise KeyError(f"the model has no body {name!r}")
    return index


def joint_id(model: Any, name: str) -> int:
    """Return the id of joint ``name`` (a KeyError naming it if the model has none)."""
    import mujoco

    index = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name))
    if index < 0:
        raise KeyError(f"the model has no joint {name!r}")
    return index


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


def colliding_geoms(model: Any, body: int) -> list[int]:
    """Return the geoms of ``body`` that take part in contacts (contype or conaffinity set)."""
    return [
        g
        for g in range(model.ngeom)
        if int(model.geom_bodyid[g]) == body
        and (int(model.geom_contype[g]) or int(model.geom_conaffinity[g]))
    ]


def _geom_low_points(model: Any, data: Any, geom: int) -> FloatArray:
    """Return the world points of ``geom`` that can touch a floor below it [m], shape (k, 3).

    A sphere: its centre minus its radius in z; a capsule: both end centres minus the radius;
    a box: its eight corners; a mesh: its vertices. The caller keeps the lowest.
    """
    import mujoco

    kind = int(model.geom_type[geom])
    centre = np.array(data.geom_xpos[geom], dtype=float)
    rot = np.array(data.geom_xmat[geom], dtype=float).reshape(3, 3)
    size = np.array(model.geom_size[geom], dtype=float)
    down = np.array([0.0, 0.0, size[0]])
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return (centre - down)[None, :]
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        ends = np.array([[0.0, 0.0, -size[1]], [0.0, 0.0, size[1]]])
        return centre + ends @ rot.T - down
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        return centre + (signs * size) @ rot.T
    if kind == mujoco.mjtGeom.mjGEOM_MESH:
        mesh = int(model.geom_dataid[geom])
        start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        vertices = np.array(model.mesh_vert[start : start + count], dtype=float)
        return centre + vertices @ rot.T
    raise ValueError(f"geom {geom} of type {kind} cannot be a sole (sphere, capsule, box, mesh)")


def sole_points(model: Any, data: Any, foot: int) -> FloatArray:
    """Return the world points of foot body ``foot``'s sole [m], shape (k, 3).

    The points of its colliding geoms within :data:`SOLE_TOLERANCE` of the lowest (after
    ``mj_kinematics``): the corners of a flat box, the bottoms of contact spheres, the ends of
    capsules lying on the floor.
    """
    points = np.vstack([_geom_low_points(model, data, g) for g in colliding_geoms(model, foot)])
    return np.asarray(points[points[:, 2] <= points[:, 2].min() + SOLE_TOLERANCE], dtype=float)


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

    Σ_b m_b |a × (c_b − p)|² + aᵀ R_b diag(I_b) R_bᵀ a with each body's centre of mass c_b and
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
