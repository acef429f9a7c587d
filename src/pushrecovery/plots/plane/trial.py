"""A trial in the ground plane, seen from above: the feet, the XCoM and the CoP (issue 18).

ap is horizontal (forward → right), ml vertical (the subject's left ↑), lab positions in metres
at equal scale. The base of support (the polygon of the supporting soles,
:mod:`pushrecovery.analysis.base_polygon`) is outlined at a few moments: the start, the push
onset, each foot-off and foot-contact, the end. The XCoM path is coloured by the strategy the
frame needs (the 2-D verdict when the trial has one, else the more demanding of ap and ml),
grey where no verdict is given; events are marked on it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pushrecovery.analysis.base_polygon import BasePolygons
from pushrecovery.analysis.trial import TrialAnalysis
from pushrecovery.arguments import require_type
from pushrecovery.plots.analysis import (
    STRATEGY_COLOURS,
    WITHHELD_COLOURS,
    XCOM_COLOUR,
    _events,
    _figure,
    _save,
    figure_legend,
    strategy_label,
    withheld_frames,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["base_moments", "plane_figure", "plot_plane"]

#: Outline colours of the base at successive moments (none of them a strategy's).
MOMENT_COLOURS = ("0.15", "#00838f", "#ad1457", "#6d4c41", "#3949ab", "#827717", "#4e342e")
_MARKERS = {"start": "o", "onset": "*", "foot-off": "^", "foot-contact": "v", "end": "s"}


def base_moments(analysis: TrialAnalysis, base: BasePolygons) -> list[tuple[int, list[str]]]:
    """Return the frames whose base the plane outlines, each with the moments it stands for.

    The first and last frames with a known base, the push onset and each foot event (the
    nearest frame with a known base); moments whose polygons coincide share one frame.

    Returns
    -------
    list of (frame, descriptions)
        In time order; a description is e.g. ``"1.60 s push onset"``.
    """
    require_type("analysis", analysis, TrialAnalysis)
    time = analysis.columns["time"]
    known = np.flatnonzero(base.counts >= 3)
    if not known.size:
        return []
    wanted = [(float(time[known[0]]), "start")]
    wanted += [(when, text) for when, _, text in _events(analysis)]
    wanted.append((float(time[known[-1]]), "end"))
    moments: list[tuple[int, list[str]]] = []
    for when, text in sorted(wanted):
        frame = int(known[np.argmin(np.abs(time[known] - when))])
        note = f"{time[frame]:.2f} s {text}"
        if abs(time[frame] - when) > 0.02:  # no base at the moment itself (e.g. in flight)
            note = f"{when:.2f} s {text} (base of {time[frame]:.2f} s)"
        same = [m for m in moments if _same_polygon(base, m[0], frame)]
        if same:
            same[0][1].append(note)
        else:
            moments.append((frame, [note]))
    return moments


def _same_polygon(base: BasePolygons, a: int, b: int) -> bool:
    count = int(base.counts[a])
    return count == int(base.counts[b]) and np.allclose(
        base.vertices[a, :count], base.vertices[b, :count], atol=1e-3
    )


def _rectangles(analysis: TrialAnalysis) -> BasePolygons:
    """Return the per-axis extents of the base as rectangles (no polygon given)."""
    columns = analysis.columns
    lo_ap, hi_ap = columns["ap_base_min"], columns["ap_base_max"]
    lo_ml, hi_ml = columns["ml_base_min"], columns["ml_base_max"]
    corners = [(lo_ap, lo_ml), (hi_ap, lo_ml), (hi_ap, hi_ml), (lo_ap, hi_ml)]
    vertices = np.stack([np.column_stack(c) for c in corners], axis=1)
    known = np.isfinite(vertices).all(axis=(1, 2)) & (hi_ap > lo_ap) & (hi_ml > lo_ml)
    vertices[~known] = np.nan
    counts = np.where(known, 4, 0).astype(np.int64)
    return BasePolygons(vertices, counts, "per-axis extents (no polygon given)")


def plot_plane(analysis: TrialAnalysis, base: BasePolygons | None, path: Path) -> Path:
    """Write :func:`plane_figure` to ``path`` (format from its suffix, default PNG).

    Parameters
    ----------
    analysis : TrialAnalysis
        The analysed trial.
    base : BasePolygons or None
        The plane's base per frame (see :func:`plane_figure`).
    path : Path
        The image to write.

    Returns
    -------
    Path
        The file written.
    """
    require_type("analysis", analysis, TrialAnalysis)
    return _save(plane_figure(analysis, base), path)


def plane_figure(analysis: TrialAnalysis, base: BasePolygons | None = None) -> Figure:
    """Draw the trial in the ground plane: base outlines, XCoM, CoM and CoP paths, events.

    Parameters
    ----------
    analysis : TrialAnalysis
        The analysed trial (:func:`pushrecovery.analysis.trial.analyze`).
    base : BasePolygons or None
        The plane's base per frame, as the analysis built it (one polygon per frame of
        ``analysis``); None: the rectangles of the per-axis extents (``{axis}_base_min`` and
        ``_max``), said so in the title.

    Returns
    -------
    Figure

    Raises
    ------
    ValueError
        If ``base`` has not one polygon per frame of ``analysis``.
    """
    require_type("analysis", analysis, TrialAnalysis)
    columns = analysis.columns
    time = columns["time"]
    if base is None:
        base = _rectangles(analysis)
    if len(base) != len(time):
        raise ValueError(f"the base has {len(base)} frames, the analysis {len(time)}")
    fig, axes = _figure(1, 1, 8.0, 7.6)
    ax = axes[0, 0]
    shown: list[np.ndarray] = []
    for k, (frame, notes) in enumerate(base_moments(analysis, base)):
        polygon = base.vertices[frame, : int(base.counts[frame])]
        closed = np.vstack([polygon, polygon[:1]])
        colour = MOMENT_COLOURS[k % len(MOMENT_COLOURS)]
        style = ("-", "--", "-.", ":")[(k // len(MOMENT_COLOURS)) % 4]
        ax.fill(polygon[:, 0], polygon[:, 1], color=colour, alpha=0.05, lw=0)
        ax.plot(closed[:, 0], closed[:, 1], color=colour, ls=style, lw=1.3,
                label="base at " + "; ".join(notes))  # fmt: skip
        shown.append(polygon)
    cop = np.column_stack([columns["ap_cop"], columns["ml_cop"]])
    if np.isfinite(cop).any():
        ax.plot(cop[:, 0], cop[:, 1], color="0.45", lw=0.7, label="CoP path")
    com = np.column_stack([columns["ap_com"], columns["ml_com"]])
    ax.plot(com[:, 0], com[:, 1], color="0.1", lw=0.8, ls="--", label="CoM path (on the floor)")
    # The per-axis capture points: the XCoM of every frame (xcom_ap, xcom_ml are withheld
    # with the verdicts; the XCoM itself is a measurement).
    xcom = np.column_stack([columns["ap_capture_point"], columns["ml_capture_point"]])
    which = _xcom_paths(ax, analysis, xcom)
    _mark(ax, analysis, base, xcom)
    note = _limits(ax, [*shown, cop], np.concatenate([xcom, com]))
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("ap position [m]   (forward +, to the right)")
    ax.set_ylabel("ml position [m]   (subject's left +, up)")
    source = analysis.summary.plane.base_source or base.source
    if base.source.startswith("per-axis"):
        source = base.source
    ax.set_title(
        f"Ground plane seen from above; XCoM coloured by {which}{note}\nbase: {source}",
        fontsize=9,
    )
    figure_legend(fig, fontsize=7, ncols=2, markerscale=1.0)
    return fig


def _xcom_paths(ax: Axes, analysis: TrialAnalysis, xcom: np.ndarray) -> str:
    """Draw the XCoM path, a line per strategy and per reason for no verdict; say by what."""
    columns = analysis.columns
    column, which = "strategy_2d", "the 2-D verdict (against the polygon)"
    if not np.isin(columns["strategy_2d"].astype(str), list(STRATEGY_COLOURS)).any():
        column, which = "strategy", "the strategy needed (more demanding of ap, ml)"
    strategy = columns[column]
    marks = [
        ("XCoM, " + strategy_label(n), c, 1.8, strategy == n) for n, c in STRATEGY_COLOURS.items()
    ]
    for key, (text, mask) in withheld_frames(analysis, column).items():
        if key == "missing" and column == "strategy_2d":
            text = "no verdict: CoM or base missing, or no feet to classify against"
        marks.append((f"XCoM, {text}", WITHHELD_COLOURS[key], 1.2, mask))
    for label, colour, width, mask in marks:
        # Each run one frame longer, so that the runs of successive colours meet.
        joined = mask | np.concatenate([[False], mask[:-1]])
        if (mask & np.isfinite(xcom).all(axis=1)).any():
            path = np.where(joined[:, None], xcom, np.nan)
            ax.plot(path[:, 0], path[:, 1], color=colour, lw=width, label=label)
    if not np.isfinite(xcom).any():
        ax.plot([], [], color=XCOM_COLOUR, label="XCoM: not known in any frame")
    return which


def _mark(ax: Axes, analysis: TrialAnalysis, base: BasePolygons, xcom: np.ndarray) -> None:
    """Mark the start, events, end and the smallest margin of stability on the XCoM path."""
    time = analysis.columns["time"]
    finite = np.flatnonzero(np.isfinite(xcom).all(axis=1))
    if not finite.size:
        return
    marks = [(float(time[finite[0]]), "start", "start")]
    marks += _events(analysis)
    marks.append((float(time[finite[-1]]), "end", "end"))
    for when, kind, text in marks:
        frame = int(finite[np.argmin(np.abs(time[finite] - when))])
        ax.plot(*xcom[frame], _MARKERS.get(kind, "D"), ms=9 if kind == "onset" else 7,
                mfc="white" if kind in ("start", "end") else "0.1", mec="0.1",
                label=f"XCoM at {text} ({when:.2f} s)", ls="none")  # fmt: skip
    smallest = analysis.summary.plane.min_mos
    if smallest.time is not None and smallest.value is not None:
        frame = int(np.argmin(np.abs(time - smallest.time)))
        ax.plot(*xcom[frame], "X", ms=8, color="#d81b60", ls="none",
                label=f"smallest margin of stability {smallest.value * 100:.1f} cm "
                f"({smallest.time:.2f} s)")  # fmt: skip


def _limits(ax: Axes, body: list[np.ndarray], xcom: np.ndarray) -> str:
    """Frame the outlined bases and the CoP, and the CoM and XCoM up to 0.5 m beyond them.

    Returns a note for the title when the CoM or XCoM leaves the view (a fall's runaway tail).
    """
    reach = xcom[np.isfinite(xcom).all(axis=1)]
    inner = [p[np.isfinite(p).all(axis=1)] for p in body]
    inner = [p for p in inner if len(p)] or ([reach] if len(reach) else [])
    if not inner:
        return ""
    low = np.min([p.min(axis=0) for p in inner], axis=0)
    high = np.max([p.max(axis=0) for p in inner], axis=0)
    note = ""
    if len(reach):
        low = np.minimum(low, np.maximum(reach.min(axis=0), low - 0.5))
        high = np.maximum(high, np.minimum(reach.max(axis=0), high + 0.5))
        outside = ((reach < low) | (reach > high)).any(axis=1)
        if outside.any():
            note = f"\nthe CoM or XCoM leaves the view in {int(outside.sum())} frames"
    pad = 0.08 * float(max(high - low)) + 0.02
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    return note
