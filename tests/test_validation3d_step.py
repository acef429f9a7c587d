"""The step column of the 3-D validation (issue 19 item 5): prediction and a short measurement."""

import math
from dataclasses import replace

import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.experiments.validation3d.step import (
    StepRow,
    measure_step_critical,
    predicted_step_critical,
    run_step_validation,
)
from pushrecovery.ground.support import Support


@pytest.fixture(scope="module")
def params():
    return load_params()


def test_left_push_prediction_is_the_closed_form_of_s1(params):
    """ρ = w/2 − s/2 + e^{−ωΔt} l along +y for a left step of a rectangle foot (S1, N = 1)."""
    reach = math.exp(-params.omega * params.min_step_time) * params.max_step_length
    rho = 0.5 * params.foot_width - 0.5 * params.stance_width + reach
    expected = params.mass * params.omega * rho
    assert predicted_step_critical(params, 90.0, origin=(0.0, 0.0)) == pytest.approx(expected)


def test_prediction_is_mirror_symmetric_and_beyond_the_ankle(params):
    ankle = Support.from_params(params).polygon
    for azimuth in range(0, 360, 30):
        left = predicted_step_critical(params, azimuth)
        assert left == pytest.approx(predicted_step_critical(params, -azimuth), rel=1e-9)
        # One step reaches farther than the feet where they stand.
        rho = ankle.ray_distance(0.0, 0.0, math.radians(azimuth))
        assert left > params.mass * params.omega * rho


def test_a_slower_step_or_a_shorter_reach_shrinks_the_prediction(params):
    quick = predicted_step_critical(params, 0.0)
    assert predicted_step_critical(params, 0.0, step_time=0.4) < quick
    short = replace(params, max_step_length=0.5)
    assert predicted_step_critical(short, 0.0) < quick


def test_measured_step_critical_is_beyond_the_ankle_and_below_the_prediction(params):
    """A short bisection to the left: stepping stands more than the CoP region allows."""
    ankle = params.mass * params.omega * 0.15  # the CoP region's edge, 0.15 m to the left
    measured, bracket, runs, run = measure_step_critical(
        params, 90.0, guess=60.0, rel_tolerance=0.2, duration=2.0
    )
    assert bracket[0] == measured < bracket[1] <= measured + 0.2 * 60.0 + 1e-9
    assert 1.2 * ankle < measured < predicted_step_critical(params, 90.0)
    assert run.stood and run.steps >= 1 and run.step_length > 0.2
    assert runs <= 12
    # The run's physical checks travel with it (the landing's strike above m g).
    assert run.foot_slip >= 0.0 and run.peak_force > 1.0


def test_row_errors_and_cause(params):
    row = StepRow(0.0, 100.0, 80.0, 60.0, (60.0, 61.0), 5, 2, 0.3, 0.5)
    assert row.relative_error == pytest.approx(-0.4)
    assert row.corrected_error == pytest.approx(-0.25)
    cause = row.cause(params)
    assert "swing 0.30 s" in cause and "step 0.50 m" in cause and "2 steps" in cause
    close = StepRow(0.0, 100.0, 80.0, 85.0, (85.0, 86.0), 5, 1, 0.2, 0.9)
    assert close.cause(params) == ""


@pytest.fixture(scope="module")
def g1():
    """The G1's validation plant; skipped without MuJoCo or the robots extra."""
    pytest.importorskip("mujoco")
    from pushrecovery.sim.mujoco.humanoid3d import robots

    try:
        robots.robot_path("g1")
    except robots.RobotsExtraMissing:
        pytest.skip("the robots extra is not installed")
    from pushrecovery.experiments.validation3d import validation_plant

    return validation_plant("g1")


def test_the_g1_steps_beyond_its_ankles_and_short_of_the_one_step_prediction(g1):
    """Forward: the G1 with stepping stands pushes its CoP region cannot hold.

    The CoP region's plain limit m ω (toe − x₀) is above what the G1's ankles hold (10.3 N s
    against 15.2, docs/validation3d.md): stepping must stand more than that, and less than the
    one-step region's plain prediction.
    """
    p = g1.params
    ankle = p.mass * p.omega * (p.toe - g1.reset()[0])
    measured, bracket, runs, run = measure_step_critical(
        p, 0.0, guess=30.0, rel_tolerance=0.2, duration=2.0, plant=g1
    )
    assert bracket[0] == measured < bracket[1] <= measured + 0.2 * 30.0 + 1e-9
    assert ankle < measured < predicted_step_critical(p, 0.0, origin=tuple(g1.reset()[:2]))
    assert run.stood and run.steps >= 1 and run.step_length > 0.1
    assert runs <= 12


def test_cli_validates_the_g1s_step_column(g1, tmp_path, capsys):
    import json

    from pushrecovery.cli import main

    args = ["humanoid", "validate", "--model", "g1", "--strategy", "step", "--azimuth", "90",
            "--rel-tolerance", "0.3", "--duration", "2", "--no-confusion", "--json",
            "--out", str(tmp_path)]  # fmt: skip
    with pytest.raises(SystemExit) as done:
        main(args)
    assert done.value.code in (0, None)
    data = json.loads(capsys.readouterr().out)
    (row,) = data["step_critical"]
    assert row["azimuth"] == 90.0 and row["measured"] > 0.0 and row["steps"] >= 0
    assert (tmp_path / "validation3d_g1_step.md").exists()


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda p: predicted_step_critical(p, 400.0), "azimuth"),
        (lambda p: predicted_step_critical(p, 0.0, step_time=-1.0), "step_time"),
        (lambda p: predicted_step_critical("body", 0.0), "params"),
        (lambda p: measure_step_critical(p, 0.0, guess=0.0), "guess"),
        (lambda p: measure_step_critical(p, 0.0, guess=10.0, rel_tolerance=0.9), "rel_tolerance"),
        (lambda p: measure_step_critical(p, 0.0, guess=10.0, duration=0.0), "duration"),
        (lambda p: measure_step_critical(p, 500.0, guess=10.0), "azimuth"),
        (lambda p: run_step_validation([]), "azimuths"),
        (lambda p: run_step_validation("0"), "azimuths"),
        (lambda p: run_step_validation([0.0], params="body"), "params"),
        (lambda p: run_step_validation([0.0], rel_tolerance=0.0), "rel_tolerance"),
        (lambda p: run_step_validation([0.0], model="h1"), "model"),
        (lambda p: measure_step_critical(p, 0.0, guess=10.0, plant="biped"), "plant"),
    ],
)
def test_bad_inputs(params, call, name):
    with pytest.raises((InvalidParameterError, PushRecoveryError), match=name):
        call(params)


def test_the_g1s_controller_has_no_hip_task_unless_asked_and_the_biped3ds_has(g1):
    # Measured: on the G1 the hip task lowers the critical push at every azimuth
    # (docs/validation3d.md), so its default WBC balances without it; the biped3d keeps it.
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, wbc_for

    assert wbc_for(g1).hip_params is None
    assert wbc_for(g1, hip=True).hip_params is g1.params
    biped = Biped3DPlant(load_params())
    assert wbc_for(biped).hip_params is biped.params
    assert wbc_for(biped, hip=False).hip_params is None
    for bad in ("yes", 1, 1.0):
        with pytest.raises(InvalidParameterError, match="hip must be a bool or None"):
            wbc_for(biped, hip=bad)
