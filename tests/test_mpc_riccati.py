"""The Riccati active-set route of the MPC against an independent solution of Eq. (17)."""

import numpy as np
import pytest

from pushrecovery.control.mpc import MPCController, MPCSettings
from pushrecovery.control.mpc.riccati import RiccatiSolver
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from test_mpc import P, sparse_solution

SCALE = np.array([P.toe - P.heel, P.torque_max])


@pytest.mark.parametrize("horizon", [50, 100, 200])
def test_verified_riccati_solutions_equal_the_sparse_qp(horizon):
    # Random states, most with the CoP or torque bounds active: the Riccati passes, started
    # from DAQP's active set, must verify the KKT conditions and give quadprog's first input
    # of the uncondensed QP (states kept as variables) to 1e-6 of the ranges.
    settings = MPCSettings(horizon=horizon)
    controller = MPCController(P, settings)
    solver = RiccatiSolver(P, settings)
    rng = np.random.default_rng(horizon)
    constrained = 0
    for _ in range(6):
        x0 = rng.uniform([-0.03, -0.5, -0.5, -1.0], [0.1, 0.5, 0.6, 1.0])
        assert controller.workspace is not None
        if controller.workspace.solve(x0) is None:
            continue
        active = controller.workspace.active_set()
        solver.seed(active)
        # τ_i and θ_{i+1} both at a bound (a state constraint) included: the θ row is carried
        # back to the stage whose torque is free.
        assert solver.solve(x0, shift=False)
        assert solver.passes == 1
        constrained += bool(np.abs(solver.active).sum())
        reference = sparse_solution(x0, settings)
        np.testing.assert_allclose(solver.inputs[0] / SCALE, reference[0] / SCALE, atol=1e-6)
        # The predicted states are the inputs simulated (states kept, not condensed).
        np.testing.assert_allclose(
            solver.states, controller.qp.simulate(x0, solver.inputs), rtol=0, atol=1e-9
        )
    assert constrained >= 2


@pytest.mark.parametrize("horizon", [50, 200])
def test_closed_loop_ticks_take_the_riccati_route_and_are_exact(horizon):
    # A pushed run: the ticks after the first start from the last active set shifted by a stage
    # and are verified by the passes (DAQP only where they are not); sampled ticks against the
    # sparse QP to 1e-6.
    plant = make_plant("flywheel", P)
    run = simulate(plant, MPCController(P, horizon=horizon), plant.reset(0.0, 0.55))
    controller = MPCController(P, horizon=horizon)
    controller.reset(run.states[0])
    verified = []
    for k, state in enumerate(run.states[:-1]):
        plan = controller.plan(state)
        verified.append(controller.riccati.passes > 0)
        if k % 15 == 1:
            reference = sparse_solution(state, controller.settings)
            np.testing.assert_allclose(plan.first_input / SCALE, reference[0] / SCALE, atol=1e-6)
    assert np.mean(verified) > 0.9


def test_a_wrong_active_set_is_not_accepted():
    # The KKT check can fail: with one pass allowed and a wrong start, the solve is refused.
    settings = MPCSettings()
    solver = RiccatiSolver(P, settings)
    x0 = np.array([0.0, 0.0, 0.6, 0.0])
    assert not solver.solve(x0, max_passes=1)  # from the empty set in one pass
    solver.active[:, 1] = 1  # full torque forward over the whole horizon: wrong
    guess = solver.active.copy()
    from pushrecovery.kernels.mpc.riccati import CHANGED, _pass

    outcome = _pass(
        x0, solver.a, solver.b, solver.wx, solver.wu, guess, solver.bounds, solver.tols,
        1e-9, solver.inputs, solver.states, solver._gains, solver._offsets, solver._curvature,
        solver.multipliers, 0,
    )  # fmt: skip
    assert outcome == CHANGED


def test_without_hip_torque_the_controller_skips_the_riccati_route():
    from pushrecovery import load_params

    no_hip = load_params(overrides={"torque_max": 0.0})
    assert MPCController(no_hip).riccati is None
    assert MPCController(P).riccati is not None
    assert MPCController(P, solver="quadprog").riccati is None


def test_daqp_seeded_with_the_verified_set_ends_on_it():
    # The verified set of the passes, as DAQP's sense flags, is DAQP's own optimal set.
    controller = MPCController(P)
    solver = controller.riccati
    assert solver is not None
    x0 = np.array([0.06, 0.2, 0.45, -1.0])
    solver.reset()
    verified = solver.solve(x0, shift=False) or solver.solve(x0, shift=False)
    if not verified:  # a cold start the passes cannot take: seed them from DAQP first
        controller.workspace.solve(x0)
        solver.seed(controller.workspace.active_set())
        assert solver.solve(x0, shift=False)
    workspace = controller.workspace
    workspace.seed(solver.active)
    scaled = workspace.solve(x0)
    assert scaled is not None
    np.testing.assert_array_equal(workspace.active_set(), solver.active)
    first = controller.qp.first_input(x0, scaled)
    np.testing.assert_allclose(first / SCALE, solver.inputs[0] / SCALE, atol=1e-6)


@pytest.mark.parametrize("horizon", [50, 200])
def test_a_resumed_recursion_equals_a_whole_one(horizon):
    # The passes keep the Riccati recursion of the last active set and, when the next set
    # differs only up to stage k, resume it from what entered stage k (P, p and the θ rows
    # carried back), or skip it (the same set). Every resumption must give the numbers of a
    # whole recursion on a fresh solver, bit for bit: the same verified inputs, states and
    # multipliers. States with the flywheel near its limit: θ rows carried back.
    settings = MPCSettings(horizon=horizon)
    controller = MPCController(P, settings)
    assert controller.workspace is not None
    theta = 0.9 * P.flywheel_angle_max
    rng = np.random.default_rng(7 + horizon)
    resumed = RiccatiSolver(P, settings)  # one solver through every state: it resumes
    compared = 0
    for _ in range(60):
        if compared >= 12:
            break
        x0 = rng.uniform([-0.03, -theta, -0.5, -2.0], [0.1, theta, 0.6, 2.0])
        if controller.workspace.solve(x0) is None:
            continue
        active = controller.workspace.active_set()
        for stage in (None, 0, 2, 5, 10, 20):  # the set, then with one stage's rows cleared
            start = active.copy()
            if stage is not None:
                start[stage] = 0
            fresh = RiccatiSolver(P, settings)
            resumed.seed(start)
            fresh.seed(start)
            ok = resumed.solve(x0, shift=False)
            assert ok == fresh.solve(x0, shift=False)
            assert resumed.passes == fresh.passes
            if ok:
                compared += 1
                np.testing.assert_array_equal(resumed.inputs, fresh.inputs)
                np.testing.assert_array_equal(resumed.states, fresh.states)
                np.testing.assert_array_equal(resumed.multipliers, fresh.multipliers)
                np.testing.assert_array_equal(resumed.active, fresh.active)
    assert compared >= 12


@pytest.mark.parametrize("horizon", [50, 200])
def test_the_recursion_resumed_inside_a_carried_chain_equals_a_whole_one(horizon):
    # The kernel itself: a recursion on set S1, then one resumed at stage k on S2 (S1 with
    # stage k's rows changed), against a whole recursion on S2: the same gains, offsets and
    # curvature bit for bit. S1 holds the torque at its bound over stages 3..12 with θ_13 at
    # its bound (a θ row carried back through the chain: the rows entering stages 4..12), and
    # k lies inside the chain.
    from pushrecovery.kernels.mpc.riccati import _backward, scratch

    solver = RiccatiSolver(P, MPCSettings(horizon=horizon))
    n = horizon

    def recursion(active, start, work, arrays):
        gains, offsets, curvature = arrays
        return _backward(solver.a, solver.b, solver.wx, solver.wu, active, solver.bounds,
                         gains, offsets, curvature, work[0], work[2], start, work[3])  # fmt: skip

    def fresh_arrays():
        return np.zeros((n, 2, 4)), np.zeros((n, 2)), np.zeros((n, 2))

    first = np.zeros((n, 3), dtype=np.int8)
    first[3:13, 1] = 1
    first[12, 2] = 1
    first[n - 5 :, 0] = -1  # and the CoP at the heel late in the horizon
    resumed_with = 0
    for stage, column, side in ((8, 0, 1), (5, 0, -1), (12, 0, 1), (10, 1, 0), (2, 2, 1)):
        second = first.copy()
        second[stage, column] = side
        work, arrays = scratch(n), fresh_arrays()
        assert recursion(first, n - 1, work, arrays) == 0
        left = recursion(second, stage, work, arrays)  # resumed at the changed stage
        reference = fresh_arrays()
        assert left == recursion(second, n - 1, scratch(n), reference)
        if left == 0:
            resumed_with += 1
            for got, want in zip(arrays, reference, strict=True):
                np.testing.assert_array_equal(got, want)
    assert resumed_with >= 3
