"""Plots of an analysed trial: time series with the regions shaded, and the phase portrait.

Every mark has a legend entry. Frames with no verdict (flight, a CoP beyond the base, a base
the CoP contradicts, missing data) are drawn grey with their reason, never in a strategy's
colour. The plane (the feet seen from above) is :mod:`pushrecovery.plots.plane.trial`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.recording import AXES
from pushrecovery.analysis.trial import TrialAnalysis
from pushrecovery.arguments import require_type
from pushrecovery.plots.common import FALL_COLOUR, HIP_COLOUR, RECOVER_COLOUR, save_figure
from pushrecovery.surfaces.classify import Strategy

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "STRATEGY_COLOURS",
    "WITHHELD_COLOURS",
    "phase_coordinates",
    "phase_portrait_figure",
    "plot_phase_portrait",
    "plot_time_series",
    "strategy_label",
    "time_series_figure",
    "withheld_frames",
]

STEP_COLOUR = "#1565c0"
XCOM_COLOUR = "#6a1b9a"
#: One colour per strategy, shared by the bands, the strips and the points.
STRATEGY_COLOURS = {
    Strategy.ANKLE.value: RECOVER_COLOUR,
    Strategy.HIP.value: HIP_COLOUR,
    Strategy.STEP.value: STEP_COLOUR,
    Strategy.FALL.value: FALL_COLOUR,
}
#: Greys of the frames with no verdict, per reason (keys of :func:`withheld_frames`).
WITHHELD_COLOURS = {
    "flight": "#90a4ae",
    "cop_outside": "0.55",
    "rejected": "0.7",
    "missing": "0.82",
}
_TITLES = {"ap": "anterior-posterior (forward +)", "ml": "medio-lateral (left +)"}
#: The edges of each axis's base, for the labels: (base_min, base_max).
EDGE_NAMES = {"ap": ("rear (heel) edge", "front (toe) edge"), "ml": ("right edge", "left edge")}


def _figure(rows: int, cols: int, width: float, height: float) -> tuple[Figure, Any]:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    return figure, figure.subplots(rows, cols, squeeze=False)


def _median(values: np.ndarray, default: float = 0.0) -> float:
    """Median of the finite values; ``default`` when there are none (no All-NaN warning)."""
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else default


def _save(fig: Figure, path: Path) -> Path:
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".") or "png"])[0]


def figure_legend(fig: Figure, **options: Any) -> None:
    """One legend under the figure with every labelled mark of every panel, once each."""
    entries: dict[str, Any] = {}
    for ax in fig.axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    if entries:
        fig.legend(list(entries.values()), list(entries), loc="outside lower center", **options)


def strategy_label(name: str) -> str:
    """Legend text of a strategy's colour."""
    require_type("name", name, str)
    return f"needs {name}"


def withheld_frames(
    analysis: TrialAnalysis, column: str = "strategy"
) -> dict[str, tuple[str, NDArray[np.bool_]]]:
    """Frames with no verdict in ``column``, per reason: key → (legend text, mask).

    ``column`` is a strategy column: ``"strategy"`` (the frame's), ``"ap_strategy"``,
    ``"ml_strategy"`` or ``"strategy_2d"``. Each frame counts under its first reason: flight, a
    CoP beyond the base, a base the CoP contradicts (the whole trial unclassified), missing data
    (or, for ``strategy_2d``, a base with no feet to classify against).
    """
    require_type("analysis", analysis, TrialAnalysis)
    columns = analysis.columns
    strategy = columns[column]
    none = ~np.isin(strategy.astype(str), list(STRATEGY_COLOURS))
    flight = none & columns["flight"].astype(bool)
    outside = none & columns["cop_outside_base"].astype(bool) & ~flight
    rest = none & ~flight & ~outside
    rejected = analysis.summary.checks.base_rejected
    empty = np.zeros_like(none)
    return {
        "flight": ("no verdict: flight (no ground contact)", flight),
        "cop_outside": ("no verdict: CoP beyond the base by > 2 cm", outside),
        "rejected": ("no verdict: base contradicted by the CoP", rest if rejected else empty),
        "missing": ("no verdict: CoM, capture point or base missing", empty if rejected else rest),
    }


def _events(analysis: TrialAnalysis) -> list[tuple[float, str, str]]:
    """Return the summary's events: (time [s], kind, legend text), in time order."""
    events = analysis.summary.events
    found: list[tuple[float, str, str]] = []
    if events.onset.time is not None:
        found.append((float(events.onset.time), "onset", "push onset"))
    for event in (found_event.event for found_event in events.foot_events):
        found.append((float(event.time), event.kind, f"{event.foot} {event.kind}"))
    return sorted(found)


def time_series_figure(analysis: TrialAnalysis) -> Figure:
    """Draw CoM, CoP, CMP and capture point over time, per axis, with the regions shaded.

    Green band: the base of support (CoP region, Eq. 4); orange: what the hip strategy adds
    (corrected Eq. 15); the strip under each panel shows the strategy each frame needs (grey:
    no verdict, with its reason); flight phases are shaded grey, events marked by vertical
    lines. Positions [m] are relative to the median stance ankle (ap) or base centre (ml).
    """
    require_type("analysis", analysis, TrialAnalysis)
    columns = analysis.columns
    time = columns["time"]
    fig, axes = _figure(2, 1, 9.0, 7.2)
    for ax, axis in zip(axes[:, 0], AXES, strict=True):
        # ap relative to the ankle (the paper's origin); ml to the middle of the base.
        centre = 0.5 * (columns[f"{axis}_base_min"] + columns[f"{axis}_base_max"])
        origin = _median(columns[f"{axis}_ankle"] if axis == "ap" else centre)
        lower = columns[f"{axis}_base_min"] - origin
        upper = columns[f"{axis}_base_max"] - origin
        reach = columns[f"{axis}_margin_cmp"] - columns[f"{axis}_margin_cop"]
        if np.isfinite(reach).any():
            ax.fill_between(
                time,
                lower - reach,
                upper + reach,
                color=HIP_COLOUR,
                alpha=0.15,
                lw=0,
                label="CMP region (hip), corr. Eq. (15)",
            )
        ax.fill_between(
            time,
            lower,
            upper,
            color=RECOVER_COLOUR,
            alpha=0.18,
            lw=0,
            label="base of support (CoP region, Eq. 4)",
        )
        for start, end in _spans(time, columns["flight"].astype(bool)):
            ax.axvspan(start, end, color=WITHHELD_COLOURS["flight"], alpha=0.25, lw=0,
                       label="flight (no ground contact)")  # fmt: skip
        ax.plot(time, columns[f"{axis}_com"] - origin, color="0.2", lw=1.0, label="CoM")
        ax.plot(time, columns[f"{axis}_cop"] - origin, color="0.55", lw=0.7, label="CoP")
        if np.isfinite(columns[f"{axis}_cmp"]).any():
            ax.plot(
                time, columns[f"{axis}_cmp"] - origin, color=HIP_COLOUR, lw=0.6, ls=":", label="CMP"
            )
        ax.plot(
            time,
            columns[f"{axis}_capture_point"] - origin,
            color=XCOM_COLOUR,
            lw=1.2,
            label="capture point ξ (XCoM)",
        )
        _mark_events(ax, analysis)
        _strategy_strip(ax, analysis, axis)
        ax.set_title(_title(analysis, axis), fontsize=10)
        ax.set_ylabel(
            "ap position − median stance ankle [m]"
            if axis == "ap"
            else "ml position − median base centre [m]"
        )
        _limit(ax, columns, axis, origin)
    axes[-1, 0].set_xlabel("time [s]   (strip at the bottom: the strategy each frame needs)")
    figure_legend(fig, fontsize=7, ncols=4)
    return fig


def plot_time_series(analysis: TrialAnalysis, path: Path) -> Path:
    """Write :func:`time_series_figure` to ``path`` (format from its suffix, default PNG)."""
    require_type("analysis", analysis, TrialAnalysis)
    return _save(time_series_figure(analysis), path)


def plot_phase_portrait(analysis: TrialAnalysis, path: Path) -> Path:
    """Write :func:`phase_portrait_figure` to ``path`` (format from its suffix, default PNG)."""
    require_type("analysis", analysis, TrialAnalysis)
    return _save(phase_portrait_figure(analysis), path)


def _title(analysis: TrialAnalysis, axis: str) -> str:
    """Return the axis and the most demanding strategy its frames need (or no verdict)."""
    needs = analysis.summary.directions[axis].most_demanding
    return f"{_TITLES[axis]}: needs {needs}" if needs else f"{_TITLES[axis]}: no verdict"


_EVENT_STYLES = {
    "onset": ("#00838f", "-."),
    "foot-off": (STEP_COLOUR, "--"),
    "foot-contact": (STEP_COLOUR, ":"),
}


def _mark_events(ax: Axes, analysis: TrialAnalysis) -> None:
    """Vertical lines at the push onset and the foot events."""
    for when, kind, text in _events(analysis):
        colour, style = _EVENT_STYLES.get(kind, ("0.3", "-."))
        ax.axvline(when, color=colour, ls=style, lw=0.9, label=text)


def _spans(time: np.ndarray, mask: NDArray[np.bool_]) -> list[tuple[float, float]]:
    """(start, end) times [s] of each run of ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(float(time[a]), float(time[b])) for a, b in zip(starts, ends, strict=True)]


def _limit(ax: Axes, columns: dict[str, np.ndarray], axis: str, origin: float) -> None:
    """Zoom on the base and the capture point, not on a fall's runaway tail."""
    spans = [columns[f"{axis}_base_min"], columns[f"{axis}_base_max"], columns[f"{axis}_com"]]
    values = np.concatenate([np.asarray(s, dtype=float) for s in spans]) - origin
    values = values[np.isfinite(values)]
    if len(values):
        low, high = float(values.min()), float(values.max())
        pad = 0.6 * (high - low) + 0.02
        ax.set_ylim(low - pad, high + pad)


def _strategy_strip(ax: Axes, analysis: TrialAnalysis, axis: str) -> None:
    """Colour the bottom of a panel by the strategy each frame needs (grey: no verdict)."""
    from matplotlib.transforms import blended_transform_factory

    time, strategy = analysis.columns["time"], analysis.columns[f"{axis}_strategy"]
    transform = blended_transform_factory(ax.transData, ax.transAxes)
    marks = [(strategy_label(n), c, strategy == n) for n, c in STRATEGY_COLOURS.items()]
    marks += [
        (text, WITHHELD_COLOURS[key], mask)
        for key, (text, mask) in withheld_frames(analysis, f"{axis}_strategy").items()
    ]
    for label, colour, mask in marks:
        if mask.any():
            ax.fill_between(time, 0.0, 0.04, where=mask, color=colour, transform=transform,
                            lw=0, step="mid", label=label)  # fmt: skip


def phase_coordinates(analysis: TrialAnalysis, axis: str) -> tuple[np.ndarray, np.ndarray]:
    """Return the phase portrait's coordinates of every frame along ``axis``.

    Returns
    -------
    position : ndarray
        The capture point ξ in the frame's own base, (ξ − base_min) / (base_max − base_min)
        [–]: 0 at the rear (ap) or right (ml) edge, 1 at the front or left edge; NaN where the
        base is unknown.
    velocity : ndarray
        CoM velocity [m/s].
    """
    require_type("analysis", analysis, TrialAnalysis)
    columns = analysis.columns
    low, high = columns[f"{axis}_base_min"], columns[f"{axis}_base_max"]
    length = high - low
    with np.errstate(invalid="ignore", divide="ignore"):
        position = np.where(length > 0, (columns[f"{axis}_capture_point"] - low) / length, np.nan)
    return position, columns[f"{axis}_com_velocity"]


def phase_portrait_figure(analysis: TrialAnalysis) -> Figure:
    """Plot each axis's capture point within the frame's own base against the CoM velocity.

    The horizontal coordinate is :func:`phase_coordinates`' normalised position: the frame's
    own base spans [0, 1], so the CoP region's edges (Eq. 4) are the vertical lines at 0 and 1
    for every frame and a point coded ankle lies between them. The hip strategy reaches r / L
    beyond them (r the CMP reach of corrected Eq. 15, L the frame's base length): the orange
    lines, a band when L varies. Points are coloured by the strategy the frame needs; frames
    with no verdict grey, with their reason; frames with no base are not drawn (counted in
    the legend).
    """
    require_type("analysis", analysis, TrialAnalysis)
    columns = analysis.columns
    fig, axes = _figure(1, 2, 11.0, 5.6)
    for ax, axis in zip(axes[0], AXES, strict=True):
        position, velocity = phase_coordinates(analysis, axis)
        drawable = np.isfinite(position) & np.isfinite(velocity)
        strategy = columns[f"{axis}_strategy"]
        ax.axvspan(0.0, 1.0, color=RECOVER_COLOUR, alpha=0.12, lw=0,
                   label="frame's base: ankle (CoP) region, Eq. (4)")  # fmt: skip
        for edge in (0.0, 1.0):
            ax.axvline(edge, color=RECOVER_COLOUR, lw=1.0, ls="--")
        _hip_edges(ax, analysis, axis)
        marks = [(strategy_label(n), c, strategy == n, 3.0) for n, c in STRATEGY_COLOURS.items()]
        marks += [
            (text, WITHHELD_COLOURS[key], mask, 2.0)
            for key, (text, mask) in withheld_frames(analysis, f"{axis}_strategy").items()
        ]
        for label, colour, mask, size in marks:
            shown = mask & drawable
            hidden = int((mask & ~drawable).sum())
            if hidden:
                label += f" ({hidden} frames not drawn: no ξ or no base)"
            if shown.any():
                ax.plot(position[shown], velocity[shown], ".", ms=size, color=colour, label=label)
            elif hidden:
                ax.plot([], [], ".", ms=size, color=colour, label=label)
        _phase_limits(ax, position[drawable], velocity[drawable])
        ax.set_title(_title(analysis, axis), fontsize=10)
        low, high = EDGE_NAMES[axis]
        ax.set_xlabel(
            f"capture point ξ_{axis} in the frame's base [–]\n"
            f"(ξ − base min) / base length: 0 = {low}, 1 = {high}"
        )
        ax.set_ylabel(f"CoM velocity along {axis} [m/s]")
    figure_legend(fig, fontsize=7, ncols=2, markerscale=3)
    return fig


def _hip_edges(ax: Axes, analysis: TrialAnalysis, axis: str) -> None:
    """Draw the CMP region's edges, r / L beyond the base's, as lines or the band they sweep."""
    columns = analysis.columns
    length = columns[f"{axis}_base_max"] - columns[f"{axis}_base_min"]
    with np.errstate(invalid="ignore", divide="ignore"):
        reach = (columns[f"{axis}_margin_cmp"] - columns[f"{axis}_margin_cop"]) / length
    reach = reach[np.isfinite(reach)]
    if not reach.size or reach.max() <= 0:
        return
    near, far = float(reach.min()), float(reach.max())
    label = f"{axis}: hip (CMP) region edge, corr. Eq. (15): r / L beyond the base"
    if far - near > 1e-3:
        label += f" ({near:.2f}–{far:.2f}, band: L varies)"
        for a, b in ((-far, -near), (1 + near, 1 + far)):
            ax.axvspan(a, b, color=HIP_COLOUR, alpha=0.25, lw=0, label=label)
            label = "_"
    for edge in (-near, 1 + near):
        ax.axvline(edge, color=HIP_COLOUR, lw=1.0, ls=":", label=label)
        label = "_"


def _phase_limits(ax: Axes, position: np.ndarray, velocity: np.ndarray) -> None:
    """Show the base and most points; a fall's runaway tail may leave the frame."""
    low, high = -0.5, 1.5
    if position.size:
        low = min(low, float(np.quantile(position, 0.01)) - 0.1)
        high = max(high, float(np.quantile(position, 0.99)) + 0.1)
    low, high = max(low, -4.0), min(high, 5.0)
    ax.set_xlim(low, high)
    velocity = velocity[(position >= low) & (position <= high)]
    if velocity.size:
        vmax = max(float(np.abs(velocity).max()), 0.05) * 1.3
        ax.set_ylim(-vmax, vmax)
