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
  push beyond the first failure recovers again. On the 3-D models the groups are the azimuths
  (``direction`` "ψ deg", ``azimuth``), the pushes J/m along ψ, and the analytic value the
  ground plane's m ω ρ_R(r₀, ψ)/m for ankle and hip
  (:mod:`~pushrecovery.campaign.spec.humanoid`; none for step).
"""

from __future__ import annotations

import math
from collections import defaultdict
from typing import Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.campaign.arrow import column_array
from pushrecovery.campaign.spec import CampaignSpec
from pushrecovery.errors import ParameterTypeError
from pushrecovery.sim.critical import predicted_critical_velocity
from pushrecovery.sim.validation import LABELS as VALIDATION_LABELS
from pushrecovery.surfaces.probability.scores import BINS

__all__ = ["APART", "LABELS", "SummaryTally", "boundary", "summarize"]

#: Rows and columns of the confusion matrix: the strategies, escalating (as ``validate``'s).
LABELS = VALIDATION_LABELS
#: Outcomes counted in columns of their own beside the matrix: neither a strategy nor a fall.
APART = ("undecided", "slipped")


def _clean(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _analytic3d(spec: CampaignSpec, params: Any, azimuth: float) -> float:
    """Return the ground plane's critical push along ``azimuth`` [m/s] (NaN for step)."""
    from pushrecovery.campaign.spec.humanoid import critical_impulse, standing_origin

    if not isinstance(spec.strategy, str) or spec.strategy not in ("ankle", "hip"):
        return math.nan
    origin = standing_origin(spec.source, params)
    return critical_impulse(params, origin, azimuth, spec.strategy) / params.mass


def boundary(spec: CampaignSpec, columns: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Empirical critical pushes against the analytic ones (module docstring)."""
    require_type("spec", spec, CampaignSpec)
    require_type("columns", columns, dict)
    strategy = spec.strategy
    names = [f"param_{name}" for name in spec.sweeps]
    where = "azimuth" if spec.is_3d else "x0"
    groups: dict[tuple[float, ...], list[int]] = defaultdict(list)
    for i in range(len(columns["x0"])):
        if columns["outcome"][i] == "error":
            continue  # no outcome: neither a recovery nor a fall
        key = (*(float(columns[n][i]) for n in names), float(columns[where][i]))
        groups[key].append(i)
    rows = []
    for key, members in groups.items():
        swept, x0 = key[:-1], key[-1]
        params = spec.body(swept)
        ways = [(f"{x0:g} deg", 1.0)] if spec.is_3d else [("forward", 1.0), ("backward", -1.0)]
        for direction, sign in ways:
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
            analytic = (
                _analytic3d(spec, params, x0)
                if spec.is_3d
                else predicted_critical_velocity(params, strategy, x0, direction)
            )
            error = (abs(empirical) - abs(analytic)) / abs(analytic) if analytic else math.nan
            rows.append(
                {
                    **{name: value for name, value in zip(spec.sweeps, swept, strict=True)},
                    where: x0,
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
    require_type("spec", spec, CampaignSpec)
    if not hasattr(table, "column_names"):
        raise ParameterTypeError(f"table must be a pyarrow table, got {type(table).__name__}")
    tally = SummaryTally(spec)
    tally.add(table)
    return tally.result()


class SummaryTally:
    """The summary of a campaign, added up one table of pushes (a batch) at a time.

    Only counts are kept, and for grid campaigns the few columns of the boundary (the swept
    parameters, x0, ẋ and whether the push recovered or has no outcome): a campaign of 10⁸
    random pushes is summarised in the memory of one batch.
    """

    def __init__(self, spec: CampaignSpec) -> None:
        require_type("spec", spec, CampaignSpec)
        self.spec = spec
        self.total = self.judged = self.agree = 0
        self.outcomes = dict.fromkeys(("recovered", "fell", "undecided", "slipped", "error"), 0)
        self.predicted = dict.fromkeys(LABELS, 0)
        self.used = dict.fromkeys((*LABELS, *APART), 0)
        self.counts = np.zeros((len(LABELS), len(LABELS)), dtype=np.int64)
        self.apart = {name: np.zeros(len(LABELS), dtype=np.int64) for name in APART}
        self.steps_predicted: dict[int, int] = defaultdict(int)
        self.steps_taken: dict[int, int] = defaultdict(int)
        self.stepping = self.exact = 0
        self.has_steps = True
        self.boundary_names = [f"param_{name}" for name in spec.sweeps] + ["x0", "xdot"]
        self.boundary_names += ["azimuth"] if spec.is_3d else []
        self.boundary_parts: list[dict[str, np.ndarray]] = []
        # p_recovers against the outcome, per bin of 0.1: pushes, sum of p, recoveries; and the
        # squared errors of p and of the estimate's certain verdict (campaigns with state_sd).
        self.bins = np.zeros((3, BINS))
        self.squared = np.zeros(2)

    def add(self, table: Any) -> None:
        """Count the pushes of ``table`` (a ``pyarrow.Table`` of the campaign's columns)."""
        wanted = ["outcome", "predicted", "used", "predicted_recovers", "predicted_steps"]
        wanted += ["steps", *self.boundary_names]
        columns = {name: column_array(table, name) for name in wanted if name in table.column_names}
        outcome, predicted, used = columns["outcome"], columns["predicted"], columns["used"]
        # A push without an outcome (its physics diverged, its worker died) is counted apart
        # and left out of the confusion matrix, the accuracy and the critical pushes.
        decided = outcome != "error"
        undecided = outcome == "undecided"
        apart = undecided | (outcome == "slipped")
        for p, u in zip(predicted[decided & ~apart], used[decided & ~apart], strict=True):
            self.counts[LABELS.index(p), LABELS.index(u)] += 1
        for name, counts in self.apart.items():
            for p in predicted[outcome == name]:
                counts[LABELS.index(p)] += 1
        recovered = outcome == "recovered"
        judged = decided & ~undecided
        self.total += len(outcome)
        self.judged += int(np.sum(judged))
        self.agree += int(np.sum((columns["predicted_recovers"] == recovered) & judged))
        for name in self.outcomes:
            self.outcomes[name] += int(np.sum(outcome == name))
        for name in LABELS:
            self.predicted[name] += int(np.sum(predicted == name))
            self.used[name] += int(np.sum((used == name) & ~apart))
        for name in APART:  # tables written before these runs had their own `used`
            self.used[name] += int(np.sum(outcome == name))
        self._add_steps(columns, recovered)
        self._add_calibration(table, judged, recovered)
        if self.spec.samples is None:
            part = {name: columns[name] for name in self.boundary_names}
            self.boundary_parts.append(part | {"outcome": outcome})

    def _add_calibration(self, table: Any, judged: Any, recovered: Any) -> None:
        if "p_recovers" not in table.column_names:
            return
        p = column_array(table, "p_recovers")
        certain = np.array(
            [v is not None and bool(v) for v in column_array(table, "estimate_recovers")]
        )
        scored = judged & np.isfinite(p)
        if not scored.any():
            return
        p, hit, certain = p[scored], recovered[scored].astype(np.float64), certain[scored]
        which = np.clip((p * BINS).astype(np.int64), 0, BINS - 1)
        for row, values in enumerate((np.ones_like(p), p, hit)):
            self.bins[row] += np.bincount(which, weights=values, minlength=BINS)
        self.squared += (np.sum((p - hit) ** 2), np.sum((certain - hit) ** 2))

    def _calibration(self) -> dict[str, Any] | None:
        """p_recovers against the outcomes (campaigns with state_sd or latency), or None.

        ``brier``: mean (p − recovered)²; ``brier_estimate_verdict``: the same for the certain
        verdict of the estimate (0 or 1); ``brier_base_rate``: for always predicting the
        share recovered; ``reliability``: per bin of p with pushes, the mean p and the share
        recovered with its binomial standard error. Undecided pushes and errors are left out.
        """
        count = float(self.bins[0].sum())
        if count == 0:
            return None
        rate = float(self.bins[2].sum()) / count
        rows = []
        for b in range(BINS):
            n = self.bins[0, b]
            if n == 0:
                continue
            share = float(self.bins[2, b] / n)
            rows.append({
                "low": b / BINS, "high": (b + 1) / BINS, "pushes": int(n),
                "mean_predicted": float(self.bins[1, b] / n), "recovered": share,
                "standard_error": float(np.sqrt(share * (1.0 - share) / n)),
            })  # fmt: skip
        return {
            "pushes": int(count),
            "brier": float(self.squared[0] / count),
            "brier_estimate_verdict": float(self.squared[1] / count),
            "brier_base_rate": rate * (1.0 - rate),
            "reliability": rows,
        }

    def _add_steps(self, columns: dict[str, Any], recovered: Any) -> None:
        if "predicted_steps" not in columns:  # a table written before the column existed
            self.has_steps = False
            return
        predicted, taken = columns["predicted_steps"], columns["steps"]
        for counter, values in ((self.steps_predicted, predicted), (self.steps_taken, taken)):
            found, counts = np.unique(values, return_counts=True)
            for value, count in zip(found.tolist(), counts.tolist(), strict=True):
                counter[int(value)] += int(count)
        stepping = recovered & (predicted > 0)
        self.stepping += int(np.sum(stepping))
        self.exact += int(np.sum(taken[stepping] == predicted[stepping]))

    def result(self) -> dict[str, Any]:
        """Return the summary JSON of every push added (module docstring)."""
        if self.boundary_parts:
            names = [*self.boundary_names, "outcome"]
            columns = {n: np.concatenate([p[n] for p in self.boundary_parts]) for n in names}
            found = boundary(self.spec, columns)
        else:
            found = []
        return {
            "spec": self.spec.to_dict(),
            "pushes": self.total,
            "outcomes": dict(self.outcomes),
            "predicted": dict(self.predicted),
            "used": dict(self.used),
            "accuracy": self.agree / self.judged if self.judged else None,
            "confusion": {
                "labels": list(LABELS),
                "rows": "predicted",
                "columns": "used",
                "counts": self.counts.tolist(),
                "apart": {name: counts.tolist() for name, counts in self.apart.items()},
            },
            "boundary": found,
            "steps": self._steps(),
            "judged": self.judged,
            "calibration": self._calibration(),
        }

    def _steps(self) -> dict[str, Any]:
        """N-step predictions against the steps taken.

        ``predicted``: pushes per predicted number of steps (key "-1": fall); ``taken``: per
        number of steps the run took; ``exact``: the share of recovered pushes predicted to
        need steps that took exactly the predicted number (None without such pushes).
        """
        if not self.has_steps:
            return {"predicted": {}, "taken": {}, "exact": None}
        return {
            "predicted": {str(n): self.steps_predicted[n] for n in sorted(self.steps_predicted)},
            "taken": {str(n): self.steps_taken[n] for n in sorted(self.steps_taken)},
            "exact": self.exact / self.stepping if self.stepping else None,
        }
