"""A controller that reacts late: the hold, the hand-over, and the batch entry point."""

import math

import numpy as np
import pytest

from pushrecovery.control.base import Command, Controller, make_controller
from pushrecovery.control.delay import reaction_delay
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.presets import load_params
from pushrecovery.sim.critical import pushed_state
from pushrecovery.sim.many import run_many
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

P = load_params()


class Recorder(Controller):
    """Remembers its resets and the times it was asked at."""

    name = "recorder"

    def __init__(self, params):
        super().__init__(params)
        self.resets, self.times = [], []

    def reset(self, state):
        self.resets.append(np.array(state))

    def compute(self, t, state):
        self.times.append(t)
        return Command(0.01, 0.0)


def test_it_holds_then_hands_over_on_the_state_it_finds():
    inner = Recorder(P)
    delayed = reaction_delay(inner, 0.05)
    assert delayed.name == "recorder" and delayed.state_labels == inner.state_labels
    delayed.reset(np.zeros(2))
    held = delayed.compute(0.0, np.zeros(2))
    assert held.cop == pytest.approx(0.5 * (P.heel + P.toe)) and held.flywheel_torque == 0.0
    assert delayed.compute(0.049, np.zeros(2)).cop == held.cop and inner.resets == []
    assert delayed.compute(0.05, np.array([0.02, 0.3])).cop == 0.01
    assert [r.tolist() for r in inner.resets] == [[0.02, 0.3]] and inner.times == [0.0]
    delayed.compute(0.07, np.array([0.03, 0.3]))
    assert inner.times == pytest.approx([0.0, 0.02])  # the wrapped controller's own clock
    delayed.reset(np.zeros(2))  # a new run holds again
    assert delayed.compute(0.0, np.zeros(2)).cop == held.cop


def test_the_batch_entry_point_runs_the_delayed_loop():
    velocities = [0.2, 0.35, 0.5]
    runs = run_many("pendulum", "ankle-pd", [P] * 3, [0.0] * 3, velocities, duration=3.0,
                    latency=0.1)  # fmt: skip
    assert runs.engine == "loop"
    for velocity, outcome in zip(velocities, runs.outcomes, strict=True):
        plant = make_plant("pendulum", P, "analytic")
        control = reaction_delay(make_controller("ankle-pd", P), 0.1)
        alone = simulate(
            plant, control, pushed_state(plant, 0.0, velocity, force=False), duration=3.0
        )
        assert alone.outcome == outcome
    # The hold lets the body lean on: a push the ankle holds on time falls 0.1 s late.
    on_time = run_many("pendulum", "ankle-pd", [P], [0.0], [0.4], duration=3.0, engine="loop")
    late = run_many("pendulum", "ankle-pd", [P], [0.0], [0.4], duration=3.0, latency=0.1)
    assert on_time.outcomes[0].value == "recovered" and late.outcomes[0].value == "fell"


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: reaction_delay(make_controller("ankle-pd", P), -0.1), "latency"),
        (lambda: reaction_delay(make_controller("ankle-pd", P), math.nan), "latency"),
        (lambda: reaction_delay("ankle-pd", 0.1), "controller"),
        (
            lambda: run_many(
                "pendulum",
                "ankle-pd",
                [P],
                [0.0],
                [0.3],
                duration=1.0,
                engine="compiled",
                latency=0.1,
            ),
            "through the loop",
        ),
    ],
)
def test_bad_latencies_are_refused(call, match):
    with pytest.raises(PushRecoveryError, match=match):
        call()
    assert issubclass(InvalidParameterError, PushRecoveryError)
