"""The CMP bound (corrected Eq. 15) proved three ways: closed form, simulation, LP."""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.models.flywheel import max_spin_up_time
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.capture.lp import largest_capture_point
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.cmp import cmp_margin, cmp_offset, cmp_region

P = load_params()
T_MAX = max_spin_up_time(P)
EPS = 1e-4  # capture-point distance to the bound [m]; 0.05 % of the foot


def printed_eq15_offset(p):
    spin = max_spin_up_time(p)
    return p.torque_max / p.weight * (math.exp(p.omega * spin) - 1.0) ** 2


def test_closed_form_equals_supremum_integral():
    # Errata E12: the capturable capture point is δ⁺ + (ω³ I / m g) ∫ e^{−ωs} θ(s) ds, maximal
    # for the bang-bang θ(s). Evaluate that integral by quadrature, independently of Eq. 15.
    u = P.torque_max / P.flywheel_inertia

    def theta(s):
        if s < T_MAX:
            return 0.5 * u * s * s
        if s < 2 * T_MAX:
            return P.flywheel_angle_max - 0.5 * u * (2 * T_MAX - s) ** 2
        return P.flywheel_angle_max

    w = P.omega
    integral = sum(
        quad(lambda s: math.exp(-w * s) * theta(s), a, b, epsabs=1e-14)[0]
        for a, b in ((0, T_MAX), (T_MAX, 2 * T_MAX), (2 * T_MAX, 60.0))
    )
    assert w**3 * P.flywheel_inertia / P.weight * integral == pytest.approx(
        cmp_offset(P), rel=1e-10
    )


@pytest.mark.parametrize("x0", [-0.04, 0.05, 0.14])
@pytest.mark.parametrize("forward", [True, False])
def test_bang_bang_just_inside_recovers_just_outside_falls(x0, forward):
    region = cmp_region(P)
    bound, inward = (region.upper, -1.0) if forward else (region.lower, 1.0)
    plant, controller = make_plant("flywheel", P), make_controller("bang-bang", P)
    outcomes = []
    for xi in (bound + inward * EPS, bound - inward * EPS):
        run = simulate(
            plant,
            controller,
            plant.reset(x0, P.omega * (xi - x0)),
            control_period=T_MAX / 400,
        )  # the switch falls on a tick
        outcomes.append(run.outcome.value)
    assert outcomes == ["recovered", "fell"]


def test_lp_exact_region_agrees_with_closed_form():
    bound = cmp_region(P)
    coarse = largest_capture_point(P, dt=0.02)
    fine = largest_capture_point(P, dt=0.01)
    backward = largest_capture_point(P, dt=0.01, direction=-1.0)
    # Piecewise-constant inputs, θ checked at 4 points per step: the LP approaches the
    # supremum from below as dt shrinks (measured gaps 1.2e-5 and 5e-6 m).
    assert coarse.capture_point < fine.capture_point < bound.upper
    assert bound.upper - fine.capture_point < 2e-5
    # Between its check points θ can exceed θmax by at most u (dt/4)² / 8.
    u = P.torque_max / P.flywheel_inertia
    offsets = np.linspace(0.0, 0.01, 41)
    peak = max(
        (state[1] + state[3] * offsets + torque * offsets**2 / (2 * P.flywheel_inertia)).max()
        for state, torque in zip(fine.states[:-1], fine.torques, strict=True)
    )
    assert peak <= P.flywheel_angle_max + u * (0.01 / 4) ** 2 / 8 + 1e-12
    assert backward.capture_point == pytest.approx(bound.lower, abs=2e-5)
    # The printed Eq. (15) claims 0.35 m more than any controller can do.
    assert P.toe + printed_eq15_offset(P) - fine.capture_point > 0.3


def test_lp_optimum_is_bang_bang():
    # E12: the LP, free to use any input, chooses saturated ankle and ±τmax for ~T_max each.
    lp = largest_capture_point(P, dt=0.01)
    ticks = round(T_MAX / 0.01)
    assert np.all(lp.cops[: 2 * ticks] == pytest.approx(P.toe))
    assert np.all(lp.torques[: ticks - 1] == pytest.approx(P.torque_max))
    assert np.all(lp.torques[ticks + 1 : 2 * ticks - 1] == pytest.approx(-P.torque_max))
    assert np.abs(lp.states[:, 1]).max() <= P.flywheel_angle_max + 1e-7  # HiGHS feasibility tol


@given(x=st.floats(-0.04, 0.14), xi=st.floats(-0.3, 0.4))
def test_classification_matches_bang_bang_outcome(x, xi):
    region = cmp_region(P)
    if min(abs(xi - region.upper), abs(xi - region.lower)) < 5e-3:
        return  # the 1 ms control tick quantises T; the exact boundary is tested above
    v = P.omega * (xi - x)
    plant = make_plant("flywheel", P)
    run = simulate(plant, make_controller("bang-bang", P), plant.reset(x, v))
    assert run.recovered == (classify(x, v, P).strategy in ("ankle", "hip"))


def test_classify_strategies():
    assert classify(0.0, 0.3, P).strategy == "ankle"
    hip = classify(0.0, 0.55, P)
    assert hip.strategy == "hip" and hip.margins["cop"] < 0 < hip.margins["cmp"]
    assert classify(0.0, 0.7, P).strategy == "step"


@given(x=st.floats(-1, 1), v=st.floats(-3, 3), torque=st.floats(0, 300))
def test_cmp_mirror_symmetry(x, v, torque):
    p = load_params(overrides={"torque_max": torque})
    mirrored = dataclasses.replace(p, heel=-p.toe, toe=-p.heel)
    assert float(cmp_margin(x, v, p)) == pytest.approx(
        float(cmp_margin(-x, -v, mirrored)), abs=1e-12
    )


@given(
    torque=st.floats(1, 300),
    more_torque=st.floats(0, 100),
    angle=st.floats(0.1, 2),
    more_angle=st.floats(0, 1),
    inertia=st.floats(1, 30),
    more_inertia=st.floats(0, 10),
)
def test_more_hip_authority_never_shrinks_region(
    torque, more_torque, angle, more_angle, inertia, more_inertia
):
    small = load_params(
        overrides={"torque_max": torque, "flywheel_angle_max": angle, "flywheel_inertia": inertia}
    )
    for change in (
        {"torque_max": torque + more_torque},
        {"flywheel_angle_max": angle + more_angle},
        {"flywheel_inertia": inertia + more_inertia},
    ):
        big = dataclasses.replace(small, **change)
        assert cmp_offset(big) >= cmp_offset(small) - 1e-15
    assert cmp_offset(small) > 0.0
    assert cmp_offset(load_params(overrides={"torque_max": 0.0})) == 0.0
