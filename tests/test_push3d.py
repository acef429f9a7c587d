"""Pushes from any direction on the 3-D models (issue 19 item 4): Push3D, plant3d, the CLI."""

import json
import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.cli import main
from pushrecovery.control.base import Command
from pushrecovery.control.wbc.observation import HumanoidCommand
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.polygon import convex_hull
from pushrecovery.sim.mujoco.humanoid3d import robots
from pushrecovery.sim.mujoco.humanoid3d.plant3d import (
    CONTROL_PERIOD,
    STATE_LABELS,
    Biped3DPlant,
    wbc_for,
)
from pushrecovery.sim.push import Push, Push3D, push_direction

P = load_params()
#: The CoM's velocity jump of a 10 ms torso push against J/m: the floor's friction and the
#: motors holding the standing torques take or add a few per cent while the force acts
#: (measured: +2 to +4 %).
MOMENTUM_TOLERANCE = 0.06


def test_push_direction_components():
    assert push_direction(0.0) == (1.0, 0.0)
    for azimuth, expected in ((90.0, (0.0, 1.0)), (180.0, (-1.0, 0.0)), (-90.0, (0.0, -1.0)),
                              (270.0, (0.0, -1.0)), (45.0, (math.sqrt(0.5),) * 2)):  # fmt: skip
        assert push_direction(azimuth) == pytest.approx(expected, abs=1e-12)
    push = Push3D(7.2, 90.0)
    assert push.body == "torso"
    assert push.delta_velocity(72.0) == pytest.approx((0.0, 0.1), abs=1e-12)
    assert push.force(0.01) == pytest.approx((0.0, 720.0, 0.0), abs=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"impulse": -1.0}, "impulse must be in [0, 10000]"),
        ({"impulse": math.nan}, "impulse"),
        ({"impulse": 1.0, "azimuth": 361.0}, "azimuth must be in [-360, 360]"),
        ({"impulse": 1.0, "azimuth": "left"}, "azimuth"),
        ({"impulse": 1.0, "body": ""}, "body must be"),
        ({"impulse": 1.0, "body": 3}, "body must be"),
    ],
)
def test_bad_pushes_name_the_argument_and_range(kwargs, words):
    with pytest.raises(InvalidParameterError) as caught:
        Push3D(**kwargs)
    assert words in str(caught.value)
    with pytest.raises(InvalidParameterError, match="azimuth"):
        push_direction(math.inf)


def test_the_plant_keeps_the_contract_where_it_is_3d():
    plant = Biped3DPlant(P)
    state = plant.reset()
    assert plant.state_labels == STATE_LABELS and state.shape == (6,)
    assert plant.state_labels[len(state) // 2] == "xdot"
    assert plant.begin(state) == pytest.approx(state)
    assert plant.at_rest(state, 1e-3) and not plant.falling(state)
    with pytest.raises(InvalidParameterError, match="x must be 0"):
        plant.reset(0.01, 0.0)
    with pytest.raises(InvalidParameterError, match="body must be a body of the biped3d"):
        plant.apply_push(Push3D(1.0, 0.0, "nose"))
    with pytest.raises(InvalidParameterError, match="command motors must be 12"):
        plant.step(HumanoidCommand(0.0, motors=np.zeros(3)), 0.002)
    with pytest.raises(InvalidParameterError, match="command motors must be 12"):
        plant.step(HumanoidCommand(0.0, motors=np.full(12, math.nan)), 0.002)
    with pytest.raises(ParameterTypeError, match="command must be a Command"):
        plant.step(np.zeros(12), 0.002)
    held = plant.step(Command(0.0), 0.002)  # a plain Command holds the motors (none yet)
    assert held.applied == (0.0,) * 12
    # The capture point beyond the hips' reach outside the feet is the fall set.
    assert plant.falling(np.array([0.0, 0.0, state[2], 5.0, 0.0, 0.0]))


def standing(plant, seconds=0.05):
    """Reset ``plant`` and stand it under the WBC (the motors then hold through a push)."""
    state = plant.reset()
    controller = wbc_for(plant)
    controller.reset(state)
    for _ in range(round(seconds / CONTROL_PERIOD)):
        state = plant.step(controller.compute(0.0, state), CONTROL_PERIOD).state
    return state


@pytest.mark.parametrize("azimuth", [0.0, 90.0, -135.0])
def test_a_push_changes_the_com_velocity_by_j_over_m_at_its_azimuth(azimuth):
    plant = Biped3DPlant(P)
    before = standing(plant)
    impulse = 15.0
    after = plant.apply_push(Push3D(impulse, azimuth))
    change = after[3:5] - before[3:5]
    expected = impulse / P.mass * np.array(push_direction(azimuth))
    # Along the azimuth J/m within the tolerance; across it < 3 % of J/m (1.4 % diagonally:
    # the feet's contacts resist x and y differently).
    along = change @ np.array(push_direction(azimuth))
    assert along == pytest.approx(impulse / P.mass, rel=MOMENTUM_TOLERANCE)
    assert np.linalg.norm(change - along * np.array(push_direction(azimuth))) < 0.03 * (
        np.linalg.norm(expected)
    )
    # A sagittal Push is J = m Δẋ forward (or backward) on the torso.
    before = standing(plant)
    back = plant.apply_push(Push(-0.1)) - before
    assert back[3] == pytest.approx(-0.1, rel=MOMENTUM_TOLERANCE) and abs(back[4]) < 1e-3


def test_a_scheduled_push_acts_over_the_next_steps_under_the_controller():
    """Push3D(scheduled=True): nothing now, no row; the force on the next 10 ms of physics
    steps while the WBC commands (its motors change during the push); push_row at its end."""
    plant = Biped3DPlant(P)
    before = standing(plant)
    controller = wbc_for(plant)
    controller.reset(before)
    rows = len(plant.run_rows().time)
    now = plant.apply_push(Push3D(15.0, 90.0, scheduled=True))
    assert np.array_equal(now, before) and len(plant.run_rows().time) == rows
    assert plant.push_left == pytest.approx(0.01) and plant.push_row is None
    motors = []
    for tick in range(5):  # 10 ms: five 2 ms ticks of four 0.5 ms steps
        step = plant.step(controller.compute(0.0, plant.state), CONTROL_PERIOD)
        motors.append(step.applied)
        assert plant.push_left == pytest.approx(0.01 - (tick + 1) * CONTROL_PERIOD)
    assert plant.push_row == len(plant.run_rows().time) - 1 and plant.max_torso_tilt >= 0.0
    assert not np.array_equal(motors[0], motors[-1])  # the controller reacted
    gained = plant.state[3:5] - before[3:5]
    assert gained[1] == pytest.approx(15.0 / P.mass, rel=MOMENTUM_TOLERANCE)
    assert abs(gained[0]) < 0.03 * 15.0 / P.mass
    plant.step(controller.compute(0.0, plant.state), CONTROL_PERIOD)  # the force is over
    assert plant.push_left == 0.0 and not np.any(plant.data.xfrc_applied)
    # In the loop: one row per tick (none of the push's own); push_row where the force ended.
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import run_push3d

    run = run_push3d(plant, wbc_for(plant), Push3D(15.0, 90.0, scheduled=True),
                     duration=0.02, push_time=2 * CONTROL_PERIOD)  # fmt: skip
    assert len(run.time) == 2 + 10 + 1 and run.extras.push_row == 2 + 5
    assert np.diff(run.time) == pytest.approx(CONTROL_PERIOD)


def test_a_push_the_3d_plant_cannot_apply_is_refused_naming_the_field():
    plant = Biped3DPlant(P)
    plant.reset()
    with pytest.raises(InvalidParameterError, match="push kind must be 'force'"):
        plant.apply_push(Push(0.1, "velocity"))
    with pytest.raises(InvalidParameterError, match=r"push duration must be 0\.01 s"):
        plant.apply_push(Push(0.1, duration=0.02))
    with pytest.raises(InvalidParameterError, match="body must be a body of the biped3d"):
        plant.apply_push(Push(0.1, body="nose"))
    with pytest.raises(InvalidParameterError, match="scheduled must be a bool"):
        Push3D(1.0, scheduled="yes")  # type: ignore[arg-type]
    # A Push's body and scheduling are honoured: the Push3D of J = m Δẋ on the left thigh.
    ends = []
    for push in (Push(0.1, body="left_thigh", scheduled=True),
                 Push3D(0.1 * P.mass, 0.0, "left_thigh", scheduled=True), Push(0.1)):  # fmt: skip
        state = plant.reset()
        assert np.array_equal(plant.apply_push(push), state) == push.scheduled
        for _ in range(5):
            plant.step(Command(0.0), CONTROL_PERIOD)  # the motors held
        ends.append(plant.state)
    assert np.array_equal(ends[0], ends[1]) and not np.allclose(ends[0], ends[2])


def run_cli(capsys, *args):
    with pytest.raises(SystemExit) as caught:
        main(list(args))
    out, err = capsys.readouterr()
    return caught.value.code, out, err


def test_simulate_biped3d_recovers_a_small_push_and_reports_the_new_keys(capsys):
    args = ("--model", "biped3d", "--azimuth", "60", "--push", "8")
    code, out, err = run_cli(capsys, "humanoid", "simulate", *args, "--duration", "4", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["recovered"] is True and data["outcome"] == "recovered"
    assert data["steps"] == 0 and data["strategy"] == "ankle"
    assert data["azimuth"] == 60.0 and data["impulse"] == 8.0 and data["push_body"] == "torso"
    assert data["controller"] == "wbc" and data["backend"] == "mujoco"
    assert set(data["final_state"]) == set(STATE_LABELS)
    measured, expected = data["delta_velocity"]["measured"], data["delta_velocity"]["expected"]
    assert measured == pytest.approx(expected, rel=MOMENTUM_TOLERANCE, abs=1e-3)
    assert {"peak_hip_torque", "max_torso_tilt", "after_push", "predicted"} <= set(data)


def test_simulate_with_stepping_steps_where_the_balance_strategies_fall(capsys):
    # 50 N s to the left (1.5 x the ankle's 2-D limit): the whole-body controller falls
    # without stepping and comes to rest after one step when --stepping lets it (at rest:
    # recovered, or slipped while its feet slide: tests/test_physical_checks.py).
    args = ("humanoid", "simulate", "--model", "biped3d", "--azimuth", "90", "--push", "50",
            "--duration", "6", "--json")  # fmt: skip
    code, out, err = run_cli(capsys, *args, "--no-stepping")
    assert code == 0, err
    still = json.loads(out)
    assert still["outcome"] == "fell" and still["steps"] == 0 and still["stepping"] is False
    code, out, err = run_cli(capsys, *args)  # stepping is the default
    assert code == 0, err
    stepped = json.loads(out)
    assert stepped["outcome"] in ("recovered", "slipped") and stepped["steps"] >= 1
    assert stepped["recovered"] is (stepped["physics"]["violations"] == [])
    assert stepped["strategy"] == "step" and stepped["stepping"] is True


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("humanoid", "simulate", "--model", "biped3d", "--azimuth", "400"),
         "azimuth must be in [-360, 360]"),
        (("simulate", "--model", "biped3d"),
         "--model biped3d is a 3-D humanoid: use 'pushrecovery humanoid simulate --model biped3d'"),
        (("simulate", "--azimuth", "30"), "use 'pushrecovery humanoid simulate --azimuth 30'"),
        (("humanoid", "campaign", "--model", "biped3d", "--out", "x"),
         "humanoid campaign needs one of --impulse, --fraction"),
        (("humanoid", "validate", "--model", "g1", "--azimuth", "400"),
         "--azimuth must be in [-360, 360]"),
        (("simulate", "--model", "foot", "--stepping"),
         "use 'pushrecovery humanoid simulate --stepping'"),
    ],
)  # fmt: skip
def test_bad_3d_requests_are_one_line_and_exit_2(capsys, args, words):
    code, _, err = run_cli(capsys, *args)
    assert code == 2 and err.count("\n") == 1 and words in err and "Traceback" not in err


def test_g1_without_the_robots_extra_is_one_line_and_exit_2(capsys, monkeypatch):
    monkeypatch.setattr(robots.importlib.util, "find_spec", lambda name: None)
    code, _, err = run_cli(capsys, "humanoid", "simulate", "--model", "g1", "--push", "3")
    assert code == 2 and err.count("\n") == 1
    assert "the G1 model needs the robots extra: pip install 'pushrecovery[robots]'" in err


def test_the_critical_impulse_search_brackets_a_known_threshold():
    # A body that stands below 12.3 N s (ankle below 10, hip above): the search of both
    # critical_push3d (from 0, doubling) and the validation (from a guess, shrinking) finds it.
    from pushrecovery.sim.critical import bisect_critical

    def stands(impulse):
        return impulse < 12.3, "ankle" if impulse < 10.0 else "hip"

    for start, kwargs in ((dict(low=0.0, high=1.0)), {}), ((dict(low=16.0, high=24.0)),
                          {"grow": 1.3, "shrink": 0.7}):  # fmt: skip
        found, (low, high), strategy = bisect_critical(stands, **start, tolerance=0.01, **kwargs)
        assert low <= 12.3 < high and high - low <= 0.01 and found == low
        assert strategy == "hip"


def test_make_plant3d_builds_only_the_3d_humanoids():
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant
    from pushrecovery.sim.registry import make_plant3d

    assert isinstance(make_plant3d("biped3d", P), Biped3DPlant)
    with pytest.raises(InvalidParameterError, match=r"model must be one of \['biped3d', 'g1'\]"):
        make_plant3d("torso", P)
    with pytest.raises(ParameterTypeError, match="name must be a str"):
        make_plant3d(3, P)


def test_a_stepping_controllers_support_reaches_the_fall_rule_through_the_step_info():
    """The support a stepping WBC commands comes back in ``StepInfo.support``: the fall set is
    then the body down only, and rest needs it under the CoM with no foot swinging.
    """
    plant = Biped3DPlant(P)
    state = plant.reset()
    fast = np.array([*state[:3], 5.0, 0.0, 0.0])  # ξ far beyond the feet: the plant's fall set
    assert plant.falling(fast) and plant.info.support is None
    far = convex_hull(np.array([[5.0, 5.0], [5.1, 5.0], [5.0, 5.1]]))
    step = plant.step(HumanoidCommand(0.0, support=far, stance=False), CONTROL_PERIOD)
    assert step.info.support is far and not step.info.stance and plant.info is step.info
    assert not plant.falling(fast)  # a step answers it: down only
    assert plant.falling(np.array([*state[:2], 0.5 * state[2], 0.0, 0.0, 0.0]))
    assert not plant.at_rest(state, 1.0)  # a foot swings, and the CoM is off that support
    plant.step(HumanoidCommand(0.0, support=plant.support, stance=True), CONTROL_PERIOD)
    assert plant.at_rest(plant.state, 1.0)
    plant.reset()
    assert plant.info.support is None and plant.falling(fast)
