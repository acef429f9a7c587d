r"""The confusion matrix of the strategy predicted against the strategy used, on the 3-D bodies.

Each push of a 3-D campaign (columns of :mod:`~pushrecovery.campaign.pushes.humanoid`, read by
:func:`confusion_from_rows`) has a **predicted** strategy, the ground plane's verdict
(``surfaces.classify.classify``) for the standing CoM and the velocity J/m along ψ, also for
the push corrected for its height (``predicted_corrected``), and a **used** one, what the
whole-body controller did in MuJoCo: ``step`` if a step landed, ``hip`` if the hip law's CMP
offset passed 1 N m, ``ankle`` otherwise, ``fall`` if the body did not come to rest. Where they
differ, :func:`classify_cause` names the reason (:data:`CAUSES`). docs/validation3d.md, "The
confusion matrix: predicted against used strategy", has the grid and the numbers.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

__all__ = [
    "APART",
    "CAUSES",
    "DEFAULT_AZIMUTHS",
    "DEFAULT_FRACTIONS",
    "FAILED_TICKS",
    "LABELS",
    "SATURATED",
    "USED",
    "Confusion3D",
    "ConfusionPush",
    "classify_cause",
    "confusion_counts",
    "confusion_from_rows",
]

#: Rows (predicted) and columns (used) of the matrix, escalating.
LABELS: tuple[str, ...] = ("ankle", "hip", "step", "fall")
#: Runs neither recovered nor fallen, in columns of their own beside the matrix.
APART: tuple[str, ...] = ("undecided", "slipped")
#: Every value of a push's ``used``: a strategy, a fall, or apart.
USED: tuple[str, ...] = LABELS + APART
#: The grid of the documented matrix: every 30°, and fractions of the ankle's critical push.
DEFAULT_AZIMUTHS: tuple[float, ...] = tuple(float(a) for a in range(0, 360, 30))
DEFAULT_FRACTIONS: tuple[float, ...] = (0.5, 0.9, 1.1, 1.5, 2.0)
#: A motor command at this fraction of its limit or more is saturated [-].
SATURATED = 0.999
#: Ticks DAQP must fail in a run (20 ms at 500 Hz) for the QP's failure to count as a cause:
#: the hip motors reach their limits in nearly every hip run (bang-bang by design), and a
#: single failed tick (the last command held 2 ms) does not decide a fall.
FAILED_TICKS = 10
#: Why a push's used strategy differs from the predicted one (:func:`classify_cause`).
CAUSES: Mapping[str, str] = {
    "agree": "used = predicted",
    "torso lever": "the push at the torso's height: used = the verdict for the velocity "
    "× (1 + d/z₀)",
    "lesser sufficed": "recovered with a lesser strategy than predicted (the prediction is "
    "conservative there)",
    "undecided": "the run neither came to rest nor fell within its duration (a column apart)",
    "slipped": "the run came to rest, but a loaded foot slid more than the slip limit (a "
    "column apart: docs/physical_checks.md)",
    "hip shortfall": "predicted hip (plain or corrected), the hip law did not recover it: it "
    "stepped or fell (the hip law's band is narrower than the CMP region)",
    "step failed": "predicted step, a step was begun but the body did not come to rest",
    "no step": "predicted step, the controller never lifted a foot and fell",
    "saturation": "the controller saturated (a motor at its limit and DAQP failed for at least "
    "FAILED_TICKS ticks) and the body fell",
    "other": "none of the above",
}


@dataclass(frozen=True)
class ConfusionPush:
    """One push of the matrix (a campaign row's columns, same names and units).

    Attributes
    ----------
    azimuth : float
        ψ [deg].
    fraction : float
        J / J*_ankle(ψ) [-].
    impulse : float
        J [N s].
    predicted, predicted_corrected, used : str
        Labels of :data:`LABELS`: predicted, predicted for the push's height; used, of
        :data:`USED` (a run undecided or slipped is labelled so).
    outcome : str
        recovered, fell, undecided or slipped.
    steps, lift_offs : int
        Steps that landed, steps begun.
    peak_torque_ratio : float
        Largest abs(motor command) / limit [-].
    failed_ticks : int
        Ticks DAQP did not solve.
    """

    azimuth: float
    fraction: float
    impulse: float
    predicted: str
    predicted_corrected: str
    used: str
    outcome: str
    steps: int
    lift_offs: int
    peak_torque_ratio: float
    failed_ticks: int

    def __post_init__(self) -> None:
        for name, allowed in (("predicted", LABELS), ("predicted_corrected", LABELS),
                              ("used", USED)):  # fmt: skip
            if not isinstance(getattr(self, name), str) or getattr(self, name) not in allowed:
                raise InvalidParameterError(
                    f"{name} must be one of {list(allowed)}, got {getattr(self, name)!r}"
                )

    @property
    def cause(self) -> str:
        """Why ``used`` differs from ``predicted`` (:func:`classify_cause`)."""
        return classify_cause(self)


#: The campaign columns a :class:`ConfusionPush` reads.
COLUMNS: tuple[str, ...] = tuple(f.name for f in fields(ConfusionPush))


def _rank(label: str) -> int:
    return LABELS.index(label)


def classify_cause(push: ConfusionPush) -> str:
    """Return the key of :data:`CAUSES` for ``push``, tried in this order.

    1. ``agree``: used = predicted.
    2. ``undecided``, ``slipped``: the run neither came to rest nor fell, or came to rest on
       feet that slid.
    3. ``lesser sufficed``: it recovered with a strategy below the predicted one.
    4. ``torso lever``: used = the corrected verdict.
    5. ``saturation``: it fell, a motor at :data:`SATURATED` of its limit and DAQP failed on
       at least :data:`FAILED_TICKS` ticks.
    6. ``hip shortfall``: the plain or corrected verdict is hip, the run stepped or fell.
    7. ``step failed`` / ``no step``: the verdict is step and the body fell, with or without
       a step begun.
    8. ``other``.
    """
    require_type("push", push, ConfusionPush)
    predicted, corrected, used = push.predicted, push.predicted_corrected, push.used
    if used == predicted:
        return "agree"
    if used in APART:
        return used
    if used != "fall" and _rank(used) < _rank(predicted):
        return "lesser sufficed"
    if used == corrected:
        return "torso lever"
    saturated = push.peak_torque_ratio >= SATURATED and push.failed_ticks >= FAILED_TICKS
    if used == "fall" and saturated:
        return "saturation"
    if "hip" in (predicted, corrected) and _rank(used) > _rank("hip"):
        return "hip shortfall"
    if "step" in (predicted, corrected) and used == "fall":
        return "step failed" if push.lift_offs > 0 else "no step"
    return "other"


def confusion_counts(
    predicted: Sequence[str], used: Sequence[str], labels: Sequence[str] = LABELS
) -> NDArray[np.int64]:
    """Return the matrix of counts: row = predicted label, column = used label.

    Raises
    ------
    InvalidParameterError
        If the sequences differ in length or hold a label not in ``labels``.
    """
    for name, names in (("predicted", predicted), ("used", used), ("labels", labels)):
        if (
            isinstance(names, str)
            or not isinstance(names, Sequence)
            or not all(isinstance(n, str) for n in names)
        ):
            raise ParameterTypeError(f"{name} must be a list of strategy names")
    if len(predicted) != len(used):
        raise InvalidParameterError(
            f"predicted and used must have the same length, got {len(predicted)} and {len(used)}"
        )
    counts = np.zeros((len(labels), len(labels)), dtype=np.int64)
    index = {label: k for k, label in enumerate(labels)}
    for p, u in zip(predicted, used, strict=True):
        if p not in index or u not in index:
            raise InvalidParameterError(f"labels must be among {list(labels)}, got {p!r}, {u!r}")
        counts[index[p], index[u]] += 1
    return counts


@dataclass(frozen=True)
class Confusion3D:
    """The matrix of one model and controller: predicted (rows) against used (columns).

    Attributes
    ----------
    model : str
        ``biped3d`` or ``g1``.
    pushes : tuple of ConfusionPush
        Every push with an outcome (error rows are left out), in the order given.
    errors : int
        Rows left out because they have no outcome.
    """

    model: str
    pushes: tuple[ConfusionPush, ...]
    errors: int = 0

    @property
    def counts(self) -> NDArray[np.int64]:
        """Predicted (rows) × used (columns), :data:`LABELS`: the runs that recovered or fell."""
        decided = [p for p in self.pushes if p.used in LABELS]
        return confusion_counts([p.predicted for p in decided], [p.used for p in decided])

    @property
    def counts_corrected(self) -> NDArray[np.int64]:
        """The same with the verdict corrected for the push's height as rows."""
        decided = [p for p in self.pushes if p.used in LABELS]
        return confusion_counts([p.predicted_corrected for p in decided], [p.used for p in decided])

    def apart(self, *, corrected: bool = False) -> dict[str, list[int]]:
        """Return the runs of each :data:`APART` outcome per predicted (or corrected) row."""
        found = {name: [0] * len(LABELS) for name in APART}
        for p in self.pushes:
            if p.used in found:
                found[p.used][_rank(p.predicted_corrected if corrected else p.predicted)] += 1
        return found

    @property
    def judged(self) -> int:
        """Pushes with a decided outcome: every push but the undecided ones."""
        return sum(1 for p in self.pushes if p.used != "undecided")

    @property
    def accuracy(self) -> float:
        """Share of the judged pushes whose used strategy is the predicted one (NaN: none).

        A slipped run counts as a disagreement (it did not recover); an undecided one is left
        out.
        """
        total = self.judged
        return float(np.trace(self.counts)) / total if total else float("nan")

    @property
    def accuracy_corrected(self) -> float:
        """The same against the corrected verdict."""
        total = self.judged
        return float(np.trace(self.counts_corrected)) / total if total else float("nan")

    def causes(self) -> dict[str, int]:
        """Return the pushes per cause (:data:`CAUSES` order; ``agree`` included)."""
        found = dict.fromkeys(CAUSES, 0)
        for push in self.pushes:
            found[push.cause] += 1
        return found

    def to_rows(self) -> list[dict[str, Any]]:
        """Return one dict per push: its fields and its ``cause``."""
        return [{**{n: getattr(p, n) for n in COLUMNS}, "cause": p.cause} for p in self.pushes]

    def to_markdown(self, *, corrected: bool = False) -> str:
        """Return the matrix as a markdown table (rows predicted, columns used)."""
        counts = self.counts_corrected if corrected else self.counts
        apart = self.apart(corrected=corrected)
        name = "predicted (corrected)" if corrected else "predicted"
        lines = [f"| {name} \\ used | " + " | ".join(USED) + " |", "|---" * (len(USED) + 1) + "|"]
        for i, (label, row) in enumerate(zip(LABELS, counts.tolist(), strict=True)):
            cells = [*row, *(apart[n][i] for n in APART)]
            lines.append(f"| {label} | " + " | ".join(str(v) for v in cells) + " |")
        return "\n".join(lines)

    def write(self, stem: Path | str) -> tuple[Path, Path]:
        """Write the pushes (with causes) as ``stem.parquet`` and ``stem.csv``; return both."""
        import pyarrow as pa
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq

        stem = Path(stem)
        rows = self.to_rows()
        table = pa.Table.from_pylist(rows) if rows else pa.table({n: [] for n in COLUMNS})
        parquet, csv = stem.with_suffix(".parquet"), stem.with_suffix(".csv")
        pq.write_table(table, parquet)
        pacsv.write_csv(table, csv)
        return parquet, csv


def confusion_from_rows(rows: Iterable[Mapping[str, Any]], model: str) -> Confusion3D:
    """Return the matrix of a 3-D campaign's rows (``table.to_pylist()`` of its pushes).

    Rows whose ``outcome`` is ``error`` are counted apart; a row not recovered is used =
    ``fall`` whatever its ``used`` column says.

    Raises
    ------
    InvalidParameterError
        If a row lacks a column of :data:`COLUMNS` (a 2-D campaign's rows) or holds a label
        not in :data:`LABELS`.
    """
    require_type("model", model, str)
    if isinstance(rows, str | Mapping) or not isinstance(rows, Iterable):
        raise ParameterTypeError(
            f"rows must be campaign rows (mappings), got {type(rows).__name__}"
        )
    rows = list(rows)
    if not all(isinstance(r, Mapping) for r in rows):
        raise ParameterTypeError("rows must be campaign rows (mappings)")
    pushes, errors = [], 0
    for row in rows:
        missing = [name for name in COLUMNS if row.get(name) is None]
        if row.get("outcome") == "error":
            errors += 1
            continue
        if missing:
            raise InvalidParameterError(
                f"rows must be a 3-D campaign's: missing {', '.join(missing)}"
            )
        values = {name: row[name] for name in COLUMNS}
        if values["outcome"] != "recovered":  # tables written before `used` said so too
            values["used"] = values["outcome"] if values["outcome"] in APART else "fall"
        pushes.append(ConfusionPush(**values))
    return Confusion3D(model, tuple(pushes), errors)
