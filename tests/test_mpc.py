"""The receding-horizon controller (Eqs. 16-17): exactness, constraints, infeasibility."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from qpsolvers import Problem, solve_problem

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control.mpc import CondensedQP, MPCController, MPCSettings, Status
from pushrecovery.control.mpc.solvers import SolveQpSolver
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


def eq17_cost(x0, inputs, settings):
    """Eq. (17) of inputs (N, 2) applied open loop from x0."""
    a, b = flywheel_discrete(P, settings.dt)
    q, r = np.diag(settings.state_weights), np.diag(settings.input_weights)
    x, total, n = np.asarray(x0, dtype=float), 0.0, settings.horizon
    for i in range(1, n + 1):
        x = a @ x + b @ inputs[i - 1]
        total += settings.gamma ** (n - i) * (x @ q @ x + inputs[i - 1] @ r @ inputs[i - 1])
    return total


def sparse_solution(x0, settings=SETTINGS, solver="quadprog"):
    """Independent exact solution of Eq. (17), constraints included: the sparse QP.

    States and inputs are both variables, linked by equality constraints x_{i+1} = A x_i +
    B u_i; solved by quadprog (Goldfarb-Idnani, dense; or ``solver``): another formulation and
    another code than the controller's. Returns the inputs, (N, 2).
    """
    a, b = flywheel_discrete(P, settings.dt)
    n, g = settings.horizon, settings.gamma
    q, r = np.array(settings.state_weights), np.array(settings.input_weights)
    size = 6 * n  # [u_0, x_1, u_1, x_2, ..., u_{N-1}, x_N]
    weights = np.concatenate([np.concatenate([g ** (n - i) * r, g ** (n - i) * q])
                              for i in range(1, n + 1)])  # fmt: skip
    equality, rhs = np.zeros((4 * n, size)), np.zeros(4 * n)
    for i in range(n):
        row, u, x = 4 * i, 6 * i, 6 * i + 2
        equality[row : row + 4, x : x + 4] = np.eye(4)
        equality[row : row + 4, u : u + 2] = -b
        if i:
            equality[row : row + 4, x - 6 : x - 2] = -a
        else:
            rhs[0:4] = a @ x0
    lower, upper = np.full(size, -np.inf), np.full(size, np.inf)
    for i in range(n):
        lower[6 * i : 6 * i + 2] = (P.heel, -P.torque_max)
        upper[6 * i : 6 * i + 2] = (P.toe, P.torque_max)
        lower[6 * i + 3], upper[6 * i + 3] = -P.flywheel_angle_max, P.flywheel_angle_max
    scale = 1.0 / np.sqrt(weights)  # each variable in units of its weight
    problem = Problem(
        np.diag(2.0 * weights * scale**2), np.zeros(size), A=equality * scale, b=rhs,
        lb=lower / scale, ub=upper / scale,
    )  # fmt: skip
    options = (
        {"tol_gap_abs": 1e-12, "tol_gap_rel": 1e-12, "tol_feas": 1e-12}
        if solver == "clarabel"
        else {}
    )
    solution = solve_problem(problem, solver=solver, **options)
    assert solution.found
    return (solution.x * scale).reshape(n, 6)[:, :2]


@pytest.mark.parametrize("horizon", [50, 100, 200])
def test_the_qp_is_well_conditioned_at_every_horizon(horizon):
    assert (SETTINGS.dt, SETTINGS.horizon, SETTINGS.gamma) == (0.02, 50, 0.9)
    assert SETTINGS.state_weights == (1e3, 1e3, 10.0, 10.0)
    assert SETTINGS.input_weights == (1e-2, 1e-5)
    qp = CondensedQP(P, MPCSettings(horizon=horizon))
    # Condensed on the inputs themselves the scaled Hessian had 1.5e8 at N = 50 and lost
    # positive definiteness to rounding by N = 200; pre-stabilised it stays near 4.
    assert np.linalg.cond(qp.scaled_hessian) < 10.0
    assert max(abs(np.linalg.eigvals(qp.phi[:4]))) < 0.9  # A + B K is stable


@pytest.mark.parametrize("horizon", [3, 50])
def test_the_qp_cost_is_eq_17(horizon):
    # For any V the QP's objective differs from Eq. (17), evaluated by simulating the inputs
    # U = Ψ x0 + Λ V open loop, by a constant only: its minimiser is Eq. (17)'s.
    settings = MPCSettings(horizon=horizon)
    qp = CondensedQP(P, settings)
    a, b = flywheel_discrete(P, settings.dt)
    q, r = np.diag(settings.state_weights), np.diag(settings.input_weights)
    x0 = np.array([0.02, 0.1, 0.3, -0.5])
    linear, _, _ = qp.vectors(x0)

    def eq17(v):
        u = (qp.psi @ x0 + qp.lam @ v).reshape(-1, 2)
        x, total = x0, 0.0
        for i in range(1, horizon + 1):
            x = a @ x + b @ u[i - 1]
            total += settings.gamma ** (horizon - i) * (x @ q @ x + u[i - 1] @ r @ u[i - 1])
        return total

    rng = np.random.default_rng(3)
    base = eq17(np.zeros(2 * horizon))
    for _ in range(3):
        v = rng.normal(scale=0.01, size=2 * horizon)
        quadratic = 0.5 * v @ qp.hessian @ v + (linear / qp.scale) @ v
        assert eq17(v) - base == pytest.approx(quadratic, rel=1e-9, abs=1e-12 * abs(base))


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
    np.testing.assert_allclose(plan.inputs[0], plan.first_input, rtol=1e-12)


CONSTRAINED_STARTS = ([0.0, 0.0, 0.5, 0.0], [0.1, 0.3, -0.6, 1.0], [0.0, 0.0, 0.64, 0.0])


@pytest.mark.parametrize(
    "x0, horizon",
    [(x0, 50) for x0 in CONSTRAINED_STARTS]
    + [
        pytest.param(x0, 200, marks=() if k == 1 else pytest.mark.validate)
        for k, x0 in enumerate(CONSTRAINED_STARTS)
    ],
)
def test_constrained_solution_equals_an_independent_one(x0, horizon):
    x0 = np.array(x0)
    controller = MPCController(P, horizon=horizon)
    settings = controller.settings
    plan = controller.plan(x0)
    assert plan.feasible
    assert (np.abs(plan.inputs[:, 1]) >= P.torque_max * (1 - 1e-9)).any()  # constrained
    reference = sparse_solution(x0, settings)
    scale = np.array([P.toe - P.heel, P.torque_max])
    np.testing.assert_allclose(plan.first_input / scale, reference[0] / scale, atol=1e-6)
    # The same optimum, and the plan keeps its constraints (θ from its own prediction).
    cost, best = eq17_cost(x0, plan.inputs, settings), eq17_cost(x0, reference, settings)
    assert cost == pytest.approx(best, rel=1e-6)
    assert np.abs(plan.states[1:, 1]).max() <= P.flywheel_angle_max + 1e-9
    # And quadprog (another dual active-set code) on the same condensed QP.
    slow = MPCController(P, horizon=horizon, solver="quadprog")
    np.testing.assert_allclose(
        slow.plan(x0).first_input / scale, plan.first_input / scale, rtol=0, atol=1e-8
    )


def test_daqp_workspace_matches_qpsolvers():
    # The default route keeps the QP in a DAQP workspace warm-started tick to tick; replay
    # pushed runs that saturate the inputs (one recovers, one falls), then infeasible states,
    # through it and through qpsolvers' cold solve_qp with DAQP (the route of the other
    # solvers, and of DAQP without its workspace).
    plant = make_plant("flywheel", P)
    runs = [simulate(plant, MPCController(P), plant.reset(0.0, v)) for v in (0.64, -0.5)]
    infeasible = [np.array([0.0, 0.9, 0.0, 5.0]), np.array([0.05, -0.95, 0.1, -3.0])]
    start = runs[0].states[:2]
    states = [*runs[0].states, *runs[1].states, *infeasible, *start]
    fast = MPCController(P)
    slow = SolveQpSolver(fast.qp, "daqp")
    assert fast.route.daqp is not None
    fast.reset(states[0])
    scale = np.array([P.toe - P.heel, P.torque_max])
    feasible, saturated = [], False
    for x in states:
        a, b = fast.plan(x), slow.solve(x)
        feasible.append(a.feasible)
        if a.feasible != b.feasible:
            # At the edge of feasibility (θ 0.994 rad, 0.35 rad/s toward the 1 rad stop) the
            # one-sided rows qpsolvers builds lose a feasible point: the sparse QP decides.
            assert a.feasible and abs(x[1]) > 0.99
            sparse_solution(x)  # asserts it is feasible
            continue
        if not a.feasible:  # both: the controller's fallback, qpsolvers' failure
            assert a.status is Status.INFEASIBLE and b.status is Status.FAILED
            continue
        saturated |= bool(np.any(np.abs(b.inputs[:, 1]) >= P.torque_max - 1e-9))
        # DAQP stops within 1e-9 of its unit rows: the inputs agree to ~1e-8 of their ranges.
        np.testing.assert_allclose(a.first_input / scale, b.first_input / scale, rtol=0, atol=1e-8)
        # Later inputs to a few 1e-8 of the range (measured 1.8e-8 of τmax).
        np.testing.assert_allclose(a.inputs / scale, b.inputs / scale, rtol=0, atol=5e-8)
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
    # The bounds are rows of the pre-stabilised QP, kept to DAQP's 1e-9 in its own scaling:
    # up to 1.1e-8 m of CoP over 3000 random states (the applied input is clipped).
    tol = 2e-8
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
