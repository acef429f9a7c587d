"""A campaign's noisy state estimates and their probabilities (issue 37), against the API."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.campaign import CampaignSpec, run_campaign
from pushrecovery.surfaces.probability import StateGaussian, verdict_probabilities

P = dataclasses.replace(load_params(), max_steps=2)
SD = (0.01, 0.1)


def stepping(**changes):
    options = {"x0": (0.0, 0.0, 1.0), "xdot": (2.6, 3.9, 0.05), "state_sd": SD, **changes}
    return CampaignSpec("analytic", "stepping", "recovery", P, **options)


def test_each_push_gets_an_estimate_and_its_probabilities(tmp_path):
    result = run_campaign(stepping(), tmp_path / "c", workers=1)
    rows = result.table.to_pylist()
    assert len(rows) == 27
    for row in rows:
        state = StateGaussian(np.array([row["estimate_x"], row["estimate_xdot"]]),
                              np.diag(np.square(SD)))  # fmt: skip
        found = verdict_probabilities(state, P)
        # A stepping controller: any of ankle, hip, 1 or 2 steps.
        assert row["p_recovers"] == pytest.approx(found.at_most(P.max_steps), abs=1e-12)
        assert row["p_fall"] == pytest.approx(found.fall, abs=1e-12)
        certain = verdict_probabilities(StateGaussian(state.mean, np.zeros((2, 2))), P)
        assert row["estimate_recovers"] == (certain.fall == 0.0)
    calibration = result.summary["calibration"]
    judged = [r for r in rows if r["outcome"] != "undecided"]
    assert calibration["pushes"] == len(judged)
    brier = np.mean([(r["p_recovers"] - (r["outcome"] == "recovered")) ** 2 for r in judged])
    assert calibration["brier"] == pytest.approx(brier)
    assert sum(b["pushes"] for b in calibration["reliability"]) == len(judged)
    assert calibration["brier"] < calibration["brier_base_rate"]


def test_an_ankle_controller_is_scored_on_the_ankle_alone(tmp_path):
    spec = CampaignSpec("analytic", "pendulum", "ankle-pd", P, x0=(0.0, 0.0, 1.0),
                        xdot=(0.2, 0.6, 0.1), state_sd=SD, latency=0.02)  # fmt: skip
    for row in run_campaign(spec, tmp_path / "c", workers=1).table.to_pylist():
        state = StateGaussian(np.array([row["estimate_x"], row["estimate_xdot"]]),
                              np.diag(np.square(SD)))  # fmt: skip
        found = verdict_probabilities(state, P, latency=0.02)
        assert row["p_recovers"] == pytest.approx(found.ankle, abs=1e-12)


def test_the_estimates_depend_on_the_seed_and_the_push_alone(tmp_path):
    whole = run_campaign(stepping(), tmp_path / "a", workers=1).table
    batched = run_campaign(stepping(batch_size=4), tmp_path / "b", workers=2).table
    for name in ("estimate_x", "estimate_xdot", "p_recovers"):
        assert whole.column(name).to_pylist() == batched.column(name).to_pylist()
    other = run_campaign(stepping(seed=5), tmp_path / "c", workers=1).table
    assert other.column("estimate_xdot").to_pylist() != whole.column("estimate_xdot").to_pylist()
    # The errors are the spec's: mean 0 and SD state_sd over many pushes.
    many = stepping(xdot=(0.0, 3.0, 0.0015), x0=(0.0, 0.0, 1.0))
    table = run_campaign(many, tmp_path / "d", workers=1).table
    errors = np.array(table.column("estimate_xdot").to_pylist()) - np.array(
        table.column("xdot").to_pylist()
    )
    assert len(errors) == 2001
    assert abs(errors.mean()) < 4 * SD[1] / math.sqrt(len(errors))
    assert errors.std() == pytest.approx(SD[1], rel=0.1)


def test_without_a_state_estimate_the_columns_are_null(tmp_path):
    result = run_campaign(stepping(state_sd=None), tmp_path / "c", workers=1)
    assert set(result.table.column("p_recovers").to_pylist()) == {None}
    assert result.summary["calibration"] is None


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"state_sd": (-0.01, 0.1)}, r"state_sd\[0\]"),
        ({"state_sd": (0.01,)}, "state_sd must be"),
        ({"latency": 2.0}, "latency"),
        ({"latency": math.nan}, "latency"),
    ],
)
def test_bad_estimates_are_refused(changes, match):
    with pytest.raises(InvalidParameterError, match=match):
        stepping(**changes)


def test_the_3d_humanoids_refuse_estimates():
    with pytest.raises(InvalidParameterError, match="planar models"):
        CampaignSpec("mujoco", "biped3d", "wbc-ankle", load_params(), x0=(0.0, 0.0, 1.0),
                     impulse=(5.0, 5.0, 1.0), state_sd=SD)  # fmt: skip


def test_the_spec_keeps_its_estimates():
    spec = stepping(latency=0.03)
    again = CampaignSpec.from_dict(spec.to_dict())
    assert again.state_sd == SD and again.latency == 0.03
    plain = stepping(state_sd=None).to_dict()
    assert "state_sd" not in plain and "latency" not in plain  # older specs read the same


def test_the_cli_takes_state_sd_and_latency(tmp_path, capsys):
    import json

    from pushrecovery.cli import main

    out = tmp_path / "c"
    with pytest.raises(SystemExit) as info:
        main(["campaign", "--x0", "0", "0", "1", "--xdot", "2.6", "3.9", "0.1", "--param",
              "max_steps=2:2:1", "--state-sd", "0.01,0.1", "--latency", "0.02", "--workers", "1",
              "--out", str(out), "--json"])  # fmt: skip
    assert info.value.code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["calibration"]["pushes"] == 14 and data["spec"]["state_sd"] == [0.01, 0.1]
    with pytest.raises(SystemExit) as info:
        main(["campaign", "--x0", "0", "0", "1", "--xdot", "1", "2", "1", "--state-sd", "a,b",
              "--workers", "1", "--out", str(tmp_path / "d")])  # fmt: skip
    err = capsys.readouterr().err
    assert info.value.code == 2 and "--state-sd must be two numbers" in err
    assert err.count("\n") == 1
