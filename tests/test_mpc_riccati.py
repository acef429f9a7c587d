"""The Riccati active-set route of the MPC against an independent solution of Eq. (17)."""

import numpy as np
import pytest

from pushrecovery.control.mpc import MPCController, MPCSettings, SparseQP, Status
from pushrecovery.control.mpc.solvers import Guess, RiccatiSolver
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from test_mpc import P, sparse_solution

SCALE = np.array([P.toe - P.heel, P.torque_max])


@pytest.mark.parametrize("horizon", [50, 100, pytest.param(200, marks=pytest.mark.validate)])
def test_verified_riccati_solutions_equal_the_sparse_qp(horizon):
    # Random states, most with the CoP or torque bounds active: the Riccati passes, started
    # from DAQP's active set, must verify the KKT conditions and give quadprog's first input
    # of the uncondensed QP (states kept as variables) to 1e-6 of the ranges.
    settings = MPCSettings(horizon=horizon)
    controller = MPCController(P, settings)
    problem = SparseQP(P, settings)
    solver = RiccatiSolver(problem)
    rng = np.random.default_rng(horizon)
    constrained = 0
    for _ in range(6):
        x0 = rng.uniform([-0.03, -0.5, -0.5, -1.0], [0.1, 0.5, 0.6, 1.0])
        daqp = controller.route.daqp
        assert daqp is not None
        active = daqp.solve(x0).active
        if active is None:
            continue
        # τ_i and θ_{i+1} both at a bound (a state constraint) included: the θ row is carried
        # back to the stage whose torque is free.
        plan = solver.solve(x0, Guess(active, shift=False))
        assert plan.status is Status.VERIFIED
        assert plan.iterations == 1
        np.testing.assert_array_equal(plan.active, solver.active)
        constrained += bool(np.abs(solver.active).sum())
        reference = sparse_solution(x0, settings)
        np.testing.assert_allclose(plan.first_input / SCALE, reference[0] / SCALE, atol=1e-6)
        # The predicted states are the inputs simulated (states kept, not condensed).
        np.testing.assert_allclose(
            plan.states, problem.simulate(x0, plan.inputs), rtol=0, atol=1e-9
        )
    assert constrained >= 2


@pytest.mark.parametrize("horizon", [50, pytest.param(200, marks=pytest.mark.validate)])
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
        verified.append(plan.status is Status.VERIFIED)
        if k % 15 == 1:
            reference = sparse_solution(state, controller.settings)
            np.testing.assert_allclose(plan.first_input / SCALE, reference[0] / SCALE, atol=1e-6)
    assert np.mean(verified) > 0.9


def test_a_wrong_active_set_is_not_accepted():
    # The KKT check can fail: with one pass allowed and a wrong start, the solve is refused,
    # the pass having changed its working set (the KKT check refused it, not a degenerate
    # recursion), and the solver keeps its start.
    solver = RiccatiSolver(SparseQP(P, MPCSettings()))
    x0 = np.array([0.0, 0.0, 0.6, 0.0])
    assert solver.solve(x0, Guess(budget=1)).status is Status.FAILED  # the empty set, 1 pass
    wrong = np.zeros_like(solver.active)
    wrong[:, 1] = 1  # full torque forward over the whole horizon: wrong
    plan = solver.solve(x0, Guess(wrong, shift=False, budget=1))
    assert plan.status is Status.FAILED and not plan.feasible and not solver.verified
    assert not np.array_equal(solver._guess, wrong)
    np.testing.assert_array_equal(solver.active, wrong)


def test_without_hip_torque_the_controller_skips_the_riccati_route():
    from pushrecovery import load_params

    no_hip = load_params(overrides={"torque_max": 0.0})
    assert MPCController(no_hip).riccati is None
    assert MPCController(P).riccati is not None
    assert MPCController(P, solver="quadprog").riccati is None


def test_daqp_seeded_with_the_verified_set_ends_on_it():
    # The verified set of the passes, as DAQP's sense flags, is DAQP's own optimal set.
    controller = MPCController(P)
    solver, daqp = controller.route.riccati, controller.route.daqp
    assert solver is not None and daqp is not None
    x0 = np.array([0.06, 0.2, 0.45, -1.0])
    solver.reset()
    here = Guess(shift=False)
    plan = solver.solve(x0, here)
    if not plan.feasible:
        plan = solver.solve(x0, here)
    if not plan.feasible:  # a cold start the passes cannot take: seed them from DAQP first
        plan = solver.solve(x0, Guess(daqp.solve(x0).active, shift=False))
        assert plan.status is Status.VERIFIED
    seeded = daqp.solve(x0, Guess(solver.active))
    assert seeded.status is Status.SOLVED
    np.testing.assert_array_equal(seeded.active, solver.active)
    np.testing.assert_allclose(seeded.first_input / SCALE, plan.first_input / SCALE, atol=1e-6)


@pytest.mark.parametrize("horizon", [50, 200])
def test_a_resumed_recursion_equals_a_whole_one(horizon):
    # The passes keep the Riccati recursion of the last active set and, when the next set
    # differs only up to stage k, resume it from what entered stage k (P, p and the θ rows
    # carried back), or skip it (the same set). Every resumption must give the numbers of a
    # whole recursion on a fresh solver, bit for bit: the same verified inputs, states and
    # multipliers. States with the flywheel near its limit: θ rows carried back.
    settings = MPCSettings(horizon=horizon)
    controller = MPCController(P, settings)
    daqp = controller.route.daqp
    assert daqp is not None
    problem = SparseQP(P, settings)
    theta = 0.9 * P.flywheel_angle_max
    rng = np.random.default_rng(7 + horizon)
    resumed = RiccatiSolver(problem)  # one solver through every state: it resumes
    compared = 0
    for _ in range(60):
        if compared >= 12:
            break
        x0 = rng.uniform([-0.03, -theta, -0.5, -2.0], [0.1, theta, 0.6, 2.0])
        active = daqp.solve(x0).active
        if active is None:
            continue
        for stage in (None, 0, 2, 5, 10, 20):  # the set, then with one stage's rows cleared
            start = active.copy()
            if stage is not None:
                start[stage] = 0
            fresh = RiccatiSolver(problem)
            one = resumed.solve(x0, Guess(start, shift=False))
            two = fresh.solve(x0, Guess(start, shift=False))
            assert one.status == two.status and one.iterations == two.iterations
            if one.feasible:
                compared += 1
                np.testing.assert_array_equal(one.inputs, two.inputs)
                np.testing.assert_array_equal(one.states, two.states)
                np.testing.assert_array_equal(resumed.multipliers, fresh.multipliers)
                np.testing.assert_array_equal(one.active, two.active)
    assert compared >= 12


@pytest.mark.parametrize("horizon", [50, 200])
def test_the_recursion_resumed_inside_a_carried_chain_equals_a_whole_one(horizon):
    # The kernel itself: a recursion on set S1, then one resumed at stage k on S2 (S1 with
    # stage k's rows changed), against a whole recursion on S2: the same gains, offsets and
    # curvature bit for bit. S1 holds the torque at its bound over stages 3..12 with θ_13 at
    # its bound (a θ row carried back through the chain: the rows entering stages 4..12), and
    # k lies inside the chain.
    from pushrecovery.kernels.mpc.riccati import _backward, scratch

    p = SparseQP(P, MPCSettings(horizon=horizon))
    n = horizon

    def recursion(active, start, work, arrays):
        gains, offsets, curvature = arrays
        return _backward(p.a, p.b, p.wx, p.wu, active, p.bounds, gains, offsets, curvature,
                         work[0], work[2], start, work[3])  # fmt: skip

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
