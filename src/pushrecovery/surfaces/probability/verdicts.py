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
A body known only up to a spread (:class:`~.body.BodySpread`) is averaged over by
randomised quasi-Monte Carlo, with the replicates' standard error.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtr

from pushrecovery.arguments import finite_vector, non_negative_float, require_type, whole_number
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.gaussian import gaussian_mass
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cop import cop_region
from pushrecovery.surfaces.probability.body import BodySpread
from pushrecovery.surfaces.probability.inputs import StateGaussian, check_states
from pushrecovery.surfaces.probability.latency import (
    delayed_capture_point,
    latency_growth,
    latency_nodes,
)
from pushrecovery.surfaces.probability.regions import (
    Level,
    cumulative_masses,
    region_middle,
    verdict_regions,
)
from pushrecovery.surfaces.probability.results import ProbabilityTable, VerdictProbabilities

__all__ = ["ankle_probability", "verdict_probabilities", "verdict_probability_table"]

FloatArray = NDArray[np.float64]


def verdict_probabilities(
    state: StateGaussian,
    params: BodyParams,
    *,
    support: Support | None = None,
    latency: float | tuple[float, float] = 0.0,
    cop: ArrayLike | None = None,
    spread: BodySpread | None = None,
    samples: int = 64,
    replicates: int = 8,
    seed: int = 0,
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
    spread : BodySpread, optional
        How well the body is known. The probabilities are then averaged over ``samples``
        bodies of a scrambled Sobol sequence, ``replicates`` times with independent
        scramblings (seeds ``seed`` …); ``error`` is the larger of the replicates' standard
        error and the latency quadrature's (method ``quasi-Monte Carlo over the body``).
    samples : int
        Bodies per replicate, a power of 2 in [2, 4096].
    replicates : int
        Independent scramblings, in [2, 64].
    seed : int
        Seed of the first scrambling, >= 0.

    Raises
    ------
    InvalidParameterError
        A support for a sagittal state, a latency that is negative, an empty range, or so
        long that e^{ωτ} > :data:`MAX_LATENCY_GROWTH`, a ``cop`` of the wrong size, a spread
        whose ±3 SD leave the body's valid range, ``samples``, ``replicates`` or ``seed`` out of
        range.
    """
    require_type("state", state, StateGaussian)
    if spread is not None:
        return _spread_probabilities(
            state, params, support, latency, cop, spread, samples, replicates, seed
        )
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


def _spread_probabilities(
    state: StateGaussian,
    params: BodyParams,
    support: Support | None,
    latency: float | tuple[float, float],
    cop: ArrayLike | None,
    spread: BodySpread,
    samples: int,
    replicates: int,
    seed: int,
) -> VerdictProbabilities:
    """:func:`verdict_probabilities` averaged over bodies of the spread (randomised QMC)."""
    require_type("spread", spread, BodySpread)
    require_type("params", params, BodyParams)
    samples = whole_number("samples", samples, 2, 4096)
    if samples & (samples - 1):
        raise InvalidParameterError(f"samples must be a power of 2 (Sobol), got {samples}")
    replicates = whole_number("replicates", replicates, 2, 64)
    seed = whole_number("seed", seed, 0, 2**31 - 1)
    if support is not None:
        require_type("support", support, Support)
    estimates, numerical = [], 0.0
    mean_xi, cov_xi = [], []
    for r in range(replicates):
        total = None
        for body in spread.bodies(params, samples, seed + r):
            # The same stance and feet, the body's own foot (a foot length spread changes it).
            feet = (
                None
                if support is None
                else Support.from_params(
                    body, support.stance, left=support.left, right=support.right
                )
            )
            table = verdict_probability_table(
                state.mean, state.cov, body, support=feet, latency=latency, cop=cop
            )
            numerical = max(numerical, table.error)
            total = table.levels[0] if total is None else total + table.levels[0]
            mean_xi.append(table.capture_point_mean[0])
            cov_xi.append(table.capture_point_cov[0])
        assert total is not None
        estimates.append(total / samples)
    runs = np.array(estimates)
    levels = runs.mean(axis=0)
    standard_error = float(
        np.max(np.std(np.cumsum(runs, axis=1), axis=0, ddof=1)) / math.sqrt(replicates)
    )
    centres = np.array(mean_xi)
    # ξ over the bodies too: the mean of the means, and the law of total covariance.
    xi_mean = centres.mean(axis=0)
    spread_cov = np.atleast_2d(np.cov(centres.T, bias=True))
    xi_cov = np.mean(np.array(cov_xi), axis=0) + spread_cov
    return VerdictProbabilities(
        ankle=float(levels[0]),
        hip=float(levels[1]),
        steps=tuple(float(p) for p in levels[2:-1]),
        fall=float(levels[-1]),
        capture_point_mean=tuple(float(v) for v in xi_mean),
        capture_point_cov=tuple(tuple(float(v) for v in row) for row in xi_cov),
        error=max(standard_error, numerical),
        method="quasi-Monte Carlo over the body",
        by_level=tuple(float(p) for p in levels[:-1]),
    )


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
    means, covs = check_states(mean, cov)
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
    regions = verdict_regions(params, support)
    held = region_middle(regions[0]) if cop is None else finite_vector("cop", cop, dims, unit="m")
    nodes, weights = latency_nodes(latency)
    cumulative = _mixture(xi_mean, xi_cov, omega, held, nodes, weights, regions)
    error = 0.0
    if len(nodes) > 1:
        coarse = _mixture(xi_mean, xi_cov, omega, held, *latency_nodes(latency, len(nodes) // 2),
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
    means, covs = check_states(mean, cov)
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
        growth = latency_growth(params.omega, tau)
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
        region: Level = [support.polygon]
    else:
        foot = cop_region(params)
        region = [(foot.lower, foot.upper)]
    omega = params.omega
    rows = np.hstack([np.eye(dims), np.eye(dims) / omega])
    held = region_middle(region) if cop is None else finite_vector("cop", cop, dims, unit="m")
    xi_mean, xi_cov = delayed_capture_point(means @ rows.T, rows @ covs @ rows.T, omega, tau, held)
    if plane and np.ndim(mean) == 1 and xi_cov.ndim == 2:  # one state: the mass in floats
        return gaussian_mass(xi_mean[0], xi_cov, region[0])  # type: ignore[arg-type]
    found = cumulative_masses(xi_mean, xi_cov, [region])[:, 0]
    return found if np.ndim(mean) > 1 else found[0]


def _mixture(
    xi_mean: FloatArray,
    xi_cov: FloatArray,
    omega: float,
    held: FloatArray,
    nodes: FloatArray,
    weights: FloatArray,
    regions: list[Level],
) -> FloatArray:
    """P(level <= L) per state and level, averaged over the latency's nodes."""
    total = np.zeros((len(xi_mean), len(regions)))
    for tau, weight in zip(nodes, weights, strict=True):
        mean, cov = delayed_capture_point(xi_mean, xi_cov, omega, tau, held)
        total += weight * cumulative_masses(mean, cov, regions)
    return total
