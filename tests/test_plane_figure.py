"""The capture-point plane figure (plots.plane), its file in write_figures, its report section."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.collections import PathCollection
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon

from pushrecovery import BodyParams, InvalidParameterError
from pushrecovery.experiments.paper_figures import PaperRuns
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.plots import figures
from pushrecovery.plots.campaign import STRATEGY_COLOURS
from pushrecovery.plots.common import save_figure
from pushrecovery.plots.plane import (
    LIMIT_HEADINGS,
    capture_plane_figure,
    capture_plane_panels,
    plane_samples,
    recovery_limits,
)
from pushrecovery.report import SECTIONS
from pushrecovery.report.build import build_report
from pushrecovery.report.data import PlaneSection, StepsSection
from pushrecovery.surfaces.bounds import plane_bounds
from pushrecovery.surfaces.classify import STRATEGY_CODES, classify
from pushrecovery.surfaces.plane import DIRECTIONS, cmp_polygon

PNG = b"\x89PNG\r\n\x1a\n"
STRATEGIES = [s.value for s in STRATEGY_CODES]


def _supports(params: BodyParams) -> list[Support]:
    return [
        Support.from_params(params, "double"),
        Support.from_params(params, "left"),
        Support.from_params(params, "right"),
        Support.from_params(params, "left", left=FootPose(0.05, 0.1, 0.5)),
    ]


def _verdicts(ax: object) -> dict[str, PathCollection]:
    """The scatter collection of each strategy, by label."""
    return {
        str(c.get_label()): c
        for c in ax.collections  # type: ignore[attr-defined]
        if isinstance(c, PathCollection) and c.get_label() in STRATEGIES
    }


@pytest.mark.parametrize("index", range(4), ids=["double", "left", "right", "yawed"])
def test_figure_draws_the_regions_feet_and_verdicts(params: BodyParams, index: int) -> None:
    support = _supports(params)[index]
    fig = capture_plane_figure(params, support, speeds=np.linspace(0.1, 3.0, 12), headings=16)
    assert isinstance(fig, Figure)
    whole, close = fig.axes[:2]
    for ax in (whole, close):
        assert ax.get_xlabel() == "x, forward [m]"
        assert ax.get_ylabel() == "y, left [m]"
        assert ax.get_aspect() == 1.0
        polygons = [p for p in ax.patches if isinstance(p, Polygon)]
        labels = {str(p.get_label()): p for p in polygons}
        ankle = labels["support polygon: ankle (Eq. 4)"]
        hip = labels["CMP region: hip (corrected Eq. 15)"]
        np.testing.assert_allclose(ankle.get_xy()[:-1], support.polygon.vertices)
        np.testing.assert_allclose(hip.get_xy()[:-1], cmp_polygon(support, params).vertices)
        # Every sample drawn once, in its strategy's colour.
        verdicts = _verdicts(ax)
        assert sum(np.shape(c.get_offsets())[0] for c in verdicts.values()) == 12 * 16
        for name, collection in verdicts.items():
            if np.shape(collection.get_offsets())[0]:
                colour = np.asarray(collection.get_facecolor())[0]
                np.testing.assert_allclose(colour, to_rgba(STRATEGY_COLOURS[name]))
        # Both feet outlined; the lifted one dashed in single support.
        dashed = [
            line
            for line in ax.lines
            if isinstance(line, Line2D)
            and np.size(np.asarray(line.get_xdata())) == 5
            and line.get_linestyle() != "-"
        ]
        assert len(dashed) == (0 if support.stance is Stance.DOUBLE else 1)
    # Everything drawn fits in the whole view; the close-up holds the CMP region.
    hip_box = cmp_polygon(support, params)
    x0, x1 = close.get_xlim()
    y0, y1 = close.get_ylim()
    assert x0 < hip_box.xmin and hip_box.xmax < x1 and y0 < hip_box.ymin and hip_box.ymax < y1
    offsets = np.vstack([c.get_offsets() for c in _verdicts(whole).values()])
    assert whole.get_xlim()[0] < offsets[:, 0].min() and offsets[:, 0].max() < whole.get_xlim()[1]
    assert "largest push [m/s]" in "".join(t.get_text() for t in fig.axes[2].texts)


def test_coloured_states_are_classify_verdicts(params: BodyParams) -> None:
    support = Support.from_params(params, "left", left=FootPose(0.05, 0.1, 0.5))
    fig = capture_plane_figure(params, support)
    ax, omega = fig.axes[0], params.omega
    seen = set()
    for name, collection in _verdicts(ax).items():
        points = np.asarray(collection.get_offsets())
        for xi_x, xi_y in points[:: max(1, len(points) // 5)]:
            # A push from rest at the reference point: its capture point gives the velocity.
            ax_, ay_ = support.ankle
            verdict = classify(
                ax_,
                (xi_x - ax_) * omega,
                params,
                y=ay_,
                ydot=(xi_y - ay_) * omega,
                support=support,
            )
            assert verdict.strategy.value == name
            seen.add(name)
    assert seen == set(STRATEGIES)  # the default pushes reach every verdict
    # The first sample: the slowest push straight forward.
    samples = plane_samples(params, support)
    first = classify(
        samples.x[0], samples.xdot[0], params, y=samples.y[0], ydot=samples.ydot[0], support=support
    )
    assert STRATEGY_CODES[samples.codes[0]] is first.strategy
    assert samples.ydot[0] == 0.0 and samples.xdot[0] > 0.0
    assert (samples.xi_x[0], samples.xi_y[0]) == pytest.approx(first.capture_point_xy)


def test_recovery_limit_is_the_n_step_threshold(params: BodyParams) -> None:
    for support in _supports(params)[:2]:
        limits = recovery_limits(params, support)
        assert limits.shape == (LIMIT_HEADINGS,)
        exact = plane_bounds(params, support)["thresholds"]["step"]
        for name, heading in DIRECTIONS.items():
            index = round(heading / (2 * math.pi) * LIMIT_HEADINGS) % LIMIT_HEADINGS
            assert limits[index] == pytest.approx(exact[name], abs=2e-4)


def test_panels_show_three_stances_on_one_scale(params: BodyParams, tmp_path: Path) -> None:
    fig = capture_plane_panels(params, headings=8, speeds=[0.2, 1.0, 3.0])
    plots = [ax for ax in fig.axes if ax.get_xlabel()]
    assert len(plots) == 6
    wholes, closes = plots[:3], plots[3:]  # row by row
    assert [ax.get_title() for ax in wholes] == [
        "double support",
        "left support",
        "right support",
    ]
    assert len({ax.get_xlim() for ax in wholes}) == 1  # the whole views share limits
    assert len({ax.get_ylim() for ax in closes}) == 1  # so do the close-ups
    assert all(ax.get_title().endswith("close to the feet") for ax in closes)
    paths = save_figure(fig, tmp_path / "panels", ("png",))
    assert paths[0].read_bytes().startswith(PNG)


def test_bad_pushes_are_refused(params: BodyParams) -> None:
    support = Support.from_params(params)
    with pytest.raises(InvalidParameterError, match="headings"):
        plane_samples(params, support, headings=0)
    with pytest.raises(InvalidParameterError, match="speeds"):
        plane_samples(params, support, speeds=[-1.0])
    with pytest.raises(InvalidParameterError, match="at least one"):
        capture_plane_panels(params, [])


def test_write_figures_writes_the_plane(
    params: BodyParams, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in ("fig3a", "fig3b", "fig5", "fig6", "fig9", "fig10"):
        monkeypatch.setattr(figures, name, lambda *args: [])
    runs = PaperRuns([], [], [], [], [])  # the paper's figures are stubbed out above
    files = figures.write_figures(params, runs, tmp_path)
    stems = ("plane", "steps-map", "steps-regions")
    assert sorted(p.name for p in files) == [f"{s}.{e}" for s in stems for e in ("png", "svg")]
    assert all(p.stat().st_size > 1000 for p in files)
    assert (tmp_path / "plane.png").read_bytes().startswith(PNG)
    assert figures.write_figures(params, runs, tmp_path / "none", ground_plane=False) == []


def test_report_has_the_ground_plane_section(params: BodyParams, tmp_path: Path) -> None:
    skip = [key for key in SECTIONS if key != "plane"]
    report = build_report(params, tmp_path, skip=skip)
    assert [key for key, _, _ in report.sections] == ["plane"]
    section = report.section("plane")
    assert isinstance(section, PlaneSection)
    assert section.picture.path.read_bytes().startswith(PNG)
    table = section.thresholds
    assert table.ident == "plane-thresholds"
    assert len(table.rows) == 3 * 3  # ankle, hip, step for each stance
    cells = table.rows[3 + 2]  # left support, step
    expected = plane_bounds(params, Support.from_params(params, "left"))["thresholds"]["step"]
    assert cells[:2] == ("left", "step")
    numbers = [float(c.replace("−", "-")) for c in cells[2:]]
    for value, direction in zip(numbers, ("forward", "backward", "left", "right"), strict=True):
        assert value == pytest.approx(expected[direction], rel=5e-3)
    assert report.footer is not None
    assert [title for title, _ in report.footer.timings] == ["Ground plane"]


def test_report_has_the_steps_section(params: BodyParams, tmp_path: Path) -> None:
    skip = [key for key in SECTIONS if key != "steps"]
    section = build_report(params, tmp_path, skip=skip).section("steps")
    assert isinstance(section, StepsSection)
    for picture in (section.regions, section.steps_map):
        assert picture.path.read_bytes().startswith(PNG)
    rows = section.thresholds.rows
    assert len(rows) == params.max_steps + 1  # N = 1 ... max_steps, ∞
    forward = [float(r[2]) for r in rows]
    assert forward == sorted(forward)  # more steps, bigger pushes


def test_a_dot_in_the_figure_name_is_kept(tmp_path: Path) -> None:
    # s02_push0.30_time once became s02_push0.png, and the next push's figure overwrote it.
    from matplotlib.figure import Figure

    paths = save_figure(Figure(), tmp_path / "s02_push0.30_time", ("png", "svg"))
    assert [p.name for p in paths] == ["s02_push0.30_time.png", "s02_push0.30_time.svg"]
    assert all(p.exists() for p in paths)
