"""How good are probabilities? Their reliability table and Brier score against outcomes.

The Brier score is the mean squared difference of each predicted probability and its outcome
(1 if it happened, 0 if not): 0 is perfect, and always predicting the base rate p̄ scores
p̄ (1 − p̄). The reliability table puts the predictions in equal-width bins of [0, 1] and gives
each bin's mean prediction beside how often the outcome happened there, with its binomial
standard error: a calibrated prediction lies on the diagonal.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pushrecovery.arguments import finite_array, whole_number
from pushrecovery.errors import InvalidParameterError

__all__ = ["BINS", "ReliabilityRow", "brier_score", "reliability"]

#: Equal-width bins of the predicted probability in a reliability table.
BINS = 10

#: One bin: (low, high, runs, mean predicted, observed frequency, its standard error).
ReliabilityRow = tuple[float, float, int, float, float, float]


def _checked(predicted: ArrayLike, happened: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    p = finite_array("predicted", predicted)
    try:
        hit = np.asarray(happened)
    except ValueError:  # ragged
        raise InvalidParameterError("happened must be a 1-D array of booleans") from None
    if p.ndim != 1 or p.shape != hit.shape:
        raise InvalidParameterError(
            f"predicted and happened must be 1-D of one length, got {p.shape} and {hit.shape}"
        )
    if hit.dtype != np.bool_:
        raise InvalidParameterError(f"happened must be booleans, got dtype {hit.dtype}")
    if np.any((p < 0.0) | (p > 1.0)):
        raise InvalidParameterError("predicted must be probabilities in [0, 1]")
    return p, hit


def brier_score(predicted: ArrayLike, happened: ArrayLike) -> float:
    """Return the mean of (p − outcome)² (module docstring); NaN for no predictions."""
    p, hit = _checked(predicted, happened)
    return float(np.mean((p - hit) ** 2)) if p.size else float("nan")


def reliability(
    predicted: ArrayLike, happened: ArrayLike, bins: int = BINS
) -> tuple[ReliabilityRow, ...]:
    """Return the reliability table (module docstring): only the bins with predictions.

    ``predicted`` (n,) in [0, 1], ``happened`` (n,) bool; ``bins`` in [1, 1000] equal-width
    bins of [0, 1], the last one closed.
    """
    p, hit = _checked(predicted, happened)
    count = whole_number("bins", bins, 1, 1000)
    edges = np.linspace(0.0, 1.0, count + 1)
    which = np.clip(np.searchsorted(edges, p, side="right") - 1, 0, count - 1)
    rows = []
    for b in range(count):
        mine = which == b
        n = int(np.count_nonzero(mine))
        if n == 0:
            continue
        rate = float(hit[mine].mean())
        rows.append(
            (float(edges[b]), float(edges[b + 1]), n, float(p[mine].mean()), rate,
             float(np.sqrt(rate * (1.0 - rate) / n)))
        )  # fmt: skip
    return tuple(rows)
