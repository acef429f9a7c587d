"""The verdict probabilities in a control loop: a support's regions kept between ticks.

:class:`ProbabilityMonitor` answers, for a state estimate (mean and covariance) at every tick,
P(ankle), P(hip), P(step) (any number of steps) and P(fall), the same numbers as
:func:`~pushrecovery.surfaces.probability.verdicts.verdict_probabilities` summed over the
step counts. What depends on the support alone is built when the support is set: on the
plane the CoP and CMP polygons, the N-step regions that no other contains and their
intersections (the unions' inclusion–exclusion terms); on the line the three intervals. A
query then evaluates a handful of Gaussian masses.

Threads: :meth:`ProbabilityMonitor.set_support` builds the new state aside and swaps one
reference, so a query running meanwhile answers for the old support or the new one, never a
mix (the rule of :class:`~pushrecovery.surfaces.monitor.BalanceMonitor`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ndtr

from pushrecovery.arguments import non_negative_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.gaussian import gaussian_mass, union_terms
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.probability.inputs import check_states
from pushrecovery.surfaces.probability.latency import latency_growth
from pushrecovery.surfaces.step.regions import StepRegions, sagittal_step_interval

__all__ = ["MonitorProbabilities", "ProbabilityMonitor"]


@dataclass(frozen=True, slots=True)
class MonitorProbabilities:
    """One tick's answer (dimensionless, summing to 1).

    Attributes
    ----------
    ankle, hip, step, fall : float
        P(the ankle suffices), P(the hip is needed and suffices), P(at most ``max_steps``
        steps are needed, and some), P(fall) (dimensionless, in [0, 1]).
    """

    ankle: float
    hip: float
    step: float
    fall: float


# A union by inclusion and exclusion: (sign, polygon) terms.
_Terms = tuple[tuple[float, ConvexPolygon], ...]


@dataclass(frozen=True, slots=True)
class _State:
    """What a support fixes (swapped as one reference)."""

    cop: ConvexPolygon | tuple[float, float]
    cmp: ConvexPolygon | tuple[float, float]
    capture: _Terms | tuple[float, float]  # the union of every region (line: C_max)
    held: tuple[float, ...]


class ProbabilityMonitor:
    """Verdict probabilities of state estimates for one body, tick after tick (module docstring).

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support, optional
        The support on the plane; None: the sagittal line (states (x, ẋ)).
    latency : float
        Loop latency [s], >= 0 (the CoP held at the middle of the CoP region meanwhile).
    """

    def __init__(
        self, params: BodyParams, support: Support | None = None, *, latency: float = 0.0
    ) -> None:
        require_type("params", params, BodyParams)
        self.params = params
        self.latency = non_negative_float("latency", latency, "s")
        self._growth = latency_growth(params.omega, self.latency)
        self._plane = support is not None
        self._state = self._build(support)

    def set_support(self, support: Support) -> None:
        """Use ``support`` from the next query on (the plane only)."""
        if not self._plane:
            raise InvalidParameterError("a line monitor has no support (built without one)")
        self._state = self._build(support)

    def query(self, mean: ArrayLike, cov: ArrayLike) -> MonitorProbabilities:
        """Return the probabilities of the state estimate (mean, covariance).

        ``mean``: (x, ẋ) on the line or (x, y, ẋ, ẏ) on the plane [m, m/s]; ``cov`` its
        covariance, symmetric positive semi-definite.

        Raises
        ------
        InvalidParameterError
            A state of the other kind, not finite, or a covariance that is not one.
        """
        state = self._state  # one read: the old support or the new, never a mix
        means, covs = check_states(mean, cov)
        dims = 2 if self._plane else 1
        if means.shape != (1, 2 * dims) or covs.shape != (2 * dims, 2 * dims):
            raise InvalidParameterError(
                f"this monitor takes one state of {2 * dims} numbers and its "
                f"({2 * dims}, {2 * dims}) covariance, got {np.shape(mean)} and {covs.shape}"
            )
        inv = 1.0 / self.params.omega
        rows = np.hstack([np.eye(dims), np.eye(dims) * inv])
        held = np.array(state.held)
        xi = held + (rows @ means[0] - held) * self._growth
        sigma = rows @ covs @ rows.T * self._growth**2
        if self._plane:
            ankle = float(gaussian_mass(xi, sigma, state.cop))  # type: ignore[arg-type]
            hip = float(gaussian_mass(xi, sigma, state.cmp))  # type: ignore[arg-type]
            caught = 0.0
            for sign, polygon in state.capture:  # type: ignore[misc]
                caught += sign * float(gaussian_mass(xi, sigma, polygon))
        else:
            sd = math.sqrt(max(float(sigma[0, 0]), 0.0))
            ankle, hip, caught = (
                _interval(float(xi[0]), sd, region)  # type: ignore[arg-type]
                for region in (state.cop, state.cmp, state.capture)
            )
        # The regions are nested (CoP in CMP in the union of every region): the differences.
        caught = min(max(float(caught), hip), 1.0)
        return MonitorProbabilities(ankle, hip - ankle, caught - hip, 1.0 - caught)

    def _build(self, support: Support | None) -> _State:
        params = self.params
        if support is None:
            cop, cmp = cop_region(params), cmp_region(params)
            steps = sagittal_step_interval(params)
            return _State(
                (cop.lower, cop.upper),
                (cmp.lower, cmp.upper),
                (min(steps.lower, cmp.lower), max(steps.upper, cmp.upper)),
                (0.5 * (cop.lower + cop.upper),),
            )
        require_type("support", support, Support)
        regions = StepRegions.of(params, support)
        grown = cmp_polygon(support, params)
        terms = union_terms([support.polygon, grown, *regions.polygons])
        return _State(support.polygon, grown, terms, tuple(support.polygon.centroid))


def _interval(mu: float, sd: float, region: tuple[float, float]) -> float:
    """P(ξ in an open interval) of ξ ~ N(mu, sd²) (sd 0: strictly inside)."""
    low, high = region
    if sd == 0.0:
        return float(low < mu < high)
    return float(ndtr((high - mu) / sd) - ndtr((low - mu) / sd))
