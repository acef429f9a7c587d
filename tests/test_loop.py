"""One loop (issue 15, item 2): scheduled pushes, plant steps, observers, the backend contract."""

import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.control.base import Command, StepInfo, make_controller
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.sim.backend import Backend, Step
from pushrecovery.sim.events import ScheduledPush
from pushrecovery.sim.push import Push, Push3D
from pushrecovery.sim.registry import MODELS, make_plant
from pushrecovery.sim.result import HIP_TORQUE_THRESHOLD, Outcome, SimulationResult
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import Strategy

P = load_params()


class Counter:
    def __init__(self):
        self.indices = []
        self.commands = []

    def on_step(self, index: int, step: Step, command: Command) -> None:
        self.indices.append(index)
        self.commands.append(command)


def test_a_scheduled_push_is_the_pushed_start_delayed():
    # Quiet standing, then a jump of 0.4 m/s: from the push on the run is the one that starts
    # on the pushed state (the controller restarts there), shifted by the push time.
    quiet = 0.3
    plant = make_plant("pendulum", P)
    start = plant.reset(0.0, 0.0)
    delayed = simulate(
        plant,
        make_controller("ankle-pd", P),
        start,
        duration=3.0 + quiet,
        push=ScheduledPush(quiet, Push(0.4, "velocity")),
    )
    direct = simulate(
        make_plant("pendulum", P), make_controller("ankle-pd", P), np.array([0.0, 0.4])
    )
    k = round(quiet / 1e-3)
    np.testing.assert_array_equal(delayed.states[:k], 0.0)  # at rest until the push
    n = min(len(direct.states), len(delayed.states) - k)
    np.testing.assert_allclose(delayed.states[k : k + n], direct.states[:n], atol=1e-15)
    assert delayed.outcome is direct.outcome is Outcome.RECOVERED
    assert delayed.decided_time == pytest.approx(direct.decided_time + quiet, abs=1e-9)


def test_plant_steps_finer_than_the_ticks_hold_each_command():
    plant = make_plant("flywheel", P)
    counter = Counter()
    run = simulate(
        plant,
        make_controller("mpc", P),  # 20 ms ticks
        plant.reset(0.0, 0.3),
        duration=0.2,
        plant_step=1e-3,
        observers=(counter,),
    )
    assert counter.indices == list(range(len(run.time) - 1))
    assert len(run.time) == 201 and run.time[1] == pytest.approx(1e-3)
    # One command per 20 ms tick, held over its 20 plant steps.
    for tick in range(10):
        held = counter.commands[20 * tick : 20 * tick + 20]
        assert all(command is held[0] for command in held)
    assert counter.commands[0] is not counter.commands[20]


def test_keep_running_after_a_fall_and_the_decision_time():
    plant = make_plant("lipm", P)
    ctrl = make_controller("ankle-saturated", P)
    fell = simulate(plant, ctrl, plant.reset(0.0, 1.0), duration=5.0)
    longer = simulate(plant, ctrl, plant.reset(0.0, 1.0), duration=5.0, keep_running=(0.0, 0.1))
    assert fell.outcome is longer.outcome is Outcome.FELL
    assert fell.decided_time == longer.decided_time == pytest.approx(fell.time[-1])
    assert longer.time[-1] == pytest.approx(fell.time[-1] + 0.1)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"push": ScheduledPush(5.0, Push(0.1))}, "push time must be before the end"),
        ({"push": ScheduledPush(0.1, Push3D(5.0, 90.0))}, "Push3D\\) needs a 3-D model"),
        ({"plant_step": 0.01}, "plant_step must be <= the control period"),
        ({"plant_step": -1.0}, "plant_step must be"),
        ({"keep_running": (-1.0, 0.0)}, "keep_running must be"),
        ({"keep_running": (0.0, math.nan)}, "keep_running must be"),
    ],
)
def test_bad_loop_arguments_are_refused(kwargs, match):
    plant = make_plant("lipm", P)
    with pytest.raises(InvalidParameterError, match=match):
        simulate(plant, make_controller("ankle-pd", P), plant.reset(0, 0), duration=1, **kwargs)
    with pytest.raises(InvalidParameterError, match="push time"):
        ScheduledPush(-1.0, Push(0.1))
    with pytest.raises(InvalidParameterError, match="kind"):
        Push(0.1, "shove")  # type: ignore[arg-type]
    with pytest.raises(ParameterTypeError, match="push must be a Push or Push3D, got float"):
        ScheduledPush(0.0, 0.3)  # type: ignore[arg-type]


def test_the_3d_humanoids_run_in_the_one_loop():
    # The plant's own clock and rows (Clocked): MuJoCo's time, a row before and one after the
    # push's 10 ms of physics steps; the WBC keeps running through the push (react).
    from pushrecovery.sim.backend import Clocked
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import (
        CONTROL_PERIOD,
        PUSH_DURATION,
        Biped3DPlant,
        wbc_for,
    )
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import run_push3d

    plant = Biped3DPlant(P)
    assert isinstance(plant, Clocked)
    push = ScheduledPush(4 * CONTROL_PERIOD, Push3D(10.0, 45.0), react=True)
    run = simulate(plant, wbc_for(plant), plant.reset(), duration=10 * CONTROL_PERIOD,
                   control_period=CONTROL_PERIOD, push=push)  # fmt: skip
    assert run.outcome is Outcome.UNDECIDED and run.decided_time is None
    assert len(run.time) == 10 + 2 and run.inputs.shape == (11, len(plant.input_labels))
    assert run.time[-1] == plant.clock and np.array_equal(run.states[-1], plant.state)
    assert plant.push_row == 5
    assert run.time[5] - run.time[4] == pytest.approx(PUSH_DURATION)
    assert np.diff(run.time)[[0, 1, 2, 3, 5, 6]] == pytest.approx(CONTROL_PERIOD)
    assert np.array_equal(run.inputs[4], run.inputs[3])  # the motors hold during the push
    assert np.hypot(*run.states[5, 3:5]) > np.hypot(*run.states[4, 3:5]) + 0.1
    fell = simulate(plant, wbc_for(plant), plant.reset(), duration=1.0,
                    control_period=CONTROL_PERIOD,
                    push=ScheduledPush(0.0, Push3D(60.0, 90.0), react=True))  # fmt: skip
    assert fell.outcome is Outcome.FELL and fell.decided_time == fell.time[-1] == plant.clock
    with pytest.raises(InvalidParameterError, match="duration must be"):
        run_push3d(plant, wbc_for(plant), Push3D(1.0, 0.0), duration=59.95)


def test_a_pushed_3d_run_carries_its_extras_in_the_result():
    # run_push3d: the loop's result with the push's row, peaks and frames (Push3DExtras);
    # pushed_rows: the standing start, then every row from the end of the push on.
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, wbc_for
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import pushed_rows, run_push3d

    plant = Biped3DPlant(P)
    push = Push3D(30.0, 0.0)
    result = run_push3d(plant, wbc_for(plant), push, duration=0.2, push_time=0.01, record=True)
    extras = result.extras
    assert extras is not None and extras.push is push and extras.push_row == 6
    assert extras.qpos is not None and len(extras.qpos) == len(result.time)
    assert result.strategy_used() is Strategy.HIP and extras.peak_hip_torque > 1.0
    rows = pushed_rows(result)
    assert rows.tolist() == [0, *range(6, len(result.time))]  # rows 1-5: standing, then the push
    again = run_push3d(plant, wbc_for(plant), push, duration=0.2, push_time=0.01, record=True)
    assert again.strategy_used() is Strategy.HIP
    assert np.array_equal(again.states, result.states) and np.array_equal(again.time, result.time)
    with pytest.raises(InvalidParameterError, match="pushed 3-D run"):
        pushed_rows(simulate(make_plant("lipm", P), make_controller("ankle-pd", P),
                             np.zeros(2), duration=0.01))  # fmt: skip
    with pytest.raises(ParameterTypeError, match="result must be a SimulationResult"):
        pushed_rows(extras)  # type: ignore[arg-type]
    from pushrecovery.sim.mujoco.humanoid3d.render3d import Recording3D

    recorded = Recording3D.of_plant_run(plant, result)  # its rows from the push on
    assert np.array_equal(recorded.time, result.time[rows])
    assert np.array_equal(recorded.qpos, extras.qpos[rows])
    with pytest.raises(ParameterTypeError, match="result must be a SimulationResult"):
        Recording3D.of_plant_run(plant, extras)  # type: ignore[arg-type]


@pytest.mark.parametrize("model", MODELS)
def test_every_analytic_plant_keeps_the_contract(model):
    plant: Backend = make_plant(model, P)
    state = plant.reset(0.01, 0.2)
    assert len(state) == len(plant.state_labels) and plant.state_labels[0] == "x"
    assert plant.state_labels[len(state) // 2] == "xdot"
    pushed = plant.apply_push(Push(0.1))
    assert pushed[len(state) // 2] == pytest.approx(0.3)
    step = plant.step(Command(0.0), 1e-3)
    assert len(step.applied) == len(plant.input_labels)
    assert isinstance(step.info, StepInfo) and step.info.stance
    assert plant.begin(state) is not state  # a copy: the caller's array stays its own
    with pytest.raises(InvalidParameterError):
        plant.begin(np.zeros(len(state) + 1))


def test_a_stepping_controller_learns_its_landings_from_step_info():
    plant = make_plant("stepping", P)
    ctrl = make_controller("recovery", P)
    seen = []
    original = ctrl.observe
    ctrl.observe = lambda info: (seen.append(info.stance), original(info))[1]
    run = simulate(plant, ctrl, plant.reset(0.0, 1.2))
    assert run.recovered and len(run.footholds) == 2
    swings = np.flatnonzero(~np.array(seen))
    assert swings.size and np.all(np.diff(swings) == 1)  # one swing, then stance again
    assert seen[swings[-1] + 1]


def test_strategy_used_has_one_definition():
    def result(torque, footholds=(0.0,)):
        return SimulationResult(
            time=np.array([0.0, 1.0]),
            states=np.zeros((2, 4)),
            inputs=np.array([[0.0, torque]]),
            outcome=Outcome.RECOVERED,
            model="flywheel",
            controller="mpc",
            footholds=footholds,
        )

    assert result(2e-5).strategy_used() is Strategy.ANKLE  # a solver's rounding, no hip
    assert result(HIP_TORQUE_THRESHOLD * 1.01).strategy_used() is Strategy.HIP
    assert result(50.0, (0.0, 0.4)).strategy_used() is Strategy.STEP
    assert math.isclose(result(-7.0).peak_hip_torque, 7.0)
