"""One point's signed distance to a convex polygon, compiled, to the bit of the numpy form.

The single-state paths of :func:`pushrecovery.surfaces.classify.classify` (the support
polygon and the CMP region) and :func:`pushrecovery.surfaces.step.impact.plan_impacts` (the
landing foot's region) call it on Python floats instead of building arrays. Each distance is
the same floating-point operations as
:meth:`pushrecovery.ground.polygon.ConvexPolygon.signed_distance` (numpy), so that it agrees
to the bit: inside, −max_i(n_i · p − b_i); outside, −min_i hypot(d_i − t_i e_i), with d_i
the point minus vertex i, e_i edge i, t_i = clip((d_i · e_i) / (e_i · e_i), 0, 1); a NaN
propagates as numpy's max and min propagate it. The operands that numpy computes with a
reduction (e_i · e_i) come from numpy too (:func:`edge_rows`).
"""

from __future__ import annotations

import numpy as np

from pushrecovery.kernels.jit import hypot, njit

__all__ = ["edge_rows", "signed_distance"]


def edge_rows(vertices, normals, offsets):  # type: ignore[no-untyped-def]
    """Return the rows :func:`signed_distance` reads, one per edge (E, 8), read-only.

    n_x, n_y, b, v_x, v_y, e_x, e_y, e · e of a convex polygon's counter-clockwise
    ``vertices`` (E, 2), outward unit ``normals`` (E, 2) and ``offsets`` (E,), computed as
    the numpy signed distance computes them.
    """
    edges = np.concatenate((vertices[1:], vertices[:1])) - vertices
    length2 = np.einsum("ij,ij->i", edges, edges)
    rows = np.ascontiguousarray(np.column_stack([normals, offsets, vertices, edges, length2]))
    rows.flags.writeable = False  # read-only, always: one compiled signature
    return rows


@njit(cache=True, nogil=True)
def signed_distance(rows, px, py):  # type: ignore[no-untyped-def]
    """Signed distance of p = (px, py) to the polygon of ``rows`` (:func:`edge_rows`) [m].

    Positive inside.
    """
    count = rows.shape[0]
    excess = -np.inf
    for k in range(count):
        e = rows[k, 0] * px + rows[k, 1] * py - rows[k, 2]
        if e > excess or e != e:  # a NaN stays, as in numpy's max
            excess = e
    if not excess > 0.0:
        return -excess
    best = np.inf
    for k in range(count):
        dx = px - rows[k, 3]
        dy = py - rows[k, 4]
        ex, ey = rows[k, 5], rows[k, 6]
        along = (dx * ex + dy * ey) / rows[k, 7]
        if along < 0.0:
            along = 0.0
        if along > 1.0:
            along = 1.0
        gap = hypot(dx - along * ex, dy - along * ey)
        if gap < best or gap != gap:
            best = gap
    return -best
