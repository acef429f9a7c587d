"""The convex hull of every frame's points in one compiled loop (numba, cached on disk).

:func:`pushrecovery.analysis.base_polygon._hulls` calls it: the base of support of each frame
is the hull of its supporting soles' corners.
"""

from __future__ import annotations

import numpy as np

from pushrecovery.kernels.jit import hypot, njit

__all__: list[str] = []


@njit(cache=True, nogil=True)
def hull_kernel(points, out, counts, min_edge):  # type: ignore[no-untyped-def]
    """Andrew's monotone chain per frame (as :func:`pushrecovery.ground.convex_hull`).

    Collinear and repeated points dropped, vertices closer than ``min_edge`` merged; a hull
    of fewer than 3 vertices or zero area leaves ``counts`` 0.
    """
    n, k = points.shape[0], points.shape[1]
    chain = np.empty((2 * k + 2, 2))
    for f in range(n):
        finite = np.flatnonzero(np.isfinite(points[f, :, 0]) & np.isfinite(points[f, :, 1]))
        m = finite.size
        if m < 3:
            continue
        pts = points[f][finite]
        pts = pts[np.argsort(pts[:, 1], kind="mergesort")]  # by x, then y
        pts = pts[np.argsort(pts[:, 0], kind="mergesort")]
        scale = max(1.0, np.abs(pts).max())
        size = 0
        for a in range(m):  # lower chain
            px, py = pts[a, 0], pts[a, 1]
            while size >= 2 and _turn(chain, size, px, py) <= 0.0:
                size -= 1
            chain[size, 0], chain[size, 1] = px, py
            size += 1
        floor = size + 1
        for a in range(m - 2, -1, -1):  # upper chain
            px, py = pts[a, 0], pts[a, 1]
            while size >= floor and _turn(chain, size, px, py) <= 0.0:
                size -= 1
            chain[size, 0], chain[size, 1] = px, py
            size += 1
        size -= 1  # the last point is the first again
        kept = 0
        tol = max(min_edge, 1e-12 * scale)
        for i in range(size):
            j = i - 1 if i > 0 else size - 1
            if hypot(chain[i, 0] - chain[j, 0], chain[i, 1] - chain[j, 1]) > tol:
                out[f, kept, 0], out[f, kept, 1] = chain[i, 0], chain[i, 1]
                kept += 1
        area = 0.0
        for i in range(kept):
            j = i + 1 if i + 1 < kept else 0
            area += out[f, i, 0] * out[f, j, 1] - out[f, j, 0] * out[f, i, 1]
        if kept >= 3 and 0.5 * area > 1e-12 * scale * scale:
            counts[f] = kept
        else:
            for i in range(kept):
                out[f, i, 0], out[f, i, 1] = np.nan, np.nan


@njit(cache=True, nogil=True, inline="always")
def _turn(chain, size, px, py):  # type: ignore[no-untyped-def]
    """Return z of (b − a) × (p − b), a, b the chain's last two points: > 0 turning left."""
    ax, ay = chain[size - 2, 0], chain[size - 2, 1]
    bx, by = chain[size - 1, 0], chain[size - 1, 1]
    return (bx - ax) * (py - by) - (by - ay) * (px - bx)
