"""Reading a compiled MuJoCo humanoid: bodies by name, the colliding geoms, each sole's points.

Shared by the whole-body controller (its feet, :mod:`~pushrecovery.control.wbc.foot_contact`,
and the stepper's touchdown) and the plants that build and measure the humanoids
(``pushrecovery.sim.mujoco.humanoid3d``), as mink's ``utils`` serve its tasks. World frame:
x forward, y left, z up, the floor at z = 0 [m]. MuJoCo's types appear as ``Any``: its
bindings ship no type information.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError

FloatArray = NDArray[np.float64]

__all__ = ["SOLE_TOLERANCE", "body_id", "colliding_geoms", "sole_points"]

#: Points of a foot's colliding geoms within this height of its lowest one form its sole [m].
SOLE_TOLERANCE = 1e-3


def body_id(model: Any, name: str) -> int:
    """Return the id of body ``name`` (a KeyError naming it if the model has none)."""
    import mujoco

    index = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))
    if index < 0:
        raise KeyError(f"the model has no body {name!r}")
    return index


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
    geoms = colliding_geoms(model, foot)
    if not geoms:  # a model's file without a sole on this body
        raise InvalidParameterError(
            f"foot body {model.body(foot).name!r} has no colliding geom to stand on"
        )
    points = np.vstack([_geom_low_points(model, data, g) for g in geoms])
    return np.asarray(points[points[:, 2] <= points[:, 2].min() + SOLE_TOLERANCE], dtype=float)
