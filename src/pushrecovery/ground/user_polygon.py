"""User polygons checked: a foot outline given as vertices becomes a :class:`ConvexPolygon`.

Every way a polygon can be wrong gets a message naming the parameter and the vertex: too few,
non-finite, out of range or repeated vertices, crossing edges, a reflex vertex, zero area, or
an ankle outside.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.polygon import (
    MAX_COORDINATE,
    MIN_AREA,
    MIN_EDGE,
    ConvexPolygon,
    _cross,
    following,
)

__all__ = ["convex_polygon"]

FloatArray = NDArray[np.float64]


def convex_polygon(name: str, vertices: object, *, contains_origin: bool = False) -> ConvexPolygon:
    """Validate user vertices as a convex polygon (either orientation) or raise naming them.

    Collinear vertices (on the line of their neighbours) are dropped; clockwise input is
    reversed.

    Parameters
    ----------
    name : str
        Parameter name for the messages, e.g. ``"foot_polygon"``.
    vertices : sequence of (x, y)
        The vertices in order [m].
    contains_origin : bool
        Require the origin (the ankle) strictly inside.

    Raises
    ------
    InvalidParameterError
        Fewer than 3 vertices, a non-finite or repeated vertex, self-intersecting edges, a
        non-convex vertex, zero area, or (with ``contains_origin``) the origin not inside.
    """
    require_type("name", name, str)
    try:
        pts = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):  # an int beyond float too
        raise InvalidParameterError(
            f"{name} must be a list of [x, y] vertices in m, got {vertices!r:.60}"
        ) from None
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3:
        raise InvalidParameterError(
            f"{name} must be at least 3 [x, y] vertices in m, got shape {pts.shape}"
        )
    for index, (x, y) in enumerate(pts):
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InvalidParameterError(f"{name} vertex {index} is not finite: ({x}, {y})")
        if max(abs(x), abs(y)) > MAX_COORDINATE:
            raise InvalidParameterError(
                f"{name} vertex {index} ({x:g}, {y:g}) lies beyond ±{MAX_COORDINATE:g} m"
            )
    n = len(pts)
    scale = max(1e-3, float(np.abs(pts).max()))
    eps = 1e-12 * scale * scale
    for index in range(n):
        if np.hypot(*(pts[index] - pts[(index + 1) % n])) <= max(MIN_EDGE, 1e-12 * scale):
            raise InvalidParameterError(
                f"{name} vertex {(index + 1) % n} repeats vertex {index} at "
                f"({pts[index][0]:g}, {pts[index][1]:g})"
            )
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent through the closing edge
            if _segments_cross(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n], eps):
                raise InvalidParameterError(
                    f"{name} is self-intersecting: edge {i}-{(i + 1) % n} crosses edge "
                    f"{j}-{(j + 1) % n}"
                )
    turns = np.array([_cross(pts[i - 1], pts[i], pts[(i + 1) % n]) for i in range(n)])
    # A turn relative to its edges' lengths (the sine of the angle): tiny edges still turn.
    lengths = np.hypot(*(following(pts) - pts).T)
    bends = 1e-12 * lengths * following(lengths, -1)
    area = 0.5 * float(np.sum(pts[:, 0] * following(pts[:, 1]) - following(pts[:, 0]) * pts[:, 1]))
    if abs(area) < max(MIN_AREA, eps):
        raise InvalidParameterError(
            f"{name} is degenerate: area {abs(area):.3g} m², at least {MIN_AREA:g} m² (1 mm²)"
        )
    sign = 1.0 if area > 0.0 else -1.0
    for index, turn in enumerate(turns):
        if sign * turn < -bends[index]:
            x, y = pts[index]
            raise InvalidParameterError(f"{name} is not convex at vertex {index} ({x:g}, {y:g})")
    keep = np.abs(turns) > bends
    ordered = pts[keep] if sign > 0.0 else pts[keep][::-1]
    polygon = ConvexPolygon._from_ccw(ordered)
    if not isinstance(contains_origin, bool | np.bool_):
        raise ParameterTypeError(
            f"contains_origin must be True or False, got {type(contains_origin).__name__}"
        )
    if contains_origin and float(polygon.signed_distance(0.0, 0.0)) <= 0.0:
        raise InvalidParameterError(
            f"{name} must contain the ankle (0, 0) strictly inside; it spans x in "
            f"[{polygon.xmin:g}, {polygon.xmax:g}] m, y in [{polygon.ymin:g}, {polygon.ymax:g}] m"
        )
    return polygon


def _segments_cross(a: FloatArray, b: FloatArray, c: FloatArray, d: FloatArray, eps: float) -> bool:
    """Proper or touching intersection of segments ab and cd."""

    def orient(p: FloatArray, q: FloatArray, r: FloatArray) -> float:
        return float((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    def on_segment(p: FloatArray, q: FloatArray, r: FloatArray) -> bool:
        return bool(
            min(p[0], q[0]) - 1e-15 <= r[0] <= max(p[0], q[0]) + 1e-15
            and min(p[1], q[1]) - 1e-15 <= r[1] <= max(p[1], q[1]) + 1e-15
        )

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if ((o1 > eps and o2 < -eps) or (o1 < -eps and o2 > eps)) and (
        (o3 > eps and o4 < -eps) or (o3 < -eps and o4 > eps)
    ):
        return True
    return any(
        abs(o) <= eps and on_segment(p, q, r)
        for o, p, q, r in ((o1, a, b, c), (o2, a, b, d), (o3, c, d, a), (o4, c, d, b))
    )
