"""The campaign plots and the HTML report, on tiny campaigns (the whole file runs in seconds)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from pushrecovery import BodyParams, InvalidParameterError, PushRecoveryError
from pushrecovery.campaign import CampaignResult, CampaignSpec, run_campaign
from pushrecovery.cli.app import cli
from pushrecovery.plots.campaign import (
    plot_critical_vs_parameter,
    plot_outcome_map,
    step_limit_curve,
)
from pushrecovery.report import SECTIONS, PushGrid, write_report
from pushrecovery.sim.critical import predicted_critical_velocity
from pushrecovery.surfaces.bounds import bounds_data

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def ankle_campaign(tmp_path_factory: pytest.TempPathFactory) -> CampaignResult:
    """Pendulum + ankle PD, 2 starts x 5 pushes."""
    from pushrecovery import load_params

    spec = CampaignSpec(
        "analytic",
        "pendulum",
        "ankle-pd",
        load_params(),
        x0=(0.0, 0.05, 0.05),
        xdot=(-0.4, 0.6, 0.25),
    )
    result = run_campaign(spec, tmp_path_factory.mktemp("ankle"), workers=1)
    assert result is not None
    return result


@pytest.fixture(scope="module")
def sweep_campaign(tmp_path_factory: pytest.TempPathFactory) -> CampaignResult:
    """Flywheel + MPC from upright, 6 pushes for each of two hip torque limits."""
    from pushrecovery import load_params

    spec = CampaignSpec(
        "analytic",
        "flywheel",
        "mpc",
        load_params(),
        x0=(0.0, 0.0, 1.0),
        xdot=(-0.5, 0.75, 0.25),
        sweeps={"torque_max": (0.0, 100.0, 100.0)},
    )
    result = run_campaign(spec, tmp_path_factory.mktemp("sweep"), workers=1)
    assert result is not None
    return result


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


def _confusion(html: str, ident: str) -> list[list[int]]:
    """Counts of the confusion table ``ident`` (without the totals)."""
    block = re.search(rf'<table class="confusion" id="{ident}">(.*?)</table>', html, re.S)
    assert block is not None
    rows = re.findall(r"<tr><th[^>]*>(\w+)</th>(.*?)</tr>", block.group(1))
    return [
        [int(c) for c in re.findall(r"<td[^>]*>(\d+)</td>", cells)[:-1]]
        for label, cells in rows
        if label != "total"
    ]


TINY = {
    "analytic_grid": PushGrid((0.0, 0.05, 0.05), (-1.0, 1.0, 0.5)),
    "sweep_grid": PushGrid((0.0, 0.0, 1.0), (-0.4, 0.8, 0.4), {"torque_max": (0.0, 100.0, 100.0)}),
}


def test_report_is_one_self_contained_page(params: BodyParams, tmp_path: Path) -> None:
    lines: list[str] = []
    path = write_report(params, tmp_path, mujoco=False, workers=1, progress=lines.append, **TINY)
    assert path == tmp_path / "index.html"
    assert [p.name for p in tmp_path.glob("*.html")] == ["index.html"]
    html = path.read_text(encoding="utf-8")
    # Nothing outside the page: no remote or relative resources, no script, no stylesheet link.
    for forbidden in ('src="http', 'href="http', "<script", "<link", "url("):
        assert forbidden not in html
    images = re.findall(r'<img src="([^"]*)"', html)
    assert len(images) >= 8 + 4  # the paper's figures, the map, the plane, two campaign plots
    assert all(src.startswith("data:image/png;base64,") for src in images)
    for key in ("bounds", "map", "plane", "figures", "analytic", "sweep"):
        assert f"<h2>{SECTIONS[key].replace(chr(39), '&#x27;')}</h2>" in html
    for key in ("mujoco", "biped", "critical", "filmstrips"):
        assert f'id="{key}"' not in html
    for number in ("Eq. (4)", "Eq. (15)", "Eq. (12)", "Sec. IV"):
        assert number in html
    # The confusion matrix is the one of the campaign's summary.
    summary = json.loads((tmp_path / "campaign-analytic" / "summary.json").read_text())
    assert _confusion(html, "confusion-analytic") == summary["confusion"]["counts"]
    assert f"Accuracy {summary['accuracy']:.3g}" in html
    # Every section's wall time in the footer, and reported as it ran.
    footer = html[html.index("<footer>") :]
    for key in ("bounds", "map", "plane", "figures", "analytic", "sweep"):
        assert SECTIONS[key].replace("'", "&#x27;") in footer
    assert any(line.startswith(SECTIONS["analytic"] + ":") for line in lines)


def test_report_reuses_and_replaces_its_campaigns(params: BodyParams, tmp_path: Path) -> None:
    skip = ("bounds", "map", "plane", "figures", "sweep")
    write_report(params, tmp_path, mujoco=False, skip=skip, workers=1, **TINY)
    batch = next((tmp_path / "campaign-analytic" / "batches").iterdir())
    stamp = batch.stat().st_mtime_ns
    write_report(params, tmp_path, mujoco=False, skip=skip, workers=1, **TINY)
    assert batch.stat().st_mtime_ns == stamp  # reused, not simulated again
    other = PushGrid((0.0, 0.0, 1.0), (0.0, 0.5, 0.5))
    html = write_report(
        params, tmp_path, mujoco=False, skip=skip, workers=1, analytic_grid=other
    ).read_text()
    summary = json.loads((tmp_path / "campaign-analytic" / "summary.json").read_text())
    assert summary["pushes"] == 2
    assert _confusion(html, "confusion-analytic") == summary["confusion"]["counts"]


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


def test_report_rejects_unknown_sections_and_sizes(params: BodyParams, tmp_path: Path) -> None:
    with pytest.raises(InvalidParameterError, match="size"):
        write_report(params, tmp_path, size="huge")
    with pytest.raises(InvalidParameterError, match="section"):
        write_report(params, tmp_path, skip=("nope",))
    assert not (tmp_path / "index.html").exists()
