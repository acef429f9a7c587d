r"""The probability that a 2-D Gaussian point lies in a convex polygon, exactly (Owen's T).

For X ~ N(μ, Σ) in the plane and a convex polygon Q, whiten: with Σ = L Lᵀ (Cholesky),
z = L⁻¹(X − μ) ~ N(0, I) and Q maps to the convex polygon Q' with vertices w_i = L⁻¹(v_i − μ)
(still counter-clockwise: det L > 0). Fan Q' from the origin: the signed triangles (0, w_i,
w_{i+1}) sum to the indicator of Q' wherever the origin lies, so P(X ∈ Q) = Σ_i P_i with the
standard normal's mass of each signed triangle. For the edge a = w_i → b = w_{i+1}, with h the
signed distance of its line from the origin (h = (a × b)/‖b − a‖, > 0 when the triangle is
counter-clockwise) and t_a, t_b the positions of a and b along the edge's unit direction e
measured from the foot of the perpendicular (t = w · e), polar coordinates give

.. math:: P_i = \frac{1}{2\pi}\int_{u_a}^{u_b} \left(1 - e^{-h^2 / (2\cos^2 u)}\right) du
          = \frac{\angle(a, b)}{2\pi} - \left[T\!\left(h, \frac{t_b}{h}\right)
          - T\!\left(h, \frac{t_a}{h}\right)\right],

where ∠(a, b) = atan2(a × b, a · b) is the signed angle the edge subtends and
T(h, a) = (1/2π) ∫₀^a exp(−h²(1 + x²)/2)/(1 + x²) dx is Owen's T function (the substitution
x = tan u turns the first integral into it; T is odd in a and even in h, so the same formula
holds for clockwise triangles, h < 0). An edge whose line passes through the origin (h = 0)
spans no area and adds nothing. ``scipy.special.owens_t`` evaluates T to double precision, so
the probability is exact up to rounding (absolute error ~1e-15; tests/test_gaussian_polygon.py
checks it against an adaptive quadrature to 1e-9 and against 10⁶ samples).

A singular Σ (a state known exactly along some direction) has no L⁻¹: rank 1 leaves X on a
line, whose chord through Q gives P = Φ(s⁺/σ) − Φ(s⁻/σ); rank 0 gives the indicator of Q's
interior (a point on the boundary counts as outside, as the verdicts' strict inequalities).
A union of convex polygons is summed by inclusion and exclusion over their intersections
(:func:`~pushrecovery.ground.minkowski.clip`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtr, owens_t

from pushrecovery.arguments import finite_array, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import clip
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import MAX_POSE

__all__ = [
    "MAX_UNION",
    "RANK_TOLERANCE",
    "covariance_2d",
    "gaussian_mass",
    "gaussian_union_mass",
    "maximal",
    "union_terms",
]

FloatArray = NDArray[np.float64]

#: A covariance whose smaller eigenvalue is below this fraction of the larger is singular.
RANK_TOLERANCE = 1e-14
#: Most polygons :func:`gaussian_union_mass` sums (2^n − 1 intersections).
MAX_UNION = 8


def covariance_2d(name: str, cov: ArrayLike) -> FloatArray:
    """Return ``cov`` as a finite, symmetric, positive semi-definite (…, 2, 2) array.

    Raises
    ------
    InvalidParameterError
        Another shape, a non-finite entry, an asymmetric matrix (beyond 1e-12 of its largest
        entry) or a negative eigenvalue (beyond 1e-12 of the largest), naming ``name``.
    """
    require_type("name", name, str)
    array = finite_array(name, cov)
    if array.ndim < 2 or array.shape[-2:] != (2, 2):
        raise InvalidParameterError(
            f"{name} must have shape (2, 2) or (n, 2, 2), got {array.shape}"
        )
    scale = np.max(np.abs(array), axis=(-2, -1))
    if np.any(np.abs(array[..., 0, 1] - array[..., 1, 0]) > 1e-12 * scale):
        raise InvalidParameterError(f"{name} must be symmetric (a covariance matrix)")
    if array.shape == (2, 2):  # one covariance (a loop's tick): its eigenvalues in floats
        (a, b), (_, d) = array.tolist()
        smallest = np.array(0.5 * (a + d) - math.hypot(0.5 * (a - d), b))
    else:
        smallest = _eigenvalues(array)[0][..., 0]
    if np.any(smallest < -1e-12 * scale):
        raise InvalidParameterError(
            f"{name} must be positive semi-definite (a covariance), got an eigenvalue "
            f"{float(np.min(smallest)):.3g}"
        )
    return array


def gaussian_mass(mean: ArrayLike, cov: ArrayLike, polygon: ConvexPolygon) -> FloatArray:
    """Return P(X ∈ polygon) for X ~ N(mean, cov) in the plane (module docstring).

    Parameters
    ----------
    mean : array_like, shape (2,) or (n, 2)
        Means [m] (or any unit, the polygon's).
    cov : array_like, shape (2, 2) or (n, 2, 2)
        Covariance [m²]: one for every mean, or one per mean; singular allowed.
    polygon : ConvexPolygon
        The polygon, in the means' frame and unit.

    Returns
    -------
    ndarray, shape () or (n,)
        The probabilities, in [0, 1].

    Raises
    ------
    InvalidParameterError
        Means that are not finite, beyond ±1e6 m (:data:`~pushrecovery.ground.support.MAX_POSE`)
        or of other shapes, covariances not finite or of other shapes, a covariance that is not
        symmetric positive semi-definite.
    """
    require_type("polygon", polygon, ConvexPolygon)
    mu = finite_array("mean", mean, MAX_POSE, "m")  # as a foot pose: beyond, distances overflow
    if mu.ndim not in (1, 2) or mu.shape[-1] != 2:
        raise InvalidParameterError(f"mean must have shape (2,) or (n, 2), got {mu.shape}")
    sigma = covariance_2d("cov", cov)
    if sigma.ndim == 3 and (mu.ndim != 2 or len(sigma) != len(mu)):
        raise InvalidParameterError(
            f"cov of shape {sigma.shape} needs means of shape ({len(sigma)}, 2), got {mu.shape}"
        )
    if mu.ndim == 1 and sigma.ndim == 2:  # one mean, one covariance: no batch overhead
        return np.array(_one(mu, sigma, polygon))
    means = np.atleast_2d(mu)
    sigmas = np.broadcast_to(sigma, (len(means), 2, 2))
    values, _ = _eigenvalues(sigmas)
    singular = values[..., 0] <= RANK_TOLERANCE * values[..., 1]
    result = np.empty(len(means))
    regular = ~singular
    if regular.any():
        result[regular] = _regular(means[regular], sigmas[regular], polygon.vertices)
    for k in np.flatnonzero(singular).tolist():
        result[k] = _singular(means[k], sigmas[k], polygon)
    return result.reshape(mu.shape[:-1])


def gaussian_union_mass(
    mean: ArrayLike, cov: ArrayLike, polygons: Sequence[ConvexPolygon]
) -> FloatArray:
    """Return P(X ∈ ⋃ polygons) by inclusion and exclusion (at most :data:`MAX_UNION`).

    The sum of :func:`union_terms`; arguments and result as :func:`gaussian_mass`.
    """
    terms = union_terms(polygons)
    total = np.zeros(np.shape(finite_array("mean", mean))[:-1])
    for sign, polygon in terms:
        total = total + sign * gaussian_mass(mean, cov, polygon)
    return np.clip(total, 0.0, 1.0)


def union_terms(polygons: Sequence[ConvexPolygon]) -> tuple[tuple[float, ConvexPolygon], ...]:
    """Return the inclusion–exclusion terms of a union of convex polygons: (sign, polygon).

    The polygons no other one contains (:func:`maximal`, at most :data:`MAX_UNION`), then
    their intersections two by two, three by three …, with signs +, −, + …; the mass of the
    union is the signed sum of the terms' masses. Empty intersections are left out.
    """
    kept = maximal(polygons)
    if len(kept) > MAX_UNION:
        raise InvalidParameterError(
            f"polygons: at most {MAX_UNION} that no other contains, got {len(kept)}"
        )
    terms: list[tuple[float, ConvexPolygon]] = []
    for size in range(1, len(kept) + 1):
        for group in itertools.combinations(kept, size):
            common: ConvexPolygon | None = group[0]
            for other in group[1:]:
                common = None if common is None else clip(common, other)
            if common is not None:
                terms.append(((-1.0) ** (size + 1), common))
    return tuple(terms)


def maximal(polygons: Sequence[ConvexPolygon]) -> list[ConvexPolygon]:
    """Return the polygons that no other one of the list contains (of equal ones, the first)."""
    require_type("polygons", polygons, (list, tuple))
    for k, polygon in enumerate(polygons):
        require_type(f"polygons[{k}]", polygon, ConvexPolygon)
    kept: list[ConvexPolygon] = []
    for i, polygon in enumerate(polygons):
        inside = any(
            j != i
            and _contains_all(other, polygon)
            and (not _contains_all(polygon, other) or j < i)
            for j, other in enumerate(polygons)
        )
        if not inside:
            kept.append(polygon)
    return kept


def _contains_all(outer: ConvexPolygon, inner: ConvexPolygon) -> bool:
    scale = max(1.0, float(np.max(np.abs(inner.vertices))))
    slack = inner.vertices @ outer.normals.T - outer.offsets
    return bool(np.all(slack <= 1e-12 * scale))


def _eigenvalues(cov: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Eigenvalues (ascending, last axis) and the unit eigenvector of the larger, of 2 × 2s."""
    a, b, d = cov[..., 0, 0], 0.5 * (cov[..., 0, 1] + cov[..., 1, 0]), cov[..., 1, 1]
    mid, half = 0.5 * (a + d), np.hypot(0.5 * (a - d), b)
    values = np.stack([mid - half, mid + half], axis=-1)
    # The larger's eigenvector: (b, λ − a) or (λ − d, b), whichever is longer.
    big = values[..., 1]
    first = np.stack([b, big - a], axis=-1)
    second = np.stack([big - d, b], axis=-1)
    vector = np.where(
        (np.hypot(*np.moveaxis(first, -1, 0)) >= np.hypot(*np.moveaxis(second, -1, 0)))[..., None],
        first,
        second,
    )
    norm = np.hypot(*np.moveaxis(vector, -1, 0))[..., None]
    vector = np.divide(vector, norm, out=np.tile([1.0, 0.0], (*vector.shape[:-1], 1)),
                       where=norm > 0.0)  # fmt: skip
    return values, vector


def _one(mean: FloatArray, sigma: FloatArray, polygon: ConvexPolygon) -> float:
    """:func:`gaussian_mass` of one mean and covariance, in floats (the same sum)."""
    (a, b), (_, d) = sigma.tolist()
    half = math.hypot(0.5 * (a - d), b)
    if 0.5 * (a + d) - half <= RANK_TOLERANCE * (0.5 * (a + d) + half):
        return _singular(mean, sigma, polygon)
    # Cholesky of [[a, b], [b, d]]: L = [[l0, 0], [l1, l2]].
    l0 = math.sqrt(a)
    l1 = b / l0
    l2 = math.sqrt(d - l1 * l1)
    offsets = polygon.vertices - mean
    z0 = offsets[:, 0] / l0
    z1 = (offsets[:, 1] - l1 * z0) / l2
    x0, y0 = z0.tolist(), z1.tolist()
    x1, y1 = x0[1:] + x0[:1], y0[1:] + y0[:1]
    angles: list[float] = []
    heights: list[float] = []
    along: list[float] = []
    for ax, ay, bx, by in zip(x0, y0, x1, y1, strict=True):
        cross = ax * by - ay * bx
        if cross == 0.0:
            continue
        ex, ey = bx - ax, by - ay
        length = math.hypot(ex, ey)
        h = cross / length
        angles.append(math.atan2(cross, ax * bx + ay * by))
        heights += (h, h)
        along += ((bx * ex + by * ey) / length / h, (ax * ex + ay * ey) / length / h)
    if not angles:
        return 0.0
    t = owens_t(heights, along).tolist()  # T(h, t_b/h), T(h, t_a/h) of each edge
    total = sum(angles) / (2.0 * math.pi) - sum(t[0::2]) + sum(t[1::2])
    return min(max(total, 0.0), 1.0)


def _regular(means: FloatArray, sigmas: FloatArray, vertices: FloatArray) -> FloatArray:
    """Owen's-T sum of the whitened fan (module docstring), for full-rank covariances."""
    lower = np.linalg.cholesky(sigmas)  # (n, 2, 2)
    offsets = vertices[None, :, :] - means[:, None, :]  # (n, k, 2)
    # L⁻¹ d for a lower-triangular L: forward substitution.
    z0 = offsets[..., 0] / lower[:, None, 0, 0]
    z1 = (offsets[..., 1] - lower[:, None, 1, 0] * z0) / lower[:, None, 1, 1]
    a = np.stack([z0, z1], axis=-1)
    b = np.roll(a, -1, axis=1)
    cross = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    dot = np.einsum("nkj,nkj->nk", a, b)
    edge = b - a
    length = np.hypot(edge[..., 0], edge[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        h = cross / length
        t_a = np.einsum("nkj,nkj->nk", a, edge) / length
        t_b = np.einsum("nkj,nkj->nk", b, edge) / length
        terms = np.arctan2(cross, dot) / (2.0 * math.pi) - (
            owens_t(h, t_b / h) - owens_t(h, t_a / h)
        )
    terms = np.where(cross == 0.0, 0.0, terms)
    return np.clip(terms.sum(axis=1), 0.0, 1.0)


def _singular(mean: FloatArray, sigma: FloatArray, polygon: ConvexPolygon) -> float:
    """P for a covariance of rank 1 (a chord of the polygon) or 0 (the interior's indicator)."""
    values, vectors = _eigenvalues(sigma)
    if values[1] <= 0.0:
        return float(polygon.point_signed_distance(float(mean[0]), float(mean[1])) > 0.0)
    sd, direction = math.sqrt(float(values[1])), vectors
    # The line mean + s·direction inside every half-plane n · p <= b.
    rate = polygon.normals @ direction
    room = polygon.offsets - polygon.normals @ mean
    low, high = -math.inf, math.inf
    for r, slack in zip(rate.tolist(), room.tolist(), strict=True):
        if r > 0.0:
            high = min(high, slack / r)
        elif r < 0.0:
            low = max(low, slack / r)
        elif slack <= 0.0:
            return 0.0  # parallel to an edge, on or outside it
    if not low < high:
        return 0.0
    return float(ndtr(high / sd) - ndtr(low / sd))
