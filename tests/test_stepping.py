"""Stepping (Sec. IV): closed form vs an independent ODE-with-events route, ranges checked by
simulating the post-impact LIPM, and the strategy map."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import make_controller
from pushrecovery.models.stepping import (
    fall_rate,
    post_impact_capture_point,
    solve_step_angle,
    step_solution,
)
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import classify, classify_states
from pushrecovery.surfaces.step import plan_steps

P = load_params()
L, G = P.leg_length, P.gravity
OMEGA = math.sqrt(G / L)
SPEEDS = np.linspace(0.1, 3.0, 30)


def ode_step(v0, target=0.0):
    """Independent route: integrate the stance pendulum θ̈ = (g/L) sin θ and stop when the
    post-impact capture point, computed from the *integrated* state, crosses the target."""

    def capture_after(t, y):
        theta, rate = y
        # The impact from first principles: the CoM velocity v⁻ of the pendulum, plus an
        # impulse along the new leg (unit vector from the new foot to the CoM) that cancels v_z.
        v_before = np.array([L * math.cos(theta) * rate, -L * math.sin(theta) * rate])
        leg = np.array([-math.sin(theta), math.cos(theta)])
        v_after = v_before + (-v_before[1] / leg[1]) * leg
        height = L * math.cos(theta)
        return -L * math.sin(theta) + v_after[0] / math.sqrt(G / height) - target

    capture_after.terminal = True
    capture_after.direction = -1
    sol = solve_ivp(
        lambda t, y: [y[1], G / L * math.sin(y[0])],
        (0.0, 10.0),
        [0.0, v0 / L],
        events=capture_after,
        rtol=1e-12,
        atol=1e-13,
        method="DOP853",
    )
    (t_event,), (y_event,) = sol.t_events[0], sol.y_events[0]
    return y_event[0], y_event[1], t_event


def test_closed_form_matches_ode_with_events():
    sol = step_solution(SPEEDS, L, G, P.heel, P.toe)
    for i, v0 in enumerate(SPEEDS):
        theta, rate, time = ode_step(v0)
        assert sol.theta[i] == pytest.approx(theta, abs=1e-9)  # the 1e-9 rad
        assert sol.theta_rate[i] == pytest.approx(rate, abs=1e-8)
        assert sol.time_to_impact[i] == pytest.approx(time, abs=1e-8)


@pytest.mark.parametrize("edge", ["toe", "heel", "centre"])
def test_range_ends_match_ode(edge):
    target = {"toe": P.toe, "heel": P.heel, "centre": 0.5 * (P.heel + P.toe)}[edge]
    sol = step_solution(SPEEDS, L, G, P.heel, P.toe)
    ends = {"toe": sol.theta_low, "heel": sol.theta_high, "centre": sol.centred_theta}[edge]
    for v0, theta in zip(SPEEDS, ends, strict=True):
        if v0 / OMEGA <= target:
            assert theta == 0.0  # even the shortest step lands short of this edge
            continue
        assert theta == pytest.approx(ode_step(v0, target)[0], abs=1e-9)


@pytest.mark.parametrize("v0", [0.6, 1.0, 1.8, 2.4])
def test_range_verified_by_simulating_the_post_impact_lipm(v0):
    # Just inside each end of the range the new foot's ankle recovers the post-impact state;
    # just outside it cannot (Eq. 4 on the new foot, integrated as a LIPM at the new height).
    sol = step_solution(np.array(v0), L, G, P.heel, P.toe)
    eps = 1e-6
    for theta, inside_sign in ((float(sol.theta_low), 1.0), (float(sol.theta_high), -1.0)):
        if theta == 0.0:
            continue
        for shift, recovers in ((inside_sign * eps, True), (-inside_sign * eps, False)):
            step = theta + shift
            rate = float(fall_rate(step, v0, L, G))
            x0 = -L * math.sin(step)
            v_after = L * rate * math.cos(2 * step) / math.cos(step)
            # The new stance: a LIPM at height L cos θ on the same foot, ankle strategy.
            new_body = load_params(overrides={"com_height": L * math.cos(step)})
            run = simulate(
                make_plant("lipm", new_body),
                make_controller("ankle-capture-point", new_body),
                np.array([x0, v_after]),
                duration=15.0,
            )
            assert run.recovered == recovers, (theta, shift, run.outcome)


def test_post_impact_capture_point_decreases_with_step_angle():
    theta = np.linspace(1e-6, math.pi / 4 - 1e-9, 20001)
    for v0 in (0.01, 0.5, 1.0, 3.0, 6.0):
        xi = post_impact_capture_point(theta, v0, L, G)
        assert np.all(np.diff(xi) < 0)


def test_eq22_holds_at_the_optimal_step():
    # Eq. (22), in our sign convention: θ̇ = ω sin θ cos^{1/2} θ / cos 2θ.
    sol = step_solution(SPEEDS, L, G, P.heel, P.toe)
    theta = sol.theta
    np.testing.assert_allclose(
        sol.theta_rate,
        OMEGA * np.sin(theta) * np.sqrt(np.cos(theta)) / np.cos(2 * theta),
        rtol=1e-12,
    )


def test_impact_removes_vertical_velocity_along_the_leg():
    sol = step_solution(SPEEDS, L, G, P.heel, P.toe)
    # Eq. (19): Δv_x / Δv_z = −tan θ in our convention (paper: tan θ with θ_paper = −θ).
    dvx = sol.velocity_after - sol.velocity_before_x
    dvz = 0.0 - sol.velocity_before_z
    np.testing.assert_allclose(dvx / dvz, -np.tan(sol.theta), rtol=1e-12)
    assert np.all(dvx < 0)  # the impact always slows the CoM
    np.testing.assert_allclose(sol.height_after, L * np.cos(sol.theta))


@pytest.mark.parametrize("v0", [0.5, 2.0, 2.6, 3.0])
def test_compression_flag_against_newton_on_the_trajectory(v0):
    # Leg force from Newton on a simulated Cartesian path, independent of the model's formula:
    # F/m = a − g along the leg (positive = pushing the mass away from the foot).
    sol = step_solution(np.array(v0), L, G, P.heel, P.toe)
    h = 1e-4
    t = np.arange(0.0, float(sol.time_to_impact) + h / 2, h)
    path = solve_ivp(
        lambda _, y: [y[1], G / L * math.sin(y[0])],
        (0.0, t[-1]),
        [0.0, v0 / L],
        t_eval=t,
        rtol=1e-12,
        atol=1e-13,
        method="DOP853",
    ).y[0]
    x, z = L * np.sin(path), L * np.cos(path)
    ax = (x[2:] - 2 * x[1:-1] + x[:-2]) / h**2
    az = (z[2:] - 2 * z[1:-1] + z[:-2]) / h**2 + G
    push_along_leg = (ax * x[1:-1] + az * z[1:-1]) / L
    assert bool(sol.stance_leg_in_compression) == bool(push_along_leg.min() >= -1e-4)


@given(v0=st.floats(0.05, 5.0), target=st.floats(-0.7, 0.5))
def test_solver_residual(v0, target):
    theta = float(solve_step_angle(v0, target, L, G))
    if 0.0 < theta < math.pi / 4:
        assert float(post_impact_capture_point(theta, v0, L, G)) == pytest.approx(target, abs=1e-12)


def n_step_thresholds(params):
    """Push speeds from rest over the ankle that max_steps steps absorb (docs/steps.md, S2).

    ξ = v/ω must stay inside δ± ± (a + l Σ_{k=1}^{N} β^k), β = e^{−ω Δt_s}, a the corrected
    Eq. (15) offset (errata E11) — written out here from the formulas, not the code.
    """
    omega = math.sqrt(params.gravity / params.com_height)
    spin = math.sqrt(params.flywheel_inertia * params.flywheel_angle_max / params.torque_max)
    hip = params.torque_max / (params.mass * params.gravity) * (1 - math.exp(-omega * spin)) ** 2
    beta = math.exp(-omega * params.min_step_time)
    grow = hip + params.max_step_length * sum(beta**k for k in range(1, params.max_steps + 1))
    return omega * (params.heel - grow), omega * (params.toe + grow)


def test_strategy_map_regions():
    thresholds = n_step_thresholds(P)
    cases = {
        0.3: "ankle",
        0.55: "hip",
        1.2: "step",
        thresholds[1] + 0.01: "fall",
        -0.1: "ankle",
        -0.25: "hip",
        -1.0: "step",
        thresholds[0] - 0.01: "fall",
    }
    for v, expected in cases.items():
        assert classify(0.0, v, P).strategy == expected, v
    codes = classify_states(np.zeros(len(cases)), list(cases), P)
    assert [["ankle", "hip", "step", "fall"][c] for c in codes] == list(cases.values())


def test_recommended_step_is_eq21_within_reach():
    plan = plan_steps(0.0, 1.2, P)
    sol = step_solution(np.array(1.2), L, G, P.heel, P.toe)
    assert float(plan.theta) == pytest.approx(float(sol.theta), abs=1e-12)
    short_reach = load_params(overrides={"max_step_length": 0.6})
    clipped = plan_steps(0.0, 1.2, short_reach)
    assert bool(clipped.feasible) and float(clipped.step_length) == pytest.approx(0.6)
    none = load_params(overrides={"max_step_length": 0.3})
    assert not bool(plan_steps(0.0, 1.2, none).feasible)
    shorter = load_params(overrides={"max_step_length": 0.1})  # N steps reach 0.27 m < ξ
    assert classify(0.0, 1.2, shorter).strategy == "fall"


def test_backward_step_is_the_mirror():
    mirrored = load_params(overrides={"heel": -P.toe, "toe": -P.heel})
    back = plan_steps(0.0, -1.0, P)
    forward = plan_steps(0.0, 1.0, mirrored)
    assert float(back.step_length) == pytest.approx(-float(forward.step_length), abs=1e-12)


def test_bad_step_parameters():
    with pytest.raises(InvalidParameterError, match="max_step_length must be < 2 leg_length"):
        load_params(overrides={"max_step_length": 2.5})
    with pytest.raises(InvalidParameterError, match="max_step_length must be > 0"):
        load_params(overrides={"max_step_length": 0.0})
