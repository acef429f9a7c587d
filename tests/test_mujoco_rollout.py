"""MuJoCo's own speed (issue 17, item 3): the settled state restored, and the lockstep rollout
of the ankle PD on ``foot`` against the one loop (same verdicts, times, CoP excursions)."""

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import make_controller
from pushrecovery.errors import ParameterTypeError
from pushrecovery.sim.critical import pushed_state
from pushrecovery.sim.mujoco.rollout import ankle_pd_rollout
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import simulate

P = load_params()
#: A grid across the three outcomes from two starts: falls backward, recoveries (saturated
#: at the heel, unsaturated, saturated at the toe) and falls forward. The critical pushes
#: from x0 = 0 are about -0.14 and +0.46 m/s, from x0 = 0.05 m about -0.31 and +0.31 m/s.
X0 = np.repeat([0.0, 0.05], 7)
XDOT = np.array([-0.3, -0.1, 0.05, 0.2, 0.4, 0.55, 0.7, -0.45, -0.2, 0.0, 0.15, 0.25, 0.4, 0.6])


def loop_rows(x0, xdot, duration=6.0):
    plant, ctrl = make_plant("foot", P, "mujoco"), make_controller("ankle-pd", P)
    rows = []
    for a, v in zip(x0, xdot, strict=True):
        run = simulate(plant, ctrl, pushed_state(plant, a, v, force=True), duration=duration)
        rows.append((run.outcome, float(run.time[-1]), run.cops.min(), run.cops.max()))
    return rows


def test_outcomes_equal_the_loops_on_a_grid_of_pushes():
    runs = ankle_pd_rollout(P, X0, XDOT, duration=6.0, threads=2)
    expected = loop_rows(X0, XDOT)
    assert {o for o, *_ in expected} == {Outcome.FELL, Outcome.RECOVERED}
    assert runs.outcomes == tuple(o for o, *_ in expected)
    assert not runs.diverged.any()
    # The control law and its 1 ms sampling are the loop's; only the solver's warm start
    # between ticks (rebuilt from the velocity change) and numpy's last bits differ: the
    # constraint forces move within the solver's tolerance. Measured on 86 pushes: times
    # equal, CoP excursions within 2e-13 m. Allowed: one tick, and 1 µm.
    np.testing.assert_allclose(runs.times, [t for _, t, *_ in expected], atol=1e-3 + 1e-12)
    np.testing.assert_allclose(runs.cop_min, [c for *_, c, _ in expected], atol=1e-6)
    np.testing.assert_allclose(runs.cop_max, [c for *_, c in expected], atol=1e-6)


def test_threads_do_not_change_the_results():
    one = ankle_pd_rollout(P, X0[:4], XDOT[:4], duration=3.0, threads=1)
    two = ankle_pd_rollout(P, X0[:4], XDOT[:4], duration=3.0, threads=2)
    assert one.outcomes == two.outcomes
    for a, b in ((one.times, two.times), (one.cop_min, two.cop_min), (one.cop_max, two.cop_max)):
        np.testing.assert_array_equal(a, b)


def test_a_short_run_is_undecided_at_its_duration():
    runs = ankle_pd_rollout(P, [0.0], [0.2], duration=0.2)
    assert runs.outcomes == (Outcome.UNDECIDED,)
    assert runs.times[0] == pytest.approx(0.2)
    (row,) = loop_rows([0.0], [0.2], duration=0.2)
    assert row[0] is Outcome.UNDECIDED and row[1] == pytest.approx(0.2)


def test_a_reused_plant_runs_as_a_new_one_bit_for_bit():
    # reset() restores the settled state instead of settling again: the same numbers.
    ctrl = make_controller("ankle-pd", P)
    fresh = make_plant("foot", P, "mujoco")
    first = simulate(fresh, ctrl, pushed_state(fresh, 0.02, 0.3, force=True), duration=1.0)
    again = simulate(fresh, ctrl, pushed_state(fresh, 0.02, 0.3, force=True), duration=1.0)
    other = make_plant("foot", P, "mujoco")
    third = simulate(other, ctrl, pushed_state(other, 0.02, 0.3, force=True), duration=1.0)
    np.testing.assert_array_equal(first.states, again.states)
    np.testing.assert_array_equal(first.states, third.states)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"x0": [0.0, 0.0], "xdot": [0.1]}, "one entry per push"),
        ({"x0": [0.0], "xdot": [float("nan")]}, "xdot"),
        ({"x0": [2.0], "xdot": [0.1]}, "com_height"),
        ({"xdot": [40.0]}, "10 sqrt"),
        ({"duration": 0.0}, "duration"),
        ({"duration": 61.0}, "duration"),
        ({"threads": 0}, r"threads must be an int in \[1, 64\]"),
        ({"threads": 65}, "threads"),
        ({"threads": True}, "threads"),
        ({"threads": 1.5}, "threads"),
        ({"cop_margin": -0.001}, "cop_margin"),
        ({"cop_margin": 1.0}, "cop_margin"),
    ],
)
def test_bad_input_is_refused_naming_it(kwargs, match):
    arguments = {"x0": [0.0], "xdot": [0.1], "duration": 1.0} | kwargs
    duration = arguments.pop("duration")
    with pytest.raises(InvalidParameterError, match=match):
        ankle_pd_rollout(P, duration=duration, **arguments)


def test_no_pushes_give_no_runs():
    runs = ankle_pd_rollout(P, [], [], duration=1.0)
    assert runs.outcomes == () and runs.times.shape == (0,)


def test_params_must_be_a_body():
    with pytest.raises(ParameterTypeError, match="params"):
        ankle_pd_rollout("body", [0.0], [0.1], duration=1.0)


def test_a_campaign_batch_of_foot_and_ankle_pd_runs_in_lockstep():
    # run_batch takes the lockstep rollout for MuJoCo's foot + ankle-pd; its rows are the
    # one-push loop's: the same verdicts, times within one tick, CoP excursions within 1 µm.
    # The rollout does not audit contacts: its physical checks are null, the loop's not.
    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.campaign.pushes import push_rows, run_batch
    from pushrecovery.campaign.rows import COLUMNS_PHYSICS
    from pushrecovery.sim.many import ROLLOUT

    assert ("foot", "ankle-pd") in ROLLOUT
    campaign = CampaignSpec(
        "mujoco", "foot", "ankle-pd", P, x0=(0.0, 0.04, 0.04), xdot=(-0.6, 0.6, 0.3),
        sweeps={"toe": (0.12, 0.16, 0.04)}, duration=4.0, batch_size=100,
    )  # fmt: skip
    _, rows = run_batch(campaign, 0)
    outcomes = set()
    loops = push_rows(campaign, campaign.pushes(0), engine="loop")
    for row, push, loop in zip(rows, campaign.pushes(0), loops, strict=True):
        outcomes.add(loop["outcome"])
        close = ("time", "cop_min", "cop_max", "peak_ankle_torque", *COLUMNS_PHYSICS)
        exact = {k: v for k, v in loop.items() if k not in close}
        assert all(row[k] is None for k in COLUMNS_PHYSICS)
        assert loop["foot_slip"] >= 0.0 and loop["peak_ground_force"] > 0.9
        assert {k: row[k] for k in exact} == exact, push
        assert abs(row["peak_ankle_torque"] - loop["peak_ankle_torque"]) < P.weight * 1e-6
        assert abs(row["time"] - loop["time"]) <= 1e-3 + 1e-12
        assert abs(row["cop_min"] - loop["cop_min"]) < 1e-6
        assert abs(row["cop_max"] - loop["cop_max"]) < 1e-6
    assert outcomes == {"recovered", "fell"}
    assert campaign.size == len(rows) == 20


def test_a_small_foot_campaign_takes_the_rollout_too(monkeypatch):
    # The loop's rows are the rollout's only within a tick: a campaign's engine must not depend
    # on its size here (only the analytic compiled pairs run small campaigns in the loop).
    import pushrecovery.sim.many as many
    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.campaign.pushes import run_batch

    campaign = CampaignSpec(
        "mujoco", "foot", "ankle-pd", P, x0=(0.0, 0.0, 0.1), xdot=(0.2, 0.4, 0.2), duration=0.5,
    )  # fmt: skip
    assert campaign.size == 2

    def refuse(*args, **kwargs):
        raise AssertionError("the one-push loop ran")

    monkeypatch.setattr(many, "_loop", refuse)
    _, rows = run_batch(campaign, 0)
    assert len(rows) == 2 and all(row["error"] is None for row in rows)
