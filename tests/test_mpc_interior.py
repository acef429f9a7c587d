"""The MPC's interior-point route against the sparse QP and the KKT equations."""

import math

import numpy as np
import pytest

from pushrecovery.control.mpc import (
    FlywheelFeasibility,
    MPCController,
    MPCSettings,
    SparseQP,
    Status,
)
from pushrecovery.control.mpc.solvers import Guess, InteriorPointSolver, RiccatiSolver
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.kernels.mpc import interior as kernels
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from test_mpc import P, sparse_solution

SCALE = np.array([P.toe - P.heel, P.torque_max])


def kkt_residuals(solver, u, x, nu, sl, su, zl, zu):
    """The KKT residuals of the sparse Eq. (17), written out independently of the kernels.

    Stationarity in u_i and x_{i+1} of J + Σ ν_i^T (x_{i+1} − A x_i − B u_i) − z⁻ (v − lo)
    − z⁺ (hi − v), the bounds' slack equations and the dynamics.
    """
    p = solver.problem
    a, b, n = p.a, p.b, u.shape[0]
    grad_u = 2 * p.wu * u - nu @ b
    grad_u -= zl[:, :2] - zu[:, :2]
    later = np.vstack([nu[1:], np.zeros((1, 4))])
    grad_x = 2 * p.wx * x[1:] + nu - later @ a
    grad_x[:, 1] -= zl[:, 2] - zu[:, 2]
    values = np.column_stack([u, x[1:, 1]])
    lower = values - p.bounds[:, 0] - sl
    upper = p.bounds[:, 1] - values - su
    dynamics = x[1:] - x[:-1] @ a.T - u @ b.T
    return grad_u, grad_x, lower, upper, dynamics, n


def test_a_full_newton_step_solves_the_linearised_kkt_system():
    # The Riccati recursion of a Newton step against the KKT equations: from a random
    # interior iterate (random multipliers, inputs off their bounds), one full step of the
    # predictor must zero the linear residuals (stationarity, slacks) and meet the linearised
    # complementarity s Δz + z Δs = −s z.
    solver = InteriorPointSolver(SparseQP(P, MPCSettings(horizon=8)))
    p = solver.problem
    rng = np.random.default_rng(1)
    n = 8
    u = rng.normal(size=(n, 2)) * [0.3, 150.0]
    x = np.zeros((n + 1, 4))
    x[0] = [0.01, 0.1, -0.4, 0.5]
    for i in range(n):
        x[i + 1] = p.a @ x[i] + p.b @ u[i]
    nu = rng.normal(size=(n, 4))
    sl, su, zl, zu = (rng.uniform(0.1, 1.0, (n, 3)) for _ in range(4))
    work = np.zeros((17, n + 1, 4))
    rdu, rdx, rl, ru = work[0, :n, :2], work[1, :n], work[2, :n, :3], work[3, :n, :3]
    kernels._residuals(p.a, p.b, p.wx, p.wu, p.bounds, u, x, nu, sl, su, zl, zu, rdu, rdx, rl,
                       ru, work[15, :n, :2], work[16, :n])  # fmt: skip
    grad_u, grad_x, lower, _, _, _ = kkt_residuals(solver, u, x, nu, sl, su, zl, zu)
    np.testing.assert_allclose(rdu, grad_u, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(rdx, grad_x, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(rl, lower, atol=1e-12)
    target_l, target_u = -sl * zl, -su * zu
    steps = [np.zeros((n, 2)), np.zeros((n + 1, 4)), np.zeros((n, 4))]
    steps += [np.zeros((n, 3)) for _ in range(4)]
    kernels._newton(p.a, p.b, p.wx, p.wu, sl, su, zl, zu, rdu, rdx, rl, ru,
                    target_l, target_u, True, np.zeros((n + 1, 4, 4)), np.zeros((n, 2, 4)),
                    np.zeros((n, 2, 2)), np.zeros((n + 1, 4)), np.zeros((n, 4, 2)),
                    np.zeros((n, 4, 4)), np.zeros((n, 2)), np.zeros((n, 2)),
                    *steps)  # fmt: skip
    du, dx, dnu, dsl, dsu, dzl, dzu = steps
    after = kkt_residuals(solver, u + du, x + dx, nu + dnu, sl + dsl, su + dsu, zl + dzl,
                          zu + dzu)  # fmt: skip
    for residual, size in zip(after[:5], (1e3, 1e3, 1e2, 1e2, 1.0), strict=True):
        assert np.abs(residual).max() < 1e-12 * size
    np.testing.assert_allclose(zl * dsl + sl * dzl, target_l, atol=1e-13)
    np.testing.assert_allclose(zu * dsu + su * dzu, target_u, atol=1e-13)


@pytest.mark.parametrize("horizon", [50, 100, pytest.param(200, marks=pytest.mark.validate)])
def test_the_interior_point_equals_the_sparse_qp(horizon):
    # Random states with the CoP, torque and θ bounds active: the interior point alone (no
    # Riccati verification) gives quadprog's first input of the sparse QP to 1e-6 of the
    # ranges, and its plan keeps every bound to 1e-9 of its range.
    settings = MPCSettings(horizon=horizon)
    solver = InteriorPointSolver(SparseQP(P, settings))
    bounds = solver.problem.bounds
    feasibility = FlywheelFeasibility(P, settings)
    rng = np.random.default_rng(horizon)
    solved = 0
    # quadprog's dense solve of the 1200-variable sparse QP is slow and fails on the wider
    # states at N = 200: fewer, milder ones there.
    count, wide = (2, 0.5) if horizon == 200 else (5, 1.0)
    while solved < count:
        x0 = rng.uniform([-0.03, -0.6, -0.5, -2.0], [0.1, 0.6, 0.6, 2.0]) * wide
        if feasibility.gauge(x0) > 0.99:
            continue
        plan = solver.solve(x0)
        assert plan.status is Status.CONVERGED and plan.iterations == solver.iterations > 0
        reference = sparse_solution(x0, settings)
        np.testing.assert_allclose(plan.first_input / SCALE, reference[0] / SCALE, atol=1e-6)
        span = bounds[:, 1] - bounds[:, 0]
        values = np.column_stack([plan.inputs, plan.states[1:, 1]])
        assert (values >= bounds[:, 0] - 1e-9 * span).all()
        assert (values <= bounds[:, 1] + 1e-9 * span).all()
        solved += 1


def test_a_backward_push_is_planned_at_long_horizons():
    # 0.4 m/s backward: at N = 100 and 200 the condensed QP failed numerically here (DAQP and
    # quadprog) and the controller braked with its fallback; the interior point solves it. At
    # N = 100 against quadprog's sparse QP; at N = 200 quadprog and clarabel fail too, so
    # the interior point's final iterate is checked as an optimality certificate: the KKT
    # conditions, written out here, hold to rounding of their terms.
    x0 = np.array([0.0, 0.0, -0.4, 0.0])
    controller = MPCController(P, horizon=100)
    plan = controller.plan(x0)
    assert plan.feasible
    reference = sparse_solution(x0, controller.settings)
    np.testing.assert_allclose(plan.first_input / SCALE, reference[0] / SCALE, atol=1e-6)
    solver = InteriorPointSolver(SparseQP(P, MPCSettings(horizon=200)))
    p = solver.problem
    plan = solver.solve(x0)
    assert plan.status is Status.CONVERGED
    (sl, su), (zl, zu) = solver._slacks, solver._bound_multipliers
    nu = solver._multipliers
    u, x = plan.inputs, plan.states
    grad_u, grad_x, lower, upper, dynamics, _ = kkt_residuals(solver, u, x, nu, sl, su, zl, zu)
    size_u = np.abs(2 * p.wu * u) + np.abs(nu) @ np.abs(p.b) + zl[:, :2] + zu[:, :2]
    assert (np.abs(grad_u) <= 1e-8 * np.maximum(size_u, solver.scales[:, :2])).all()
    size_x = (
        np.abs(2 * p.wx * x[1:])
        + np.abs(nu)
        + np.abs(np.vstack([nu[1:], 0 * nu[:1]])) @ np.abs(p.a)
    )
    size_x[:, 1] += zl[:, 2] + zu[:, 2]
    assert (np.abs(grad_x) <= 1e-8 * np.maximum(size_x, solver.scales[:, 3:])).all()
    span = p.bounds[:, 1] - p.bounds[:, 0]
    assert (np.abs(lower) <= 1e-9 * span).all() and (np.abs(upper) <= 1e-9 * span).all()
    assert np.abs(dynamics).max() <= 1e-9 * np.abs(x).max()
    assert (sl > 0).all() and (su > 0).all() and (zl > 0).all() and (zu > 0).all()
    scale = solver.scales[:, :3] * span
    assert (sl * zl <= 1e-9 * scale).all() and (su * zu <= 1e-9 * scale).all()


def test_closed_loop_runs_need_daqp_only_at_the_boundary():
    # Pushed runs at N = 50: every tick is solved by the passes or the interior point except
    # those within INTERIOR_MARGIN of S_N's boundary (no interior there): full braking held, then
    # DAQP.
    from pushrecovery.control.mpc.solvers.route import INTERIOR_MARGIN

    plant = make_plant("flywheel", P)
    feasibility = FlywheelFeasibility(P, MPCSettings())
    for push in (0.55, -0.4, 0.65):
        controller = MPCController(P)
        run = simulate(plant, controller, plant.reset(0.0, push))
        controller.reset(run.states[0])
        calls = []
        daqp = controller.route.daqp
        solve = daqp.solve
        daqp.solve = lambda x, guess, solve=solve, calls=calls: (
            calls.append(x.copy()) or solve(x, guess)
        )
        for state in run.states[:-1]:
            controller.plan(state)
        for state in calls:
            assert feasibility.gauge(state) >= 1.0 - INTERIOR_MARGIN


def test_bad_iterate_reports_failure_not_nan():
    # An infeasible QP (θ̇ far beyond what τmax can stop): the interior point gives up.
    solver = InteriorPointSolver(SparseQP(P, MPCSettings()))
    plan = solver.solve(np.array([0.0, 0.9, 0.0, 30.0]))
    assert plan.status is Status.FAILED and not plan.feasible
    assert solver.iterations == -1


def test_forced_braking_on_the_boundary_of_the_viable_set():
    # On S_N's boundary (γ = 1) full braking for k stages brings θ to its bound exactly
    # (simulated here from the flywheel's own double integrator); inside it nothing is forced.
    settings = MPCSettings()
    feasibility = FlywheelFeasibility(P, settings)
    top = np.array([0.0, 0.996, 0.0, 0.3])  # full braking from here just touches θmax
    assert feasibility.gauge(top) == pytest.approx(1.0, abs=1e-14)
    stages, side = feasibility.forced_braking(top)
    assert side == -1 and stages > 0
    dt, inertia = settings.dt, P.flywheel_inertia
    theta, rate = top[1], top[3]
    for _ in range(stages):
        theta += dt * rate - 0.5 * dt * dt / inertia * P.torque_max
        rate -= dt / inertia * P.torque_max
    assert theta == pytest.approx(P.flywheel_angle_max, abs=1e-12)
    assert feasibility.forced_braking(0.5 * top) == (0, 0)
    assert feasibility.forced_braking(np.zeros(4)) == (0, 0)


def test_boundary_ticks_solved_with_forced_braking_equal_daqp():
    # Ticks of a pushed run on S_N's boundary: the passes with the braking held, started from
    # DAQP's active set, verify and give DAQP's first input (another method on the condensed
    # QP) to 1e-6 of the ranges.
    settings = MPCSettings()
    feasibility = FlywheelFeasibility(P, settings)
    plant = make_plant("flywheel", P)
    run = simulate(plant, MPCController(P), plant.reset(0.0, 0.65))
    controller, solver = MPCController(P, settings), RiccatiSolver(SparseQP(P, settings))
    daqp = controller.route.daqp
    compared = 0
    for state in run.states[:-1]:
        if feasibility.gauge(state) < 1.0 - 1e-9:
            continue
        daqp.reset()
        condensed = daqp.solve(state)
        assert condensed.status is Status.SOLVED
        forced = feasibility.forced_braking(state)
        plan = solver.solve(state, Guess(condensed.active, shift=False, forced=forced))
        if not plan.feasible:
            continue
        np.testing.assert_allclose(
            plan.first_input / SCALE, condensed.first_input / SCALE, atol=1e-6
        )
        compared += 1
    assert compared >= 3


def test_the_cold_start_is_the_unconstrained_optimum():
    # The interior point's cold start (its feedback gains, kernels.mpc.scales.dual_scales) is the
    # unconstrained Eq. (17)'s solution: its first input equals an independent backward
    # recursion's (test_mpc.riccati_first_input) where no bound binds.
    from test_mpc import riccati_first_input

    solver = InteriorPointSolver(SparseQP(P, MPCSettings()))
    for x0 in ([0.0, 0.0, 0.05, 0.0], [0.01, 0.02, -0.03, 0.1]):
        x0 = np.array(x0)
        np.testing.assert_allclose(solver.feedback[0] @ x0, riccati_first_input(x0), rtol=1e-9)


def test_the_sparse_problem_refuses_what_is_not_a_body_or_settings():
    with pytest.raises(ParameterTypeError, match="params"):
        SparseQP("paper", MPCSettings())
    with pytest.raises(ParameterTypeError, match="settings"):
        SparseQP(P, {"horizon": 50})


@pytest.mark.parametrize("value", [0.0, -1.0, math.inf, math.nan])
def test_bad_warm_start_settings_are_refused(value):
    with pytest.raises(InvalidParameterError, match="guide_centre"):
        InteriorPointSolver(SparseQP(P, MPCSettings(horizon=8)), guide_centre=value)
