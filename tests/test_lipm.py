"""Closed forms of the LIPM (Eq. 23-24) against numerical integration of the same ODE."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from pushrecovery.models.lipm import lipm_acceleration, lipm_state, lipm_transition

RTOL, ATOL = 1e-10, 1e-12  # the integrator's own tolerances; the closed form is exact


def normalised_error(actual, expected):
    return np.max(np.abs(actual - expected) / (ATOL + RTOL * np.abs(expected)))


@given(
    x0=st.floats(-0.2, 0.3),
    v0=st.floats(-1.0, 1.0),
    cop=st.floats(-0.05, 0.15),
    omega=st.floats(1.0, 6.0),
)
def test_eq24_matches_integration(x0, v0, cop, omega):
    t = np.linspace(0.0, 1.5, 7)
    sol = solve_ivp(
        lambda _, s: [s[1], omega**2 * (s[0] - cop)],
        (0, t[-1]),
        [x0, v0],
        t_eval=t,
        rtol=RTOL / 10,
        atol=ATOL / 10,
        method="DOP853",
    )
    x, xdot = lipm_state(t, x0, v0, cop, omega)
    # Scale the tolerance with the state's own size: errors grow like cosh(ωt).
    scale = 1.0 + np.abs(sol.y).max()
    assert np.max(np.abs(x - sol.y[0])) < 1e-8 * scale
    assert np.max(np.abs(xdot - sol.y[1])) < 1e-8 * scale * omega


def test_eq24_in_paper_form():
    # Eq. (24) as printed, with f = -g δ / L (Eq. 23).
    omega, x0, v0, cop, t = 3.0, 0.02, 0.4, 0.15, 0.7
    f = -(omega**2) * cop
    printed = (
        (f / omega**2 + x0) * np.cosh(omega * t) + v0 / omega * np.sinh(omega * t) - f / omega**2
    )
    assert lipm_state(t, x0, v0, cop, omega)[0] == pytest.approx(printed, rel=1e-14)


def test_transition_is_matrix_exponential():
    omega, dt = 3.13, 0.02
    a_cont = np.array([[0.0, 1.0, 0.0], [omega**2, 0.0, -(omega**2)], [0.0, 0.0, 0.0]])
    phi = expm(a_cont * dt)
    a, b = lipm_transition(omega, dt)
    np.testing.assert_allclose(a, phi[:2, :2], rtol=1e-13)
    np.testing.assert_allclose(b, phi[:2, 2], rtol=1e-12)


def test_propagate_vectorised_matches_transition():
    rng = np.random.default_rng(42)
    x, v, cop = rng.normal(size=(3, 1000)) * 0.1
    omega, dt = 3.13, 0.01
    a, b = lipm_transition(omega, dt)
    nx, nv = lipm_state(dt, x, v, cop, omega)
    expected = a @ np.vstack([x, v]) + np.outer(b, cop)
    np.testing.assert_allclose(np.vstack([nx, nv]), expected, rtol=1e-12, atol=1e-15)
    # The equilibrium is the CoM above the CoP.
    assert lipm_acceleration(0.1, 0.1, omega) == 0.0
