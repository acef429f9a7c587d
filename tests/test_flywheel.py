"""Flywheel model (Eqs. 6, 7, 16) and bang-bang end state (Eqs. 8-12) against integration."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import Command, Controller, make_controller
from pushrecovery.models.flywheel import (
    bang_bang_end_state,
    bang_bang_switch_time,
    bang_bang_torque,
    flywheel_continuous,
    flywheel_discrete,
    flywheel_propagate,
    max_spin_up_time,
)
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.cmp import cmp_region

P = load_params()
T_MAX = max_spin_up_time(P)


def test_eq12_spin_up_time():
    assert T_MAX == pytest.approx(math.sqrt(10.0 * 1.0 / 100.0))


def test_zoh_is_matrix_exponential_of_eq16():
    a, b = flywheel_continuous(P)
    block = np.zeros((6, 6))
    block[:4, :4], block[:4, 4:] = a, b
    phi = expm(block * 0.02)
    ad, bd = flywheel_discrete(P, 0.02)
    np.testing.assert_allclose(ad, phi[:4, :4], atol=1e-15)
    np.testing.assert_allclose(bd, phi[:4, 4:], atol=1e-15)


def test_eq6_cmp_form():
    # ẍ = ω² (x − δ − τ/(m g)) is Eq. (16)'s third row.
    a, b = flywheel_continuous(P)
    x, cop, torque = 0.03, 0.1, 40.0
    xddot = a[2] @ np.array([x, 0, 0, 0]) + b[2] @ np.array([cop, torque])
    assert xddot == pytest.approx(P.omega**2 * (x - cop - torque / P.weight), rel=1e-14)


def test_propagate_vectorised():
    rng = np.random.default_rng(3)
    states, inputs = rng.normal(size=(100, 4)), rng.normal(size=(100, 2))
    a, b = flywheel_discrete(P, 0.01)
    np.testing.assert_allclose(
        flywheel_propagate(states, inputs, P, 0.01), states @ a.T + inputs @ b.T, rtol=1e-13
    )


def integrate_bang_bang(x0, v0, switch, cop, direction=1.0):
    def rhs(t, s):
        torque = direction * float(bang_bang_torque(t, switch, P.torque_max))
        return [
            s[2],
            s[3],
            P.omega**2 * (s[0] - cop - torque / P.weight),
            torque / P.flywheel_inertia,
        ]

    # Integrate piecewise so the solver never steps across a switch.
    state = [x0, 0.0, v0, 0.0]
    for t0, t1 in ((0.0, switch), (switch, 2 * switch)):
        mid = 0.5 * (t0 + t1)
        sol = solve_ivp(
            lambda t, s, m=mid: rhs(m, s), (t0, t1), state, rtol=1e-12, atol=1e-14, method="DOP853"
        )
        state = sol.y[:, -1]
    return state


@given(
    x0=st.floats(-0.05, 0.15), v0=st.floats(-1, 1), frac=st.floats(0.1, 1.0), forward=st.booleans()
)
def test_end_state_at_2T_matches_integration(x0, v0, frac, forward):
    direction = 1.0 if forward else -1.0
    switch = frac * T_MAX
    cop = P.toe if forward else P.heel
    expected = integrate_bang_bang(x0, v0, switch, cop, direction)
    x, xdot, theta, rate = bang_bang_end_state(
        x0, v0, P, switch_time=switch, cop=cop, direction=direction
    )
    np.testing.assert_allclose([x, theta, xdot, rate], expected, atol=1e-9)


def test_printed_x_of_2T_line_is_wrong():
    # Errata E10: the printed line has cosh(ωT) where 2 cosh(ωT) belongs.
    x0, v0, cop = 0.0, 0.6, P.toe
    a, w, t = P.torque_max / P.weight, P.omega, T_MAX
    printed = (
        cop
        + (x0 - cop) * math.cosh(2 * w * t)
        + v0 / w * math.sinh(2 * w * t)
        + a * (-math.cosh(2 * w * t) + math.cosh(w * t) - 1)
    )
    truth = integrate_bang_bang(x0, v0, t, cop)[0]
    assert abs(printed - truth) > 0.1  # off by a cosh(ωT) = 0.22 m
    assert bang_bang_end_state(x0, v0, P, switch_time=t, cop=cop)[0] == pytest.approx(
        truth, abs=1e-9
    )


def test_plant_runs_bang_bang_exactly():
    period = T_MAX / 400  # switch exactly on a tick
    controller = make_controller("bang-bang", P, switch_time=T_MAX)
    plant = make_plant("flywheel", P)
    run = simulate(
        plant, controller, plant.reset(0.0, 0.6), duration=2 * T_MAX, control_period=period
    )
    x, xdot, theta, rate = bang_bang_end_state(0.0, 0.6, P, switch_time=T_MAX, cop=P.toe)
    np.testing.assert_allclose(run.states[800], [x, theta, xdot, rate], atol=1e-12)
    assert theta == pytest.approx(P.flywheel_angle_max)  # Eq. (11) with T = T_max


def test_joint_stop_conserves_generalised_momentum():
    plant = make_plant("flywheel", P)
    state = plant.reset(0.0, 0.0)
    state[1] = 0.99
    state[3] = 2.0
    plant.begin(state)
    new = plant.step(Command(0.0, 0.0), 0.01).state
    assert new[1] == P.flywheel_angle_max and new[3] == 0.0
    assert plant.step(Command(0.0), 0.01).info.stop_impacts == 1  # counted in the run's info
    # m L ẋ + I θ̇ only changes through gravity over the step, not through the stop.
    free, _, _ = make_plant("flywheel", P).advance(state, Command(0.0, 0.0), 0.01)
    momentum = lambda s: P.mass * P.com_height * s[2] + P.flywheel_inertia * s[3]  # noqa: E731
    assert momentum(new) == pytest.approx(momentum(free), rel=1e-12)


@given(excess=st.floats(1e-3, 0.06), target=st.floats(-0.04, 0.14), forward=st.booleans())
def test_switch_time_hits_its_target_or_caps(excess, target, forward):
    direction, edge = (1.0, P.toe) if forward else (-1.0, P.heel)
    capture = edge + direction * excess
    switch = bang_bang_switch_time(capture, target, P, cop=edge, direction=direction)
    assert 0.0 <= switch <= T_MAX
    x, xdot, _, _ = bang_bang_end_state(
        0.0, capture * P.omega, P, switch_time=switch, cop=edge, direction=direction
    )
    reached = x + xdot / P.omega
    if switch < T_MAX:
        assert reached == pytest.approx(target, abs=1e-9)
    else:
        assert direction * (reached - target) >= -1e-9  # could not get all the way


def test_driving_into_the_stop_is_reported_and_beats_the_bound():
    # Errata E12 (scope): a hard stop is an impulsive torque beyond τmax. Full torque into the
    # stop then CoP balancing recovers capture points beyond the corrected Eq. (15).
    class IntoTheStop(Controller):
        name = "into-the-stop"
        strategy = "hip"

        def reset(self, state):
            pass

        def compute(self, t, state):
            capture = state[0] + state[2] / P.omega
            if state[1] < P.flywheel_angle_max:
                return Command(P.toe, P.torque_max, saturated=True)
            return Command(min(P.toe, capture), 0.0, saturated=capture > P.toe)

    plant = make_plant("flywheel", P)
    xi = cmp_region(P).upper + 5e-4
    run = simulate(plant, IntoTheStop(P), plant.reset(0.0, P.omega * xi))
    assert run.recovered and run.stop_impacts == 1
    assert run.to_dict()["stop_impacts"] == 1


def test_flywheel_fall_set_accounts_for_the_stop():
    plant = make_plant("flywheel", P)
    upper = plant.fall_limits[1]
    # Beyond the limit moving out, but the flywheel carries enough backward momentum that a stop
    # impact reverses the CoM: not (yet) a fall.
    assert not plant.falling(np.array([upper + 0.05, -0.99, 0.05, -3.0]))
    assert plant.falling(np.array([upper + 0.05, 0.0, 0.05, 0.0]))
    assert plant.falling(np.array([-upper - 0.5, 0.0, -0.05, 0.0]))


def test_bad_flywheel_inputs():
    with pytest.raises(InvalidParameterError, match="switch_time must be <= T_max"):
        make_controller("bang-bang", P, switch_time=1.0)
    with pytest.raises(InvalidParameterError, match="theta must satisfy"):
        simulate(
            make_plant("flywheel", P),
            make_controller("bang-bang", P),
            np.array([0.0, 1.5, 0.0, 0.0]),
        )
    with pytest.raises(InvalidParameterError, match="state must be"):
        simulate(make_plant("flywheel", P), make_controller("bang-bang", P), np.array([0.0, 0.0]))
    no_hip = load_params(overrides={"torque_max": 0.0})
    with pytest.raises(InvalidParameterError, match="torque_max > 0"):
        make_controller("bang-bang", no_hip)
