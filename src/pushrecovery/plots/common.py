"""Shared drawing helpers: the phase plane with the CoP region shaded, and saving."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cop import cop_region

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["FALL_COLOUR", "RECOVER_COLOUR", "new_figure", "save_figure", "shade_cop_region"]

RECOVER_COLOUR = "#2e7d32"
FALL_COLOUR = "#c62828"


def new_figure(width: float = 6.4, height: float = 4.8) -> tuple[Figure, Axes]:
    """Create a figure with one axes, drawn off-screen (Agg)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(width, height), layout="constrained")
    return fig, ax


def shade_cop_region(
    ax: Axes, params: BodyParams, xlim: tuple[float, float], ylim: tuple[float, float]
) -> None:
    """Shade Eq. (4) in the (x, ẋ) plane: green inside, red outside; mark the foot edges."""
    omega, region = params.omega, cop_region(params)
    xs = np.linspace(*xlim, 200)
    lower, upper = omega * (region.lower - xs), omega * (region.upper - xs)
    ax.fill_between(
        xs,
        lower,
        upper,
        color=RECOVER_COLOUR,
        alpha=0.15,
        lw=0,
        label="CoP balancing region, Eq. (4)",
    )
    ax.fill_between(xs, upper, ylim[1], color=FALL_COLOUR, alpha=0.10, lw=0)
    ax.fill_between(xs, ylim[0], lower, color=FALL_COLOUR, alpha=0.10, lw=0)
    for edge in (region.lower, region.upper):
        ax.plot(xs, omega * (edge - xs), color=RECOVER_COLOUR, lw=1.0, ls="--")
        ax.axvline(edge, color="0.5", lw=0.8, ls=":")
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel("CoM position x [m] (relative to the ankle)")
    ax.set_ylabel("CoM velocity ẋ [m/s]")


def save_figure(fig: Figure, stem: Path, formats: Iterable[str]) -> list[Path]:
    """Save ``fig`` as ``stem.<fmt>`` for each format; close it; return the paths."""
    import matplotlib.pyplot as plt

    stem.parent.mkdir(parents=True, exist_ok=True)
    paths = []
    for fmt in formats:
        path = stem.with_suffix(f".{fmt}")
        fig.savefig(path, dpi=150)
        paths.append(path)
    plt.close(fig)
    return paths
