"""Issue 38's examples, each refused in one named line (the ones this change fixed)."""

import json

import numpy as np
import pytest

from conftest import cli_error
from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError
from pushrecovery.ground import Support
from pushrecovery.ground.user_polygon import convex_polygon
from pushrecovery.surfaces.n_step import hip_box, reach_polygon

P = load_params()


def test_a_subnormal_range_step_is_refused(capsys):
    err = cli_error(capsys, "step", "--v0-range", "0.1", "3", "5e-324")
    assert "--v0-range gives too many values" in err


def test_an_empty_trial_path_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    err = cli_error(capsys, "analyze", "", "--out", str(tmp_path / "o"))
    assert "a trial path is empty" in err
    assert not (tmp_path / "o").exists()


def test_foot_poses_must_be_foot_poses():
    with pytest.raises(ParameterTypeError, match=r"left must be a FootPose"):
        Support.from_params(P, "left", left=(0.0, 0.1))


def test_a_vertex_beyond_float_is_refused():
    with pytest.raises(InvalidParameterError, match="foot_polygon must be a list"):
        convex_polygon("foot_polygon", [[10**400, 0], [0, 1], [-1, -1]])


@pytest.mark.parametrize("yaw", [np.array(np.inf), 1e300, -7.0, float("nan"), "x"])
def test_hip_box_and_reach_refuse_a_yaw_beyond_a_turn(yaw):
    with pytest.raises(PushRecoveryError, match="yaw"):
        hip_box(P, yaw)
    with pytest.raises(PushRecoveryError, match="yaw"):
        reach_polygon(P, "left", yaw)


def test_reach_is_a_foot_s():
    with pytest.raises(InvalidParameterError, match="side must be 'left' or 'right'"):
        reach_polygon(P, "double", 0.0)
    assert reach_polygon(P, "left", 0.3) is reach_polygon(P, "left", 0.3)  # still kept


def _csv_trial(tmp_path):
    from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

    path = tmp_path / "c.csv"
    path.write_text(lipm_trial_csv(P, 0.2, 0.0))
    return path


def test_a_fifo_trial_is_refused(tmp_path, capsys):
    import os

    fifo = tmp_path / "f.csv"
    os.mkfifo(fifo)
    assert "not a regular file" in cli_error(
        capsys, "analyze", str(fifo), "--out", str(tmp_path / "o")
    )


def test_an_integer_of_thousands_of_digits_in_toml_is_refused(tmp_path, capsys):
    big = tmp_path / "big.toml"
    big.write_text("mass = " + "9" * 5000 + "\n")
    err = cli_error(capsys, "classify", "--x", "0", "--xdot", "0.3", "--params", str(big))
    assert "unreadable TOML" in err


@pytest.mark.parametrize("flag", ["--cutoff", "--force-cutoff"])
@pytest.mark.parametrize("value", ["1e-300", "5e-324"])
def test_a_vanishing_cutoff_is_refused(tmp_path, capsys, flag, value):
    trial = _csv_trial(tmp_path)
    err = cli_error(capsys, "analyze", str(trial), "--mass", "72", "--out", str(tmp_path / "o"),
                flag, value)  # fmt: skip
    assert "cutoff must be" in err and ("at least" in err or "in (0," in err)


@pytest.mark.parametrize("tolerance", [0.0, 1e-300, -1e-3, float("nan"), 1.0])
def test_a_step_bisection_refuses_a_tolerance_it_cannot_reach(tolerance):
    from pushrecovery.surfaces.step import step_critical_velocity, step_thresholds

    with pytest.raises(InvalidParameterError, match=r"tolerance must be .*in \[1e-12, 0.1\]"):
        step_critical_velocity(0.0994, -1, P, tolerance=tolerance)
    with pytest.raises(InvalidParameterError, match="tolerance"):
        step_thresholds(P, tolerance=tolerance)


def test_the_finest_step_tolerance_still_ends():
    from pushrecovery.surfaces.step import step_thresholds

    fine, coarse = step_thresholds(P, tolerance=1e-12), step_thresholds(P, tolerance=1e-3)
    assert abs(fine[0] - coarse[0]) <= 1e-3 and abs(fine[1] - coarse[1]) <= 1e-3


def test_an_mpc_period_of_a_microsecond_is_refused(capsys):
    err = cli_error(
        capsys, "simulate", "--model", "flywheel", "--controller", "mpc", "--impulse", "31.55",
        "--option", "dt=1e-6", "--json",
    )  # fmt: skip
    assert "dt must be in [0.001, 1]" in err


def test_the_monitor_refuses_a_capture_point_beyond_any_foot():
    from pushrecovery.surfaces.monitor import BalanceMonitor

    monitor = BalanceMonitor(P, Support.from_params(P))
    with pytest.raises(InvalidParameterError, match="capture point within"):
        monitor.query(0.19, -1.79e308, -0.94, 1e-300)
    assert monitor.query(0.19, -1e5, -0.94, 0.0).strategy.value == "fall"  # far, still finite


def test_a_trial_sixty_folders_deep_keeps_the_batch(tmp_path, capsys):
    from pushrecovery.cli import main
    from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

    text = lipm_trial_csv(P, 0.2, 0.0)
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "good.csv").write_text(text)
    deep = tmp_path / "data" / "/".join(["n" * 40] * 60)
    deep.mkdir(parents=True)
    (deep / "deep.csv").write_text(text)
    args = ["analyze", str(tmp_path / "data"), "--mass", "70", "--out", str(tmp_path / "o")]
    with pytest.raises(SystemExit) as end:
        main([*args, "--json"])
    assert end.value.code == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["trials"], summary["analysed"]) == (2, 2)
    names = sorted(p.name for p in (tmp_path / "o" / "trials").iterdir())
    assert "good.csv" in names and all(len(n.encode()) <= 200 for n in names)


# --- Found by the library fuzz (issue 38, item 3) ---------------------------------------------
def test_project_errors_are_one_line():
    error = InvalidParameterError(f"x bad {np.ones((3, 3))!r}")
    assert "\n" not in str(error) and isinstance(error, ValueError)


def test_out_arrays_and_shapes_are_checked():
    from pushrecovery.surfaces.cop import capture_margin, cop_region

    region = cop_region(P)
    with pytest.raises(InvalidParameterError, match="out must be a writeable array of shape"):
        capture_margin(np.zeros(2), 0.1, P.omega, region, out=np.zeros(1))
    with pytest.raises(ParameterTypeError, match="out must be a float64 numpy array"):
        capture_margin(np.zeros(2), 0.1, P.omega, region, out=0.1)
    with pytest.raises(InvalidParameterError, match="x and xdot must broadcast"):
        capture_margin(np.zeros(2), np.zeros(3), P.omega, region)
    with pytest.raises(ParameterTypeError, match="real numbers, got complex"):
        capture_margin(np.array([1 + 2j]), 0.1, P.omega, region)


def test_classify_refuses_a_capture_point_beyond_any_foot():
    from pushrecovery.surfaces.classify import classify

    with pytest.raises(InvalidParameterError, match="capture point must be within"):
        classify(0.01, -1.0, P, y=1e300)


def test_a_billion_frames_are_refused_before_any_allocation():
    from pushrecovery.sim.mujoco.render.frames import select_indices

    with pytest.raises(InvalidParameterError, match="count must be"):
        select_indices([0.0, 0.0], 10**9)
    assert select_indices([0.0, 1.0, 2.0], 2) == [0, 2]


def test_a_fifo_is_no_c3d_parameter_section(tmp_path):
    import os
    from pathlib import Path

    from pushrecovery.analysis.c3d.structure import read_parameter_section
    from pushrecovery.errors import InputFileError

    fifo = Path(tmp_path / "f.c3d")
    os.mkfifo(fifo)
    with pytest.raises(InputFileError, match="not a regular file"):
        read_parameter_section(fifo)


def test_mjcf_files_without_a_joint_or_a_sole_are_refused(tmp_path, capsys):
    from pushrecovery.sim.mujoco.humanoid3d.biped3d import build_biped3d

    xml = build_biped3d(P).to_xml()
    no_joint = tmp_path / "no_joint.xml"
    no_joint.write_text(xml.replace('joint="right_hip_roll"', 'joint="nowhere"', 1))
    err = cli_error(capsys, "humanoid", "simulate", "--model", str(no_joint), "--duration", "0.05")
    assert "actuator 'right_hip_roll' drives 'nowhere', which is no joint" in err
