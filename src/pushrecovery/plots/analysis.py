"""Plots of an analysed trial: time series with the regions shaded, and the phase portrait."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.analysis.recording import AXES
from pushrecovery.analysis.trial import TrialAnalysis
from pushrecovery.plots.common import FALL_COLOUR, HIP_COLOUR, RECOVER_COLOUR, save_figure
from pushrecovery.surfaces.classify import Strategy

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["STRATEGY_COLOURS", "plot_phase_portrait", "plot_time_series"]

STEP_COLOUR = "#1565c0"
#: One colour per strategy, shared by the bands and the phase-portrait points.
STRATEGY_COLOURS = {
    Strategy.ANKLE.value: RECOVER_COLOUR,
    Strategy.HIP.value: HIP_COLOUR,
    Strategy.STEP.value: STEP_COLOUR,
    Strategy.FALL.value: FALL_COLOUR,
}
_TITLES = {"ap": "anterior-posterior (forward +)", "ml": "medio-lateral (left +)"}


def _figure(rows: int, cols: int, width: float, height: float):  # type: ignore[no-untyped-def]
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    return figure, figure.subplots(rows, cols, squeeze=False)


def _median(values: np.ndarray, default: float = 0.0) -> float:
    """Median of the finite values; ``default`` when there are none (no All-NaN warning)."""
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else default


def _legend(ax: Any, **options: Any) -> None:
    """Draw a legend when something is labelled (a trial with no valid frame has nothing)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(**options)


def plot_time_series(analysis: TrialAnalysis, path: Path) -> Path:
    """Draw CoM, CoP, CMP and capture point over time, per axis, with the regions shaded.

    Green band: the base of support (CoP region, Eq. 4); orange: what the hip strategy adds
    (corrected Eq. 15); the strip under each panel shows the strategy each frame needs.
    Positions [m] are relative to the median stance ankle (ap) or base centre (ml).
    """
    columns, summary = analysis.columns, analysis.summary
    time = columns["time"]
    fig, axes = _figure(2, 1, 9.0, 6.4)
    for ax, axis in zip(axes[:, 0], AXES, strict=True):
        # ap relative to the ankle (the paper's origin); ml to the middle of the base.
        centre = 0.5 * (columns[f"{axis}_base_min"] + columns[f"{axis}_base_max"])
        origin = _median(columns[f"{axis}_ankle"] if axis == "ap" else centre)
        lower = columns[f"{axis}_base_min"] - origin
        upper = columns[f"{axis}_base_max"] - origin
        reach = columns[f"{axis}_margin_cmp"] - columns[f"{axis}_margin_cop"]
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
        ax.plot(time, columns[f"{axis}_com"] - origin, color="0.2", lw=1.0, label="CoM")
        ax.plot(time, columns[f"{axis}_cop"] - origin, color="0.55", lw=0.7, label="CoP")
        if np.isfinite(columns[f"{axis}_cmp"]).any():
            ax.plot(
                time, columns[f"{axis}_cmp"] - origin, color=HIP_COLOUR, lw=0.6, ls=":", label="CMP"
            )
        ax.plot(
            time,
            columns[f"{axis}_capture_point"] - origin,
            color="#6a1b9a",
            lw=1.2,
            label="capture point ξ (XCoM)",
        )
        _strategy_strip(ax, time, columns[f"{axis}_strategy"])
        ax.set_title(
            f"{_TITLES[axis]}: needs {summary['directions'][axis]['most_demanding']}", fontsize=10
        )
        ax.set_ylabel(
            "ap position − ankle [m]" if axis == "ap" else "ml position − base centre [m]"
        )
        _limit(ax, columns, axis, origin)
    axes[-1, 0].set_xlabel("time [s]")
    _legend(axes[0, 0], loc="upper right", fontsize=7, ncols=3)
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".") or "png"])[0]


def _limit(ax: Axes, columns: dict[str, np.ndarray], axis: str, origin: float) -> None:
    """Zoom on the base and the capture point, not on a fall's runaway tail."""
    spans = [columns[f"{axis}_base_min"], columns[f"{axis}_base_max"], columns[f"{axis}_com"]]
    values = np.concatenate([np.asarray(s, dtype=float) for s in spans]) - origin
    values = values[np.isfinite(values)]
    if len(values):
        low, high = float(values.min()), float(values.max())
        pad = 0.6 * (high - low) + 0.02
        ax.set_ylim(low - pad, high + pad)


def _strategy_strip(ax: Axes, time: np.ndarray, strategy: np.ndarray) -> None:
    """Colour the bottom of a panel by the strategy each frame needs."""
    from matplotlib.transforms import blended_transform_factory

    transform = blended_transform_factory(ax.transData, ax.transAxes)
    for name, colour in STRATEGY_COLOURS.items():
        mask = strategy == name
        if mask.any():
            ax.fill_between(
                time, 0.0, 0.04, where=mask, color=colour, transform=transform, lw=0, step="mid"
            )


def plot_phase_portrait(analysis: TrialAnalysis, path: Path) -> Path:
    """Plot CoM velocity against CoM position relative to the stance ankle, per axis.

    Points are coloured by the strategy the frame needs; the lines ẋ = ω (edge − x) are the
    capture-point edges of the median base (Eq. 4) and of the CMP region (corrected Eq. 15).
    """
    columns, summary = analysis.columns, analysis.summary
    omega = summary["body"]["omega"]
    fig, axes = _figure(1, 2, 10.0, 4.6)
    for ax, axis in zip(axes[0], AXES, strict=True):
        ankle = columns[f"{axis}_ankle"]
        x = columns[f"{axis}_com"] - ankle
        xdot = columns[f"{axis}_com_velocity"]
        strategy = columns[f"{axis}_strategy"]
        for name, colour in STRATEGY_COLOURS.items():
            mask = strategy == name
            if mask.any():
                ax.plot(x[mask], xdot[mask], ".", ms=2.5, color=colour, label=name)
        finite = np.isfinite(x) & np.isfinite(xdot)
        if finite.any():
            span = max(float(np.abs(x[finite]).max()), 0.05) * 1.3
            xs = np.linspace(-span, span, 50)
            reach = _median(columns[f"{axis}_margin_cmp"] - columns[f"{axis}_margin_cop"])
            for end, sign in (("min", -1.0), ("max", 1.0)):
                edge = _median(columns[f"{axis}_base_{end}"] - ankle)
                ax.plot(xs, omega * (edge - xs), color=RECOVER_COLOUR, lw=1.0, ls="--")
                ax.plot(xs, omega * (edge + sign * reach - xs), color=HIP_COLOUR, lw=1.0, ls=":")
            ax.set_xlim(-span, span)
            vmax = max(float(np.abs(xdot[finite]).max()), 0.05) * 1.3
            ax.set_ylim(-vmax, vmax)
        ax.set_title(_TITLES[axis], fontsize=10)
        ax.set_xlabel(f"CoM − stance ankle along {axis} [m]")
        ax.set_ylabel("CoM velocity [m/s]")
        _legend(ax, loc="upper right", fontsize=7, markerscale=3)
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".") or "png"])[0]
