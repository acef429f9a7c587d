"""The verdict probabilities of uncertain states: one state, and a table of many."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pushrecovery.surfaces.strategy import Strategy

__all__ = ["ProbabilityTable", "VerdictProbabilities"]

FloatArray = NDArray[np.float64]


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
