r"""Convex polygons on the ground plane: validation, hulls, signed distances, Minkowski sums.

A :class:`ConvexPolygon` stores its vertices counter-clockwise and, for each edge i (vertex i to
i + 1), the outward unit normal n_i and offset b_i = n_i · v_i, so that

.. math:: P = \{p : n_i \cdot p \le b_i \ \forall i\}.

The signed distance of a point p to P (positive inside) is exact:

- inside, min_i (b_i − n_i · p): the disc of that radius about p lies in every half-plane and
  touches the nearest edge line on the boundary;
- outside, −min_i dist(p, edge_i), the Euclidean distance to the nearest edge *segment* (a
  corner is nearer than any edge line there).

Coordinates are x forward, y left [m]; yaw is counter-clockwise about z [rad]
(``docs/conventions.md``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import bounded_float, finite_array
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

__all__ = ["ConvexPolygon", "convex_hull", "rectangle"]

FloatArray = NDArray[np.float64]


def following(array: NDArray[np.float64], shift: int = 1) -> NDArray[np.float64]:
    """``np.roll(array, -shift, axis=0)``: element i + shift at i (cyclic), a few µs faster."""
    shift %= len(array)
    return np.concatenate((array[shift:], array[:shift]))


# Rows of a chunk for the numpy signed distance: (edges x chunk) temporaries stay small.
_CHUNK = 1 << 16
#: Shortest edge of a user polygon [m] and smallest area [m²]: below, a foot is a point or a
#: line, and its normals and distances are rounding noise.
MIN_EDGE = 1e-6
MIN_AREA = 1e-6
#: Largest coordinate of a user polygon [m] (a foot, in its own frame).
MAX_COORDINATE = 1e3


@dataclass(frozen=True, slots=True, eq=False)
class ConvexPolygon:
    """A convex polygon with counter-clockwise vertices [m].

    Build one with :func:`~pushrecovery.ground.user_polygon.convex_polygon` (checked user
    vertices), :func:`convex_hull` or :func:`rectangle`.

    Attributes
    ----------
    vertices : ndarray, shape (n, 2)
        Counter-clockwise vertices (x, y) [m], no repeats, no collinear triples, n >= 3.
    normals : ndarray, shape (n, 2)
        Outward unit normal of edge i (from vertex i to vertex i + 1).
    offsets : ndarray, shape (n,)
        b_i = n_i · v_i [m]: the polygon is {p : n_i · p <= b_i}.
    """

    vertices: FloatArray
    normals: FloatArray
    offsets: FloatArray
    # Per edge (x0, y0, x1, y1, n_x, n_y, b) as floats: one point's queries run in plain
    # Python, several times faster than numpy on a handful of edges (a controller's tick).
    _edges: tuple[tuple[float, ...], ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        start, normals, offsets = self.vertices, self.normals, self.offsets
        if not (
            isinstance(start, np.ndarray)
            and isinstance(normals, np.ndarray)
            and isinstance(offsets, np.ndarray)
            and start.ndim == 2
            and start.shape[1] == 2
            and len(start) >= 3
            and normals.shape == start.shape
            and offsets.shape == (len(start),)
        ):  # the library's form: users build polygons with the functions the docstring names
            raise ParameterTypeError(
                "ConvexPolygon takes arrays vertices (n, 2), normals (n, 2) and offsets (n,), "
                "n >= 3; build one with convex_polygon, convex_hull or rectangle"
            )
        v, n, b = start.tolist(), normals.tolist(), offsets.tolist()
        rows = tuple(
            (x0, y0, x1, y1, nx, ny, bb)
            for (x0, y0), (x1, y1), (nx, ny), bb in zip(v, v[1:] + v[:1], n, b, strict=True)
        )
        object.__setattr__(self, "_edges", rows)

    @classmethod
    def _from_ccw(cls, vertices: FloatArray) -> ConvexPolygon:
        vertices = np.array(vertices, dtype=np.float64)
        edges = following(vertices) - vertices
        lengths = np.hypot(edges[:, 0], edges[:, 1])
        normals = np.empty_like(edges)  # (e_y, −e_x)/‖e‖: the edge turned −90°
        normals[:, 0], normals[:, 1] = edges[:, 1], -edges[:, 0]
        normals /= lengths[:, None]
        offsets = np.einsum("ij,ij->i", normals, vertices)
        for array in (vertices, normals, offsets):
            array.flags.writeable = False
        return cls(vertices, normals, offsets)

    @property
    def edge_table(self) -> FloatArray:
        """One row per edge: n_x, n_y, b, t_x, t_y, a, length [m].

        (t_x, t_y) is the edge's unit direction (n turned +90°), a = t · v_i the tangential
        coordinate of its start: a point p lies beside the segment when 0 <= t · p − a <=
        length.
        """
        start = self.vertices
        edge = following(start) - start
        length = np.hypot(edge[:, 0], edge[:, 1])
        tangent = edge / length[:, None]
        along = np.einsum("ij,ij->i", tangent, start)
        return np.column_stack([self.normals, self.offsets, tangent, along, length])

    @property
    def area(self) -> float:
        """Area [m²] (shoelace formula), > 0."""
        x, y = self.vertices[:, 0], self.vertices[:, 1]
        return 0.5 * float(np.dot(x, following(y)) - np.dot(following(x), y))

    @property
    def centroid(self) -> tuple[float, float]:
        """Area centroid (x, y) [m]."""
        x, y = self.vertices[:, 0], self.vertices[:, 1]
        xn, yn = following(x), following(y)
        cross = x * yn - xn * y
        scale = 1.0 / (6.0 * self.area)
        return float(np.dot(x + xn, cross) * scale), float(np.dot(y + yn, cross) * scale)

    @property
    def xmin(self) -> float:
        """Smallest x of the polygon [m]."""
        return float(self.vertices[:, 0].min())

    @property
    def xmax(self) -> float:
        """Largest x of the polygon [m]."""
        return float(self.vertices[:, 0].max())

    @property
    def ymin(self) -> float:
        """Smallest y of the polygon [m]."""
        return float(self.vertices[:, 1].min())

    @property
    def ymax(self) -> float:
        """Largest y of the polygon [m]."""
        return float(self.vertices[:, 1].max())

    def support(self, direction_x: float, direction_y: float) -> float:
        """Support function h(d) = max over the polygon of d · p [m·‖d‖]."""
        return float(np.max(self.vertices @ np.array([direction_x, direction_y])))

    def signed_distance(self, px: ArrayLike, py: ArrayLike) -> FloatArray:
        """Signed Euclidean distance of points to the boundary, positive inside [m].

        Exact (module docstring); vectorised over broadcast arrays of x and y [m].
        """
        px, py = np.broadcast_arrays(
            np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64)
        )
        out = np.empty(px.shape)
        flat_x, flat_y, flat_out = px.reshape(-1), py.reshape(-1), out.reshape(-1)
        with np.errstate(all="ignore"):  # a non-finite point gives a non-finite distance
            for start in range(0, flat_x.size, _CHUNK):
                part = slice(start, start + _CHUNK)
                flat_out[part] = self._signed_distance_flat(flat_x[part], flat_y[part])
        return out

    def _signed_distance_flat(self, px: FloatArray, py: FloatArray) -> FloatArray:
        nx, ny, b = self.normals[:, 0:1], self.normals[:, 1:2], self.offsets[:, None]
        excess = (nx * px + ny * py - b).max(axis=0)  # > 0 outside
        distance = -excess
        outside = np.flatnonzero(excess > 0.0)
        if outside.size:
            distance[outside] = -self._outside_distance(px[outside], py[outside])
        return distance

    def _outside_distance(self, px: FloatArray, py: FloatArray) -> FloatArray:
        """Distance to the nearest edge segment (points outside) [m]."""
        start = self.vertices
        edge = following(start) - start
        length2 = np.einsum("ij,ij->i", edge, edge)
        dx = px[None, :] - start[:, 0:1]
        dy = py[None, :] - start[:, 1:2]
        along = np.clip((dx * edge[:, 0:1] + dy * edge[:, 1:2]) / length2[:, None], 0.0, 1.0)
        gap = np.hypot(dx - along * edge[:, 0:1], dy - along * edge[:, 1:2])
        return np.asarray(gap.min(axis=0), dtype=np.float64)

    def point_signed_distance(self, px: float, py: float) -> float:
        """:meth:`signed_distance` of one point (x, y) [m], as a float (NaN if not finite).

        A tick's kernel: floats in, no type checks (the vectorised method checks nothing
        either; callers validate states at their entry).
        """
        if not (math.isfinite(px) and math.isfinite(py)):
            return math.nan
        excess = max(nx * px + ny * py - b for _, _, _, _, nx, ny, b in self._edges)
        if excess <= 0.0:
            return -excess
        return -math.dist((px, py), self._nearest_on_edges(px, py))

    def nearest_point(self, px: float, py: float) -> tuple[float, float]:
        """Return the polygon's point nearest to (px, py): itself inside, else on an edge [m]."""
        if max(nx * px + ny * py - b for _, _, _, _, nx, ny, b in self._edges) <= 0.0:
            return px, py
        return self._nearest_on_edges(px, py)

    def _nearest_on_edges(self, px: float, py: float) -> tuple[float, float]:
        best, nearest = math.inf, (px, py)
        for x0, y0, x1, y1, _, _, _ in self._edges:
            ex, ey = x1 - x0, y1 - y0
            along = min(1.0, max(0.0, ((px - x0) * ex + (py - y0) * ey) / (ex * ex + ey * ey)))
            fx, fy = x0 + along * ex, y0 + along * ey
            gap = (fx - px) ** 2 + (fy - py) ** 2
            if gap < best:
                best, nearest = gap, (fx, fy)
        return nearest

    def contains(self, px: ArrayLike, py: ArrayLike) -> NDArray[np.bool_]:
        """Return True strictly inside the polygon (signed distance > 0)."""
        return self.signed_distance(px, py) > 0.0

    def transformed(self, x: float, y: float, yaw: float) -> ConvexPolygon:
        """Rotate by ``yaw`` [rad] (counter-clockwise), then move by (x, y) [m]."""
        if yaw == 0.0:  # a shift keeps the normals: only the offsets move
            shift = np.array([x, y])
            vertices = self.vertices + shift
            offsets = self.offsets + self.normals @ shift
            vertices.flags.writeable = offsets.flags.writeable = False
            return ConvexPolygon(vertices, self.normals, offsets)
        c, s = math.cos(yaw), math.sin(yaw)
        rotation = np.array([[c, -s], [s, c]])
        return ConvexPolygon._from_ccw(self.vertices @ rotation.T + np.array([x, y]))

    def mirrored(self) -> ConvexPolygon:
        """Mirror image about the x axis (y → −y): a right foot from a left one."""
        mirrored = self.vertices[::-1] * np.array([1.0, -1.0])
        return ConvexPolygon._from_ccw(mirrored)

    def grown(self, half_x: float, half_y: float, yaw: float = 0.0) -> ConvexPolygon:
        """Minkowski sum with the box [−half_x, half_x] × [−half_y, half_y] [m], turned by yaw.

        Its support function is h(d) + half_x abs(d · e_x) + half_y abs(d · e_y), with e_x, e_y the
        box's axes (yaw [rad] counter-clockwise from the world's x and y).
        """
        if half_x < 0.0 or half_y < 0.0:
            raise InvalidParameterError(
                f"box half-sizes must be >= 0 m, got half_x={half_x:g}, half_y={half_y:g}"
            )
        if half_x == 0.0 and half_y == 0.0:
            return self
        c, s = math.cos(yaw), math.sin(yaw)
        corners = np.array(
            [
                [c * sx * half_x - s * sy * half_y, s * sx * half_x + c * sy * half_y]
                for sx in (-1, 1)
                for sy in (-1, 1)
            ]
        )
        return convex_hull((self.vertices[:, None, :] + corners[None, :, :]).reshape(-1, 2))

    def ray_distance(self, origin_x: float, origin_y: float, angle: float) -> float:
        """Distance from an interior point to the boundary along the heading ``angle`` [m].

        ``angle`` is measured counter-clockwise from +x [rad]; the origin must lie inside.
        """
        dx, dy = math.cos(angle), math.sin(angle)
        rates = self.normals @ np.array([dx, dy])
        gaps = self.offsets - self.normals @ np.array([origin_x, origin_y])
        if np.any(gaps <= 0.0):
            raise InvalidParameterError(
                f"ray origin ({origin_x:g}, {origin_y:g}) m must lie inside the polygon"
            )
        ahead = rates > 0.0
        return float(np.min(gaps[ahead] / rates[ahead]))

    def overlap_depth(self, other: ConvexPolygon) -> float:
        """Smallest overlap of the two polygons' projections over all edge normals [m].

        By the separating-axis theorem, <= 0 when they are disjoint or only touch, > 0 when
        their interiors intersect.
        """
        depth = math.inf
        for normals in (self.normals, other.normals):
            mine, theirs = self.vertices @ normals.T, other.vertices @ normals.T
            overlap = np.minimum(mine.max(axis=0), theirs.max(axis=0)) - np.maximum(
                mine.min(axis=0), theirs.min(axis=0)
            )
            depth = min(depth, float(overlap.min()))
        return depth

    def to_list(self) -> list[list[float]]:
        """Vertices as a JSON-ready list of [x, y] [m], counter-clockwise."""
        return [[float(x), float(y)] for x, y in self.vertices]


def rectangle(heel: float, toe: float, width: float) -> ConvexPolygon:
    """Return the foot [heel, toe] × [−width/2, width/2] [m] in its own frame.

    Raises
    ------
    InvalidParameterError
        If ``heel`` or ``toe`` lies beyond ±:data:`MAX_COORDINATE` (1000 m, a user polygon's
        range), ``toe`` − ``heel`` or ``width`` is shorter than :data:`MIN_EDGE` (1 µm), or
        ``width`` exceeds 2 :data:`MAX_COORDINATE`.
    """
    heel = bounded_float("heel", heel, -MAX_COORDINATE, MAX_COORDINATE, "m")
    toe = bounded_float("toe", toe, -MAX_COORDINATE, MAX_COORDINATE, "m")
    width = bounded_float("width", width, MIN_EDGE, 2.0 * MAX_COORDINATE, "m")
    if toe - heel < MIN_EDGE:
        raise InvalidParameterError(
            f"toe must be at least {MIN_EDGE:g} m ahead of heel, got heel={heel:g} m, toe={toe:g} m"
        )
    half = 0.5 * width
    return ConvexPolygon._from_ccw(
        np.array([[heel, -half], [toe, -half], [toe, half], [heel, half]])
    )


def convex_hull(points: ArrayLike) -> ConvexPolygon:
    """Convex hull of points (Andrew's monotone chain); exactly collinear points dropped.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        The points (x, y) [m], finite.

    Raises
    ------
    InvalidParameterError
        If a point is not finite or not (x, y), or the hull has zero area (fewer than three
        non-collinear points).
    """
    pts = finite_array("points", points)
    if pts.ndim == 0 or pts.shape[-1] != 2:
        raise InvalidParameterError(f"points must be (x, y) pairs, shape (n, 2), got {pts.shape}")
    pts = pts.reshape(-1, 2)
    # Sorted by x then y (np.unique(axis=0) would load numpy.ma: 10 ms of every start-up).
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]
    scale = max(1.0, float(np.abs(pts).max())) if pts.size else 1.0
    eps = 1e-12 * scale * scale
    ordered = pts.tolist()  # Python floats: the same arithmetic, without numpy scalars
    lower, upper = _chain(ordered), _chain(ordered[::-1])
    hull = lower[:-1] + upper[:-1]
    # Vertices closer than MIN_EDGE give edges without a reliable direction: keep one of each.
    gap = max(MIN_EDGE, 1e-12 * scale)
    hull = [
        p
        for i, p in enumerate(hull)
        if math.hypot(p[0] - hull[i - 1][0], p[1] - hull[i - 1][1]) > gap
    ]
    if len(hull) < 3:
        raise InvalidParameterError("support polygon is degenerate (zero area)")
    polygon = ConvexPolygon._from_ccw(np.array(hull))
    if polygon.area <= eps:
        raise InvalidParameterError("support polygon is degenerate (zero area)")
    return polygon


def _chain(points: Sequence[list[float]]) -> list[list[float]]:
    """One chain of Andrew's monotone chain: left turns kept, collinear points dropped."""
    hull: list[list[float]] = []
    for p in points:
        cx, cy = p
        while len(hull) >= 2:
            (ax, ay), (bx, by) = hull[-2], hull[-1]
            if not (bx - ax) * (cy - by) - (by - ay) * (cx - bx) <= 0.0:  # a left turn at b
                break
            hull.pop()
        hull.append(p)
    return hull


def _cross(a: Sequence[float], b: Sequence[float], c: Sequence[float]) -> float:
    """Return the z of (b − a) × (c − b): > 0 for a left (counter-clockwise) turn at b."""
    return (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
