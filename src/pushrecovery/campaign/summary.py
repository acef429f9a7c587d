"""The summary of a campaign: counts, accuracy, confusion matrix, empirical vs analytic boundary.

- ``accuracy``: fraction of pushes where the surfaces' verdict "the controller's strategy (or a
  lesser one) recovers this push" agrees with the simulated outcome (``predicted_recovers``).
- ``confusion``: predicted strategy (rows) against the strategy the run used (columns), labels
  ankle, hip, step, fall; an undecided run counts as fall.
- ``boundary`` (grid campaigns): for every start x0 (and swept body) and direction, the
  empirical critical push, the midpoint of the bracket [largest push that recovered with every
  smaller one in that direction, the next push of the grid], next to the analytic critical
  push of the controller's surface (Eq. 4, corrected Eq. 15 or the single-step limit,
  :func:`~pushrecovery.sim.critical.predicted_critical_velocity`). ``monotone`` is false when a
  push beyond the first failure recovers again.
"""

from __future__ import annotations

import math
from collections import defaultdict
from typing import Any

import numpy as np

from pushrecovery.campaign.spec import CampaignSpec
from pushrecovery.control.base import controller_class
from pushrecovery.sim.critical import predicted_critical_velocity
from pushrecovery.sim.validation import LABELS as VALIDATION_LABELS

__all__ = ["LABELS", "boundary", "summarize"]

#: Rows and columns of the confusion matrix: the strategies, escalating (as ``validate``'s).
LABELS = VALIDATION_LABELS


def _clean(value: float) -> float | None:
    return value if math.isfinite(value) else None


def boundary(spec: CampaignSpec, columns: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Empirical critical pushes against the analytic ones (module docstring)."""
    strategy = controller_class(spec.controller).strategy
    names = [f"param_{name}" for name in spec.sweeps]
    groups: dict[tuple[float, ...], list[int]] = defaultdict(list)
    for i in range(len(columns["x0"])):
        if columns["outcome"][i] == "error":
            continue  # no outcome: neither a recovery nor a fall
        key = (*(float(columns[n][i]) for n in names), float(columns["x0"][i]))
        groups[key].append(i)
    rows = []
    for key, members in groups.items():
        swept, x0 = key[:-1], key[-1]
        params = spec.body(swept)
        for direction, sign in (("forward", 1.0), ("backward", -1.0)):
            picked = [i for i in members if sign * columns["xdot"][i] > 0.0]
            if not picked:
                continue
            picked.sort(key=lambda i: abs(columns["xdot"][i]))
            recovered = [columns["outcome"][i] == "recovered" for i in picked]
            speeds = [float(columns["xdot"][i]) for i in picked]
            first_fail = recovered.index(False) if False in recovered else len(picked)
            # None when even the smallest push of the grid fell: no push is known to recover.
            low = speeds[first_fail - 1] if first_fail > 0 else math.nan
            high = speeds[first_fail] if first_fail < len(picked) else math.nan
            empirical = 0.5 * (low + high) if 0 < first_fail < len(picked) else math.nan
            analytic = predicted_critical_velocity(params, strategy, x0, direction)
            error = (abs(empirical) - abs(analytic)) / abs(analytic) if analytic else math.nan
            rows.append(
                {
                    **{name: value for name, value in zip(spec.sweeps, swept, strict=True)},
                    "x0": x0,
                    "direction": direction,
                    "strategy": strategy,
                    "empirical": _clean(empirical),
                    "bracket": [_clean(low), _clean(high)],
                    "analytic": _clean(analytic),
                    "relative_error": _clean(error),
                    "monotone": not any(recovered[first_fail:]),
                }
            )
    return rows


def summarize(spec: CampaignSpec, table: Any) -> dict[str, Any]:
    """Return the summary JSON of the pushes in ``table`` (a ``pyarrow.Table``)."""
    columns = {
        name: table.column(name).to_numpy(zero_copy_only=False) for name in table.column_names
    }
    outcome, predicted, used = columns["outcome"], columns["predicted"], columns["used"]
    # A push without an outcome (its physics diverged, its worker died) is counted apart and
    # left out of the confusion matrix, the accuracy and the critical pushes.
    decided = outcome != "error"
    counts = np.zeros((len(LABELS), len(LABELS)), dtype=np.int64)
    for p, u in zip(predicted[decided], used[decided], strict=True):
        counts[LABELS.index(p), LABELS.index(u)] += 1
    recovered = outcome == "recovered"
    total = len(outcome)
    judged = int(np.sum(decided))
    agree = int(np.sum((columns["predicted_recovers"] == recovered) & decided))
    return {
        "spec": spec.to_dict(),
        "pushes": total,
        "outcomes": {
            name: int(np.sum(outcome == name))
            for name in ("recovered", "fell", "undecided", "error")
        },
        "predicted": {name: int(np.sum(predicted == name)) for name in LABELS},
        "used": {name: int(np.sum(used == name)) for name in LABELS},
        "accuracy": agree / judged if judged else None,
        "confusion": {
            "labels": list(LABELS),
            "rows": "predicted",
            "columns": "used",
            "counts": counts.tolist(),
        },
        "boundary": boundary(spec, columns) if spec.samples is None else [],
        "steps": _steps(columns, recovered),
    }


def _steps(columns: dict[str, Any], recovered: Any) -> dict[str, Any]:
    """N-step predictions against the steps taken.

    ``predicted``: pushes per predicted number of steps (key "-1": fall); ``taken``: per
    number of steps the run took; ``exact``: the share of recovered pushes predicted to need
    steps that took exactly the predicted number (None without such pushes).
    """
    if "predicted_steps" not in columns:  # a table written before the column existed
        return {"predicted": {}, "taken": {}, "exact": None}
    predicted, taken = columns["predicted_steps"], columns["steps"]
    stepping = recovered & (predicted > 0)
    return {
        "predicted": {str(int(n)): int(np.sum(predicted == n)) for n in np.unique(predicted)},
        "taken": {str(int(n)): int(np.sum(taken == n)) for n in np.unique(taken)},
        "exact": float(np.mean(taken[stepping] == predicted[stepping])) if stepping.any() else None,
    }
