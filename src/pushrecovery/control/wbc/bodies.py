"""Reading a compiled MuJoCo humanoid: bodies by name, the colliding geoms, each sole's points.

Shared by the whole-body controller (its feet, :mod:`~pushrecovery.control.wbc.foot_contact`,
and the stepper's touchdown) and the plants that build and measure the humanoids
(``pushrecovery.sim.mujoco.humanoid3d``), as mink's ``utils`` serve its tasks. World frame:
x forward, y left, z up, the floor at z = 0 [m]. MuJoCo's types appear as ``Any``: its
bindings ship no type information.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import MAX_MAGNITUDE, finite_vector, require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

FloatArray = NDArray[np.float64]

__all__ = [
    "SOLE_TOLERANCE",
    "body_id",
    "body_names",
    "check_data",
    "check_model",
    "check_qpos",
]

#: Points of a foot's colliding geoms within this height of its lowest one form its sole [m].
SOLE_TOLERANCE = 1e-3


def check_model(model: object) -> None:
    """Raise :class:`ParameterTypeError` unless ``model`` is a compiled ``mujoco.MjModel``.

    The check of the floors' entries that take MuJoCo's own objects (the plants, the
    controller, the renderers): a type check, once where they are built.
    """
    import mujoco

    require_type("model", model, mujoco.MjModel)


def check_data(model: Any, data: Any) -> None:
    """Raise unless ``data`` is a ``mujoco.MjData`` made for ``model`` (its nq, nv, nbody)."""
    import mujoco

    check_model(model)
    require_type("data", data, mujoco.MjData)
    if (data.qpos.size, data.qvel.size, data.xpos.shape[0]) != (model.nq, model.nv, model.nbody):
        raise InvalidParameterError(
            f"data must be made for model (nq {model.nq}, nv {model.nv}), "
            f"got nq {data.qpos.size}, nv {data.qvel.size}"
        )


def check_qpos(model: Any, qpos: ArrayLike, name: str = "qpos") -> FloatArray:
    """Return ``qpos`` as model.nq finite numbers ([m], [-] quaternions, [rad]), or raise."""
    check_model(model)
    require_type("name", name, str)
    return finite_vector(name, qpos, int(model.nq), bound=MAX_MAGNITUDE)


def body_names(model: Any, names: object, name: str) -> tuple[str, ...]:
    """Return ``names`` as a tuple of distinct body names of ``model``, or raise naming ``name``."""
    if isinstance(names, str) or not isinstance(names, Sequence):
        raise ParameterTypeError(f"{name} must be a sequence of body names, got {names!r:.40}")
    if not names:
        raise InvalidParameterError(f"{name} must name at least one body, got none")
    check_model(model)
    found = tuple(names)
    if not all(isinstance(n, str) for n in found) or len(set(found)) != len(found):
        raise InvalidParameterError(f"{name} must be distinct body names, got {str(found)[:80]}")
    for each in found:
        body_id(model, each)
    return found


def body_id(model: Any, name: str) -> int:
    """Return the id of body ``name`` of ``model``.

    Raises
    ------
    InvalidParameterError
        If the model has no body ``name`` (``name`` not a string included).
    """
    import mujoco

    check_model(model)
    if not isinstance(name, str):
        raise ParameterTypeError(f"a body name must be a string, got {type(name).__name__}")
    index = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))
    if index < 0:
        raise InvalidParameterError(f"the model has no body {name[:60]!r}")
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
