"""The per-study figure of a batch of trials: each trial's smallest margins, by condition.

Two rows of panels, the axes (ap, ml), and two columns, the measures of the trials table
(:class:`~pushrecovery.campaign.trials.rows.TrialRow`): the smallest margin of stability toward
the motion (``min_mos_axis``: Hof's b_AP, b_ML) and the smallest CoP margin
(``min_cop_margin``: to the nearer edge, Eq. 4), in metres, positive inside the base
(docs/base_polygon.md, "Which margin is which"). Along x the conditions (``condition``, from
the subjects table), sorted by name; without any condition, one group, ``all``; trials
without one among trials with one, the group ``(none)``. In each condition: every analysed
trial a dot (left), each subject's mean a diamond joined to the same subject's means in the
other conditions by a grey line (middle), and the mean ± SD over the condition's trials a
black square and bar (right; SD with ddof 1, none for one trial).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.plots.common import check_rows, save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["ALL", "MEASURES", "NONE", "conditions", "plot_study", "study_figure"]

#: The plotted columns of the trials table: (column, y label).
MEASURES: tuple[tuple[str, str], ...] = (
    ("min_mos_axis", "smallest MoS toward the motion [m]"),
    ("min_cop_margin", "smallest CoP margin (nearer edge) [m]"),
)
#: The group of a study without conditions, and of a trial without one among others.
ALL, NONE = "all", "(none)"
_TITLES = {"ap": "anterior-posterior", "ml": "medio-lateral"}
#: x offsets within a condition: the trials, each subject's mean, the condition's mean ± SD.
_TRIALS, _SUBJECTS, _MEAN = -0.22, 0.0, 0.22


def conditions(rows: Sequence[Mapping[str, Any]]) -> dict[str, str]:
    """Return each analysed trial's group (module docstring), by trial name."""
    rows = check_rows("rows", rows)
    analysed = [row for row in rows if row.get("status") == "analysed"]
    given = any(row.get("condition") for row in analysed)
    return {
        str(row["trial"]): str(row.get("condition") or (NONE if given else ALL)) for row in analysed
    }


def study_figure(rows: Sequence[Mapping[str, Any]]) -> Figure:
    """Return the per-study figure (module docstring) of a batch's trials table rows.

    ``rows``: the trials table as dicts (``trials.parquet`` read with pyarrow's
    ``to_pylist``); rows whose ``status`` is not ``analysed`` or whose value is null are left
    out.
    """
    rows = check_rows("rows", rows)
    from matplotlib.figure import Figure

    group = conditions(rows)
    names = sorted(set(group.values()))
    figure = Figure(figsize=(max(7.0, 2.2 * len(names) + 3.0), 6.5), layout="constrained")
    grid = figure.subplots(2, 2, squeeze=False, sharex=True)
    for i, axis in enumerate(("ap", "ml")):
        mine = [r for r in rows if r.get("axis") == axis and str(r.get("trial")) in group]
        for j, (column, label) in enumerate(MEASURES):
            ax = grid[i, j]
            _panel(ax, mine, column, names, group)
            ax.axhline(0.0, color="0.6", linewidth=0.8)
            ax.set_xticks(range(len(names)), names)
            ax.set_xlim(-0.6, len(names) - 0.4)
            ax.set_ylabel(label)
            ax.set_title(f"{_TITLES[axis]}: smallest {'MoS' if j == 0 else 'CoP margin'}")
            if i == 1:
                ax.set_xlabel("condition")
    if grid[0, 0].get_legend_handles_labels()[0]:
        grid[0, 0].legend(loc="best", fontsize="small")
    figure.suptitle("Each trial's smallest margin by condition (+ inside the base)")
    return figure


def _panel(
    ax: Axes, rows: list[Mapping[str, Any]], column: str, names: list[str], group: dict[str, str]
) -> None:
    """Draw one measure of one axis: trials, subjects' means and the mean ± SD per condition."""
    values = {
        (str(r["trial"]), str(r.get("subject") or "")): float(r[column]) for r in rows
        if r.get(column) is not None and np.isfinite(float(r[column]))
    }  # fmt: skip
    for k, name in enumerate(names):
        mine = np.array([v for (trial, _), v in values.items() if group[trial] == name])
        if mine.size == 0:
            continue
        spread = np.linspace(-0.08, 0.08, mine.size) if mine.size > 1 else np.zeros(1)
        ax.plot(k + _TRIALS + spread, mine, "o", color="C0", alpha=0.5, markersize=4,
                label="trial" if k == 0 else None)  # fmt: skip
        sd = mine.std(ddof=1) if mine.size > 1 else 0.0
        ax.errorbar(k + _MEAN, mine.mean(), yerr=sd, fmt="s", color="k", capsize=4,
                    label="mean ± SD" if k == 0 else None)  # fmt: skip
    for s, subject in enumerate(sorted({who for _, who in values})):
        means = np.full(len(names), np.nan)
        for k, name in enumerate(names):
            theirs = [v for (t, who), v in values.items() if who == subject and group[t] == name]
            means[k] = np.mean(theirs) if theirs else np.nan
        ax.plot(np.arange(len(names)) + _SUBJECTS, means, "-D", color="0.45", markersize=4,
                linewidth=0.8, label="each subject's mean" if s == 0 else None)  # fmt: skip


def plot_study(rows: Sequence[Mapping[str, Any]], path: Path) -> Path:
    """Write :func:`study_figure` to ``path`` (format from its suffix, default PNG)."""
    require_type("path", path, Path)
    rows = check_rows("rows", rows)
    figure = study_figure(rows)
    return save_figure(figure, path.with_suffix(""), [path.suffix.lstrip(".") or "png"])[0]
