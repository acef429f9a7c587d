"""Are the fall probabilities calibrated? Pushes simulated, their states estimated with noise.

A robot estimates the state a push leaves it in with an error, s_hat = s + e, e ~ N(0, Σ), and
asks the surfaces for P(fall | s_hat, Σ) (:mod:`pushrecovery.surfaces.probability`). The study
pushes a body many times (CoM over the ankle, velocities uniform over a range), simulates each
push with a controller from its true state (``run_many``: the analytic models or MuJoCo), draws
one estimate per push with a seeded generator and compares the predicted probabilities with the
falls: a reliability table (predictions in bins, the observed frequency of each with its
binomial standard error), the Brier score of the probabilities, that of the certain verdict of
the estimate (0 or 1) and that of the base rate (always predicting the observed frequency).

A run that slipped counts as a failure, like a fall (it did not recover as the model assumes);
an undecided run or one whose physics failed is left out and counted. The controller sees the
true state (the estimate is the monitor's, not the controller's), ``latency`` seconds late if
one is given, the CoP held at the foot's middle until then, as the prediction assumes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import (
    finite_vector,
    positive_float,
    require_type,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.many import run_many
from pushrecovery.sim.result import Outcome
from pushrecovery.surfaces.probability import verdict_probability_table
from pushrecovery.surfaces.probability.scores import ReliabilityRow, brier_score, reliability

__all__ = ["Calibration", "calibration_study"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class Calibration:
    """A calibration study's pushes, predictions, outcomes and scores.

    Attributes
    ----------
    velocity : ndarray
        Each push's true CoM velocity [m/s] (CoM over the ankle).
    estimate : ndarray, shape (n, 2)
        The robot's estimate (x, ẋ) of each pushed state [m, m/s].
    predicted : ndarray
        P(fall | estimate) (dimensionless).
    certain : ndarray of bool
        The certain verdict of the estimate is ``fall``.
    failed : ndarray of bool
        The run fell or slipped.
    kept : ndarray of bool
        The run came to a decision (not undecided, no physics error): the scored runs.
    bins : tuple of (float, float, int, float, float, float)
        Per bin of the predicted probability with runs: (low, high, runs, mean predicted,
        observed frequency, its binomial standard error).
    brier, brier_certain, brier_base_rate : float
        Mean squared error of the probabilities, of the certain verdict, of the base rate
        (dimensionless; lower is better).
    """

    velocity: FloatArray
    estimate: FloatArray
    predicted: FloatArray
    certain: NDArray[np.bool_]
    failed: NDArray[np.bool_]
    kept: NDArray[np.bool_]
    bins: tuple[ReliabilityRow, ...]
    brier: float
    brier_certain: float
    brier_base_rate: float

    @property
    def excluded(self) -> int:
        """Runs left out: undecided, or no outcome."""
        return int(np.count_nonzero(~self.kept))


def calibration_study(
    model: str,
    controller: str,
    params: BodyParams,
    *,
    velocities: tuple[float, float],
    pushes: int,
    noise: Sequence[float],
    backend: str = "analytic",
    duration: float = 4.0,
    seed: int = 0,
    latency: float = 0.0,
) -> Calibration:
    """Push, simulate, estimate with noise, predict P(fall) and score it (module docstring).

    Parameters
    ----------
    model, controller : str
        The plant and the controller (``run_many``'s names).
    params : BodyParams
        The body, for the simulation and the prediction alike (its ``max_steps`` is the
        prediction's stepping reach).
    velocities : (float, float)
        The pushes' CoM velocities are uniform over this range [m/s], low < high, in
        [-10, 10].
    pushes : int
        Number of pushes, in [10, 100000].
    noise : (float, float)
        Standard deviations of the estimate's errors in x [m] and ẋ [m/s] (independent),
        each > 0.
    backend : {"analytic", "mujoco"}
        The physics.
    duration : float
        Longest simulated time per push [s].
    seed : int
        Seed of the pushes and the estimates, >= 0.
    latency : float
        The controller reacts this late [s], in [0, 1], the CoP held at the foot's middle
        meanwhile (``run_many``'s ``latency``), and the prediction takes the same latency.

    Raises
    ------
    InvalidParameterError
        Out-of-range arguments; the checks of ``run_many``.
    """
    require_type("params", params, BodyParams)
    low, high = finite_vector("velocities", velocities, 2, 10.0, "m/s")
    if not low < high:
        raise InvalidParameterError(
            f"velocities must be (low, high) with low < high, got {velocities}"
        )
    count = whole_number("pushes", pushes, 10, 100_000)
    noise = tuple(finite_vector("noise", noise, 2, 10.0))  # (sd of x [m], sd of xdot [m/s])
    sd = np.array(
        [positive_float("noise[0]", noise[0], "m"), positive_float("noise[1]", noise[1], "m/s")]
    )
    seed = whole_number("seed", seed, 0, 2**31 - 1)
    rng = np.random.default_rng(seed)
    velocity = rng.uniform(low, high, count)
    runs = run_many(model, controller, [params] * count, [0.0] * count, velocity.tolist(),
                    duration=duration, backend=backend, latency=latency)  # fmt: skip
    outcome = np.array([o.value for o in runs.outcomes])
    errors = (
        np.array([e is not None for e in runs.errors]) if runs.errors else np.zeros(count, bool)
    )
    failed = np.isin(outcome, (Outcome.FELL.value, Outcome.SLIPPED.value))
    kept = ~errors & (outcome != Outcome.UNDECIDED.value)
    estimate = np.column_stack([np.zeros(count), velocity]) + rng.normal(0.0, sd, (count, 2))
    table = verdict_probability_table(estimate, np.diag(sd**2), params, latency=latency)
    predicted = table.fall
    exact = verdict_probability_table(estimate, np.zeros((2, 2)), params, latency=latency)
    certain = exact.fall > 0.5  # the certain verdict of the estimate (after the latency)
    p, hit = predicted[kept], failed[kept]
    base = float(hit.mean()) if hit.size else 0.0
    return Calibration(
        velocity=velocity,
        estimate=estimate,
        predicted=predicted,
        certain=certain,
        failed=failed,
        kept=kept,
        bins=reliability(p, hit),
        brier=brier_score(p, hit),
        brier_certain=brier_score(certain[kept].astype(np.float64), hit),
        brier_base_rate=base * (1.0 - base),
    )
