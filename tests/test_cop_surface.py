"""Eq. (4) against simulation, and its properties (symmetry, monotonicity, fast path)."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import make_controller
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces import cop as cop_module
from pushrecovery.surfaces.classify import STRATEGY_CODES, classify, classify_states
from pushrecovery.surfaces.cop import capture_point, cop_margin, critical_velocity

PARAMS = load_params()
OMEGA = PARAMS.omega
# Capture points this far inside / outside the surface must recover / fall. 1e-4 m is 0.05 %
# of the foot; the simulation is exact (ZOH LIPM) up to the 1 ms control tick.
EPS = 1e-4


def run(model, controller, x0, v0):
    return simulate(
        make_plant(model, PARAMS),
        make_controller(controller, PARAMS),
        np.array([x0, v0]),
        duration=10.0,
    )


def state_with_capture_point(x0, xi):
    return x0, OMEGA * (xi - x0)


@pytest.mark.parametrize("controller", ["ankle-saturated", "ankle-pd"])
@pytest.mark.parametrize("x0", np.linspace(-0.045, 0.145, 5))
@pytest.mark.parametrize("edge", ["heel", "toe"])
def test_eq4_just_inside_recovers_just_outside_falls(controller, x0, edge):
    bound = getattr(PARAMS, edge)
    inward = 1.0 if edge == "heel" else -1.0
    inside = run("lipm", controller, *state_with_capture_point(x0, bound + inward * EPS))
    outside = run("lipm", controller, *state_with_capture_point(x0, bound - inward * EPS))
    assert inside.outcome.value == "recovered"
    assert outside.outcome.value == "fell"


@given(x0=st.floats(-0.049, 0.149), margin=st.floats(2e-3, 0.1), forward=st.booleans())
def test_eq4_random_states(x0, margin, forward):
    edge, sign = (PARAMS.toe, 1.0) if forward else (PARAMS.heel, -1.0)
    inside = run("lipm", "ankle-saturated", *state_with_capture_point(x0, edge - sign * margin))
    outside = run("lipm", "ankle-saturated", *state_with_capture_point(x0, edge + sign * margin))
    assert inside.recovered
    assert outside.outcome.value == "fell"


@pytest.mark.parametrize("gap", [1e-6, 1e-5])
@pytest.mark.parametrize("x0", [0.1497, 0.1, 0.0])
def test_no_false_recovery_a_hair_outside(gap, x0):
    # A CoM resting against a saturated CoP can look still for a long time while it creeps
    # over the edge: such runs must not count as recovered.
    v0 = OMEGA * (PARAMS.toe + gap - x0)
    for controller in ("ankle-saturated", "ankle-pd"):
        assert not run("lipm", controller, x0, v0).recovered


def test_lipm_critical_push_never_exceeds_eq4():
    from pushrecovery.sim.critical import critical_push

    for direction in ("forward", "backward"):
        found = critical_push(PARAMS, "lipm", "ankle-saturated", 0.1, direction, tolerance=1e-9)
        assert abs(found.velocity) <= abs(found.predicted_velocity)
        assert abs(found.bracket[1]) >= abs(found.predicted_velocity) - 1e-12


def test_margin_values():
    # ξ = 0 is 0.05 m from the heel and 0.15 m from the toe.
    assert float(cop_margin(0.0, 0.0, PARAMS)) == pytest.approx(0.05)
    assert float(cop_margin(0.15, 0.0, PARAMS)) == pytest.approx(0.0, abs=1e-15)
    assert float(cop_margin(0.0, OMEGA * 0.25, PARAMS)) == pytest.approx(-0.10)
    assert float(capture_point(0.1, OMEGA * 0.05, OMEGA)) == pytest.approx(0.15)


def test_critical_velocity_is_on_the_surface():
    x = np.linspace(-0.04, 0.14, 7)
    for direction in (1.0, -1.0):
        v = critical_velocity(x, direction, PARAMS)
        np.testing.assert_allclose(cop_margin(x, v, PARAMS), 0.0, atol=1e-15)
        assert np.all(np.sign(v) == direction)


def test_fused_path_matches_numpy_path(monkeypatch):
    rng = np.random.default_rng(7)
    x, v = rng.normal(0.05, 0.1, size=(2, 50_000))
    fast = cop_margin(x, v, PARAMS)
    monkeypatch.setattr(cop_module, "_FUSED_MIN_SIZE", 10**9)
    slow = cop_margin(x, v, PARAMS)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-15)
    reference = np.minimum(
        capture_point(x, v, OMEGA) - PARAMS.heel, PARAMS.toe - capture_point(x, v, OMEGA)
    )
    np.testing.assert_allclose(fast, reference, atol=1e-15)


@pytest.mark.parametrize("size", [3, 50_000])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_states_raise(size, bad):
    x = np.zeros(size)
    x[size // 2] = bad
    with pytest.raises(InvalidParameterError, match="x must be finite"):
        cop_margin(x, np.zeros(size), PARAMS)
    with pytest.raises(InvalidParameterError, match="xdot must be finite"):
        cop_margin(np.zeros(size), x, PARAMS)
    with pytest.raises(InvalidParameterError, match="finite"):
        classify(0.0, float(bad), PARAMS)


def mirrored(p):
    return dataclasses.replace(p, heel=-p.toe, toe=-p.heel)


@given(
    x=st.floats(-1, 1),
    v=st.floats(-3, 3),
    heel=st.floats(-0.3, -0.01),
    toe=st.floats(0.01, 0.3),
    height=st.floats(0.5, 2.0),
)
def test_mirror_symmetry(x, v, heel, toe, height):
    p = load_params(overrides={"heel": heel, "toe": toe, "com_height": height})
    assert float(cop_margin(x, v, p)) == pytest.approx(
        float(cop_margin(-x, -v, mirrored(p))), abs=1e-12
    )
    assert (
        classify(x, v, p).strategy == classify(-x, -v, mirrored(p)).strategy
        or abs(float(cop_margin(x, v, p))) < 1e-12
    )


@given(
    x=st.floats(-0.5, 0.5),
    v=st.floats(-2, 2),
    heel=st.floats(-0.2, -0.01),
    toe=st.floats(0.01, 0.2),
    grow_heel=st.floats(0, 0.1),
    grow_toe=st.floats(0, 0.1),
)
def test_bigger_foot_never_shrinks_region(x, v, heel, toe, grow_heel, grow_toe):
    small = load_params(overrides={"heel": heel, "toe": toe})
    big = load_params(overrides={"heel": heel - grow_heel, "toe": toe + grow_toe})
    assert float(cop_margin(x, v, big)) >= float(cop_margin(x, v, small)) - 1e-15


def test_simulated_mirror_symmetry_of_critical_push():
    from pushrecovery.sim.critical import critical_push

    p = load_params()
    forward = critical_push(p, "pendulum", "ankle-pd", 0.03, "forward", tolerance=1e-5)
    backward = critical_push(mirrored(p), "pendulum", "ankle-pd", -0.03, "backward", tolerance=1e-5)
    assert forward.velocity == pytest.approx(-backward.velocity, abs=2e-5)


def test_vectorised_classifier():
    codes = classify_states([0.0, 0.0, 0.0], [0.0, 1.0, -1.0], PARAMS)
    assert [STRATEGY_CODES[c].value for c in codes] == ["ankle", "step", "step"]
