"""sim.many.run_many: one entry point for many pushes, its engine chosen per pair."""

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.many import LOOP_UP_TO, run_many

P = load_params()


def fields(runs):
    return (
        runs.outcomes, runs.times, runs.cop_min, runs.cop_max, runs.steps,
        runs.peak_hip_torque, runs.stop_impacts, runs.errors,
    )  # fmt: skip


@pytest.mark.parametrize(("model", "controller"), [("pendulum", "ankle-pd"), ("lipm", "ankle-pd")])
def test_the_compiled_engine_gives_the_loops_numbers_to_the_bit(model, controller):
    x0 = np.linspace(-0.04, 0.12, 9).tolist()
    xdot = np.linspace(-0.9, 0.9, 9).tolist()
    bodies = [P] * 9
    compiled = run_many(model, controller, bodies, x0, xdot, duration=3.0, engine="compiled")
    loop = run_many(model, controller, bodies, x0, xdot, duration=3.0, engine="loop")
    assert (compiled.engine, loop.engine) == ("compiled", "loop")
    for a, b in zip(fields(compiled), fields(loop), strict=True):
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b)  # NaN == NaN here, nothing else is loose
        else:
            assert a == b
    assert {o.value for o in loop.outcomes} == {"recovered", "fell"}


def test_auto_picks_the_fastest_engine_the_pair_has():
    small = run_many("pendulum", "ankle-pd", [P], [0.0], [0.1], duration=1.0)
    assert small.engine == "loop"  # below LOOP_UP_TO pushes, loading the compiled loop costs more
    n = LOOP_UP_TO + 1
    large = run_many("pendulum", "ankle-pd", [P] * n, [0.0] * n, [0.1] * n, duration=1.0)
    assert large.engine == "compiled"
    assert run_many("flywheel", "mpc", [P], [0.0], [0.1], duration=0.2).engine == "loop"


def test_on_start_is_told_each_unit_of_work():
    seen = []
    run_many("lipm", "ankle-pd", [P] * 3, [0.0] * 3, [0.1] * 3, duration=0.5,
             engine="loop", on_start=seen.append)  # fmt: skip
    assert seen == [1, 1, 1]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"engine": "fast"}, "engine must be one of"),
        ({"engine": "rollout"}, "engine 'rollout' does not run pendulum \\+ ankle-pd"),
        ({"engine": "compiled", "backend": "mujoco"}, "engine 'compiled' does not run"),
    ],
)
def test_bad_engines_are_refused(kwargs, message):
    with pytest.raises(InvalidParameterError, match=message):
        run_many("pendulum", "ankle-pd", [P], [0.0], [0.1], duration=1.0, **kwargs)


def test_one_entry_per_push():
    with pytest.raises(InvalidParameterError, match="one entry per push"):
        run_many("pendulum", "ankle-pd", [P, P], [0.0], [0.1, 0.2], duration=1.0)
