"""The confusion matrix of the 3-D bodies: predicted against used strategy, and where.

Left: the matrix (rows the strategy the library predicts, columns the one the whole-body
controller used; counts, the diagonal agreeing). Right: every push seen from above, the angle
its azimuth ψ (0 forward +x, 90 left +y, counter-clockwise) and the radius its size as a
fraction of the ankle's predicted critical impulse along ψ (the dashed circle, 1, is the
support polygon's edge); the colour is the strategy used, a filled dot where it is the
predicted one and a cross where it is not.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, cast

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.experiments.confusion3d import APART, LABELS, USED, Confusion3D
from pushrecovery.plots.common import FALL_COLOUR, HIP_COLOUR, RECOVER_COLOUR

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from matplotlib.projections.polar import PolarAxes

__all__ = ["USED_COLOURS", "confusion3d_figure"]

#: One colour per used strategy.
USED_COLOURS = {"ankle": RECOVER_COLOUR, "hip": HIP_COLOUR, "step": "#1565c0", "fall": FALL_COLOUR,
                "undecided": "#9e9e9e", "slipped": "#8e24aa"}  # fmt: skip


def confusion3d_figure(result: Confusion3D, *, corrected: bool = False) -> Figure:
    """Return the figure of ``result`` (module docstring) as a matplotlib Figure.

    With ``corrected`` the rows of the matrix and the dots' agreement are the verdict
    corrected for the push's height (``predicted_corrected``).
    """
    require_type("result", result, Confusion3D)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 5.2))
    grid = fig.add_gridspec(1, 2, width_ratios=(1.0, 1.2))
    ax = fig.add_subplot(grid[0, 0])
    apart = result.apart(corrected=corrected)
    matrix = result.counts_corrected if corrected else result.counts
    # The runs neither recovered nor fallen in columns of their own, right of a line.
    counts = np.column_stack([matrix, *(apart[name] for name in APART)])
    ax.imshow(counts, cmap="Blues")
    ax.axvline(len(LABELS) - 0.5, color="black", linewidth=1.5)
    peak = max(1, int(counts.max()))
    for i in range(len(LABELS)):
        for j in range(len(USED)):
            value = int(counts[i, j])
            ax.text(j, i, str(value), ha="center", va="center",
                    color="white" if value > peak / 2 else "black")  # fmt: skip
    ax.set_xticks(range(len(USED)), USED, rotation=30)
    ax.set_yticks(range(len(LABELS)), LABELS)
    ax.set_xlabel("used (whole-body controller)")
    ax.set_ylabel("predicted (corrected)" if corrected else "predicted (ground plane)")
    accuracy = result.accuracy_corrected if corrected else result.accuracy
    ax.set_title(f"{result.model}: {len(result.pushes)} pushes, agreement {accuracy:.2f}")
    polar = cast("PolarAxes", fig.add_subplot(grid[0, 1], projection="polar"))
    for label in USED:
        for agree in (True, False):
            picked = [
                p
                for p in result.pushes
                if p.used == label
                and ((p.predicted_corrected if corrected else p.predicted) == p.used) == agree
            ]
            if not picked:
                continue
            polar.scatter(
                [math.radians(p.azimuth) for p in picked],
                [p.fraction for p in picked],
                c=USED_COLOURS[label],
                marker="o" if agree else "x",
                s=28,
                label=f"used {label}" + ("" if agree else " (not predicted)"),
            )
    edge = [math.radians(a) for a in range(0, 361, 5)]
    polar.plot(edge, [1.0] * len(edge), "--", color="0.4", lw=1.0, label="ankle limit (1)")
    largest = max((p.fraction for p in result.pushes), default=1.0)
    polar.set_rlim(0.0, 1.08 * max(1.0, largest))
    polar.set_theta_zero_location("E")
    polar.set_theta_direction(1)
    polar.set_rlabel_position(112.5)
    polar.set_title("push / ankle critical push, by azimuth (0° forward, 90° left)", pad=16)
    polar.legend(loc="center left", bbox_to_anchor=(1.08, 0.5), fontsize="small")
    fig.subplots_adjust(left=0.07, right=0.78, wspace=0.35)
    return fig
