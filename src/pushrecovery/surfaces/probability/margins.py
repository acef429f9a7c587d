r"""Quantiles of a margin of an uncertain state: how close to the edge it may be, and how often.

The CoP margin (Eq. 4) and the CMP margin (corrected Eq. 15) are the signed distance M of the
capture point ξ to their region R (+ inside). With ξ ~ N(μ, Σ) at the command (after the
latency, :mod:`.latency`), the margin's distribution is ξ's mass on offset regions:

- on the line, R = [lo, hi] of half-width h: P(M > q) = Φ((hi − q − μ)/σ) − Φ((lo + q − μ)/σ)
  for q < h (for q < 0 the interval grown by −q), 0 beyond;
- on the plane, for q >= 0, {M > q} is R eroded by q, the convex polygon of the half-planes
  n_i · x <= b_i − q (exact); for q < 0 it is R ⊕ disk(−q), whose round corners lie between
  R ⊕ the regular k-gon inscribed in the disk and R ⊕ the one circumscribed about it, so its
  mass is bracketed (k = ``SIDES``).

A quantile q_α solves P(M <= q_α) = α (Brent's method to 1e-12 m); on the plane below zero it is
solved for both brackets, the middle reported and half their gap added to ``error``. A zero
covariance gives the certain margin at every level.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import brentq
from scipy.special import ndtr

from pushrecovery.arguments import finite_array, finite_vector, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.gaussian import gaussian_mass
from pushrecovery.ground.minkowski import clip_halfplanes, minkowski_sum, regular_polygon
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.probability.inputs import StateGaussian
from pushrecovery.surfaces.probability.latency import delayed_capture_point

__all__ = ["SIDES", "MarginQuantiles", "margin_quantiles"]

#: Sides of the polygons that bracket a disk in the plane's grown regions.
SIDES = 64
#: Brent's tolerance on a quantile [m].
TOLERANCE = 1e-12


@dataclass(frozen=True, slots=True)
class MarginQuantiles:
    """Quantiles of a margin of an uncertain state (:func:`margin_quantiles`).

    Attributes
    ----------
    region : {"cop", "cmp"}
        The margin: to the CoP region (Eq. 4) or the CMP region (corrected Eq. 15).
    levels : tuple of float
        The probabilities α (dimensionless, in (0, 1)).
    values : tuple of float
        q_α with P(margin <= q_α) = α [m], + inside the region.
    error : float
        Bound on each value's numerical error [m] (Brent's tolerance; on the plane below zero
        also half the bracket of the grown region's round corners).
    """

    region: str
    levels: tuple[float, ...]
    values: tuple[float, ...]
    error: float


def margin_quantiles(
    state: StateGaussian,
    params: BodyParams,
    levels: Sequence[float] = (0.01, 0.05, 0.5, 0.95, 0.99),
    *,
    region: str = "cop",
    support: Support | None = None,
    latency: float = 0.0,
    cop: ArrayLike | None = None,
) -> MarginQuantiles:
    """Return quantiles of the CoP or CMP margin of an uncertain state (module docstring).

    Parameters
    ----------
    state : StateGaussian
        The state estimate, on the line (x, ẋ) or the plane (x, y, ẋ, ẏ) [m, m/s].
    params : BodyParams
        The body.
    levels : sequence of float
        The probabilities α, each in (0, 1).
    region : {"cop", "cmp"}
        Which margin.
    support : Support, optional
        The plane's support (default double support on the default feet).
    latency : float
        Loop latency [s] (one value), the CoP held at ``cop`` meanwhile.
    cop : array_like, optional
        The CoP held during the latency [m] (default the middle of the CoP region).

    Raises
    ------
    InvalidParameterError
        A level outside (0, 1), an unknown region, a support for a line state, the latency's
        and ``cop``'s checks.
    """
    require_type("state", state, StateGaussian)
    require_type("params", params, BodyParams)
    alphas = finite_array("levels", levels)
    if alphas.ndim != 1 or alphas.size == 0 or np.any((alphas <= 0.0) | (alphas >= 1.0)):
        raise InvalidParameterError(f"levels must be probabilities in (0, 1), got {levels!r}")
    if not isinstance(region, str) or region not in ("cop", "cmp"):
        raise InvalidParameterError(f"region must be 'cop' or 'cmp', got {region!r:.40}")
    if support is not None and not state.plane:
        raise InvalidParameterError("support applies to a plane state (x, y, xdot, ydot)")
    dims = 2 if state.plane else 1
    omega = params.omega
    rows = np.hstack([np.eye(dims), np.eye(dims) / omega])
    if state.plane:
        support = Support.from_params(params) if support is None else support
        require_type("support", support, Support)
        polygon = support.polygon if region == "cop" else cmp_polygon(support, params)
        middle = np.array(support.polygon.centroid)
    else:
        interval = cop_region(params) if region == "cop" else cmp_region(params)
        foot = cop_region(params)
        middle = np.array([0.5 * (foot.lower + foot.upper)])
    held = middle if cop is None else finite_vector("cop", cop, dims, unit="m")
    mean, cov = delayed_capture_point(rows @ state.mean, rows @ state.cov @ rows.T, omega,
                                      latency, held)  # fmt: skip
    if state.plane:
        values, error = _plane(mean, cov, polygon, alphas)
    else:
        values, error = _line(float(mean[0]), float(cov[0, 0]), interval.lower, interval.upper,
                              alphas)  # fmt: skip
    return MarginQuantiles(
        region, tuple(float(a) for a in alphas), tuple(float(v) for v in values), error
    )


def _line(
    mu: float, variance: float, low: float, high: float, alphas: np.ndarray
) -> tuple[list[float], float]:
    """Quantiles of min(ξ − low, high − ξ) for ξ ~ N(mu, variance)."""
    half = 0.5 * (high - low)
    if variance <= 0.0:
        return [min(mu - low, high - mu)] * len(alphas), 0.0
    sd = math.sqrt(variance)

    def cdf(q: float) -> float:
        if q >= half:
            return 1.0
        return 1.0 - float(ndtr((high - q - mu) / sd) - ndtr((low + q - mu) / sd))

    start = -(abs(mu - 0.5 * (low + high)) + half + 40.0 * sd)
    return [_solve(cdf, a, start, half) for a in alphas], TOLERANCE


def _plane(
    mean: np.ndarray, cov: np.ndarray, polygon: ConvexPolygon, alphas: np.ndarray
) -> tuple[list[float], float]:
    """Quantiles of the signed distance of ξ ~ N(mean, cov) to a convex polygon."""
    if np.max(np.abs(cov)) == 0.0:
        return [float(polygon.point_signed_distance(*mean))] * len(alphas), 0.0
    deepest = _deepest(polygon)  # no margin exceeds the inradius

    def cdf(q: float, grown: Callable[[float], ConvexPolygon | None]) -> float:
        if q >= deepest:
            return 1.0
        shape = grown(q)
        return 1.0 if shape is None else 1.0 - float(gaussian_mass(mean, cov, shape))

    def eroded(q: float) -> ConvexPolygon | None:
        return clip_halfplanes(polygon, polygon.normals, polygon.offsets - q)

    def disk(radius: float) -> Callable[[float], ConvexPolygon | None]:
        def grow(q: float) -> ConvexPolygon | None:
            if q >= 0.0:
                return eroded(q)
            shape = regular_polygon(-q * radius, SIDES)
            return minkowski_sum([(1.0, polygon), (1.0, shape)])

        return grow

    spread = math.sqrt(float(np.max(np.linalg.eigvalsh(cov))))
    start = -(float(abs(polygon.point_signed_distance(*mean))) + deepest + 40.0 * spread)
    inner = [_solve(lambda q: cdf(q, disk(1.0)), a, start, deepest) for a in alphas]
    outer_radius = 1.0 / math.cos(math.pi / SIDES)
    outer = [_solve(lambda q: cdf(q, disk(outer_radius)), a, start, deepest) for a in alphas]
    gap = max(abs(i - o) for i, o in zip(inner, outer, strict=True))
    return [0.5 * (i + o) for i, o in zip(inner, outer, strict=True)], 0.5 * gap + TOLERANCE


def _deepest(polygon: ConvexPolygon) -> float:
    """Return the largest signed distance of any point to the polygon: its inradius [m] (LP)."""
    from scipy.optimize import linprog

    # max r s.t. n_i · c + r <= b_i: the largest disk inside.
    normals, offsets = polygon.normals, polygon.offsets
    found = linprog(
        c=[0.0, 0.0, -1.0],
        A_ub=np.column_stack([normals, np.ones(len(offsets))]),
        b_ub=offsets,
        bounds=[(None, None), (None, None), (0.0, None)],
        method="highs",
    )
    return float(-found.fun) if found.success else 0.0


def _solve(cdf: Callable[[float], float], alpha: float, low: float, high: float) -> float:
    """Return q with cdf(q) = alpha on [low, high] (cdf(low) < alpha <= cdf(high))."""
    if cdf(low) >= alpha:
        return low
    return float(brentq(lambda q: cdf(q) - alpha, low, high, xtol=TOLERANCE))
