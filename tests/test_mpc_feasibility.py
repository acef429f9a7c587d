"""Exact feasibility of Eq. (17) (the flywheel's N-step viable set) against independent checks."""

import numpy as np
import pytest
from qpsolvers import solve_qp
from scipy.optimize import linprog

from pushrecovery import load_params
from pushrecovery.control.mpc import FlywheelFeasibility, MPCController, MPCSettings
from pushrecovery.control.mpc.feasibility import BAND, viable_facets
from pushrecovery.control.mpc.qp import shared_qp
from pushrecovery.models.flywheel import flywheel_discrete

P = load_params()


def lp_gauge(x0, horizon):
    """Independent gauge: min t with |τ_j| <= t τmax, |θ_i| <= t θmax, δ_j in [heel, toe].

    An LP (HiGHS) over every input of the full 4-state model, θ_i predicted by powers of its
    A and B: the QP is feasible exactly when t* <= 1.
    """
    n = horizon
    a, b = flywheel_discrete(P, MPCSettings().dt)
    powers = [np.eye(4)]
    for _ in range(n):
        powers.append(a @ powers[-1])
    free = np.array([(powers[i] @ x0)[1] for i in range(1, n + 1)])
    forced = np.zeros((n, 2 * n))
    for i in range(1, n + 1):
        for j in range(i):
            forced[i - 1, 2 * j : 2 * j + 2] = (powers[i - 1 - j] @ b)[1]
    forced[:, 1::2] *= P.torque_max  # variables (δ_j, τ_j / τmax), then t
    theta = -P.flywheel_angle_max * np.ones((n, 1))
    torque = np.zeros((n, 2 * n + 1))
    torque[np.arange(n), 2 * np.arange(n) + 1] = 1.0
    torque[:, -1] = -1.0
    flipped = torque.copy()
    flipped[:, :-1] *= -1.0
    rows = np.vstack([np.hstack([forced, theta]), np.hstack([-forced, theta]), torque, flipped])
    rhs = np.concatenate([-free, free, np.zeros(2 * n)])
    cost = np.zeros(2 * n + 1)
    cost[-1] = 1.0
    result = linprog(
        cost, A_ub=rows, b_ub=rhs, bounds=[(P.heel, P.toe), (None, None)] * n + [(0, None)],
        method="highs",
        options={"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10},
    )  # fmt: skip
    assert result.status == 0
    return result.fun


def random_states(rng, count):
    return np.column_stack([
        rng.uniform(-0.1, 0.2, count), rng.uniform(-1.3, 1.3, count),
        rng.uniform(-1.0, 1.0, count), rng.uniform(-8.0, 8.0, count),
    ])  # fmt: skip


@pytest.mark.parametrize("horizon", [1, 2, 7, 50, 100, 200])
def test_the_gauge_is_the_lp_optimum(horizon):
    # Random states and the points 1e-9 (relative) either side of the boundary on their rays:
    # the polygon's gauge equals the LP's to 1e-12, so the verdicts agree at ±1e-9.
    feasibility = FlywheelFeasibility(P, MPCSettings(horizon=horizon))
    rng = np.random.default_rng(horizon)
    for x0 in random_states(rng, 12 if horizon < 200 else 5):
        gauge = feasibility.gauge(x0)
        assert gauge == pytest.approx(lp_gauge(x0, horizon), rel=1e-12, abs=1e-12)
        if gauge == 0.0:
            continue
        edge = x0.copy()
        edge[1::2] /= gauge
        for factor in (1 - 1e-9, 1 + 1e-9):
            near = edge.copy()
            near[1::2] *= factor
            assert (lp_gauge(near, horizon) <= 1.0) == (factor < 1.0)
            assert (feasibility.gauge(near) <= 1.0) == (factor < 1.0)


def test_the_viable_set():
    # The paper's body: 68 facets from N = 34 on, the same set at N = 50, 100 and 200 (a fixed
    # point of the recursion); centrally symmetric; the box of the proof cuts nothing.
    sets = [viable_facets(10.0, 100.0, 1.0, 0.02, n) for n in (50, 100, 200)]
    assert all(f.shape == (68, 2) and not f.flags.writeable for f in sets)
    rng = np.random.default_rng(0)
    points = rng.uniform([-1.5, -8.0], [1.5, 8.0], size=(5000, 2))
    gauges = [(points @ f.T).max(axis=1) for f in sets]
    np.testing.assert_allclose(gauges[1], gauges[0], rtol=0, atol=1e-13)
    np.testing.assert_allclose(gauges[2], gauges[0], rtol=0, atol=1e-13)
    np.testing.assert_allclose((-points @ sets[0].T).max(axis=1), gauges[0], atol=1e-13)
    # Full braking from the top of S_N just touches θmax (the discrete stopping distance).
    assert FlywheelFeasibility(P, MPCSettings()).gauge(np.array([0, 0.996, 0, 0.3])) == (
        pytest.approx(1.0, abs=1e-14)
    )
    assert not FlywheelFeasibility.applies(load_params(overrides={"torque_max": 0.0}))


@pytest.mark.parametrize("horizon", [50, 100])
def test_infeasible_ticks_skip_daqp_with_daqps_verdict(horizon):
    # Beyond the band the controller answers without DAQP, and DAQP (asked anyway) and
    # quadprog agree that the QP is infeasible; inside it DAQP is asked as before.
    rng = np.random.default_rng(7)
    settings = MPCSettings(horizon=horizon)
    feasibility = FlywheelFeasibility(P, settings)
    fast, slow = MPCController(P, settings), MPCController(P, settings)
    # Never beyond the band: the same route as `fast` except that DAQP is always asked.
    slow.route.gauge = lambda x0, gauge=slow.route.gauge: min(gauge(x0), 1.0)
    qp = shared_qp(P, settings)
    rows = qp.scaled_inequality
    asked = 0
    for x0 in random_states(rng, 12):
        x0[2] = rng.uniform(-0.3, 0.3)  # capturable: DAQP is exact there
        gauge = feasibility.gauge(x0)
        if gauge == 0.0:
            continue
        for factor in (1 + 3 * BAND, 1 + 0.5 * BAND, 1 - 1e-6):
            state = x0.copy()
            state[1::2] *= factor / gauge
            fast.reset(state)
            slow.reset(state)
            daqp = fast.route.daqp
            calls = []
            solve = daqp.solve
            daqp.solve = lambda x, g, solve=solve, calls=calls: calls.append(1) or solve(x, g)
            plan = fast.plan(state)
            del daqp.solve
            expected = slow.plan(state)
            assert plan.feasible == expected.feasible
            np.testing.assert_array_equal(plan.first_input, expected.first_input)
            if factor > 1 + BAND:
                assert not plan.feasible and not calls
                q, lower, upper = qp.vectors(state)
                found = solve_qp(
                    np.array(qp.scaled_hessian), q, np.vstack([rows, -rows]),
                    np.concatenate([upper, -lower]), solver="quadprog",
                )  # fmt: skip
                assert found is None
            else:
                asked += 1
                if factor < 1:
                    assert plan.feasible
    assert asked


def test_controllers_share_one_qp():
    one, two = MPCController(P), MPCController(P)
    assert one.qp is two.qp and not one.qp.scaled_hessian.flags.writeable
    assert one.route.daqp is not two.route.daqp
    x0 = np.array([0.02, 0.5, 0.3, 2.0])
    np.testing.assert_array_equal(one.plan(x0).first_input, two.plan(x0).first_input)
