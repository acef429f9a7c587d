"""The campaign plots and the HTML report, on tiny campaigns (the whole file runs in seconds)."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from html import unescape
from pathlib import Path
from typing import Any

import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from pushrecovery import BodyParams, InvalidParameterError, PushRecoveryError, load_params
from pushrecovery.campaign import CampaignResult, CampaignSpec, run_campaign
from pushrecovery.cli.app import cli
from pushrecovery.plots.campaign import (
    plot_critical_vs_parameter,
    plot_outcome_map,
    step_limit_curve,
)
from pushrecovery.report import SECTIONS, PushGrid, write_report
from pushrecovery.report.build import build_report
from pushrecovery.report.data import (
    BoundsSection,
    CampaignSection,
    FailedSection,
    FiguresSection,
    FilmstripsSection,
    Report,
    SweepSection,
)
from pushrecovery.report.render import render_report
from pushrecovery.sim.critical import predicted_critical_velocity
from pushrecovery.surfaces.bounds import bounds_data

PNG = b"\x89PNG\r\n\x1a\n"


def _campaign(directory: Path, model: str, controller: str, **grid: Any) -> CampaignResult:
    """Run an analytic campaign of the paper's body in this process."""
    result = run_campaign(
        CampaignSpec("analytic", model, controller, load_params(), **grid), directory, workers=1
    )
    assert result is not None
    return result


@pytest.fixture(scope="module")
def ankle_campaign(tmp_path_factory: pytest.TempPathFactory) -> CampaignResult:
    """Pendulum + ankle PD, 2 starts x 5 pushes."""
    directory = tmp_path_factory.mktemp("ankle")
    return _campaign(
        directory, "pendulum", "ankle-pd", x0=(0.0, 0.05, 0.05), xdot=(-0.4, 0.6, 0.25)
    )


@pytest.fixture(scope="module")
def sweep_campaign(tmp_path_factory: pytest.TempPathFactory) -> CampaignResult:
    """Flywheel + MPC from upright, 6 pushes for each of two hip torque limits."""
    return _campaign(
        tmp_path_factory.mktemp("sweep"),
        "flywheel",
        "mpc",
        x0=(0.0, 0.0, 1.0),
        xdot=(-0.5, 0.75, 0.25),
        sweeps={"torque_max": (0.0, 100.0, 100.0)},
    )


def test_outcome_map_writes_a_png(ankle_campaign: CampaignResult, tmp_path: Path) -> None:
    path = plot_outcome_map(ankle_campaign.table, ankle_campaign.spec, tmp_path / "map.png")
    assert path == tmp_path / "map.png"
    assert path.read_bytes().startswith(PNG)


def test_outcome_map_draws_one_panel_per_swept_value(
    ankle_campaign: CampaignResult, sweep_campaign: CampaignResult, tmp_path: Path
) -> None:
    from PIL import Image

    one = plot_outcome_map(ankle_campaign.table, ankle_campaign.spec, tmp_path / "one.png")
    two = plot_outcome_map(sweep_campaign.table, sweep_campaign.spec, tmp_path / "two.png")
    assert Image.open(two).width > 1.2 * Image.open(one).width


def test_critical_vs_parameter_writes_a_png(sweep_campaign: CampaignResult, tmp_path: Path) -> None:
    path = plot_critical_vs_parameter(sweep_campaign.summary, tmp_path / "critical.png")
    assert path.read_bytes().startswith(PNG)


def test_critical_vs_parameter_needs_one_swept_parameter(
    ankle_campaign: CampaignResult, tmp_path: Path
) -> None:
    with pytest.raises(InvalidParameterError, match="one parameter"):
        plot_critical_vs_parameter(ankle_campaign.summary, tmp_path / "critical.png")
    with pytest.raises(InvalidParameterError, match="plot must end"):
        plot_outcome_map(ankle_campaign.table, ankle_campaign.spec, tmp_path / "map.txt")


def test_step_limit_curve_is_the_predicted_critical_push(params: BodyParams) -> None:
    for direction in ("forward", "backward"):
        curve = step_limit_curve(params, [0.0, 0.1], direction, resolution=1e-3)
        for x0, value in zip((0.0, 0.1), curve, strict=True):
            exact = predicted_critical_velocity(params, "step", x0, direction)
            assert abs(value) <= abs(exact) < abs(value) + 1e-3


def test_bounds_are_the_numbers_of_the_bounds_command(params: BodyParams) -> None:
    result = CliRunner().invoke(cli, ["bounds", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.output) == json.loads(json.dumps(bounds_data(params)))


TINY = {
    "analytic_grid": PushGrid((0.0, 0.05, 0.05), (-1.0, 1.0, 0.5)),
    "sweep_grid": PushGrid((0.0, 0.0, 1.0), (-0.4, 0.8, 0.4), {"torque_max": (0.0, 100.0, 100.0)}),
}
SHOWN = ("bounds", "map", "plane", "steps", "figures", "analytic", "planar", "sweep")


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> tuple[Report, Path, list[str]]:
    """The report without MuJoCo on tiny grids, as data, with its progress lines."""
    out = tmp_path_factory.mktemp("report")
    lines: list[str] = []
    data = build_report(load_params(), out, mujoco=False, workers=1, progress=lines.append, **TINY)
    return data, out, lines


def test_report_sections_are_the_campaigns_numbers(
    report: tuple[Report, Path, list[str]],
) -> None:
    data, out, lines = report
    assert [key for key, _, _ in data.sections] == list(SHOWN)
    assert [title for _, title, _ in data.sections] == [SECTIONS[key] for key in SHOWN]
    summary = json.loads((out / "campaign-analytic" / "summary.json").read_text())
    section = data.section("analytic")
    assert isinstance(section, CampaignSection)
    # The confusion matrix is the summary's; its totals are the push count.
    assert [list(row) for row in section.confusion.counts] == summary["confusion"]["counts"]
    assert section.confusion.total == summary["pushes"] == section.pushes
    # The accuracy is explained by its own table, counted from the pushes, not the summary.
    pushes = pq.read_table(out / "campaign-analytic" / "pushes.parquet").to_pylist()
    right = sum(p["predicted_recovers"] == (p["outcome"] == "recovered") for p in pushes)
    assert section.verdicts.right == right
    assert section.verdicts.total == len(pushes)
    assert section.accuracy == pytest.approx(right / len(pushes), abs=1e-12)
    assert section.disagreements.wrong == len(pushes) - right
    assert section.recovered + section.fell + section.undecided == len(pushes)
    for name in section.data_files:
        assert (out / name).is_file()
    assert section.outcome_map.path.read_bytes().startswith(PNG)
    # The sweep and its critical pushes; the verdict paragraph's scores.
    sweep = data.section("sweep")
    assert isinstance(sweep, SweepSection) and sweep.parameter == "torque_max"
    planar = data.section("planar")
    assert isinstance(planar, CampaignSection) and planar.model == "stepping-plane"
    assert [(title, pushes) for title, _, pushes in data.verdict.scores] == [
        (SECTIONS["sweep"], sweep.pushes),
        (SECTIONS["analytic"], section.pushes),
        (SECTIONS["planar"], planar.pushes),
    ]
    # On the model of the N-step analysis every push takes the steps its verdict names.
    rows = pq.read_table(out / "campaign-planar" / "pushes.parquet").to_pylist()
    assert rows and all(r["outcome"] == "recovered" for r in rows)
    assert all(r["steps"] == max(r["predicted_steps"], 0) for r in rows)
    thresholds = bounds_data(load_params())["thresholds"]
    assert data.verdict.hip == thresholds["hip"][1]
    # Every figure is a PNG on disk; every section's wall time in the footer, as it ran.
    figures = data.section("figures")
    assert isinstance(figures, FiguresSection) and len(figures.pictures) >= 8
    assert all(p.path.read_bytes().startswith(PNG) for p in figures.pictures)
    assert data.footer is not None
    assert {title for title, _ in data.footer.timings} == {SECTIONS[key] for key in SHOWN}
    assert any(line.startswith(SECTIONS["analytic"] + ":") for line in lines)


def test_the_report_renders_one_self_contained_page(
    report: tuple[Report, Path, list[str]],
) -> None:
    data, _, _ = report
    html = render_report(data)
    # Nothing outside the page: no remote or relative resources, no script, no stylesheet link.
    for forbidden in ('src="http', 'href="http', "<script", "<link", "url("):
        assert forbidden not in html
    images = re.findall(r'<img src="([^"]*)"', html)
    assert len(images) >= 8 + 5  # the paper's figures, the map, the plane, three campaign plots
    assert all(src.startswith("data:image/png;base64,") for src in images)
    titles = re.findall(r'<section id="(\w+)">\n<h2>([^<]*)</h2>', html)
    assert [(key, unescape(title)) for key, title in titles] == [(k, SECTIONS[k]) for k in SHOWN]
    for number in ("Eq. (4)", "Eq. (15)", "Eq. (12)", "Sec. IV"):
        assert number in html
    assert html.count('<table class="confusion"') == 2  # the two analytic campaigns
    assert html.index("<footer>") > html.index('<section id="sweep">')


def test_the_page_escapes_its_data(report: tuple[Report, Path, list[str]]) -> None:
    data, _, _ = report
    hostile = "<script>alert('x')</script> & <b>"
    failed = replace(
        data,
        sections=(("bounds", hostile, FailedSection("ValueError", hostile)),),
        notes={"bounds": (hostile,)},
    )
    html = render_report(failed)
    assert "<script" not in html and "<b>" not in html
    # The title, the nav entry, the error and the note, each escaped (any quote form).
    assert html.count("&lt;script&gt;alert(") == 4
    assert html.count("&lt;/script&gt; &amp; &lt;b&gt;") == 4


def test_report_reuses_and_replaces_its_campaigns(params: BodyParams, tmp_path: Path) -> None:
    skip = ("bounds", "map", "plane", "figures", "sweep", "planar")
    write_report(params, tmp_path, mujoco=False, skip=skip, workers=1, **TINY)
    batch = next((tmp_path / "campaign-analytic" / "batches").iterdir())
    stamp = batch.stat().st_mtime_ns
    write_report(params, tmp_path, mujoco=False, skip=skip, workers=1, **TINY)
    assert batch.stat().st_mtime_ns == stamp  # reused, not simulated again
    other = PushGrid((0.0, 0.0, 1.0), (0.0, 0.5, 0.5))
    report = build_report(params, tmp_path, mujoco=False, skip=skip, workers=1, analytic_grid=other)
    summary = json.loads((tmp_path / "campaign-analytic" / "summary.json").read_text())
    section = report.section("analytic")
    assert isinstance(section, CampaignSection)
    assert summary["pushes"] == 2 == section.confusion.total
    assert [list(row) for row in section.confusion.counts] == summary["confusion"]["counts"]


def test_report_without_rendering_says_so(
    params: BodyParams, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from pushrecovery.sim.mujoco import render

    def no_gl() -> None:
        raise PushRecoveryError("no OpenGL here (MUJOCO_GL=egl)")

    monkeypatch.setattr(render, "require_offscreen_gl", no_gl)
    skip = [key for key in SECTIONS if key != "filmstrips"]
    html = write_report(params, tmp_path, skip=skip).read_text()
    assert "Rendering is not available" in html
    assert "no OpenGL here" in html
    assert "<img" not in html
    section = build_report(params, tmp_path, skip=skip).section("filmstrips")
    assert section == FilmstripsSection((), unavailable="no OpenGL here (MUJOCO_GL=egl)")


def test_report_rejects_unknown_sections_and_sizes(params: BodyParams, tmp_path: Path) -> None:
    with pytest.raises(InvalidParameterError, match="size"):
        write_report(params, tmp_path, size="huge")
    with pytest.raises(InvalidParameterError, match="section"):
        write_report(params, tmp_path, skip=("nope",))
    assert not (tmp_path / "index.html").exists()


def test_one_worker_runs_the_campaigns_in_this_process(
    params: BodyParams, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # write_report documents workers=1 as "this process"; it once isolated the pushes in a worker.
    import pushrecovery.campaign as campaign

    seen = []

    def spy(*args, **kwargs):
        seen.append(kwargs.get("isolated", True))
        return run_campaign(*args, **kwargs)

    monkeypatch.setattr(campaign, "run_campaign", spy)
    skip = ("bounds", "map", "plane", "figures", "sweep", "planar")
    write_report(params, tmp_path, mujoco=False, skip=skip, workers=1, **TINY)
    assert seen == [False]


def test_a_campaign_with_no_outcome_has_no_accuracy(
    params: BodyParams, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Every push an error row (physics diverged, worker died): accuracy None, once a TypeError.
    import pushrecovery.report.campaigns as campaigns

    real = campaigns._campaign

    def no_outcome(ctx, key, spec):
        result = real(ctx, key, spec)
        return replace(result, summary={**result.summary, "accuracy": None})

    monkeypatch.setattr(campaigns, "_campaign", no_outcome)
    skip = ("bounds", "map", "plane", "figures", "sweep", "planar")
    write_report(params, tmp_path, mujoco=False, skip=skip, workers=1, **TINY)
    assert "<strong>Accuracy —</strong>" in (tmp_path / "index.html").read_text()


def test_a_section_that_could_not_be_computed_is_named_in_the_verdict(
    params: BodyParams, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from pushrecovery.report import build

    def broken(ctx: Any) -> Any:
        raise InvalidParameterError("leg_length must equal com_height here")

    monkeypatch.setitem(build._BUILDERS, "plane", broken)
    skip = [key for key in SECTIONS if key not in ("bounds", "plane")]
    report = build_report(params, tmp_path, mujoco=False, skip=skip, workers=1)
    why = "InvalidParameterError: leg_length must equal com_height here"
    assert report.verdict.missing == (("plane", SECTIONS["plane"], why),)
    html = render_report(report)
    verdict = html[html.index('<p class="verdict">') : html.index("</p>", html.index('"verdict"'))]
    assert "Not computed (1 section):" in verdict and '<a href="#plane">' in verdict
    assert "leg_length must equal com_height here" in verdict
    # A page whose sections all computed says nothing of the kind.
    whole = build_report(params, tmp_path, mujoco=False, skip=[*skip, "plane"], workers=1)
    assert whole.verdict.missing == () and "Not computed" not in render_report(whole)


def test_the_step_thresholds_say_how_many_steps(report: tuple[Report, Path, list[str]]) -> None:
    # One step, the paper's single step and max_steps steps are three different pushes: each
    # row says which it is (the N-step limit once stood in a row labelled one step, Sec. IV).
    data, _, _ = report
    section = data.section("bounds")
    assert isinstance(section, BoundsSection)
    rows = {row[0]: row for row in section.bounds.rows}
    th = bounds_data(load_params())["thresholds"]
    n = load_params().max_steps
    assert float(rows["one-step threshold"][2]) == pytest.approx(th["steps"]["1"][1], rel=1e-5)
    assert float(rows["Sec. IV single-step threshold"][2]) == pytest.approx(
        th["step_sec4"][1], rel=1e-5
    )
    assert float(rows[f"{n}-step threshold"][2]) == pytest.approx(th["step"][1], rel=1e-5)
    units = {row[0]: row[2] for row in section.parameters.rows}
    assert all(units.values()), [name for name, unit in units.items() if not unit]
