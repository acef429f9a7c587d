"""One state's signed distances to two convex polygons, in one compiled call.

The single-state path of :func:`pushrecovery.surfaces.classify.classify` on the ground plane:
the support polygon and the CMP region of one support, each distance the
same floating-point operations as
:meth:`pushrecovery.ground.polygon.ConvexPolygon.signed_distance` (numpy), so that the margins
agree to the bit: inside, −max_i(n_i · p − b_i); outside, −min_i hypot(d − t_i e_i), with d
the point minus vertex i, e_i edge i, t_i = clip((d · e_i) / (e_i · e_i), 0, 1); a NaN
propagates as numpy's max and min propagate it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["STRIDE", "pair_distances"]

#: Values per edge row of a table: n_x, n_y, b, v_x, v_y, e_x, e_y, e · e.
STRIDE = 8


@numba.njit(cache=True, nogil=True, inline="always")
def _signed_distance(table, row, count, px, py):  # type: ignore[no-untyped-def]
    """Signed distance of p to the polygon of ``table[row, :count]`` [m], + inside."""
    excess = -np.inf
    for k in range(count):
        e = table[row, k, 0] * px + table[row, k, 1] * py - table[row, k, 2]
        if e > excess or e != e:  # a NaN stays, as in numpy's max
            excess = e
    if not excess > 0.0:
        return -excess
    best = np.inf
    for k in range(count):
        dx = px - table[row, k, 3]
        dy = py - table[row, k, 4]
        ex, ey = table[row, k, 5], table[row, k, 6]
        along = (dx * ex + dy * ey) / table[row, k, 7]
        if along < 0.0:
            along = 0.0
        if along > 1.0:
            along = 1.0
        gap = math.hypot(dx - along * ex, dy - along * ey)
        if gap < best or gap != gap:
            best = gap
    return -best


@numba.njit(cache=True, nogil=True)
def pair_distances(table, counts, px, py):  # type: ignore[no-untyped-def]
    """Return the signed distances of p = (px, py) to the polygons of rows 0 and 1 [m].

    ``table`` of shape (2, E, :data:`STRIDE`), row r's first ``counts[r]`` edges; + inside.
    """
    return (
        _signed_distance(table, 0, counts[0], px, py),
        _signed_distance(table, 1, counts[1], px, py),
    )
