"""The nonlinear pendulum: integrator, exact CoP-limited ankle torque, the fall criterion."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from pushrecovery.models.pendulum import (
    ankle_torque_for_cop,
    pendulum_acceleration,
    pendulum_step,
)
from pushrecovery.sim.result import is_falling

M, L, G = 72.0, 1.0, 9.81


def test_rk4_matches_adaptive_integrator():
    cop, theta0, rate0 = 0.1, 0.05, 0.3
    sol = solve_ivp(
        lambda _, s: [s[1], pendulum_acceleration(s[0], s[1], cop, M, L, G)],
        (0, 1.0),
        [theta0, rate0],
        rtol=1e-12,
        atol=1e-14,
        method="DOP853",
    )
    theta, rate = theta0, rate0
    for _ in range(1000):
        theta, rate = pendulum_step(theta, rate, cop, 1e-3, M, L, G)
    # RK4 with h = 1 ms: global error ~ (ωh)^4 ~ 1e-10 of the state.
    assert abs(theta - sol.y[0, -1]) < 1e-9
    assert abs(rate - sol.y[1, -1]) < 1e-9


def test_zero_cop_conserves_energy():
    theta, rate = 0.1, -0.8  # swings up over the ankle and back down
    energy0 = 0.5 * M * L**2 * rate**2 + M * G * L * math.cos(theta)
    for _ in range(2000):
        theta, rate = pendulum_step(theta, rate, 0.0, 1e-3, M, L, G)
    energy = 0.5 * M * L**2 * rate**2 + M * G * L * math.cos(theta)
    assert energy == pytest.approx(energy0, rel=1e-10)


@given(
    theta=st.floats(-0.6, 0.6),
    rate=st.floats(-1.5, 1.5),
    cop=st.floats(-0.05, 0.15),
)
def test_torque_puts_the_cop_exactly_where_asked(theta, rate, cop):
    # CoP = τ / F_z with F_z = m (g + z̈), z = L cosθ: recompute z̈ from the dynamics.
    tau = ankle_torque_for_cop(theta, rate, cop, M, L, G)
    accel = pendulum_acceleration(theta, rate, cop, M, L, G)
    z_ddot = -L * (math.sin(theta) * accel + math.cos(theta) * rate**2)
    normal = M * (G + z_ddot)
    if normal <= 0.0:
        assert tau == 0.0
    else:
        assert tau / normal == pytest.approx(cop, abs=1e-12)


@given(
    theta=st.floats(-0.6, 0.6),
    rate=st.floats(-1.5, 1.5),
    cop=st.floats(-0.05, 0.15),
    hip=st.floats(-100.0, 100.0),
    push=st.floats(-5000.0, 5000.0),
    height=st.floats(0.0, 0.1),
    foot=st.floats(0.0, 2.0),
)
def test_torque_with_hip_torque_push_and_a_real_foot(theta, rate, cop, hip, push, height, foot):
    # Errata E3, generalised: from the torque, recompute the motion of the point mass
    # (m L² θ̈ = m g L sinθ + P L cosθ − τ − τ_h), the ground force it needs (F_x = m ẍ − P,
    # F_z = m (g + z̈)) and the CoP of the floor's force on a foot of mass m_f centred at c_f,
    # whose ankle is h above the sole: moments about the ankle give
    # δ (F_z + m_f g) = τ − h F_x + c_f m_f g.
    centre = 0.05
    tau = ankle_torque_for_cop(
        theta,
        rate,
        cop,
        M,
        L,
        G,
        hip_torque=hip,
        push_force=push,
        ankle_height=height,
        foot_mass=foot,
        foot_centre=centre,
    )
    sin, cos = math.sin(theta), math.cos(theta)
    accel = (M * G * L * sin + push * L * cos - tau - hip) / (M * L * L)
    x_ddot = L * (cos * accel - sin * rate**2)
    z_ddot = -L * (sin * accel + cos * rate**2)
    normal, friction = M * (G + z_ddot), M * x_ddot - push
    if normal <= 0.0:
        assert tau == 0.0
    else:
        floor = normal + foot * G
        assert (tau - height * friction + centre * foot * G) / floor == pytest.approx(
            cop, abs=1e-12
        )


@given(
    x=st.floats(0.1501, 0.9),
    rate=st.floats(0.0, 3.0),
    cop=st.floats(-0.05, 0.15),
)
def test_fall_criterion_is_absorbing_for_pendulum(x, rate, cop):
    # Beyond the toe and moving forward, no CoP on the foot can decelerate the lean.
    theta = math.asin(x / L)
    assert is_falling(x, rate, -0.05, 0.15)
    assert pendulum_acceleration(theta, rate, cop, M, L, G) > 0.0


@given(
    x=st.floats(-0.9, -0.0501),
    rate=st.floats(-3.0, 0.0),
    cop=st.floats(-0.05, 0.15),
)
def test_fall_criterion_is_absorbing_at_the_heel(x, rate, cop):
    theta = math.asin(x / L)
    assert is_falling(x, rate, -0.05, 0.15)
    assert pendulum_acceleration(theta, rate, cop, M, L, G) < 0.0


def test_unloaded_foot_transmits_no_torque():
    # A = m cos(theta) (g cos(theta) - L rate^2) <= 0: the swing is fast enough to unload the foot.
    rate = math.sqrt(G / L) * 1.01
    assert ankle_torque_for_cop(0.0, rate, 0.15, M, L, G) == 0.0
    assert pendulum_acceleration(0.1, rate, 0.15, M, L, G) == pytest.approx(G * math.sin(0.1) / L)


def test_cop_from_newton_euler_on_the_simulated_trajectory():
    # Independent of the model's formulas: differentiate the simulated CoM path numerically
    # and recover the CoP from Newton-Euler about the ankle,
    # p F_z = dH/dt + m g x with H = m (x zdot - z xdot) and F_z = m (zddot + g).
    cop, h = 0.12, 1e-3
    theta, rate = 0.02, 0.4
    path = []
    for _ in range(400):
        path.append((L * math.sin(theta), L * math.cos(theta)))
        theta, rate = pendulum_step(theta, rate, cop, h, M, L, G, substeps=4)
    x, z = np.array(path).T
    xdd = (x[2:] - 2 * x[1:-1] + x[:-2]) / h**2
    zdd = (z[2:] - 2 * z[1:-1] + z[:-2]) / h**2
    xm, zm = x[1:-1], z[1:-1]
    recovered = (xm * zdd - zm * xdd + G * xm) / (zdd + G)
    # Central differences: error ~ h^2 / 12 times the fourth derivative, ~1e-7 m here.
    np.testing.assert_allclose(recovered, cop, atol=1e-6)


def test_fall_criterion_mirror():
    assert is_falling(-0.06, -0.1, -0.05, 0.15)
    assert not is_falling(-0.06, 0.1, -0.05, 0.15)  # outside but coming back
    assert not is_falling(0.0, 5.0, -0.05, 0.15)
    assert np.isfinite(ankle_torque_for_cop(0.0, 10.0, 0.1, M, L, G))  # unloaded foot: no torque
