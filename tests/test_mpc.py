"""The receding-horizon controller (Eqs. 16-17): exactness, constraints, infeasibility."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from qpsolvers import Problem, solve_problem

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control.mpc import CondensedQP, MPCController, MPCSettings
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.sim.critical import critical_push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

P = load_params()
SETTINGS = MPCSettings()
QP = CondensedQP(P, SETTINGS)
CONTROLLER = MPCController(P)


def riccati_first_input(x0, settings=SETTINGS):
    """Independent exact solution of the unconstrained Eq. (17) by backward recursion."""
    a, b = flywheel_discrete(P, settings.dt)
    q, r = np.diag(settings.state_weights), np.diag(settings.input_weights)
    n, g = settings.horizon, settings.gamma
    weight = lambda i: g ** (n - i)  # noqa: E731 - stage i = 1..N
    cost_to_go = weight(n) * q
    for k in range(n - 1, -1, -1):
        gain = np.linalg.solve(weight(k + 1) * r + b.T @ cost_to_go @ b, b.T @ cost_to_go @ a)
        cost_to_go = a.T @ cost_to_go @ (a - b @ gain) + (weight(k) * q if k else 0.0)
    return -gain @ x0


def test_paper_settings_and_conditioning():
    assert (SETTINGS.dt, SETTINGS.horizon, SETTINGS.gamma) == (0.02, 50, 0.9)
    assert SETTINGS.state_weights == (1e3, 1e3, 10.0, 10.0)
    assert SETTINGS.input_weights == (1e-2, 1e-5)
    # The warning: condition number ~1e11 in SI units; the Jacobi scaling helps.
    assert np.linalg.cond(QP.hessian) > 1e10
    assert np.linalg.cond(QP.scaled_hessian) < np.linalg.cond(QP.hessian) / 100


def test_weights_grow_toward_the_horizon_end():
    # γ^(N−i) with γ < 1: the last stage weighs 1, the first γ^(N−1).
    single = MPCSettings(horizon=3, state_weights=(1.0, 0, 0, 0), input_weights=(1e-9, 1e-9))
    qp = CondensedQP(P, single)
    x0 = np.array([0.01, 0.0, 0.0, 0.0])
    q, _ = qp.vectors(x0)
    expected = 2 * qp.gamma.T @ (np.kron([0.81, 0.9, 1.0], [1.0, 0, 0, 0]) * (qp.phi @ x0))
    np.testing.assert_allclose(q, qp.scale * expected, rtol=1e-12)


@pytest.mark.parametrize(
    "x0", [[0.0, 0.0, 0.02, 0.0], [5e-4, 5e-4, -1e-3, 1e-3], [-1e-3, -2e-4, 3e-3, -5e-4]]
)
def test_unconstrained_first_input_is_exact(x0):
    x0 = np.array(x0)
    plan = CONTROLLER.plan(x0)
    assert plan.feasible
    assert np.all(np.abs(plan.inputs[:, 1]) < P.torque_max)  # the constraints are inactive
    assert np.all((plan.inputs[:, 0] > P.heel) & (plan.inputs[:, 0] < P.toe))
    np.testing.assert_allclose(plan.first_input, riccati_first_input(x0), rtol=1e-7)


@pytest.mark.parametrize("x0", [[0.0, 0.0, 0.5, 0.0], [0.1, 0.3, -0.6, 1.0], [0.0, 0.0, 0.64, 0.0]])
def test_constrained_solution_satisfies_kkt(x0):
    x0 = np.array(x0)
    q, h = QP.vectors(x0)
    problem = Problem(
        QP.scaled_hessian, q, QP.scaled_inequality, h, lb=QP.scaled_lower, ub=QP.scaled_upper
    )
    solution = solve_problem(problem, solver="daqp")
    assert solution.found
    assert solution.primal_residual() < 1e-9
    assert solution.dual_residual() < 1e-9
    assert abs(solution.duality_gap()) < 1e-8
    # And an independent dual active-set code gives the same first input.
    other = CondensedQP(P, SETTINGS)
    alt = solve_problem(
        Problem(
            other.scaled_hessian,
            q,
            other.scaled_inequality,
            h,
            lb=other.scaled_lower,
            ub=other.scaled_upper,
        ),
        solver="quadprog",
    )
    np.testing.assert_allclose(
        QP.unscale(alt.x)[0], QP.unscale(solution.x)[0], rtol=1e-6, atol=1e-9
    )


def test_daqp_workspace_matches_qpsolvers():
    # The default route keeps the QP in a DAQP workspace warm-started tick to tick; replay
    # pushed runs that saturate the inputs (one recovers, one falls), then infeasible states,
    # through it and through qpsolvers' cold solve_qp (the route of the other solvers).
    plant = make_plant("flywheel", P)
    runs = [simulate(plant, MPCController(P), plant.reset(0.0, v)) for v in (0.64, -0.5)]
    infeasible = [np.array([0.0, 0.9, 0.0, 5.0]), np.array([0.05, -0.95, 0.1, -3.0])]
    start = runs[0].states[:2]
    states = [*runs[0].states, *runs[1].states, *infeasible, *start]
    fast, slow = MPCController(P), MPCController(P)
    slow.workspace = None
    assert fast.workspace is not None
    fast.reset(states[0])
    scale = np.array([P.toe - P.heel, P.torque_max])
    feasible, saturated = [], False
    for x in states:
        a, b = fast.plan(x), slow.plan(x)
        assert a.feasible == b.feasible
        feasible.append(a.feasible)
        saturated |= bool(np.any(np.abs(b.inputs[:, 1]) >= P.torque_max - 1e-9))
        # Late-horizon torques are defined to ~1e-9 τmax only (an ulp of q̃ moves them that much).
        np.testing.assert_allclose(a.first_input / scale, b.first_input / scale, rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.inputs / scale, b.inputs / scale, rtol=0, atol=1e-8)
        np.testing.assert_allclose(a.states, b.states, rtol=0, atol=1e-8)
    assert saturated
    assert feasible[-4:] == [False, False, True, True]  # and a cold restart after a failure
    assert all(feasible[:-4])
    # Exact where DAQP's default tolerance (1e-6) stops with θ over its limit by ~8e-7.
    plan = fast.plan(np.array([0.0653135, 0.72597072, 0.78963742, 0.0]))
    assert plan.feasible and np.abs(plan.states[1:, 1]).max() <= P.flywheel_angle_max + 1e-12


@given(
    x=st.floats(-0.1, 0.2),
    theta=st.floats(-0.9, 0.9),
    v=st.floats(-1.0, 1.0),
    rate=st.floats(-1.0, 1.0),
)
def test_every_plan_respects_its_constraints(x, theta, v, rate):
    plan = CONTROLLER.plan(np.array([x, theta, v, rate]))
    tol = 1e-9
    assert np.all(np.isfinite(plan.inputs))
    assert np.all(plan.inputs[:, 0] >= P.heel - tol) and np.all(plan.inputs[:, 0] <= P.toe + tol)
    assert np.all(np.abs(plan.inputs[:, 1]) <= P.torque_max + 1e-7)
    if plan.feasible:
        assert np.all(np.abs(plan.states[1:, 1]) <= P.flywheel_angle_max + 1e-7)


@given(
    theta=st.floats(0.0, 1.0),
    rate=st.floats(0.0, 30.0),
    x=st.floats(-0.1, 0.2),
    v=st.floats(-1.0, 1.0),
)
def test_feasibility_matches_the_stopping_distance(theta, rate, x, v):
    # The QP is infeasible exactly when the flywheel cannot stop before its limit. With inputs
    # held for dt, braking at −τmax from the next sample covers θ̇ dt + θ̇²/(2u) (approximately).
    u = P.torque_max / P.flywheel_inertia
    travel = rate * SETTINGS.dt + rate**2 / (2 * u)
    if abs(theta + travel - P.flywheel_angle_max) < 0.05:
        return  # near the edge the discrete stopping distance differs slightly
    state = np.array([x, theta, v, rate])
    CONTROLLER.reset(state)
    command = CONTROLLER.compute(0.0, state)
    infeasible = theta + travel > P.flywheel_angle_max
    assert CONTROLLER.last_plan.feasible == (not infeasible)
    assert np.isfinite([command.cop, command.flywheel_torque]).all()
    if infeasible:
        assert command.saturated and command.flywheel_torque == -P.torque_max


def test_mpc_recovers_inside_and_falls_outside_the_bound():
    plant = make_plant("flywheel", P)
    inside = simulate(plant, CONTROLLER, plant.reset(0.0, 0.6))
    outside = simulate(plant, CONTROLLER, plant.reset(0.0, 0.7))
    assert inside.recovered and np.abs(inside.final_state).max() < 1e-2
    assert outside.outcome.value == "fell"
    assert np.abs(inside.states[:, 1]).max() <= P.flywheel_angle_max + 1e-9


def test_mpc_critical_push_close_to_the_bound():
    # docs/mpc.md: the paper's MPC stops 0.04 % short of corrected Eq. (15) from x0 = 0.
    found = critical_push(P, "flywheel", "mpc", 0.0, "forward", tolerance=1e-4)
    assert -0.005 < found.relative_error() < 0.0


def test_settings_validation():
    with pytest.raises(InvalidParameterError, match="horizon must be an integer in \\[1, 200\\]"):
        MPCSettings(horizon=0)
    with pytest.raises(InvalidParameterError, match="gamma must be in"):
        MPCSettings(gamma=1.5)
    with pytest.raises(InvalidParameterError, match="input_weights must all be > 0"):
        MPCSettings(input_weights=(0.0, 1.0))
    with pytest.raises(InvalidParameterError, match="state_weights must have 4 entries"):
        MPCSettings(state_weights=(1.0, 1.0))
    with pytest.raises(InvalidParameterError, match="solver must be one of"):
        MPCController(P, solver="nope")
    with pytest.raises(InvalidParameterError, match="flywheel state"):
        MPCController(P).reset(np.array([0.0, 0.1]))
    with pytest.raises(InvalidParameterError, match="state_weights must have 4 entries"):
        MPCSettings(state_weights=1.0)


def test_no_hip_torque_is_not_saturation():
    no_hip = load_params(overrides={"torque_max": 0.0})
    plant = make_plant("flywheel", no_hip)
    run = simulate(plant, MPCController(no_hip), plant.reset(0.0, 0.3))
    assert run.recovered


def test_mpc_period_is_fixed():
    plant = make_plant("flywheel", P)
    with pytest.raises(InvalidParameterError, match="control_period must match"):
        simulate(plant, CONTROLLER, plant.reset(0.0, 0.3), control_period=0.01)
