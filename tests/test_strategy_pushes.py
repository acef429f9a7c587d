"""Pushes relative to a body's own thresholds (the report's filmstrips, issue 15 item 5)."""

import pytest

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.experiments.pushes import strategy_pushes
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import critical_velocity
from pushrecovery.surfaces.step import step_critical_velocity

ROBOT = {"mass": 45.0, "com_height": 0.7, "torque_max": 40.0, "flywheel_inertia": 3.0}
BODIES = [{}, ROBOT, {"mass": 95.0, "toe": 0.2}, {"torque_max": 20.0}]


@pytest.mark.parametrize("overrides", BODIES)
def test_each_push_lies_between_the_bodys_own_thresholds(overrides):
    params = load_params(overrides=overrides)
    pushes = strategy_pushes(params)
    ankle = float(critical_velocity(0.0, 1.0, params))
    hip = float(critical_velocity(0.0, 1.0, params, region=cmp_region(params)))
    step = step_critical_velocity(0.0, 1.0, params)
    assert 0.0 < pushes.ankle < ankle < pushes.hip < hip < pushes.step < step


def test_the_paper_body_keeps_its_pushes():
    params = load_params()
    pushes = strategy_pushes(params)
    assert [pushes.impulse(s, params.mass) for s in ("ankle", "hip", "step")] == [25, 40, 80]


def test_a_light_robots_hip_push_is_recovered_with_the_hip():
    # The 40 N s of the paper's body is beyond this robot's hip region (it would fall); its
    # own hip push is recovered by the MPC on the MuJoCo torso, using the hip.
    pytest.importorskip("mujoco")
    params = load_params(overrides=ROBOT)
    limit = float(critical_velocity(0.0, 1.0, params, region=cmp_region(params)))
    assert 40.0 / params.mass > limit
    plant = make_plant("torso", params, "mujoco")
    plant.reset(0.0, 0.0)
    impulse = strategy_pushes(params).impulse("hip", params.mass)
    pushed = plant.apply_push(Push.from_impulse(impulse, params.mass))
    run = simulate(plant, make_controller("mpc", params), pushed, duration=4.0)
    assert run.recovered and run.strategy_used().value == "hip"


def test_the_reports_grids_follow_the_bodys_thresholds():
    from pushrecovery.experiments.pushes import push_scale
    from pushrecovery.report.config import SIZES
    from pushrecovery.report.context import _body_grids

    paper = load_params()
    assert _body_grids(SIZES["small"], paper) == SIZES["small"]
    robot = load_params(overrides=ROBOT)
    grids = _body_grids(SIZES["small"], robot)
    step, hip = push_scale(robot, "step", paper), push_scale(robot, "hip", paper)
    assert grids.analytic.xdot[1] == pytest.approx(SIZES["small"].analytic.xdot[1] * step)
    assert grids.mujoco.xdot[1] == pytest.approx(SIZES["small"].mujoco.xdot[1] * hip)
    # The hip grid reaches as far past the robot's hip threshold as the paper's does past its.
    limit = float(critical_velocity(0.0, 1.0, robot, region=cmp_region(robot)))
    paper_limit = float(critical_velocity(0.0, 1.0, paper, region=cmp_region(paper)))
    assert grids.mujoco.xdot[1] / limit == pytest.approx(
        SIZES["small"].mujoco.xdot[1] / paper_limit
    )


def test_percentages_are_no_finer_than_their_resolution():
    from pushrecovery.report.markup import percent_within

    assert percent_within(0.2743, 0.04) == "+27 % ± 4 %"
    assert percent_within(-0.0587, 0.005) == "−5.9 % ± 0.5 %"
    assert percent_within(0.01234, 0.0004) == "+1.23 % ± 0.04 %"
    assert percent_within(0.1, None) == "+10.0 %"


def test_a_bisected_push_has_an_interval_of_errors():
    from pushrecovery.report.markup import percent_interval

    # A push bracketed in [10.8, 10.9] N s against 10.3 N s: +4.9 to +5.8 %, not "+4.9 %".
    assert percent_interval(10.8, 10.9, 10.3) == "+4.9 … +5.8 %"
    assert percent_interval(27.0, 27.1, 31.5) == "−14.3 … −14.0 %"
    assert percent_interval(1.0, 2.0, 0.0) == "—"
    assert percent_interval(-0.45, -0.46, -0.47) == "−4.3 … −2.1 %"  # backward, as magnitudes
