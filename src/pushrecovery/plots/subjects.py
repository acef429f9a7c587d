"""The per-subject figure of a batch of trials: each trial's smallest margins, by subject.

One panel per axis (ap, ml); along x the subjects of the trials table (``""``: no subjects
table), along y [m] each analysed trial's smallest CoP margin (``min_cop_margin``: to the nearer
edge, Eq. 4) and smallest margin of stability toward the motion (``min_mos_axis``: Hof's b_AP,
b_ML), with each subject's mean ± SD; positive inside the base (docs/base_polygon.md, "Which
margin is which").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.plots.common import check_rows, save_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["MEASURES", "plot_subjects", "subjects_figure"]

#: The plotted columns of the trials table: (column, label, marker, x offset).
MEASURES: tuple[tuple[str, str, str, float], ...] = (
    ("min_cop_margin", "CoP margin (nearer edge, Eq. 4)", "o", -0.15),
    ("min_mos_axis", "MoS toward the motion (Hof's b)", "^", 0.15),
)
_TITLES = {"ap": "anterior-posterior", "ml": "medio-lateral"}


def subjects_figure(rows: Sequence[Mapping[str, Any]]) -> Figure:
    """Return the per-subject figure (module docstring) of a batch's trials table rows.

    ``rows``: the trials table as dicts (``trials.parquet`` read with pyarrow's
    ``to_pylist``); rows whose ``status`` is not ``analysed`` or whose value is null are left
    out.
    """
    rows = check_rows("rows", rows)
    from matplotlib.figure import Figure

    analysed = [row for row in rows if row.get("status") == "analysed"]
    subjects = sorted({str(row.get("subject") or "") for row in analysed})
    figure = Figure(figsize=(max(6.0, 1.2 * len(subjects) + 3.0), 6.5), layout="constrained")
    axes = figure.subplots(2, 1, squeeze=False)[:, 0]
    for ax, axis in zip(axes, ("ap", "ml"), strict=True):
        for column, label, marker, offset in MEASURES:
            for k, subject in enumerate(subjects):
                values = np.array([
                    float(row[column]) for row in analysed
                    if row.get("axis") == axis and str(row.get("subject") or "") == subject
                    and row.get(column) is not None and np.isfinite(float(row[column]))
                ])  # fmt: skip
                if values.size == 0:
                    continue
                x = np.full(values.size, k + offset)
                ax.plot(x, values, marker, color="C0" if offset < 0 else "C1", alpha=0.6,
                        label=label if k == 0 else None)  # fmt: skip
                ax.errorbar(k + offset, values.mean(), yerr=values.std(ddof=1) if values.size > 1
                            else 0.0, fmt="_", color="k", capsize=4, markersize=14)  # fmt: skip
        ax.axhline(0.0, color="0.6", linewidth=0.8)
        ax.set_xticks(range(len(subjects)), [s or "(no subject)" for s in subjects])
        ax.set_xlim(-0.6, len(subjects) - 0.4)
        ax.set_ylabel("smallest margin [m], + inside")
        ax.set_title(f"{_TITLES[axis]}: each trial, and each subject's mean ± SD")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize="small")
    return figure


def plot_subjects(rows: Sequence[Mapping[str, Any]], path: Path) -> Path:
    """Write :func:`subjects_figure` to ``path`` (format from its suffix, default PNG)."""
    require_type("path", path, Path)
    rows = check_rows("rows", rows)
    figure = subjects_figure(rows)
    return save_figure(figure, path.with_suffix(""), [path.suffix.lstrip(".") or "png"])[0]
