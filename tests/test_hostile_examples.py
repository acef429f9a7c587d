"""Issue 38's examples, each refused in one named line (the ones this change fixed)."""

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
