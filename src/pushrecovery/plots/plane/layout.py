"""Axes helpers of the capture-point plane: extents, close-ups, legend, threshold box."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pushrecovery.ground.support import Stance, Support

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


__all__ = [
    "Extent",
]


_FOOT_COLOUR = "0.25"


def _feet(support: Support) -> list[tuple[NDArray[np.float64], bool]]:
    """Outline of each foot in the world frame and whether it carries weight."""
    left = support.foot.transformed(support.left.x, support.left.y, support.left.yaw)
    right = support.foot.mirrored().transformed(support.right.x, support.right.y, support.right.yaw)
    return [
        (left.vertices, support.stance is not Stance.RIGHT),
        (right.vertices, support.stance is not Stance.LEFT),
    ]


def _title(support: Support) -> str:
    title = f"{support.stance.value} support"
    if support.stance is not Stance.DOUBLE and support.yaw != 0.0:
        title += f", foot yawed {math.degrees(support.yaw):.0f}°"
    elif support.stance is Stance.DOUBLE and (support.left.yaw or support.right.yaw):
        title += (
            f", feet yawed {math.degrees(support.left.yaw):.0f}° (left) / "
            f"{math.degrees(support.right.yaw):.0f}° (right)"
        )
    return title


Extent = tuple[float, float, float, float]


def _box(points: NDArray[np.float64]) -> Extent:
    return (
        float(points[:, 0].min()),
        float(points[:, 0].max()),
        float(points[:, 1].min()),
        float(points[:, 1].max()),
    )


def _union(extents: Sequence[Extent]) -> Extent:
    box = np.array(extents)
    return (box[:, 0].min(), box[:, 1].max(), box[:, 2].min(), box[:, 3].max())


def _set_limits(ax: Axes, extent: Extent, pad: float) -> None:
    """Show ``extent`` grown by ``pad`` times its larger side, at equal scales.

    The equal aspect widens one range to the axes' shape (``adjustable="datalim"``); fixed
    limits would be overridden with a warning, so the axes autoscale to exactly this box.
    """
    xmin, xmax, ymin, ymax = extent
    pad *= max(xmax - xmin, ymax - ymin)
    ax.dataLim.set_points(np.array([[xmin - pad, ymin - pad], [xmax + pad, ymax + pad]]))
    ax.ignore_existing_data_limits = False
    ax.margins(0.0)
    ax.autoscale(enable=True)
    ax.autoscale_view()


def _mark_close_up(ax: Axes, extent: Extent, pad: float) -> None:
    from matplotlib.patches import Rectangle

    xmin, xmax, ymin, ymax = extent
    pad *= max(xmax - xmin, ymax - ymin)
    xmin, xmax, ymin, ymax = xmin - pad, xmax + pad, ymin - pad, ymax + pad
    ax.add_patch(
        Rectangle(
            (xmin, ymin),
            xmax - xmin,
            ymax - ymin,
            fill=False,
            ec="0.15",
            lw=1.0,
            ls=(0, (1.5, 1.5)),
            zorder=6,
        )
    )


def _legend_handles(ax: Axes) -> list[Artist]:
    from matplotlib.lines import Line2D

    handles, _ = ax.get_legend_handles_labels()
    return [
        *handles,
        Line2D([], [], color=_FOOT_COLOUR, lw=1.3, label="stance foot (+ ankle)"),
        Line2D([], [], color=_FOOT_COLOUR, lw=1.1, ls=(0, (3, 2)), label="lifted foot"),
        Line2D([], [], color="k", marker="x", ls="none", ms=7, mew=1.5, label="CoM before push"),
    ]


def _thresholds_box(ax: Axes, lines: list[str], x: float, y: float, va: str) -> None:
    ax.text(
        x,
        y,
        "\n".join(lines),
        transform=ax.transAxes,
        fontsize=7.5,
        family="monospace",
        va=va,
        ha="center",
        bbox={"facecolor": "white", "edgecolor": "0.75", "pad": 3.0},
    )


def _new_figure(width: float, height: float) -> Figure:
    """Create a figure outside pyplot's registry (nothing to close), drawn by Agg when saved."""
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")
