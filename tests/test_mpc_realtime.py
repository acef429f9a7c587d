"""The MPC's real-time mode: a bounded work per tick, the last verified plan shifted beyond it."""

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control.mpc import MPCController, MPCSettings, Status
from pushrecovery.control.mpc.solvers.route import (
    REALTIME_ITERATION_STAGES,
    REALTIME_PASS_STAGES,
)
from pushrecovery.kernels.mpc.interior import shift_iterate
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

P = load_params()
PLANT = make_plant("flywheel", P)


def run(controller, push, duration=3.0):
    """A closed loop after ``push`` [m/s] from x = 0; its outcome, states and plans' statuses."""
    compute, statuses = controller.compute, []

    def recorded(t, state):
        command = compute(t, state)
        statuses.append(controller.last_plan.status)
        return command

    controller.compute = recorded
    result = simulate(PLANT, controller, PLANT.reset(0.0, push), duration=duration)
    return result, statuses


@pytest.mark.parametrize("push", [0.55, -0.3])
def test_realtime_recovers_what_the_default_recovers_at_n_50(push):
    # Every tick of the real-time loop is verified (the budget suffices at N = 50) or the
    # last verified plan shifted, and the loop recovers as the default does.
    default, _ = run(MPCController(P), push)
    realtime, statuses = run(MPCController(P, realtime=True), push)
    assert default.outcome.value == realtime.outcome.value == "recovered"
    assert set(statuses) <= {Status.VERIFIED, Status.SHIFTED}


@pytest.mark.parametrize("horizon", [100, 200])
def test_realtime_recovers_at_longer_horizons(horizon):
    # Beyond N = 50 the first ticks after a reset run out of budget with no plan to shift
    # (EXHAUSTED: the interior point's iterate, continued on the next tick); then verified.
    result, statuses = run(MPCController(P, horizon=horizon, realtime=True), 0.55)
    assert result.outcome.value == "recovered"
    first = statuses.index(Status.VERIFIED)
    assert first <= 5 and set(statuses[:first]) <= {Status.EXHAUSTED}
    assert set(statuses[first:]) <= {Status.VERIFIED, Status.SHIFTED}


@pytest.mark.parametrize("horizon", [50, 200])
def test_each_tick_keeps_to_its_budget(horizon):
    # The budget is counted, not timed: interior-point iterations and warm passes per tick.
    controller = MPCController(P, horizon=horizon, realtime=True)
    route, interior, riccati = controller.route, controller.interior, controller.riccati
    assert route.realtime_iterations == max(1, REALTIME_ITERATION_STAGES // horizon)
    assert route.realtime_passes == max(1, min(15, REALTIME_PASS_STAGES // horizon))
    counts = {"iterations": 0, "warm": []}
    iterate, solve = interior._iterate, riccati.solve

    def counted_iterate(*args, **kwargs):
        status, count = iterate(*args, **kwargs)
        counts["iterations"] += count
        return status, count

    def counted_solve(x0, guess):
        if guess.budget is not None and guess.budget > 3:  # a warm start, not an offer
            counts["warm"].append(guess.budget)
        return solve(x0, guess)

    interior._iterate, riccati.solve = counted_iterate, counted_solve
    compute, per_tick = controller.compute, []

    def recorded(t, state):
        counts["iterations"] = 0
        command = compute(t, state)
        per_tick.append(counts["iterations"])
        return command

    controller.compute = recorded
    simulate(PLANT, controller, PLANT.reset(0.0, 0.65), duration=2.0)
    assert max(per_tick) <= route.realtime_iterations
    assert max(per_tick) > 0  # the interior point is asked
    if horizon == 200:  # where its budget is small, the push uses all of it
        assert max(per_tick) == route.realtime_iterations
    assert max(counts["warm"]) <= route.realtime_passes


def test_a_tick_out_of_budget_applies_the_last_verified_plan_shifted():
    controller = MPCController(P, realtime=True)
    route = controller.route
    state = np.array([0.0, 0.0, 0.45, 0.0])
    controller.reset(state)
    controller.compute(0.0, state)
    held = controller.last_plan
    assert held.status is Status.VERIFIED
    route.realtime_passes = route.realtime_iterations = 0  # nothing solves from here on
    n = controller.settings.horizon
    for age in range(1, n + 1):
        state = PLANT.advance(state, controller.compute(0.02 * age, state), 0.02)[0]
        plan = controller.last_plan
        if age == n:  # older than the horizon: nothing left to shift
            assert plan.status is Status.EXHAUSTED
            break
        assert plan.status is Status.SHIFTED and not plan.feasible
        assert np.array_equal(plan.first_input, held.inputs[age])
        assert np.array_equal(plan.inputs[: n - age], held.inputs[age:])
        assert np.array_equal(plan.active[: n - age], held.active[age:])
        # The next tick's passes start from its active set (shifted once more by them).
        assert np.array_equal(controller.riccati.active, plan.active)


def test_with_no_plan_to_shift_the_tick_is_exhausted():
    controller = MPCController(P, realtime=True)
    controller.route.realtime_passes = controller.route.realtime_iterations = 0
    state = np.array([0.0, 0.0, 0.55, 0.0])
    controller.reset(state)
    command = controller.compute(0.0, state)
    assert controller.last_plan.status is Status.EXHAUSTED
    assert P.heel <= command.cop <= P.toe and abs(command.flywheel_torque) <= P.torque_max


def test_the_realtime_mode_is_deterministic():
    # The budget is counted in passes and iterations: two runs give the same plans, bit for bit.
    first, _ = run(MPCController(P, horizon=200, realtime=True), 0.55, duration=1.0)
    second, _ = run(MPCController(P, horizon=200, realtime=True), 0.55, duration=1.0)
    assert np.array_equal(first.states, second.states)


def test_a_shifted_iterate_continues_the_horizon():
    # Shifting to the state the iterate's first input leads to moves every stage down by
    # one, the gain's correction zero (no deviation), and the dynamics hold exactly.
    controller = MPCController(P, horizon=30)
    interior, a, b = controller.interior, controller.riccati.problem.a, controller.riccati.problem.b
    rng = np.random.default_rng(3)
    n = 30
    u = rng.normal(size=(n, 2)) * [0.05, 20.0]
    x = np.zeros((n + 1, 4))
    x[0] = [0.01, 0.05, 0.3, -0.2]
    for i in range(n):
        x[i + 1] = a @ x[i] + b @ u[i]
    nu, sl, su, zl, zu = (rng.uniform(0.1, 1.0, shape) for shape in [(n, 4)] + [(n, 3)] * 4)
    before = [arr.copy() for arr in (u, x, nu, sl, su, zl, zu)]
    shift_iterate(x[1].copy(), a, b, interior.feedback, u, x, nu, sl, su, zl, zu)
    for old, new in zip(before[2:], (nu, sl, su, zl, zu), strict=True):
        assert np.array_equal(new[:-1], old[1:]) and np.array_equal(new[-1], old[-1])
    np.testing.assert_allclose(u[:-1], before[0][1:], rtol=0, atol=1e-12)
    np.testing.assert_allclose(x[:n], before[1][1:], rtol=0, atol=1e-12)
    np.testing.assert_allclose(x[1:], x[:-1] @ a.T + u @ b.T, rtol=0, atol=1e-12)


def test_bad_realtime_settings_are_refused():
    with pytest.raises(InvalidParameterError, match="realtime"):
        MPCSettings(realtime="yes")
    with pytest.raises(InvalidParameterError, match="realtime"):
        MPCSettings(realtime=2)
    with pytest.raises(InvalidParameterError, match="solver='daqp'"):
        MPCSettings(realtime=True, solver="quadprog")
    with pytest.raises(InvalidParameterError, match="torque_max > 0"):
        MPCController(load_params(overrides={"torque_max": 0.0}), realtime=True)
    assert MPCSettings(realtime=1).realtime is True  # the CLI's --option realtime=1
    assert MPCSettings().realtime is False
