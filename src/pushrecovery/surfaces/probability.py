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

from pushrecovery.arguments import (
    finite_array,
    finite_vector,
    non_negative_float,
    positive_float,
    require_type,
)
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
    "ProbabilityTable",
    "StateGaussian",
    "VerdictProbabilities",
    "ankle_probability",
    "delayed_capture_point",
    "verdict_probabilities",
    "verdict_probability_table",
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
        means, cov = _states(self.mean, self.cov)
        if len(means) != 1 or np.ndim(self.mean) != 1 or cov.ndim != 2:
            raise InvalidParameterError(
                "a StateGaussian is one state: mean of shape (2,) or (4,) and its (d, d) cov, "
                f"got {np.shape(self.mean)} and {cov.shape}"
            )
        mean = means[0].copy()
        cov = cov.copy()
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
        P(the ankle suffices), P(the hip is needed and suffices) (dimensionless, in [0, 1]).
    steps : tuple of float
        P(exactly k steps are needed), k = 1 … ``max_steps`` (dimensionless).
    fall : float
        P(no strategy of the model captures the state) (dimensionless).
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
    omega = positive_float("omega", omega, "1/s")
    growth = _growth(omega, non_negative_float("latency", latency, "s"))
    p = finite_array("cop", cop)
    return p + (finite_array("mean", mean) - p) * growth, finite_array("cov", cov) * growth**2


def _growth(omega: float, tau: float) -> float:
    """e^{ωτ}, refused beyond :data:`MAX_LATENCY_GROWTH`."""
    growth = math.exp(omega * tau) if omega * tau < 700.0 else math.inf
    if growth > MAX_LATENCY_GROWTH:
        raise InvalidParameterError(
            f"latency must keep e^(omega tau) <= {MAX_LATENCY_GROWTH:g} (tau <= "
            f"{math.log(MAX_LATENCY_GROWTH) / omega:.3g} s for omega = {omega:.3g} 1/s), "
            f"got {tau!r} s"
        )
    return growth


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
    table = verdict_probability_table(
        state.mean, state.cov, params, support=support, latency=latency, cop=cop
    )
    levels = table.levels[0]
    return VerdictProbabilities(
        ankle=float(levels[0]),
        hip=float(levels[1]),
        steps=tuple(float(p) for p in levels[2:-1]),
        fall=float(levels[-1]),
        capture_point_mean=tuple(float(v) for v in table.capture_point_mean[0]),
        capture_point_cov=tuple(tuple(float(v) for v in row) for row in table.capture_point_cov[0]),
        error=table.error,
        method=table.method,
        by_level=tuple(float(p) for p in levels[:-1]),
    )


@dataclass(frozen=True, slots=True, eq=False)
class ProbabilityTable:
    """The verdict probabilities of many uncertain states (:func:`verdict_probability_table`).

    Attributes
    ----------
    levels : ndarray, shape (n, 3 + max_steps)
        Per state: P(ankle), P(hip), P(exactly k steps) for k = 1 … max_steps, P(fall); rows
        sum to 1.
    capture_point_mean : ndarray, shape (n, d)
        Mean of ξ at the command [m] (d = 1 on the line, 2 on the plane).
    capture_point_cov : ndarray, shape (n, d, d)
        Its covariance [m²].
    error : float
        Bound on the numerical error of a probability (0: exact up to rounding).
    method : str
        ``exact`` or ``latency quadrature``.
    """

    levels: FloatArray
    capture_point_mean: FloatArray
    capture_point_cov: FloatArray
    error: float
    method: str

    @property
    def ankle(self) -> FloatArray:
        """P(the ankle suffices), per state."""
        return self.levels[:, 0]

    @property
    def hip(self) -> FloatArray:
        """P(the hip is needed and suffices), per state."""
        return self.levels[:, 1]

    @property
    def steps(self) -> FloatArray:
        """P(exactly k steps), shape (n, max_steps), column k − 1."""
        return self.levels[:, 2:-1]

    @property
    def fall(self) -> FloatArray:
        """P(fall), per state."""
        return self.levels[:, -1]


def verdict_probability_table(
    mean: ArrayLike,
    cov: ArrayLike,
    params: BodyParams,
    *,
    support: Support | None = None,
    latency: float | tuple[float, float] = 0.0,
    cop: ArrayLike | None = None,
) -> ProbabilityTable:
    """Return the verdict probabilities of many Gaussian states at once (vectorised).

    Parameters
    ----------
    mean : array_like, shape (n, 2) or (n, 4) (or one state)
        (x, ẋ) on the line or (x, y, ẋ, ẏ) on the plane [m, m/s], as :class:`StateGaussian`.
    cov : array_like, shape (d, d) or (n, d, d)
        The states' covariance, one for all or one each (d = 2 or 4), symmetric positive
        semi-definite.
    params : BodyParams
        The body.
    support : Support, optional
        The plane's support, as :func:`verdict_probabilities`.
    latency : float or (float, float)
        Loop latency [s], or a range of it [s], as :func:`verdict_probabilities`.
    cop : array_like, optional
        The CoP held during the latency [m].

    Raises
    ------
    InvalidParameterError
        As :func:`verdict_probabilities`, and means or covariances of other shapes, not finite,
        not symmetric positive semi-definite.
    """
    means, covs = _states(mean, cov)
    require_type("params", params, BodyParams)
    plane = means.shape[1] == 4
    if support is not None and not plane:
        raise InvalidParameterError("support applies to a plane state (x, y, xdot, ydot)")
    if support is None and plane:
        support = Support.from_params(params)
    if support is not None:
        require_type("support", support, Support)
    dims = 2 if plane else 1
    omega = params.omega
    rows = np.hstack([np.eye(dims), np.eye(dims) / omega])
    xi_mean = means @ rows.T
    xi_cov = rows @ covs @ rows.T
    regions = _regions(params, support)
    held = _middle(regions[0]) if cop is None else finite_vector("cop", cop, dims, unit="m")
    nodes, weights = _latencies(latency)
    cumulative = _mixture(xi_mean, xi_cov, omega, held, nodes, weights, regions)
    error = 0.0
    if len(nodes) > 1:
        coarse = _mixture(xi_mean, xi_cov, omega, held, *_latencies(latency, len(nodes) // 2),
                          regions)  # fmt: skip
        error = float(np.max(np.abs(cumulative - coarse)))
    levels = np.diff(cumulative, axis=1, prepend=0.0, append=1.0)
    # ξ at the command: over a latency range the mixture's mean and covariance.
    growth = np.exp(omega * nodes)
    first, second = float(weights @ growth), float(weights @ growth**2)
    offset = xi_mean - held
    outer = np.einsum("ni,nj->nij", offset, offset)
    return ProbabilityTable(
        levels=levels,
        capture_point_mean=held + offset * first,
        capture_point_cov=np.broadcast_to(xi_cov * second, outer.shape)
        + (second - first**2) * outer,
        error=error,
        method="exact" if len(nodes) == 1 else "latency quadrature",
    )


def ankle_probability(
    mean: ArrayLike,
    cov: ArrayLike,
    params: BodyParams,
    *,
    support: Support | None = None,
    latency: float = 0.0,
    cop: ArrayLike | None = None,
) -> FloatArray:
    """Return P(the ankle suffices) of Gaussian states: ξ's mass on the CoP region alone.

    The first column of :func:`verdict_probability_table` without the other regions (the
    cheap question a loop asks every tick). Arguments as there; ``latency`` one value [s].
    Returns shape (n,) for states (n, d), () for one state.
    """
    means, covs = _states(mean, cov)
    require_type("params", params, BodyParams)
    plane = means.shape[1] == 4
    if support is not None and not plane:
        raise InvalidParameterError("support applies to a plane state (x, y, xdot, ydot)")
    dims = 2 if plane else 1
    tau = non_negative_float("latency", latency, "s")
    if not plane and covs.ndim == 2:  # the line, one covariance: normal CDFs of ξ's z-scores
        foot = cop_region(params)
        inv = 1.0 / params.omega
        centre = (
            0.5 * (foot.lower + foot.upper)
            if cop is None
            else float(finite_vector("cop", cop, 1, unit="m")[0])
        )
        growth = _growth(params.omega, tau)
        sd = (
            math.sqrt(max(covs[0, 0] + 2.0 * inv * covs[0, 1] + inv * inv * covs[1, 1], 0.0))
            * growth
        )
        xi = centre + (means[:, 0] + inv * means[:, 1] - centre) * growth
        if sd == 0.0:
            found = ((foot.lower < xi) & (xi < foot.upper)).astype(np.float64)
        else:
            found = ndtr((foot.upper - xi) / sd) - ndtr((foot.lower - xi) / sd)
        return found if np.ndim(mean) > 1 else found[0]
    if plane:
        support = Support.from_params(params) if support is None else support
        require_type("support", support, Support)
        region: _Level = [support.polygon]
    else:
        foot = cop_region(params)
        region = [(foot.lower, foot.upper)]
    omega = params.omega
    rows = np.hstack([np.eye(dims), np.eye(dims) / omega])
    held = _middle(region) if cop is None else finite_vector("cop", cop, dims, unit="m")
    xi_mean, xi_cov = delayed_capture_point(means @ rows.T, rows @ covs @ rows.T, omega, tau, held)
    found = _cumulative(xi_mean, xi_cov, [region])[:, 0]
    return found if np.ndim(mean) > 1 else found[0]


def _states(mean: ArrayLike, cov: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Means (n, d) and covariances (d, d) or (n, d, d), checked."""
    means = np.atleast_2d(finite_array("mean", mean))
    if means.ndim != 2 or means.shape[1] not in (2, 4):
        raise InvalidParameterError(
            f"mean must be states (x, xdot) or (x, y, xdot, ydot): shape (n, 2) or (n, 4), "
            f"got {np.shape(mean)}"
        )
    d = means.shape[1]
    covs = finite_array("cov", cov)
    if covs.shape not in ((d, d), (len(means), d, d)):
        raise InvalidParameterError(
            f"cov must have shape ({d}, {d}) or ({len(means)}, {d}, {d}), got {covs.shape}"
        )
    if covs.shape == (2, 2):  # one state's (x, xdot): the checks in closed form (a loop's tick)
        (a, b), (c, e) = covs.tolist()
        scale = max(abs(a), abs(b), abs(c), abs(e))
        if abs(b - c) > 1e-12 * scale:
            raise InvalidParameterError("cov must be symmetric (a covariance matrix)")
        half, mid = math.hypot(0.5 * (a - e), 0.5 * (b + c)), 0.5 * (a + e)
        if mid - half < -1e-12 * scale:
            raise InvalidParameterError(
                "cov must be positive semi-definite (a covariance), got an eigenvalue "
                f"{mid - half:.3g}"
            )
        return means, covs
    scale = np.max(np.abs(covs), axis=(-2, -1), keepdims=True)
    if np.any(np.abs(covs - np.swapaxes(covs, -1, -2)) > 1e-12 * scale):
        raise InvalidParameterError("cov must be symmetric (a covariance matrix)")
    smallest = np.linalg.eigvalsh(0.5 * (covs + np.swapaxes(covs, -1, -2)))[..., 0]
    if np.any(smallest < -1e-12 * scale[..., 0, 0]):
        raise InvalidParameterError(
            "cov must be positive semi-definite (a covariance), got an eigenvalue "
            f"{float(np.min(smallest)):.3g}"
        )
    return means, covs


def _mixture(
    xi_mean: FloatArray,
    xi_cov: FloatArray,
    omega: float,
    held: FloatArray,
    nodes: FloatArray,
    weights: FloatArray,
    regions: list[_Level],
) -> FloatArray:
    """P(level <= L) per state and level, averaged over the latency's nodes."""
    total = np.zeros((len(xi_mean), len(regions)))
    for tau, weight in zip(nodes, weights, strict=True):
        mean, cov = delayed_capture_point(xi_mean, xi_cov, omega, tau, held)
        total += weight * _cumulative(mean, cov, regions)
    return total


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


def _cumulative(mean: FloatArray, cov: FloatArray, regions: list[_Level]) -> FloatArray:
    """P(ξ in the union of the regions of levels 0 … L), per state (rows) and level L."""
    cumulative = np.empty((len(mean), len(regions)))
    if isinstance(regions[0][0], ConvexPolygon):
        sigma = covariance_2d("cov", cov)
        kept: list[ConvexPolygon] = []
        last = None
        for level, group in enumerate(regions):
            # Only the polygons no other one contains count (nested levels change nothing);
            # once the union holds all the mass but rounding, larger unions hold it too.
            kept = maximal([*kept, *group])
            if level and (kept == last or np.all(cumulative[:, level - 1] >= 1.0 - 1e-15)):
                cumulative[:, level] = cumulative[:, level - 1]
            else:
                cumulative[:, level] = gaussian_union_mass(mean, sigma, kept)
            last = kept
    else:
        sd = np.sqrt(np.maximum(np.broadcast_to(cov, (len(mean), 1, 1))[:, 0, 0], 0.0))
        for level in range(len(regions)):
            pieces = [r for group in regions[: level + 1] for r in group]
            cumulative[:, level] = _interval_union_mass(mean[:, 0], sd, pieces)  # type: ignore[arg-type]
    return np.maximum.accumulate(np.clip(cumulative, 0.0, 1.0), axis=1)


def _interval_union_mass(
    mu: FloatArray, sd: FloatArray, pieces: list[tuple[float, float]]
) -> FloatArray:
    """P(ξ in a union of intervals) of 1-D Gaussians (a zero deviation: strictly inside)."""
    merged: list[list[float]] = []
    for low, high in sorted(pieces):
        if merged and low <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], high)
        else:
            merged.append([low, high])
    total = np.zeros(len(mu))
    exact = sd == 0.0
    safe = np.where(exact, 1.0, sd)
    for low, high in merged:
        total += np.where(
            exact, (low < mu) & (mu < high), ndtr((high - mu) / safe) - ndtr((low - mu) / safe)
        )
    return total
