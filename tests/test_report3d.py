"""The report's "3-D humanoid" section: present with the robots extra, one line without it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from pushrecovery import load_params
from pushrecovery.report import SECTIONS, SIZES, write_report
from pushrecovery.report import humanoid3d as section3d
from pushrecovery.report.build import build_report
from pushrecovery.report.context import _Context
from pushrecovery.report.data import Humanoid3DSection
from pushrecovery.report.render import render_report
from pushrecovery.sim.mujoco.humanoid3d import robots

PNG = b"\x89PNG\r\n\x1a\n"
ONLY_3D = [key for key in SECTIONS if key != "humanoid3d"]


def no_extra(name: str) -> Path:
    raise robots.RobotsExtraMissing("the G1 model needs the robots extra")


def test_without_the_extra_the_section_is_one_line(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(robots, "robot_path", no_extra)
    report = build_report(load_params(), tmp_path, skip=ONLY_3D)
    section = report.section("humanoid3d")
    assert section == Humanoid3DSection(unavailable=section3d.HINT)
    html = render_report(report)
    assert html.count("pip install &#39;pushrecovery[robots]&#39;") == 1
    assert "<img" not in html
    assert not (tmp_path / "humanoid3d").exists()  # nothing simulated


def test_the_section_is_left_out_without_mujoco_sections(tmp_path: Path) -> None:
    report = build_report(load_params(), tmp_path, mujoco=False, skip=ONLY_3D)
    assert [key for key, _, _ in report.sections] == []


@pytest.fixture
def tiny(monkeypatch) -> None:
    """One azimuth and strategy of the biped3d, one short filmstrip: seconds, not minutes."""
    monkeypatch.setattr(section3d, "VALIDATIONS", (("biped3d", ("ankle",)),))
    strip = ("biped3d", 90.0, 0.5, "ankle", "biped3d, push to the left", (0.1, 0.2, 0.3))
    monkeypatch.setattr(section3d, "HUMANOID3D_STRIPS", {"biped3d-ankle": strip})


def test_with_the_extra_the_section_has_polar_plots_tables_and_filmstrips(
    tiny: None, tmp_path: Path, monkeypatch
) -> None:
    pytest.importorskip("mujoco")
    try:
        robots.robot_path("g1")
    except robots.RobotsExtraMissing:
        pytest.skip("the robots extra is not installed")
    grids = replace(SIZES["small"], azimuths3d=(90.0,), tolerance3d=0.2, duration3d=1.5)
    ctx = _Context(load_params(), tmp_path, grids, workers=1, scheduler=None)
    section = section3d.humanoid3d_section(ctx)
    assert section.unavailable is None
    (polar,) = section.polar
    assert polar.path.read_bytes().startswith(PNG)
    (table,) = section.tables
    assert [row[:2] for row in table.rows] == [("90", "ankle")]
    # The measured critical push: below the fall of the bracket, within 20 % of the
    # prediction's push-height correction (docs/validation3d.md: +3.8 % at 90° at 1 %).
    measured, corrected = float(table.rows[0][4]), float(table.rows[0][3])
    assert measured == pytest.approx(corrected, rel=0.2)
    if section.rendering is None:  # offscreen OpenGL available
        (strip,) = section.strips
        assert strip.picture is not None and strip.picture.path.read_bytes().startswith(PNG)
        assert strip.impulse == pytest.approx(0.5 * 33.8, rel=0.05)  # half the 2-D limit
    # A second build reuses what is on disk (the same settings), and says so.
    stamp = (tmp_path / "humanoid3d" / "validation3d-biped3d.json").stat().st_mtime_ns
    again = _Context(load_params(), tmp_path, grids, workers=1, scheduler=None)
    assert section3d.humanoid3d_section(again).tables == section.tables
    assert (tmp_path / "humanoid3d" / "validation3d-biped3d.json").stat().st_mtime_ns == stamp
    assert any("Reused" in note for note in again.notes["humanoid3d"])
    # Other settings compute afresh.
    other = _Context(load_params(), tmp_path, replace(grids, duration3d=1.4), 1, None)
    section3d.humanoid3d_section(other)
    assert "humanoid3d" not in other.notes
    # So does other code (a development tree after a controller change): the cache is keyed by
    # a digest of the package's sources.
    monkeypatch.setattr(section3d, "_code_fingerprint", lambda: "another")
    changed = _Context(load_params(), tmp_path, grids, workers=1, scheduler=None)
    section3d.humanoid3d_section(changed)
    assert "humanoid3d" not in changed.notes


def test_the_code_fingerprint_is_a_digest_of_the_sources() -> None:
    digest = section3d._code_fingerprint()
    assert len(digest) == 16 and int(digest, 16) >= 0
    section3d._code_fingerprint.cache_clear()
    assert section3d._code_fingerprint() == digest  # the same sources, the same digest


def test_the_page_shows_the_section(tiny: None, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(robots, "robot_path", no_extra)
    html = write_report(load_params(), tmp_path, skip=ONLY_3D).read_text()
    assert '<section id="humanoid3d">' in html and "<h2>3-D humanoid</h2>" in html


def test_a_report_on_an_mjcf_robot_validates_and_films_it(
    tiny: None, tmp_path: Path, capsys
) -> None:
    # The user's robot (the biped3d written to an MJCF file, its bent-knee keyframe) in place
    # of the biped3d: its table and filmstrip are named after the file, its body is the file's.
    pytest.importorskip("mujoco")
    from pushrecovery.sim.mjcf_source import MjcfSource
    from pushrecovery.sim.mujoco.humanoid3d.biped3d import bent_knee_qpos, build_biped3d

    spec = build_biped3d(load_params())
    spec.add_key(name="bent", qpos=list(bent_knee_qpos(spec.compile())))
    path = tmp_path / "my_robot.xml"
    path.write_text(spec.to_xml())
    robot = MjcfSource(str(path), ("left_foot", "right_foot"), "torso", "bent")
    grids = replace(SIZES["small"], azimuths3d=(90.0,), tolerance3d=0.2, duration3d=1.5)
    ctx = _Context(robot.plant().params, tmp_path, grids, workers=1, scheduler=None, robot=robot)
    section = section3d.humanoid3d_section(ctx)
    (table,) = section.tables
    assert table.ident == "validation3d-my_robot"
    assert [row[:2] for row in table.rows] == [("90", "ankle")]
    assert (tmp_path / "humanoid3d" / "validation3d-my_robot.json").is_file()
    if section.rendering is None:
        (strip,) = section.strips
        assert strip.model == "my_robot" and "my_robot" in strip.caption
    # The command line: --model PATH.xml with its bodies; body flags are refused in one line.
    from pushrecovery.cli import main

    body = ["--model", str(path), "--left-foot-body", "left_foot", "--right-foot-body",
            "right_foot", "--torso-body", "torso", "--keyframe", "bent"]  # fmt: skip
    with pytest.raises(SystemExit) as caught:
        main(["report", *body, "--mass", "60", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert caught.value.code == 2 and "has the model's own body" in err
    with pytest.raises(SystemExit) as caught:
        main(["report", "--torso-body", "torso", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert caught.value.code == 2 and "--torso-body needs --model PATH.xml" in err
