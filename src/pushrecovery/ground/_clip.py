"""Compiled (numba, cached on disk) Sutherland-Hodgman clipping of a convex polygon.

Imported lazily by :func:`pushrecovery.ground.minkowski.clip_halfplanes`: a plan clips large
foothold regions by tens of half-planes, hundreds of vertex visits per cut.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def clip_loop(points, normals, offsets):  # type: ignore[no-untyped-def]
    """Return the vertices of ``points`` ∩ {p : n_i · p <= b_i} (fewer than 3: empty).

    ``points`` a counter-clockwise convex loop (n, 2); one half-plane after the other, each
    keeping the vertices inside and adding the crossings of the edges that leave or enter.
    """
    size = points.shape[0] + normals.shape[0] + 1
    current = np.empty((size, 2))
    following = np.empty((size, 2))
    count = points.shape[0]
    current[:count] = points
    for k in range(normals.shape[0]):
        nx, ny, b = normals[k, 0], normals[k, 1], offsets[k]
        kept = 0
        for i in range(count):
            j = i + 1 if i + 1 < count else 0
            px, py = current[i, 0], current[i, 1]
            qx, qy = current[j, 0], current[j, 1]
            e = nx * px + ny * py - b
            f = nx * qx + ny * qy - b
            if e <= 0.0:
                following[kept, 0], following[kept, 1] = px, py
                kept += 1
            if (e < 0.0 < f) or (f < 0.0 < e):
                share = e / (e - f)
                following[kept, 0] = px + share * (qx - px)
                following[kept, 1] = py + share * (qy - py)
                kept += 1
        current, following = following, current
        count = kept
        if count < 3:
            return current[:count].copy()
    return current[:count].copy()
