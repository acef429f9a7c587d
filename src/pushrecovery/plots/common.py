"""Shared drawing helpers: the phase plane with the CoP region shaded, and saving."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.arguments import bounded_float, finite_array, finite_vector, require_type
from pushrecovery.errors import InputFileError, InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from pushrecovery.sim.result import SimulationResult

__all__ = [
    "FALL_COLOUR",
    "HIP_COLOUR",
    "PLOT_FORMATS",
    "RECOVER_COLOUR",
    "check_axes",
    "check_formats",
    "check_plot_path",
    "check_rows",
    "figure_outputs",
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
    require_type("path", path, (str, os.PathLike))
    path = Path(path)
    if path.suffix.lower() not in PLOT_FORMATS:
        raise InvalidParameterError(
            f"plot must end in one of {sorted(PLOT_FORMATS)}, got {path.name!r}"
        )
    return path


def check_formats(formats: object) -> tuple[str, ...]:
    """Return ``formats`` as names among :data:`PLOT_FORMATS` (without the dot), or raise."""
    if isinstance(formats, str) or not isinstance(formats, Iterable):
        raise ParameterTypeError(f"formats must be a list of names, got {formats!r:.40}")
    names = tuple(formats)
    if not names or not all(isinstance(f, str) and f".{f}" in PLOT_FORMATS for f in names):
        raise InvalidParameterError(
            f"formats must be names among {sorted(f[1:] for f in PLOT_FORMATS)}, got {names!r:.60}"
        )
    return names


def figure_outputs(
    params: object, formats: object, out: object, runs: object = ()
) -> tuple[tuple[str, ...], Path, list[SimulationResult]]:
    """Check a figure writer's arguments; return its formats, output folder and runs.

    ``params`` a BodyParams, ``formats`` names among :data:`PLOT_FORMATS` (without the dot),
    ``out`` a folder's path, ``runs`` simulation results (an iterable, read once here).
    """
    from pushrecovery.sim.result import SimulationResult

    require_type("params", params, BodyParams)
    require_type("out", out, (str, os.PathLike))
    names = check_formats(formats)
    if isinstance(runs, str) or not isinstance(runs, Iterable):
        raise ParameterTypeError(f"runs must be simulation results, got {type(runs).__name__}")
    results = list(runs)
    for run in results:
        require_type("each of runs", run, SimulationResult)
    return names, Path(out), results  # type: ignore[arg-type]


def check_rows(name: str, rows: object) -> list[Mapping[str, Any]]:
    """Return ``rows`` (a table's rows: mappings of column to value) as a list, or raise."""
    require_type("name", name, str)
    if isinstance(rows, str | bytes | Mapping) or not isinstance(rows, Iterable):
        raise ParameterTypeError(f"{name} must be a list of rows (mappings), got {rows!r:.40}")
    try:
        found = list(rows)
    except TypeError:  # a 0-d array
        raise ParameterTypeError(f"{name} must be a list of rows (mappings)") from None
    if not all(isinstance(row, Mapping) for row in found):
        raise ParameterTypeError(f"{name} must be a list of rows (mappings of column to value)")
    return found


def check_axes(name: str, ax: object) -> None:
    """Raise naming ``name`` unless ``ax`` is a matplotlib ``Axes``."""
    from matplotlib.axes import Axes

    require_type(name, ax, Axes)


def new_figure(width: float = 6.4, height: float = 4.8) -> tuple[Figure, Axes]:
    """Create a figure with one axes, outside pyplot (no global backend, nothing to close)."""
    width = bounded_float("width", width, 1.0, 100.0, "in")
    height = bounded_float("height", height, 1.0, 100.0, "in")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    return fig, fig.add_subplot()


def frame_points(ax: Axes, points: np.ndarray, margin: float) -> None:
    """Limit ``ax`` to the (x, y) ``points`` [m] grown by ``margin`` [m], at equal scales."""
    check_axes("ax", ax)
    points = finite_array("points", points, 1e6, "m")
    if points.ndim != 2 or points.shape[1] != 2 or not len(points):
        raise InvalidParameterError(f"points must be (x, y) rows [m], got shape {points.shape}")
    margin = bounded_float("margin", margin, 0.0, 1e3, "m")
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
    check_axes("ax", ax)
    require_type("params", params, BodyParams)
    xlim = tuple(finite_vector("xlim", xlim, 2, 1e6))
    ylim = tuple(finite_vector("ylim", ylim, 2, 1e6))
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
    from matplotlib.figure import Figure

    require_type("fig", fig, Figure)
    require_type("stem", stem, Path)
    formats = check_formats(formats)
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
