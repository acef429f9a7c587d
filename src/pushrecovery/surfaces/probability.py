r"""The strategy a state needs, as probabilities: a Gaussian state estimate and a loop latency.

Every verdict of :mod:`pushrecovery.surfaces.classify` depends on the state only through the
capture point ξ = x + ẋ/ω, and is the first region that holds ξ: the CoP region (ankle,
Eq. 4), the CMP region (hip, corrected Eq. 15), the N-step regions C_N (step), else fall. ξ is
linear in the state, so a Gaussian state estimate gives a Gaussian ξ,

.. math:: ξ \sim N(A μ, A Σ A^T), \qquad A = [I \;\; I/ω],

and the probability of each verdict is the Gaussian's mass on a difference of regions:
P(ankle) = P(ξ ∈ R_0), P(level ≤ L) = P(ξ ∈ R_0 ∪ … ∪ R_L) with R_1 the CMP region and
R_{1+k} the k-step regions, P(level L) the difference of two such unions, P(fall) = 1 −
P(ξ ∈ ⋃ R). On the sagittal line the regions are intervals and the masses normal CDFs; on
the ground plane they are convex polygons (two per N from double support) and the masses are
:func:`~pushrecovery.ground.gaussian.gaussian_union_mass` (Owen's T, exact to rounding).

**Latency.** A state measured τ seconds before the command acts has moved on: with the CoP
held at p in between, the LIPM (Eq. 23, ẍ = ω²(x − p)) gives ξ̇ = ẋ + ẍ/ω = ω(ξ − p), so

.. math:: ξ(τ) = p + (ξ(0) − p)\, e^{ωτ}:

the capture point's offset from the held CoP grows by e^{ωτ} (mean and standard deviation
alike; docs/uncertainty.md). p defaults to the middle of the CoP region (the foot's middle on
the line, the support polygon's centroid on the plane). A latency known as a range [τ⁻, τ⁺]
(uniform) is integrated over with Gauss–Legendre nodes; the reported ``error`` is the change
from half the nodes.

Exact, not sampled: the probabilities carry only rounding (``error`` 0) for a fixed latency.
A zero covariance gives the certain verdict (the indicator of the region, strictly inside).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtr

from pushrecovery.arguments import finite_array, finite_vector, non_negative_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.gaussian import covariance_2d, gaussian_union_mass, maximal
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.step_regions import StepRegions, sagittal_step_interval
from pushrecovery.surfaces.strategy import Strategy

__all__ = [
    "LATENCY_NODES",
    "MAX_LATENCY_GROWTH",
    "StateGaussian",
    "VerdictProbabilities",
    "delayed_capture_point",
    "verdict_probabilities",
]

FloatArray = NDArray[np.float64]

#: Gauss–Legendre nodes over a latency range.
LATENCY_NODES = 16
#: Largest e^{ωτ} a latency may give (beyond it the state is long gone: refused).
MAX_LATENCY_GROWTH = 1e6


@dataclass(frozen=True, slots=True, eq=False)
class StateGaussian:
    """A CoM state known up to a Gaussian error.

    Attributes
    ----------
    mean : ndarray, shape (2,) or (4,)
        (x, ẋ) on the sagittal line, or (x, y, ẋ, ẏ) on the ground plane [m, m/s]: the CoM
        relative to the stance ankle (line) or in the ground frame (plane), x forward, y left.
    cov : ndarray, shape (2, 2) or (4, 4)
        Its covariance [m², m²/s, m²/s²], symmetric positive semi-definite (zero: known exactly).
    """

    mean: FloatArray
    cov: FloatArray

    def __post_init__(self) -> None:
        mean = finite_array("mean", self.mean)
        if mean.shape not in ((2,), (4,)):
            raise InvalidParameterError(
                "mean must be (x, xdot) or (x, y, xdot, ydot): shape (2,) or (4,), "
                f"got {mean.shape}"
            )
        cov = finite_array("cov", self.cov)
        n = len(mean)
        if cov.shape != (n, n):
            raise InvalidParameterError(
                f"cov must have shape ({n}, {n}) for this mean, got {cov.shape}"
            )
        scale = float(np.max(np.abs(cov))) if cov.size else 0.0
        if np.any(np.abs(cov - cov.T) > 1e-12 * scale):
            raise InvalidParameterError("cov must be symmetric (a covariance matrix)")
        smallest = float(np.linalg.eigvalsh(0.5 * (cov + cov.T))[0])
        if smallest < -1e-12 * scale:
            raise InvalidParameterError(
                "cov must be positive semi-definite (a covariance), got an eigenvalue "
                f"{smallest:.3g}"
            )
        for name, array in (("mean", mean), ("cov", cov)):
            array.flags.writeable = False
            object.__setattr__(self, name, array)

    @property
    def plane(self) -> bool:
        """True for a state on the ground plane (4 numbers)."""
        return len(self.mean) == 4


@dataclass(frozen=True, slots=True)
class VerdictProbabilities:
    """The probability of each verdict of one uncertain state (:func:`verdict_probabilities`).

    Attributes
    ----------
    ankle, hip : float
        P(the ankle suffices), P(the hip is needed and suffices).
    steps : tuple of float
        P(exactly k steps are needed), k = 1 … ``max_steps``.
    fall : float
        P(no strategy of the model captures the state).
    capture_point_mean : tuple of float
        Mean of ξ at the command (after the latency) [m]: 1 or 2 numbers.
    capture_point_cov : tuple of tuple of float
        Its covariance [m²].
    error : float
        Bound on the numerical error of each probability: 0 when exact up to rounding
        (a fixed latency), else the change from half the latency nodes.
    method : str
        ``exact`` or ``latency quadrature``.
    """

    ankle: float
    hip: float
    steps: tuple[float, ...]
    fall: float
    capture_point_mean: tuple[float, ...]
    capture_point_cov: tuple[tuple[float, ...], ...]
    error: float = 0.0
    method: str = "exact"
    by_level: tuple[float, ...] = field(default=(), repr=False)

    @property
    def most_likely(self) -> Strategy:
        """The strategy of largest probability (steps counted together)."""
        options = {
            Strategy.ANKLE: self.ankle,
            Strategy.HIP: self.hip,
            Strategy.STEP: sum(self.steps),
            Strategy.FALL: self.fall,
        }
        return max(options, key=lambda s: options[s])

    def at_most(self, steps: int) -> float:
        """P(at most ``steps`` steps are needed): ankle, hip or up to that many steps."""
        return self.ankle + self.hip + sum(self.steps[:steps])

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: the probabilities, ξ's mean and covariance, the error and method."""
        return {
            "ankle": self.ankle,
            "hip": self.hip,
            "steps": list(self.steps),
            "fall": self.fall,
            "capture_point_mean": list(self.capture_point_mean),
            "capture_point_cov": [list(row) for row in self.capture_point_cov],
            "error": self.error,
            "method": self.method,
        }


def delayed_capture_point(
    mean: ArrayLike, cov: ArrayLike, omega: float, latency: float, cop: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Return the mean and covariance of ξ(τ) = p + (ξ − p) e^{ωτ} (module docstring).

    Parameters
    ----------
    mean : array_like, shape (d,)
        Mean of ξ when measured [m], d = 1 or 2.
    cov : array_like, shape (d, d)
        Its covariance [m²].
    omega : float
        sqrt(g / L) [1/s], > 0.
    latency : float
        τ [s], >= 0, with e^{ωτ} <= :data:`MAX_LATENCY_GROWTH`.
    cop : array_like, shape (d,)
        The CoP p held during the latency [m].
    """
    tau = non_negative_float("latency", latency, "s")
    growth = math.exp(omega * tau) if omega * tau < 700.0 else math.inf
    if growth > MAX_LATENCY_GROWTH:
        raise InvalidParameterError(
            f"latency must keep e^(omega tau) <= {MAX_LATENCY_GROWTH:g} (tau <= "
            f"{math.log(MAX_LATENCY_GROWTH) / omega:.3g} s for omega = {omega:.3g} 1/s), "
            f"got {tau!r} s"
        )
    p = np.asarray(cop, dtype=np.float64)
    return p + (np.asarray(mean) - p) * growth, np.asarray(cov) * growth**2


def verdict_probabilities(
    state: StateGaussian,
    params: BodyParams,
    *,
    support: Support | None = None,
    latency: float | tuple[float, float] = 0.0,
    cop: ArrayLike | None = None,
) -> VerdictProbabilities:
    """Return the probability of each verdict of an uncertain state (module docstring).

    Parameters
    ----------
    state : StateGaussian
        The state estimate: (x, ẋ) on the sagittal line or (x, y, ẋ, ẏ) on the plane.
    params : BodyParams
        The body (its ω, feet, hip and step limits).
    support : Support, optional
        The support on the plane (default: double support on the default feet, as
        :func:`~pushrecovery.surfaces.classify.classify`); not for a sagittal state.
    latency : float or (float, float)
        Loop latency τ [s] (>= 0), or a range (τ⁻, τ⁺) with τ⁻ <= τ⁺ over which it is uniform.
    cop : array_like, optional
        The CoP held during the latency [m]: 1 number (line) or 2 (plane); default the middle
        of the CoP region.

    Raises
    ------
    InvalidParameterError
        A support for a sagittal state, a latency that is negative, an empty range, or so
        long that e^{ωτ} > :data:`MAX_LATENCY_GROWTH`, a ``cop`` of the wrong size.
    """
    require_type("state", state, StateGaussian)
    require_type("params", params, BodyParams)
    if support is not None and not state.plane:
        raise InvalidParameterError("support applies to a plane state (x, y, xdot, ydot)")
    if support is None and state.plane:
        support = Support.from_params(params)
    if support is not None:
        require_type("support", support, Support)
    dims = 2 if state.plane else 1
    omega = params.omega
    rows = np.hstack([np.eye(dims), np.eye(dims) / omega])
    xi_mean, xi_cov = rows @ state.mean, rows @ state.cov @ rows.T
    regions = _regions(params, support)
    if cop is None:
        held = _middle(regions[0])
    else:
        held = finite_vector("cop", cop, dims, unit="m")
    nodes, weights = _latencies(latency)
    levels = np.zeros(len(regions))
    for tau, weight in zip(nodes, weights, strict=True):
        mean, cov = delayed_capture_point(xi_mean, xi_cov, omega, tau, held)
        levels += weight * _level_masses(mean, cov, regions)
    error = 0.0
    if len(nodes) > 1:
        coarse_nodes, coarse_weights = _latencies(latency, len(nodes) // 2)
        coarse = np.zeros(len(regions))
        for tau, weight in zip(coarse_nodes, coarse_weights, strict=True):
            mean, cov = delayed_capture_point(xi_mean, xi_cov, omega, tau, held)
            coarse += weight * _level_masses(mean, cov, regions)
        error = float(np.max(np.abs(np.cumsum(levels) - np.cumsum(coarse))))
    # ξ at the command: over a latency range the mixture's mean and covariance.
    growth = np.exp(omega * nodes)
    first, second = float(weights @ growth), float(weights @ growth**2)
    offset = xi_mean - held
    mean = held + offset * first
    cov = xi_cov * second + (second - first**2) * np.outer(offset, offset)
    return VerdictProbabilities(
        ankle=float(levels[0]),
        hip=float(levels[1]),
        steps=tuple(float(p) for p in levels[2:]),
        fall=float(max(0.0, 1.0 - levels.sum())),
        capture_point_mean=tuple(float(v) for v in mean),
        capture_point_cov=tuple(tuple(float(v) for v in row) for row in cov),
        error=error,
        method="exact" if len(nodes) == 1 else "latency quadrature",
        by_level=tuple(float(p) for p in levels),
    )


# A level's regions: intervals (lower, upper) on the line, convex polygons on the plane.
_Level = list[tuple[float, float]] | list[ConvexPolygon]


def _regions(params: BodyParams, support: Support | None) -> list[_Level]:
    """Return the regions of each level: CoP, CMP, then 1 … max_steps steps."""
    if support is None:
        intervals = [cop_region(params), cmp_region(params)] + [
            sagittal_step_interval(params, n) for n in range(1, params.max_steps + 1)
        ]
        return [[(i.lower, i.upper)] for i in intervals]
    steps = StepRegions.of(params, support)
    per_n: list[_Level] = [
        [p for p, n in zip(steps.polygons, steps.steps, strict=True) if n == count]
        for count in range(1, params.max_steps + 1)
    ]
    return [[support.polygon], [cmp_polygon(support, params)], *per_n]


def _middle(level: _Level) -> FloatArray:
    region = level[0]
    if isinstance(region, ConvexPolygon):
        return np.array(region.centroid)
    return np.array([0.5 * (region[0] + region[1])])


def _latencies(
    latency: float | tuple[float, float], nodes: int = LATENCY_NODES
) -> tuple[FloatArray, FloatArray]:
    """Nodes and weights (summing to 1) of the latency: one node, or Gauss–Legendre on a range."""
    if isinstance(latency, tuple | list):
        if len(latency) != 2:
            raise InvalidParameterError(
                f"latency must be a number or a range (low, high) [s], got {latency!r}"
            )
        low = non_negative_float("latency[0]", latency[0], "s")
        high = non_negative_float("latency[1]", latency[1], "s")
        if not low <= high:
            raise InvalidParameterError(
                f"latency range must have low <= high [s], got ({low}, {high})"
            )
        if low == high:
            return np.array([low]), np.array([1.0])
        x, w = np.polynomial.legendre.leggauss(nodes)
        return low + (x + 1.0) * 0.5 * (high - low), 0.5 * w
    return np.array([non_negative_float("latency", latency, "s")]), np.array([1.0])


def _level_masses(mean: FloatArray, cov: FloatArray, regions: list[_Level]) -> FloatArray:
    """P(the first region holding ξ is that level's), per level."""
    cumulative = np.empty(len(regions))
    if isinstance(regions[0][0], ConvexPolygon):
        sigma = covariance_2d("cov", cov)
        kept: list[ConvexPolygon] = []
        last = None
        for level, group in enumerate(regions):
            # Only the polygons no other one contains count (nested levels change nothing);
            # once the union holds all the mass but rounding, larger unions hold it too.
            kept = maximal([*kept, *group])
            if level and (kept == last or cumulative[level - 1] >= 1.0 - 1e-15):
                cumulative[level] = cumulative[level - 1]
            else:
                cumulative[level] = float(gaussian_union_mass(mean, sigma, kept))
            last = kept
    else:
        for level in range(len(regions)):
            pieces = [r for group in regions[: level + 1] for r in group]
            cumulative[level] = _interval_union_mass(mean, cov, pieces)  # type: ignore[arg-type]
    cumulative = np.maximum.accumulate(np.clip(cumulative, 0.0, 1.0))
    return np.diff(cumulative, prepend=0.0)


def _interval_union_mass(
    mean: FloatArray, cov: FloatArray, pieces: list[tuple[float, float]]
) -> float:
    """P(ξ in a union of intervals) of a 1-D Gaussian (a zero variance: strictly inside)."""
    sd = math.sqrt(max(float(cov[0, 0]), 0.0))
    merged: list[list[float]] = []
    for low, high in sorted(pieces):
        if merged and low <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], high)
        else:
            merged.append([low, high])
    mu = float(mean[0])
    if sd == 0.0:  # known exactly: strictly inside, as the verdicts
        return float(any(low < mu < high for low, high in merged))
    return float(sum(ndtr((high - mu) / sd) - ndtr((low - mu) / sd) for low, high in merged))
