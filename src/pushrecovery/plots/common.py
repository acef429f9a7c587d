"""Shared drawing helpers: the phase plane with the CoP region shaded, and saving."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pushrecovery.errors import InputFileError, InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "FALL_COLOUR",
    "HIP_COLOUR",
    "PLOT_FORMATS",
    "RECOVER_COLOUR",
    "check_plot_path",
    "frame_points",
    "new_figure",
    "save_figure",
    "shade_regions",
]

RECOVER_COLOUR = "#2e7d32"
HIP_COLOUR = "#ef6c00"
FALL_COLOUR = "#c62828"
#: Suffixes of the files a plot is written to (its format).
PLOT_FORMATS = frozenset({".png", ".svg", ".pdf"})


def check_plot_path(path: Path) -> Path:
    """Return ``path`` as a Path ending in one of :data:`PLOT_FORMATS` (any case), else raise.

    Raises
    ------
    InvalidParameterError
        Naming the file and the formats.
    """
    path = Path(path)
    if path.suffix.lower() not in PLOT_FORMATS:
        raise InvalidParameterError(
            f"plot must end in one of {sorted(PLOT_FORMATS)}, got {path.name!r}"
        )
    return path


def new_figure(width: float = 6.4, height: float = 4.8) -> tuple[Figure, Axes]:
    """Create a figure with one axes, outside pyplot (no global backend, nothing to close)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    return fig, fig.add_subplot()


def frame_points(ax: Axes, points: np.ndarray, margin: float) -> None:
    """Limit ``ax`` to the (x, y) ``points`` [m] grown by ``margin`` [m], at equal scales."""
    low, high = points.min(axis=0) - margin, points.max(axis=0) + margin
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")


def shade_regions(
    ax: Axes,
    params: BodyParams,
    xlim: tuple[float, float],
    ylim: tuple[float, float],
    *,
    hip: bool = False,
) -> None:
    """Shade the decision surfaces in the (x, ẋ) plane and mark the foot edges.

    Green: CoP balancing, Eq. (4). With ``hip``, orange: the extra states CMP balancing
    recovers (corrected Eq. 15). Red: beyond every balancing strategy.
    """
    omega = params.omega
    xs = np.linspace(*xlim, 200)
    outer = cmp_region(params) if hip else cop_region(params)
    ax.fill_between(xs, omega * (outer.upper - xs), ylim[1], color=FALL_COLOUR, alpha=0.10, lw=0)
    ax.fill_between(xs, ylim[0], omega * (outer.lower - xs), color=FALL_COLOUR, alpha=0.10, lw=0)
    inner = cop_region(params)
    if hip:
        # Only the slivers the hip adds beyond the CoP band.
        for low, high in ((outer.lower, inner.lower), (inner.upper, outer.upper)):
            ax.fill_between(
                xs,
                omega * (low - xs),
                omega * (high - xs),
                color=HIP_COLOUR,
                alpha=0.3,
                lw=0,
                label="CMP balancing, corrected Eq. (15)" if low == outer.lower else None,
            )
    ax.fill_between(
        xs,
        omega * (inner.lower - xs),
        omega * (inner.upper - xs),
        color=RECOVER_COLOUR,
        alpha=0.15,
        lw=0,
        label="CoP balancing, Eq. (4)",
    )
    for region, colour in ((inner, RECOVER_COLOUR), (outer, HIP_COLOUR if hip else None)):
        if colour is None:
            continue
        for edge in (region.lower, region.upper):
            ax.plot(xs, omega * (edge - xs), color=colour, lw=1.0, ls="--")
    for edge in (params.heel, params.toe):
        ax.axvline(edge, color="0.5", lw=0.8, ls=":")
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel("CoM position x [m] (relative to the ankle)")
    ax.set_ylabel("CoM velocity ẋ [m/s]")


def save_figure(fig: Figure, stem: Path, formats: Iterable[str]) -> list[Path]:
    """Save ``fig`` as ``stem.<fmt>`` for each format; return the paths.

    The format is appended to the stem's name, so a stem with a dot (``push0.30``) keeps it.
    """
    paths = []
    try:
        stem.parent.mkdir(parents=True, exist_ok=True)
        for fmt in formats:
            path = stem.with_name(f"{stem.name}.{fmt}")
            fig.savefig(path, dpi=150)
            paths.append(path)
    except OSError as exc:
        raise InputFileError(f"cannot write {stem.parent}: {exc.strerror or exc}") from None
    return paths
