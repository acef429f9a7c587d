r"""Minkowski algebra of convex polygons: weighted sums, intersections, regular polygons.

The capture regions of several steps (:mod:`pushrecovery.surfaces.n_step`) are
weighted Minkowski sums ⊕_k w_k P_k of convex polygons: their support function is the weighted
sum of support functions, h(d) = Σ_k w_k h_{P_k}(d) for w_k >= 0 (a negative weight is the
point reflection −P_k scaled by abs(w_k)). A sum is built exactly by merging the terms' edges in
order of angle (de Berg et al., *Computational Geometry*, Sec. 13.3), O(total edges log).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    finite_vector,
    positive_float,
    require_type,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.polygon import ConvexPolygon, following

__all__ = [
    "Shape",
    "clip",
    "decompose",
    "minkowski_sum",
    "regular_polygon",
]

FloatArray = NDArray[np.float64]
#: A term of a sum: a convex polygon, or counter-clockwise vertices of shape (n, 2) that may be
#: degenerate (a point, n = 1; a segment, n = 2; the hip's box when one axis has no torque).
Shape = ConvexPolygon | FloatArray


def _vertices(shape: Shape) -> FloatArray:
    return shape.vertices if isinstance(shape, ConvexPolygon) else np.asarray(shape, np.float64)


def _checked_terms(terms: object, *, non_negative: bool = False) -> list[tuple[float, Shape]]:
    """Return ``terms`` as (weight, shape) pairs, or raise naming the bad term.

    Weights are finite (>= 0 with ``non_negative``); a shape is a :class:`ConvexPolygon` or
    finite vertices of shape (n, 2), n >= 1.
    """
    if not isinstance(terms, list | tuple):
        raise ParameterTypeError(
            f"terms must be a list of (weight, shape) pairs, got {type(terms).__name__}"
        )
    checked: list[tuple[float, Shape]] = []
    for k, term in enumerate(terms):
        if not (isinstance(term, list | tuple) and len(term) == 2):
            raise ParameterTypeError(f"terms[{k}] must be a (weight, shape) pair, got {term!r:.60}")
        weight = finite_float(f"terms[{k}] weight", term[0])
        if non_negative and weight < 0.0:
            raise InvalidParameterError(f"terms[{k}] weight must be >= 0, got {weight:g}")
        shape = term[1]
        if not isinstance(shape, ConvexPolygon):
            shape = finite_array(f"terms[{k}] shape", shape)
            if shape.ndim != 2 or shape.shape[1] != 2 or len(shape) < 1:
                raise InvalidParameterError(
                    f"terms[{k}] shape must be a ConvexPolygon or vertices of shape (n, 2), "
                    f"got shape {shape.shape}"
                )
        checked.append((weight, shape))
    return checked


#: Edges shorter than this fraction of the sum's size are dropped (rounding of collinear
#: edges from different terms; the polygon type needs no repeated or collinear vertices).
_RELATIVE_EDGE = 1e-12


def minkowski_sum(
    terms: Sequence[tuple[float, Shape]], offset: tuple[float, float] | FloatArray = (0.0, 0.0)
) -> ConvexPolygon:
    """Return offset ⊕ w_1 P_1 ⊕ ... ⊕ w_n P_n for convex polygons P_k and real weights w_k.

    Terms of weight 0 vanish; a negative weight gives abs(w) (−P). At least one term must have
    a non-zero weight.

    Parameters
    ----------
    terms : sequence of (float, Shape)
        Weights (dimensionless) and convex shapes [m].
    offset : (float, float)
        A translation added to the sum [m].

    Returns
    -------
    ConvexPolygon
        The sum, counter-clockwise, collinear vertices merged.

    Raises
    ------
    ParameterTypeError
        If ``terms`` is not a list of (weight, shape) pairs.
    InvalidParameterError
        A weight that is not finite, a shape that is not a polygon or finite (n, 2) vertices,
        an ``offset`` that is not a finite (x, y), no term of non-zero weight, or a sum of
        zero area.
    """
    return minkowski_sum_unchecked(
        _checked_terms(terms), finite_vector("offset", offset, 2, unit="m")
    )


def minkowski_sum_unchecked(
    terms: Sequence[tuple[float, Shape]], offset: tuple[float, float] | FloatArray = (0.0, 0.0)
) -> ConvexPolygon:
    """:func:`minkowski_sum` of checked terms (the library's own calls)."""
    starts = []
    edges = []
    for weight, polygon in terms:
        if not math.isfinite(weight):
            raise InvalidParameterError(f"Minkowski weights must be finite, got {weight!r}")
        if weight == 0.0:
            continue
        vertices = weight * _vertices(polygon)  # a point reflection keeps the orientation
        step = following(vertices) - vertices
        lowest = int(np.lexsort((vertices[:, 0], vertices[:, 1]))[0])  # lowest, then leftmost
        starts.append(vertices[lowest])
        edges.append(following(step, lowest))
    if not edges:
        raise InvalidParameterError("a Minkowski sum needs at least one term of non-zero weight")
    every = np.concatenate(edges)
    every = every[np.hypot(every[:, 0], every[:, 1]) > 0.0]  # points add no edge
    # From the lowest-leftmost vertex, a convex polygon's edge angles rise through [0, 2π).
    angle = np.mod(np.arctan2(every[:, 1], every[:, 0]), 2.0 * math.pi)
    order = np.argsort(angle, kind="stable")
    every, angle = every[order], angle[order]
    # Parallel edges of different terms add up to one edge (fewer vertices to clean).
    groups = np.flatnonzero(np.concatenate([[True], np.diff(angle) > 1e-13]))
    every = np.add.reduceat(every, groups, axis=0)
    start = np.sum(starts, axis=0) + np.asarray(offset, dtype=np.float64)
    vertices = start + np.concatenate([np.zeros((1, 2)), np.cumsum(every[:-1], axis=0)])
    return _cleaned(vertices)


def stacked_shapes(
    terms: Sequence[tuple[float, Shape]],
) -> tuple[FloatArray, NDArray[np.int64], FloatArray]:
    """Return the terms as the compiled kernels take them: (shapes (K, M, 2), counts, weights)."""
    shapes = [_vertices(shape) for _, shape in terms]
    counts = np.array([len(v) for v in shapes], dtype=np.int64)
    stacked = np.zeros((len(shapes), int(counts.max()), 2))
    for k, vertices in enumerate(shapes):
        stacked[k, : len(vertices)] = vertices
    weights = np.array([w for w, _ in terms], dtype=np.float64)
    if not math.isfinite(float(weights.sum())):
        raise InvalidParameterError(f"Minkowski weights must be finite, got {weights.tolist()}")
    return stacked, counts, weights


def minkowski_sum_loop(
    terms: Sequence[tuple[float, Shape]], offset: tuple[float, float] | FloatArray = (0.0, 0.0)
) -> FloatArray:
    """Return the vertex loop of :func:`minkowski_sum`, compiled, without building a polygon."""
    from pushrecovery.kernels.polygons import minkowski_loop

    stacked, counts, weights = stacked_shapes(terms)
    return np.asarray(
        minkowski_loop(stacked, counts, weights, np.asarray(offset, dtype=np.float64))
    )


def _cleaned(vertices: FloatArray) -> ConvexPolygon:
    """Drop repeated and collinear vertices of a convex counter-clockwise vertex loop.

    Repeats first (a vertex equal to the next one), then vertices where the loop does not
    turn: a repeat's twin does not turn either, and must not be dropped with it.
    """
    scale = max(1.0, float(np.abs(vertices).max()))
    step = following(vertices) - vertices
    vertices = vertices[np.hypot(step[:, 0], step[:, 1]) > _RELATIVE_EDGE * scale]
    for _ in range(len(vertices)):  # each pass drops every flat vertex it sees; usually one
        if len(vertices) < 3:
            break
        before = vertices - following(vertices, -1)
        after = following(vertices) - vertices
        turn = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]
        keep = turn > _RELATIVE_EDGE * scale * scale
        if keep.all():
            break
        vertices = vertices[keep]
    if len(vertices) < 3:
        raise InvalidParameterError("the Minkowski sum has zero area")
    return ConvexPolygon._from_ccw(np.ascontiguousarray(vertices))


def clip(polygon: ConvexPolygon, window: ConvexPolygon) -> ConvexPolygon | None:
    """Intersection of two convex polygons, or None when it has no area [m].

    Raises
    ------
    ParameterTypeError
        If ``polygon`` or ``window`` is not a :class:`ConvexPolygon`.
    """
    require_type("polygon", polygon, ConvexPolygon)
    require_type("window", window, ConvexPolygon)
    return clip_halfplanes(polygon, window.normals, window.offsets)


def clip_halfplanes(
    polygon: ConvexPolygon, normals: FloatArray, offsets: FloatArray
) -> ConvexPolygon | None:
    """``polygon`` ∩ {p : n_i · p <= b_i for all i}, or None when it has no area [m].

    Sutherland-Hodgman: the polygon cut by one half-plane after the other.
    """
    vertices = polygon.vertices
    scale = max(1.0, float(np.abs(vertices).max()))
    normals, offsets = np.asarray(normals), np.asarray(offsets)
    cutting = np.any(vertices @ normals.T > offsets, axis=0)
    if not cutting.any():
        return polygon
    from pushrecovery.kernels.polygons import clip_loop  # compiled: hundreds of vertex visits

    points = clip_loop(
        np.ascontiguousarray(vertices),
        np.ascontiguousarray(normals[cutting]),
        np.ascontiguousarray(offsets[cutting]),
    )
    if len(points) < 3:
        return None
    area = 0.5 * float(
        np.dot(points[:, 0], following(points[:, 1]))
        - np.dot(following(points[:, 0]), points[:, 1])
    )
    if area <= 1e-12 * scale * scale:
        return None
    try:
        return _cleaned(points)
    except InvalidParameterError:
        return None


#: Most vertices of a :func:`regular_polygon` (its edges then lie within 5e-10 of the circle).
MAX_SIDES = 100_000


def regular_polygon(
    radius: float, sides: int, centre: tuple[float, float] = (0.0, 0.0), phase: float = 0.0
) -> ConvexPolygon:
    """Return the regular polygon of ``sides`` vertices on the circle of ``radius`` [m].

    Vertices at angles phase + 2πk/sides [rad] about ``centre``; its edges come within
    radius (1 − cos(π/sides)) of the circle.

    Raises
    ------
    InvalidParameterError
        If ``radius`` is not finite and > 0, ``sides`` is not a whole number in
        [3, :data:`MAX_SIDES`], ``centre`` is not finite or ``phase`` not in [-100, 100] rad.
    """
    radius = positive_float("radius", radius, "m")
    sides = whole_number("sides", sides, 3, MAX_SIDES)
    middle = finite_vector("centre", centre, 2, unit="m")
    phase = bounded_float("phase", phase, -100.0, 100.0, "rad")  # beyond, the angles round
    angle = phase + 2.0 * math.pi * np.arange(sides) / sides
    vertices = np.column_stack([np.cos(angle), np.sin(angle)]) * radius + middle
    return ConvexPolygon._from_ccw(vertices)


def decompose(
    point: FloatArray,
    terms: Sequence[tuple[float, Shape]],
    offset: FloatArray,
    total: ConvexPolygon,
) -> tuple[list[FloatArray], float]:
    """Points p_k of the shapes with offset + Σ w_k p_k = ``point``, as central as possible.

    ``total`` is :func:`minkowski_sum` of the same terms and offset, weights >= 0. With c_k
    the shapes' vertex means and c = offset + Σ w_k c_k, the ray from c through the point
    leaves ``total`` at b = c + λ u on an edge of outward normal n; b is offset + Σ w_k v_k with
    v_k on the face of shape k that maximises n · p (a vertex, or along the edge for the
    shapes that have one parallel to n). The point is the fraction s = ‖point − c‖ / λ of the
    way, so p_k = (1 − s) c_k + s v_k lies in shape k (convexity) and keeps the same relative
    depth in every shape: no term is pushed to its edge before the others.

    Returns
    -------
    (list of ndarray, float)
        The points p_k [m] (the centre c_k for zero weights) and s (> 1: the point is outside
        ``total``, and the points are those of the boundary point b).

    Raises
    ------
    ParameterTypeError
        If ``terms`` is not a list of (weight, shape) pairs or ``total`` not a
        :class:`ConvexPolygon`.
    InvalidParameterError
        A negative or non-finite weight, a shape that is not a polygon or finite (n, 2)
        vertices, or a ``point`` or ``offset`` that is not a finite (x, y).
    """
    point = finite_vector("point", point, 2, unit="m")
    terms = _checked_terms(terms, non_negative=True)
    offset = finite_vector("offset", offset, 2, unit="m")
    require_type("total", total, ConvexPolygon)
    return decompose_unchecked(point, terms, offset, total)


def decompose_unchecked(
    point: FloatArray,
    terms: Sequence[tuple[float, Shape]],
    offset: FloatArray,
    total: ConvexPolygon,
) -> tuple[list[FloatArray], float]:
    """:func:`decompose` of checked arguments."""
    shapes = [_vertices(shape) for _, shape in terms]
    weights = [float(weight) for weight, _ in terms]
    centres = [v.mean(axis=0) for v in shapes]
    centre = np.asarray(offset, np.float64) + sum(
        (w * c for w, c in zip(weights, centres, strict=True)), np.zeros(2)
    )
    gap = np.asarray(point, np.float64) - centre
    distance = math.hypot(*gap)
    if distance == 0.0:
        return centres, 0.0
    u = gap / distance
    rates = total.normals @ u
    room = total.offsets - total.normals @ centre
    ahead = rates > 0.0
    ratios = np.where(ahead, room / np.where(ahead, rates, 1.0), np.inf)
    edge = int(np.argmin(ratios))
    reach = float(ratios[edge])
    normal = total.normals[edge]
    tangent = np.array([-normal[1], normal[0]])
    boundary = centre + reach * u
    scale = max(1.0, float(np.abs(total.vertices).max()))
    faces = []
    for w, vertices in zip(weights, shapes, strict=True):
        if w == 0.0:
            faces.append((vertices.mean(axis=0), 0.0))
            continue
        height = vertices @ normal
        top = vertices[height >= height.max() - 1e-12 * scale / w]
        along = top @ tangent
        faces.append((top[int(np.argmin(along))], float(along.max() - along.min())))
    start = np.asarray(offset, np.float64) + sum(
        (w * f for w, (f, _) in zip(weights, faces, strict=True)), np.zeros(2)
    )
    left = float((boundary - start) @ tangent)
    tops = []
    for w, (face, length) in zip(weights, faces, strict=True):
        move = min(max(left, 0.0), w * length)
        left -= move
        tops.append(face + (move / w if w else 0.0) * tangent)
    share = distance / reach
    s = min(share, 1.0)
    points = [(1.0 - s) * c + s * t for c, t in zip(centres, tops, strict=True)]
    return points, share
