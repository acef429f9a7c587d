"""Convex polygons as rows of Python floats, for one point at a time (a loop's tick).

On a handful of edges, plain Python arithmetic on floats answers a single point several
times faster than numpy's per-call cost: :class:`~pushrecovery.surfaces.monitor.BalanceMonitor`
and the plane recovery controller keep a support's polygon and CMP region in this form.
Each row holds an edge's outward unit normal n, its offset b = n · v_0, its start v_0, its
vector e = v_1 − v_0 and 1/‖e‖²; the polygon is {p : n · p <= b for every edge} [m].
The functions check nothing: their callers pass supports and points they have checked (a
tick pays each check once). So they are importable but outside ``__all__``, the API a user
calls (docs/architecture.md), as the whole-body controller's per-tick parts are.
"""

from __future__ import annotations

import math

import numpy as np

from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support

__all__ = []

#: Per edge: n_x, n_y, b, x0, y0, e_x, e_y, 1/‖e‖² (module docstring).
Edges = tuple[tuple[float, float, float, float, float, float, float, float], ...]
#: The box's corners (±1, ±1), counter-clockwise, and the sum's weights and offset.
_CORNERS = ((-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0))
_UNIT_WEIGHTS = np.ones(2)
_ORIGIN = np.zeros(2)


def polygon_rows(polygon: ConvexPolygon) -> Edges:
    """Return a polygon's rows (its own normals and offsets) as Python floats [m]."""
    v = polygon.vertices.tolist()
    rows = []
    for (nx, ny), b, (x0, y0), (x1, y1) in zip(
        polygon.normals.tolist(), polygon.offsets.tolist(), v, v[1:] + v[:1], strict=True
    ):
        ex, ey = x1 - x0, y1 - y0
        rows.append((nx, ny, b, x0, y0, ex, ey, 1.0 / (ex * ex + ey * ey)))
    return tuple(rows)


def loop_rows(loop: list[list[float]]) -> Edges:
    """Return the rows of a counter-clockwise vertex loop (normals as ``ConvexPolygon``'s) [m]."""
    rows = []
    for (x0, y0), (x1, y1) in zip(loop, loop[1:] + loop[:1], strict=True):
        ex, ey = x1 - x0, y1 - y0
        length = math.hypot(ex, ey)
        nx, ny = ey / length, -ex / length
        rows.append((nx, ny, nx * x0 + ny * y0, x0, y0, ex, ey, 1.0 / (ex * ex + ey * ey)))
    return tuple(rows)


def signed_distance(edges: Edges, px: float, py: float) -> float:
    """Signed distance of (px, py) to the polygon [m], + inside (as ``ConvexPolygon``'s).

    Inside, the smallest gap to an edge's line, max_i(n_i · p − b_i) negated; outside, the
    distance to the nearest point of the boundary (the nearest point of each edge segment).
    """
    excess = -math.inf
    for nx, ny, b, _, _, _, _, _ in edges:
        e = nx * px + ny * py - b
        if e > excess:
            excess = e
    if excess <= 0.0:
        return -excess
    best = math.inf
    for _, _, _, vx, vy, ex, ey, inv in edges:
        dx, dy = px - vx, py - vy
        t = (dx * ex + dy * ey) * inv
        t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
        gap = math.hypot(dx - t * ex, dy - t * ey)
        if gap < best:
            best = gap
    return -best


def cmp_rows(support: Support, half_x: float, half_y: float) -> Edges:
    """Return the rows of the CMP region P ⊕ box (``plane.cmp_polygon``), compiled [m].

    The box [−half_x, half_x] × [−half_y, half_y] [m] in the stance's axes (the hip's CMP
    offsets along and across its heading, corrected Eq. 15), its corners placed as
    :meth:`~pushrecovery.ground.polygon.ConvexPolygon.grown` places them; one Minkowski sum of
    two shapes (``kernels.polygons.minkowski_loop``). Without a box, the support polygon's.
    """
    if half_x == 0.0 and half_y == 0.0:
        return polygon_rows(support.polygon)
    from pushrecovery.kernels.polygons import minkowski_loop

    vertices = support.polygon.vertices
    count = len(vertices)
    shapes = np.zeros((2, max(count, 4), 2))
    shapes[0, :count] = vertices
    c, s = math.cos(support.yaw), math.sin(support.yaw)
    shapes[1, :4] = [
        (c * sx * half_x - s * sy * half_y, s * sx * half_x + c * sy * half_y)
        for sx, sy in _CORNERS
    ]
    loop = minkowski_loop(shapes, np.array([count, 4]), _UNIT_WEIGHTS, _ORIGIN)
    return loop_rows(loop.tolist())
