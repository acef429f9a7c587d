r"""The feet of the whole-body QP: each sole frame and its wrench constraints.

A foot's wrench w = (F, T) is the force and moment the floor exerts on it at its *sole frame*
(the foot body's axes, its origin on the sole plane under the ankle; F_z > 0 pushes the foot
up). Its linear constraints G w ≤ 0: unilateral contact, the friction pyramid inscribed in
Coulomb's cone, the CoP inside the sole polygon and the yaw friction (the docstring of
:mod:`~pushrecovery.control.wbc.qp`, the QP).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.bodies import body_id, colliding_geoms, sole_points
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import convex_hull

FloatArray = NDArray[np.float64]

__all__ = ["FootContact", "foot_contact"]


@dataclass(frozen=True)
class FootContact:
    """A foot's sole frame and its wrench constraints.

    Attributes
    ----------
    name, body : str, int
        The foot body's name and id.
    origin : float array, shape (3,)
        The sole frame's origin in the foot body's frame [m]: under the body origin, on the
        sole plane.
    edges : float array, shape (k, 3)
        Rows (n_x, n_y, d) with n·p ≤ d for a CoP p inside the sole polygon, in the sole frame
        [-, -, m] (n a unit outward normal).
    mu : float
        Friction coefficient of the pyramid, μ' = μ/√2 [-].
    yaw_radius : float
        Inscribed radius r of the sole polygon about the frame's origin [m] (abs(T_z) ≤ μ' r F_z).
    """

    name: str
    body: int
    origin: FloatArray
    edges: FloatArray
    mu: float
    yaw_radius: float

    def constraint_rows(self) -> FloatArray:
        """Return G with G w ≤ 0 for this foot's wrench w = (F, T) [rows, 6].

        Rows: −F_z ≤ 0; ±F_x − μ' F_z ≤ 0; ±F_y − μ' F_z ≤ 0; per edge
        n_y T_x − n_x T_y − d F_z ≤ 0; ±T_z − μ' r F_z ≤ 0.
        """
        mu, rows = self.mu, [[0.0, 0.0, -1.0, 0.0, 0.0, 0.0]]
        for sign in (1.0, -1.0):
            rows.append([sign, 0.0, -mu, 0.0, 0.0, 0.0])
            rows.append([0.0, sign, -mu, 0.0, 0.0, 0.0])
        for nx, ny, d in self.edges:
            rows.append([0.0, 0.0, -d, ny, -nx, 0.0])
        for sign in (1.0, -1.0):
            rows.append([0.0, 0.0, -mu * self.yaw_radius, 0.0, 0.0, sign])
        return np.array(rows, dtype=float)


def foot_contact(model: Any, data: Any, name: str) -> FootContact:
    """Return the :class:`FootContact` of foot body ``name``, measured in ``data``'s pose.

    The sole polygon is the convex hull of the sole points (:func:`~.bodies.sole_points`,
    after ``mj_kinematics``) in the foot body's frame; the sole frame's origin is the body
    origin moved along the body's z onto the sole plane. μ is the largest sliding friction of
    the foot's colliding geoms and every geom they can touch (the floor), as MuJoCo mixes two
    geoms' friction by their maximum.

    Raises
    ------
    InvalidParameterError
        If ``name`` is not a body of ``model`` with colliding geoms, or its sole polygon does
        not contain the sole frame's origin (the yaw bound needs it inside).
    """
    try:
        body = body_id(model, name)
    except KeyError:
        raise InvalidParameterError(f"feet must name bodies of the model, got {name!r}") from None
    geoms = colliding_geoms(model, body)
    if not geoms:
        raise InvalidParameterError(f"feet: body {name!r} has no colliding geom (no sole)")
    rot = np.array(data.xmat[body], dtype=float).reshape(3, 3)
    local = (sole_points(model, data, body) - np.asarray(data.xpos[body])) @ rot
    polygon = convex_hull(local[:, :2])
    vertices, following = polygon.vertices, np.roll(polygon.vertices, -1, axis=0)
    direction = following - vertices
    normal = np.column_stack([direction[:, 1], -direction[:, 0]])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    offset = np.einsum("ij,ij->i", normal, vertices)
    if np.any(offset <= 0.0):
        raise InvalidParameterError(
            f"feet: the sole polygon of {name!r} must contain the point under its body origin"
        )
    others = [
        g for g in range(model.ngeom) if int(model.geom_bodyid[g]) != body
        and int(model.geom_conaffinity[g]) & int(model.geom_contype[geoms[0]])
    ]  # fmt: skip
    mu = max(float(model.geom_friction[g, 0]) for g in geoms + others)
    return FootContact(
        name=name,
        body=body,
        origin=np.array([0.0, 0.0, float(local[:, 2].mean())]),
        edges=np.column_stack([normal, offset]),
        mu=mu / math.sqrt(2.0),
        yaw_radius=float(offset.min()),
    )
