r"""The feet of the whole-body QP: each sole frame and its contact wrench cone.

A foot's wrench w = (F, T) is the force and moment the floor exerts on it at its *sole frame*
(the foot body's axes, its origin on the sole plane under the ankle; F_z > 0 pushes the foot
up). Its linear constraints G w ≤ 0 are the **contact wrench cone** (CWC) of the sole polygon
(:func:`contact_wrench_cone`): exactly the wrenches that point forces at the polygon's vertices,
each in the friction pyramid inscribed in Coulomb's cone, can sum to. They imply unilateral
contact, the friction pyramid on F, the CoP inside the polygon, and couple the yaw moment with
the CoP and the tangential force: a foot loaded on its toe edge cannot take the yaw moment it
could with its whole sole (Caron, Pham and Nakamura 2015, "Stability of surface contacts for
humanoid robots: closed-form formulae of the contact wrench cone for rectangular support
areas", ICRA; here computed for any convex sole). Independent bounds on F, the CoP and T_z, as
this QP had before, admit wrenches the floor cannot give: MuJoCo then turns the foot about its
loaded corner (docs/physical_checks.md: the G1 slid 12 cm at 8 N s).
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

__all__ = ["FootContact"]


def contact_wrench_cone(vertices: FloatArray, mu: float) -> FloatArray:
    r"""Return G with G w ≤ 0 exactly for the wrenches of a sole polygon's point contacts.

    Span form: every vertex p_i = (x_i, y_i, 0) of the sole polygon (sole frame) carries a
    force f_i in the friction pyramid, f_i = Σ_j λ_ij d_j, λ ≥ 0, d_j = (±μ, 0, 1), (0, ±μ, 1);
    the wrench is w = Σ_i (f_i, p_i × f_i) with p × f = (y f_z, −x f_z, x f_y − y f_x). The
    cone is pointed (F_z > 0 but at w = 0), so its face form is the facets of the convex hull of
    its 4k generators cut at F_z = 1 (Qhull through scipy): a·(F_x, F_y, T_x, T_y, T_z)/F_z + b
    ≤ 0 becomes a row (a_1, a_2, b, a_3, a_4, a_5), scaled to unit length; duplicate facets of
    the triangulation are merged, and −F_z ≤ 0 closes the cone.

    Parameters
    ----------
    vertices : float array, shape (k, 2)
        The sole polygon's vertices in the sole frame [m], k >= 3, with area.
    mu : float
        The pyramid's friction coefficient μ [-], > 0: its edges are those of MuJoCo's
        pyramidal cone of friction μ (:func:`foot_contact` passes the floor's μ/√2, a margin).

    Returns
    -------
    float array, shape (r, 6)
        Rows of G [-, -, -, 1/m, 1/m, 1/m] up to each row's scale.

    Raises
    ------
    InvalidParameterError
        If the vertices are not k >= 3 finite points with area, or mu is not > 0.
    """
    from scipy.spatial import ConvexHull, QhullError

    points = np.asarray(vertices, dtype=float)
    if points.ndim != 2 or points.shape[0] < 3 or points.shape[1] != 2:
        raise InvalidParameterError(f"vertices must be k >= 3 points (x, y), got {points.shape}")
    if not np.isfinite(points).all() or not (math.isfinite(mu) and mu > 0.0):
        raise InvalidParameterError(f"vertices must be finite and mu > 0, got mu={mu!r}")
    generators = [
        (fx, fy, y, -x, x * fy - y * fx)
        for x, y in points
        for fx, fy in ((mu, 0.0), (-mu, 0.0), (0.0, mu), (0.0, -mu))
    ]
    try:
        equations = ConvexHull(np.array(generators)).equations
    except QhullError:
        raise InvalidParameterError("vertices must span a polygon with area") from None
    rows = equations[:, [0, 1, 5, 2, 3, 4]]
    rows /= np.linalg.norm(rows, axis=1)[:, None]
    rows = np.unique(np.round(rows, 12), axis=0)
    return np.vstack([[0.0, 0.0, -1.0, 0.0, 0.0, 0.0], rows])


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
    vertices : float array, shape (k, 2)
        The sole polygon's vertices in the sole frame [m], counter-clockwise.
    mu : float
        Friction coefficient of the pyramid, μ' = μ/√2 [-]: the floor's μ with a margin (the
        pyramid's edges (±μ', 0, 1), (0, ±μ', 1) lie inside MuJoCo's for μ).
    cone : float array, shape (r, 6)
        G of the contact wrench cone, G w ≤ 0 (:func:`contact_wrench_cone`).
    """

    name: str
    body: int
    origin: FloatArray
    vertices: FloatArray
    mu: float
    cone: FloatArray

    def constraint_rows(self) -> FloatArray:
        """Return G with G w ≤ 0 for this foot's wrench w = (F, T) [rows, 6]: its cone."""
        return self.cone


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
        not contain the sole frame's origin (the point under the ankle).
    """
    try:
        body = body_id(model, name)
    except InvalidParameterError:
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
    offset = np.einsum("ij,ij->i", normal, vertices)
    if np.any(offset <= 0.0):
        raise InvalidParameterError(
            f"feet: the sole polygon of {name!r} must contain the point under its body origin"
        )
    others = [
        g for g in range(model.ngeom) if int(model.geom_bodyid[g]) != body
        and int(model.geom_conaffinity[g]) & int(model.geom_contype[geoms[0]])
    ]  # fmt: skip
    mu = max(float(model.geom_friction[g, 0]) for g in geoms + others) / math.sqrt(2.0)
    return FootContact(
        name=name,
        body=body,
        origin=np.array([0.0, 0.0, float(local[:, 2].mean())]),
        vertices=np.array(vertices, dtype=float),
        mu=mu,
        cone=contact_wrench_cone(vertices, mu),
    )
