"""Plots of an analysed trial a reader understands (issue 18, item 8).

On generated trials (a push answered by a step, measured by foot markers; quiet standing whose
base is moved off the CoP in the first frames) and on biomdp's kistler_COP.c3d: the figures
are written, every labelled mark is in a legend, the phase portrait's ankle-coded points lie
in their own frame's base, normalised to [0, 1], and the plane outlines the base of the
frames it names. No image comparisons.
"""

from __future__ import annotations

import pathlib

import biomdp
import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.analysis.readers import read_recording
from pushrecovery.analysis.trial import AnalysisSettings, analyze, body_for
from pushrecovery.analysis.trial.checks import COP_TOLERANCE
from pushrecovery.plots.analysis import (
    STRATEGY_COLOURS,
    WITHHELD_COLOURS,
    phase_portrait_figure,
    plot_phase_portrait,
    plot_time_series,
    strategy_label,
    time_series_figure,
)
from pushrecovery.plots.plane.trial import plane_figure, plot_plane
from test_trial_checks import _csv, _stepping_recording

DATA = pathlib.Path(biomdp.__file__).parent / "tests" / "datasets"
P = load_params()
TRIALS = ("stepping", "withheld", "kistler")


@pytest.fixture(scope="module", params=TRIALS)
def trial(request, tmp_path_factory):
    """(name, analysis, base polygons) of a generated or real trial."""
    params = P
    if request.param == "stepping":
        recording = _stepping_recording()
    elif request.param == "withheld":  # the base 3 cm beyond the tolerance in 60 frames
        folder = tmp_path_factory.mktemp("withheld")
        recording = read_recording(_csv(folder / "a.csv", 0.15 + COP_TOLERANCE + 0.03, 60))
    else:
        recording = read_recording(DATA / "kistler_COP.c3d")
        found, _ = body_for(recording, mass=None, com_height=None, gravity=9.81)
        params = load_params(overrides=found)
    analysis = analyze(recording, params, AnalysisSettings())
    # The pipeline's own base of support per frame in the plane, kept with the analysis.
    assert analysis.base is not None and len(analysis.base) == len(analysis.time)
    return request.param, analysis, analysis.base


def _legend_texts(figure):
    legends = [*figure.legends, *(ax.get_legend() for ax in figure.axes)]
    return {text.get_text() for legend in legends if legend for text in legend.get_texts()}


def _labelled(figure):
    """Every artist of the figure's axes that carries a label of its own."""
    for ax in figure.axes:
        for artist in (*ax.lines, *ax.collections, *ax.patches, *ax.images):
            label = artist.get_label()
            if label and not label.startswith("_"):
                yield ax, artist, label


def test_the_figures_are_written(trial, tmp_path):
    _, analysis, base = trial
    written = [
        plot_time_series(analysis, tmp_path / "time_series.png"),
        plot_phase_portrait(analysis, tmp_path / "phase_portrait.png"),
        plot_plane(analysis, base, tmp_path / "plane.png"),
        plot_plane(analysis, None, tmp_path / "plane_rectangles.png"),
    ]
    for path in written:
        assert path.is_file() and path.stat().st_size > 1000
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_every_labelled_mark_is_in_a_legend(trial):
    name, analysis, base = trial
    for figure in (
        time_series_figure(analysis),
        phase_portrait_figure(analysis),
        plane_figure(analysis, base),
    ):
        texts = _legend_texts(figure)
        labels = {label for _, _, label in _labelled(figure)}
        assert labels and labels <= texts, labels - texts
        # Nothing is drawn in a strategy's colour without saying so.
        strategies = {strategy_label(n) for n in STRATEGY_COLOURS}
        assert any(word in text for text in labels for word in (*strategies, "no verdict"))
    strip = {label for _, _, label in _labelled(time_series_figure(analysis))}
    if name == "withheld":  # the strip says why the first 60 frames have no verdict
        assert "no verdict: CoP beyond the base by > 2 cm" in strip
    if name == "stepping":
        assert {"push onset", "right foot-off", "right foot-contact"} <= strip


def test_ankle_points_lie_in_their_own_frames_base(trial):
    name, analysis, _ = trial
    columns = analysis.columns
    figure = phase_portrait_figure(analysis)
    for ax, axis in zip(figure.axes, ("ap", "ml"), strict=True):
        low, high = columns[f"{axis}_base_min"], columns[f"{axis}_base_max"]
        position = (columns[f"{axis}_capture_point"] - low) / (high - low)
        velocity = columns[f"{axis}_com_velocity"]
        strategy = columns[f"{axis}_strategy"]
        lines = {line.get_label(): line for line in ax.lines}
        for code in STRATEGY_COLOURS:
            frames = (strategy == code) & np.isfinite(position) & np.isfinite(velocity)
            line = lines.get(strategy_label(code))
            if not frames.any():
                assert line is None
                continue
            assert line is not None
            np.testing.assert_allclose(line.get_xdata(), position[frames])
            np.testing.assert_allclose(line.get_ydata(), velocity[frames])
            if code == "ankle":  # inside the edges drawn at 0 and 1, by construction
                assert ((line.get_xdata() >= 0.0) & (line.get_xdata() <= 1.0)).all()
        edges = sorted(
            float(line.get_xdata()[0])
            for line in ax.lines
            if line.get_label().startswith("_") and np.ptp(line.get_xdata()) == 0
        )
        assert 0.0 in edges and 1.0 in edges  # the CoP region: every frame's own edges
        if name == "kistler":  # quiet standing: every frame with a verdict needs the ankle
            assert len(lines[strategy_label("ankle")].get_xdata()) > 5000
        if name == "withheld":
            (greyed,) = (line for text, line in lines.items() if "CoP beyond" in text)
            assert greyed.get_color() == WITHHELD_COLOURS["cop_outside"]
            assert len(greyed.get_xdata()) == 60


def test_the_plane_outlines_the_base_at_each_event(trial):
    name, analysis, base = trial
    columns = analysis.columns
    figure = plane_figure(analysis, base)
    (ax,) = figure.axes
    assert ax.get_aspect() == 1.0  # metres at equal scale
    outlines = [line for line in ax.lines if line.get_label().startswith("base at")]
    assert outlines
    for line in outlines:
        drawn = np.column_stack([line.get_xdata(), line.get_ydata()])[:-1]
        frames = [i for i in range(len(base)) if base.counts[i] == len(drawn)]
        assert any(np.allclose(base.vertices[i, : len(drawn)], drawn) for i in frames)
    notes = " ".join(line.get_label() for line in outlines)
    assert "start" in notes and "end" in notes
    if name == "stepping":
        for event in ("push onset", "right foot-off", "right foot-contact"):
            assert event in notes
    # The XCoM path is the frames' capture points, in the colour of their strategy.
    xcom = np.column_stack([columns["ap_capture_point"], columns["ml_capture_point"]])
    paths = [line for line in ax.lines if line.get_label().startswith("XCoM, ")]
    assert paths
    for line in paths:
        drawn = np.column_stack([line.get_xdata(), line.get_ydata()])
        shown = np.isfinite(drawn).all(axis=1)
        np.testing.assert_allclose(drawn[shown], xcom[shown])


def test_the_plane_without_polygons_draws_the_extents_and_refuses_a_wrong_base(trial):
    _, analysis, base = trial
    figure = plane_figure(analysis)
    assert "per-axis extents" in figure.axes[0].get_title()
    if len(base) > 1:
        from dataclasses import replace

        shorter = replace(base, vertices=base.vertices[1:], counts=base.counts[1:])
        with pytest.raises(ValueError, match="frames"):
            plane_figure(analysis, shorter)
