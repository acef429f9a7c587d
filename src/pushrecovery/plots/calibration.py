"""Reliability diagrams: predicted fall probabilities against the observed frequency of falls.

Per study (:class:`~pushrecovery.experiments.calibration.Calibration`), each bin's mean
predicted probability (x) against the frequency of falls among its runs (y) with its binomial
standard error, the diagonal of perfect calibration, and the runs per bin; the legend gives the
Brier scores of the probabilities, of the certain verdict and of the base rate.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from pushrecovery.errors import ParameterTypeError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from pushrecovery.experiments.calibration import Calibration

__all__ = ["reliability_figure"]


def reliability_figure(studies: Sequence[tuple[str, Calibration]]) -> Figure:
    """Return one reliability diagram per (label, study), side by side (module docstring)."""
    from pushrecovery.experiments.calibration import Calibration

    pairs = isinstance(studies, list | tuple) and all(
        isinstance(s, tuple) and len(s) == 2 for s in studies
    )
    if not pairs or not all(isinstance(s[1], Calibration) for s in studies):
        raise ParameterTypeError("studies must be a list of (label, Calibration) pairs")
    from matplotlib.figure import Figure

    figure = Figure(figsize=(5.0 * max(1, len(studies)), 5.5), layout="constrained")
    axes = figure.subplots(1, max(1, len(studies)), squeeze=False)[0]
    for ax, (label, study) in zip(axes, studies, strict=False):
        ax.plot([0.0, 1.0], [0.0, 1.0], color="0.6", linewidth=0.8, label="calibrated")
        if study.bins:
            predicted = [row[3] for row in study.bins]
            observed = [row[4] for row in study.bins]
            error = [row[5] for row in study.bins]
            scores = (
                f"Brier {study.brier:.3f} (certain verdict {study.brier_certain:.3f}, "
                f"base rate {study.brier_base_rate:.3f})"
            )
            ax.errorbar(predicted, observed, yerr=error, fmt="o-", color="C0", capsize=3,
                        label=scores)  # fmt: skip
            for p, o, row in zip(predicted, observed, study.bins, strict=True):
                ax.annotate(str(row[2]), (p, o), textcoords="offset points", xytext=(4, -10),
                            fontsize="x-small", color="0.4")  # fmt: skip
        ax.set_xlim(-0.02, 1.02)
        ax.set_ylim(-0.02, 1.02)
        ax.set_aspect("equal")
        ax.set_xlabel("predicted P(fall) (bin mean)")
        ax.set_ylabel("observed frequency of falls")
        ax.set_title(f"{label}: {int(study.kept.sum())} runs ({study.excluded} undecided)")
        ax.legend(loc="lower right", fontsize="small")
    return figure
