"""The hip (CMP) region from the upper body's current angle and rate (errata E19).

The closed form of :func:`pushrecovery.surfaces.cmp.flywheel_offsets` is checked against a
linear program over the exact zero-order-hold discretisation of the flywheel
(:func:`pushrecovery.models.flywheel.flywheel_discrete`) that is free to choose any
piecewise-constant torque with abs(τ) ≤ τmax, abs(θ_k) ≤ θmax at the samples and θ̇_N = 0.
The LP restricts the torque to a grid (below the supremum) and checks the joint limit at the
samples only (above it); its optimum converges to the closed form as O(dt²). Over 48 states
(paper preset) the gap LP − closed form lies in [−5.9e-5, +3.0e-6] m at dt = 0.02 s,
[−1.4e-5, +1.4e-6] m at 0.01 s, [−3.3e-6, +7.9e-7] m at 0.005 s and [−9.5e-7, +2.1e-8] m at
0.0025 s: abs(gap) ≤ 0.15 dt² m/s² throughout (≤ 0.12 dt² for the robot body).
"""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.optimize import linprog

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.errors import ParameterTypeError
from pushrecovery.ground.support import FootPose, Support
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import (
    cmp_offset,
    cmp_offset_from,
    cmp_offset_roll,
    cmp_region,
    cmp_region_from,
    flywheel_offset,
    flywheel_offsets,
)
from pushrecovery.surfaces.plane import cmp_polygon, cmp_polygon_from

P = load_params()
#: A small robot (the 48 kg body of issue 32 with a light, short-ranged upper body).
ROBOT = load_params(
    overrides={
        "mass": 48.0,
        "com_height": 0.78,
        "flywheel_inertia": 2.0,
        "torque_max": 60.0,
        "flywheel_angle_max": 0.5,
    }
)
#: abs(LP optimum − closed form) in units of dt² [m/s²]: the observed gap is at most 0.15.
GAP_PER_DT2 = 0.2


def _rate_range(p: BodyParams, theta0: float) -> tuple[float, float]:
    accel = p.torque_max / p.flywheel_inertia
    th = p.flywheel_angle_max
    return -math.sqrt(2 * accel * (th + theta0)), math.sqrt(2 * accel * (th - theta0))


def lp_offsets(p: BodyParams, theta0: float, rate0: float, dt: float) -> tuple[float, float]:
    """(Δ⁻, Δ⁺) by linear programming over the exact ZOH flywheel; no assumption on τ's shape.

    ξ_{k+1} = e^{ω dt} ξ_k + g τ_k with g the capture-point row (x + ẋ/ω) of the ZOH input
    matrix, so the shift of the capture point brought onto an edge is Σ_k −g e^{−ω(k+1)dt} τ_k.
    """
    a, b = flywheel_discrete(p, dt)
    omega, inertia, tmax = p.omega, p.flywheel_inertia, p.torque_max
    accel = tmax / inertia
    # Horizon: past the closed form's longest stop time (2v − θ̇0)/α in either direction.
    peak = math.sqrt(2 * accel * p.flywheel_angle_max + 0.5 * rate0 * rate0)
    n = math.ceil(((2 * peak + abs(rate0)) / accel + 0.2) / dt)
    gain = np.array([1.0, 0.0, 1.0 / omega, 0.0]) @ b[:, 1]
    k = np.arange(n)
    weights = -gain * np.exp(-omega * (k + 1) * dt) * tmax
    # θ_j = θ0 + j dt θ̇0 + Σ_{i<j} (A^{j−1−i} B)_θ τ_i, the θ rows of the exact ZOH.
    step_theta, step_rate = b[1, 1], b[3, 1]
    lag = k[:, None] - k[None, :]  # j − 1 − i for θ_{j}, j = 1..n (row j − 1)
    gains = np.where(lag >= 0, step_theta + lag * a[1, 3] * step_rate, 0.0) * tmax
    free = theta0 + (k + 1) * dt * rate0
    limit = p.flywheel_angle_max
    a_ub = np.vstack([gains, -gains])
    b_ub = np.concatenate([limit - free, limit + free])
    a_eq = np.full((1, n), step_rate * tmax)
    shifts = []
    for sign in (-1.0, 1.0):
        res = linprog(
            -sign * weights,
            A_ub=a_ub,
            b_ub=b_ub,
            A_eq=a_eq,
            b_eq=[-rate0],
            bounds=(-1.0, 1.0),
            method="highs",
        )
        assert res.status == 0, res.message
        shifts.append(sign * float(weights @ res.x))
    return shifts[0], shifts[1]


def _states(p: BodyParams) -> list[tuple[float, float]]:
    """At rest; the joint limit binding at once; the rate each way; braking first; the edge."""
    th = p.flywheel_angle_max
    low, high = _rate_range(p, 0.6 * th)
    return [
        (0.0, 0.0),
        (th, 0.0),
        (-th, 0.0),
        (0.3 * th, 0.5),
        (-0.5 * th, -1.0),
        (0.6 * th, 0.9 * high),  # fast toward the near limit: Δ⁺ < 0 (must brake first)
        (0.6 * th, 0.9 * low),
        (0.6 * th, high),  # at the edge of the admissible rates
    ]


def _check_against_lp(p: BodyParams, states: list[tuple[float, float]], dt: float) -> float:
    worst = 0.0
    for theta0, rate0 in states:
        exact = np.array(cmp_offset_from(p, theta0, rate0))
        lp = np.array(lp_offsets(p, theta0, rate0, dt))
        gap = lp - exact
        assert np.all(np.abs(gap) <= GAP_PER_DT2 * dt * dt), (theta0, rate0, gap)
        worst = max(worst, float(np.max(np.abs(gap))))
    return worst


@pytest.mark.parametrize("body", [P, ROBOT], ids=["paper", "robot"])
def test_offsets_match_lp(body):
    _check_against_lp(body, _states(body), 0.01)


@pytest.mark.validate
@pytest.mark.parametrize("body", [P, ROBOT], ids=["paper", "robot"])
def test_offsets_match_lp_fine(body):
    # 40 random admissible states plus the named ones, at dt = 0.005 s; the gap shrinks with dt.
    rng = np.random.default_rng(32)
    th = body.flywheel_angle_max
    states = _states(body)
    for theta0 in rng.uniform(-th, th, 40):
        low, high = _rate_range(body, float(theta0))
        states.append((float(theta0), float(rng.uniform(low, high))))
    coarse = _check_against_lp(body, states[:8], 0.01)
    fine = _check_against_lp(body, states, 0.005)
    finer = _check_against_lp(body, states[:8], 0.0025)
    assert finer < coarse
    assert fine < 0.2 * 0.005**2 and finer < 0.2 * 0.0025**2


def test_lp_optimum_is_the_bang_bang_profile():
    # Forward from a backward-spinning, forward-leaning upper body: full torque for t₁, full
    # reverse torque to t₂ = 2t₁ + θ̇0/α, then hold at θmax.
    theta0, rate0, dt = 0.3, -1.0, 0.005
    accel = P.torque_max / P.flywheel_inertia
    peak = math.sqrt(accel * (P.flywheel_angle_max - theta0) + 0.5 * rate0**2)
    t1, t2 = (peak - rate0) / accel, (2 * peak - rate0) / accel
    a, b = flywheel_discrete(P, dt)
    n = round(1.5 / dt)
    k = np.arange(n)
    lag = k[:, None] - k[None, :]
    gains = np.where(lag >= 0, b[1, 1] + lag * a[1, 3] * b[3, 1], 0.0) * P.torque_max
    free = theta0 + (k + 1) * dt * rate0
    weights = np.exp(-P.omega * k * dt)
    res = linprog(
        -weights,
        A_ub=np.vstack([gains, -gains]),
        b_ub=np.concatenate([P.flywheel_angle_max - free, P.flywheel_angle_max + free]),
        A_eq=np.full((1, n), b[3, 1] * P.torque_max),
        b_eq=[-rate0],
        bounds=(-1.0, 1.0),
        method="highs",
    )
    t = k * dt
    arcs = (np.abs(t - t1) > 2 * dt) & (t < t2 - 2 * dt)  # u after t₂ only holds θ at θmax
    assert np.allclose(res.x[arcs], np.where(t < t1, 1.0, -1.0)[arcs], atol=1e-6)
    theta = free + gains @ res.x
    hold = (t > t2 + 2 * dt) & (t < t[-1] - 0.1)  # the last steps only meet θ̇_N = 0
    assert np.all(np.abs(theta[hold] - P.flywheel_angle_max) < 1e-6)


def test_reduces_to_corrected_eq15_at_rest():
    for body in (P, ROBOT):
        assert cmp_offset_from(body, 0.0, 0.0) == pytest.approx((cmp_offset(body),) * 2, abs=1e-12)
        assert cmp_offset_from(body, 0.0, 0.0, axis="roll") == pytest.approx(
            (cmp_offset_roll(body),) * 2, abs=1e-12
        )
        region, resting = cmp_region_from(body, 0.0, 0.0), cmp_region(body)
        assert region.lower == pytest.approx(resting.lower, abs=1e-12)
        assert region.upper == pytest.approx(resting.upper, abs=1e-12)


@given(
    torque=st.floats(1.0, 1e3),
    inertia=st.floats(0.1, 50.0),
    angle=st.floats(0.05, 3.0),
    omega=st.floats(1.0, 10.0),
)
def test_reduces_to_flywheel_offset_for_any_body(torque, inertia, angle, omega):
    at_rest = flywheel_offset(torque, inertia, angle, 700.0, omega)
    assert flywheel_offsets(torque, inertia, angle, 700.0, omega, 0.0, 0.0) == pytest.approx(
        (at_rest, at_rest), abs=1e-12
    )


@given(fraction=st.floats(-1.0, 1.0), share=st.floats(-1.0, 1.0))
def test_mirror_symmetry_and_nonempty(fraction, share):
    theta0 = fraction * P.flywheel_angle_max
    low, high = _rate_range(P, theta0)
    rate0 = share * (high if share > 0 else -low)
    minus, plus = cmp_offset_from(P, theta0, rate0)
    mirrored = cmp_offset_from(P, -theta0, -rate0)
    assert mirrored == pytest.approx((plus, minus), abs=1e-15)
    assert minus + plus >= -1e-15  # the interval of reachable shifts is never empty
    # Never more than full torque forever, a ∫ω e^{−ωt} dt = a.
    assert max(minus, plus) <= P.torque_max / P.weight


def test_leaning_or_spinning_toward_the_push_shrinks_that_side():
    minus, plus = cmp_offset_from(P, 0.5, 0.0)
    assert plus < cmp_offset(P) < minus
    assert cmp_offset_from(P, 0.0, 1.0)[1] < cmp_offset(P) < cmp_offset_from(P, 0.0, 1.0)[0]
    assert cmp_offset_from(P, P.flywheel_angle_max, 0.0)[1] == 0.0


def test_no_torque_no_hip_strategy():
    assert flywheel_offsets(0.0, 10.0, 1.0, 700.0, 3.0, 0.5, 2.0) == (0.0, 0.0)


@pytest.mark.parametrize(
    ("theta0", "rate0", "name"),
    [
        (1.01, 0.0, "theta0"),
        (-1.5, 0.0, "theta0"),
        (math.nan, 0.0, "theta0"),
        (math.inf, 0.0, "theta0"),
        (0.0, math.nan, "thetadot0"),
        (0.0, -math.inf, "thetadot0"),
        (0.5, 3.2, "thetadot0"),  # from 0.5 rad the forward stop needs θ̇0 ≤ sqrt(10) rad/s
        (-0.5, -3.2, "thetadot0"),
        ("x", 0.0, "theta0"),
    ],
)
def test_bad_input_names_the_parameter(theta0, rate0, name):
    with pytest.raises(InvalidParameterError, match=name):
        cmp_offset_from(P, theta0, rate0)


def test_too_fast_names_the_range():
    range_ = r"thetadot0 must be in \[-5\.47723, 3\.16228\]"
    with pytest.raises(InvalidParameterError, match=range_):
        cmp_offset_from(P, 0.5, 3.2)
    assert cmp_offset_from(P, 0.5, math.sqrt(10.0))[1] < 0.0  # the edge itself is admissible


def test_bad_axis_and_params():
    with pytest.raises(InvalidParameterError, match="axis"):
        cmp_offset_from(P, 0.0, 0.0, axis="yaw")
    with pytest.raises(ParameterTypeError):
        cmp_offset_from("paper", 0.0, 0.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="omega"):
        flywheel_offsets(100.0, 10.0, 1.0, 700.0, 0.0, 0.0, 0.0)


# The plane form: P ⊕ [−Δ⁻_p, Δ⁺_p] × [−Δ⁻_r, Δ⁺_r] in the stance's axes.

PLANE_SUPPORTS = {
    "double": lambda: Support.from_params(P, "double"),
    "right-yawed": lambda: Support.from_params(P, "right", right=FootPose(0.0, -0.1, -0.7)),
}


@pytest.mark.parametrize("name", PLANE_SUPPORTS)
def test_plane_polygon_at_rest_is_cmp_polygon(name):
    support = PLANE_SUPPORTS[name]()
    np.testing.assert_allclose(
        cmp_polygon_from(support, P).vertices, cmp_polygon(support, P).vertices, atol=1e-15
    )


@pytest.mark.parametrize("name", PLANE_SUPPORTS)
def test_plane_polygon_support_function(name):
    # h(d) = h_P(d) + Σ_axes Δ⁺ max(d·e, 0) + Δ⁻ max(−d·e, 0), e the body's pitch and roll axes.
    support = PLANE_SUPPORTS[name]()
    pitch, roll = (0.4, -1.2), (-0.7, 2.0)
    region = cmp_polygon_from(support, P, pitch, roll)
    minus_p, plus_p = cmp_offset_from(P, *pitch)
    minus_r, plus_r = cmp_offset_from(P, *roll, axis="roll")
    c, s = math.cos(support.yaw), math.sin(support.yaw)
    for angle in np.linspace(-math.pi, math.pi, 37):
        d = np.array([math.cos(angle), math.sin(angle)])
        along, across = d @ (c, s), d @ (-s, c)
        want = (
            support.polygon.support(*d)
            + plus_p * max(along, 0.0)
            + minus_p * max(-along, 0.0)
            + plus_r * max(across, 0.0)
            + minus_r * max(-across, 0.0)
        )
        assert region.support(*d) == pytest.approx(want, abs=1e-14)


def test_plane_polygon_bad_input():
    support = Support.from_params(P, "double")
    with pytest.raises(InvalidParameterError, match="theta0"):
        cmp_polygon_from(support, P, roll=(1.5, 0.0))
    with pytest.raises(InvalidParameterError, match="thetadot0"):
        cmp_polygon_from(support, P, pitch=(0.0, math.nan))
    with pytest.raises(InvalidParameterError, match="pitch"):
        cmp_polygon_from(support, P, pitch=0.1)  # type: ignore[arg-type]
