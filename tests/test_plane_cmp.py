"""The planar CMP (hip) region P ⊕ box(a_pitch, a_roll), proved the way Sec. III was proved.

Three independent routes to the capturable set of the planar flywheel model:

- the closed form of ``surfaces.plane`` (support function h_P(d) + a_p|d·e_p| + a_r|d·e_r|);
- a linear program over CoP and torque sequences (``surfaces.capture.lp.plane``), which assumes
  nothing about the optimal input, in 16 directions, single and double support, yawed feet;
- simulations of the planar model (matrix exponential of the equations of motion written out
  here, not the package's discretisation) just inside (a witnessing strategy recovers) and just
  outside (the best controller along the outward normal falls) in 16 push directions.
"""

import itertools
import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import linprog

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground import FootPose, Support
from pushrecovery.models.flywheel.plane import plane_continuous, plane_discrete
from pushrecovery.surfaces.capture.lp.plane import support_function_lp
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll
from pushrecovery.surfaces.plane import cmp_polygon

ANGLES = [2.0 * math.pi * k / 16 for k in range(16)]  # 16 push directions

# T_max = sqrt(I θmax / τmax) = 0.3 s on both axes (30 steps of dt = 0.01 s), the roll axis
# with half the pitch torque and its own inertia and joint limit.
GRID = load_params(
    overrides={
        "flywheel_angle_max": 0.9,  # pitch: sqrt(10 · 0.9 / 100) = 0.3 s
        "torque_max_roll": 50.0,
        "flywheel_inertia_roll": 4.5,
        "flywheel_angle_max_roll": 1.0,  # roll: sqrt(4.5 · 1.0 / 50) = 0.3 s
    }
)
DT = 0.01
# Horizon of the on-grid LPs: 4 T_max. The bang-bang witness has ξ on P's boundary at 2 T_max,
# so any horizon ≥ 2 T_max attains the supremum; the upper bound holds for every horizon.
HORIZON = 1.2
SOLVER = 1e-8  # HiGHS runs at 1e-9 feasibility on O(1) scaled variables; 10x for the value
FEAS = 1e-9  # an LP solution's constraint violation: HiGHS's feasibility tolerance, unscaled
EPS = 1e-4  # capture-point distance to the boundary in the simulations [m]; 0.1 % of a foot


def spin_up(tau, inertia, angle):
    return math.sqrt(inertia * angle / tau)


def eq15_offset(tau, inertia, angle, p):
    """Corrected Eq. 15 for one axis, written out here (only for the LP's slack bound)."""
    return tau / p.weight * (1.0 - math.exp(-p.omega * spin_up(tau, inertia, angle))) ** 2


def axes_of(p):
    return (
        (p.torque_max, p.flywheel_inertia, p.flywheel_angle_max),
        (p.torque_max_roll, p.flywheel_inertia_roll, p.flywheel_angle_max_roll),
    )


def slack_bound(p, d, yaw, dt):
    """How much the LP may exceed the closed form along d (module docstring of the LP).

    Between its check points (dt/4 apart) θ may exceed θmax by u (dt/4)² / 8, so the LP is at
    most the supremum for θmax + u (dt/4)²/8 on each axis.
    """
    body = (
        d[0] * math.cos(yaw) + d[1] * math.sin(yaw),
        -d[0] * math.sin(yaw) + d[1] * math.cos(yaw),
    )
    total = 0.0
    for (tau, inertia, angle), component in zip(axes_of(p), body, strict=True):
        extra = tau / inertia * (dt / 4) ** 2 / 8
        grown = eq15_offset(tau, inertia, angle + extra, p) - eq15_offset(tau, inertia, angle, p)
        total += abs(component) * grown
    return total


def unit(angle):
    return np.array([math.cos(angle), math.sin(angle)])


def closed_form(support, p, angle):
    return cmp_polygon(support, p).support(*unit(angle))


TOED_OUT = {"left": FootPose(0.02, 0.11, 0.5), "right": FootPose(-0.03, -0.1, 0.3)}
LP_CASES = {
    "single-left": lambda p: Support.from_params(p, "left"),
    "double": lambda p: Support.from_params(p, "double"),
    "double-yawed": lambda p: Support.from_params(p, "double", **TOED_OUT),
    "single-right-yawed": lambda p: Support.from_params(
        p, "right", right=FootPose(0.0, -0.1, -0.7)
    ),
}


# --- The linear program against the closed form ------------------------------------------------


@pytest.mark.parametrize("case", sorted(LP_CASES))
def test_lp_support_function_equals_closed_form_on_grid(case):
    # T_max of both axes on the grid: LP ∈ [closed form − solver, closed form + slack + solver].
    support = LP_CASES[case](GRID)
    assert GRID.torque_max_roll != GRID.torque_max and support.polygon.area > 0
    for angle in ANGLES:
        lp = support_function_lp(
            support.polygon, GRID, angle, dt=DT, horizon=HORIZON, yaw=support.yaw
        )
        gap = lp.value - closed_form(support, GRID, angle)
        slack = slack_bound(GRID, unit(angle), support.yaw, DT)
        assert -SOLVER <= gap <= slack + SOLVER, (case, angle, gap, slack)
    # The box is there: the LP reaches beyond P by the flywheels in every direction.
    for angle in ANGLES:
        assert closed_form(support, GRID, angle) - support.polygon.support(*unit(angle)) > 0.02


def test_lp_sees_the_box_turned_with_the_stance():
    # Feet turned by 0.4 rad on average: the same LP with the body's axes left at yaw 0 misses
    # the closed form by centimetres, so the equality above really tests the box's alignment.
    support = LP_CASES["double-yawed"](GRID)
    assert support.yaw == pytest.approx(0.4)
    worst = max(
        abs(
            support_function_lp(support.polygon, GRID, angle, dt=DT, horizon=HORIZON).value
            - closed_form(support, GRID, angle)
        )
        for angle in ANGLES[1::4]
    )
    assert worst > 0.01


def test_lp_optimum_is_bang_bang_on_both_axes():
    # Along a diagonal the LP, free to use any input, saturates both flywheels for T_max each.
    support = Support.from_params(GRID, "left")
    angle = math.radians(35.0)
    lp = support_function_lp(support.polygon, GRID, angle, dt=DT, horizon=HORIZON)
    ticks = 30  # T_max / dt on both axes
    # Saturation: a vertex of the LP, exact up to HiGHS's 1e-9 on torques scaled by τmax.
    for column, tau in ((0, GRID.torque_max), (1, GRID.torque_max_roll)):
        assert np.allclose(lp.torques[: ticks - 1, column], tau, rtol=0, atol=FEAS * tau)
        assert np.allclose(
            lp.torques[ticks + 1 : 2 * ticks - 1, column], -tau, rtol=0, atol=FEAS * tau
        )
    # CoP held at the foot's corner in the push direction (P's support point), while it spins.
    corner = support.polygon.vertices[np.argmax(support.polygon.vertices @ unit(angle))]
    assert np.allclose(lp.cops[: 2 * ticks - 1], corner, rtol=0, atol=FEAS)


def test_lp_trajectory_is_admissible_in_the_continuous_model():
    # Replay the LP's inputs through the matrix exponential of the equations of motion: the
    # states match, the CoP stays in P, θ stays within its limits (up to the interior-check
    # slack), and the end state is captured.
    support = LP_CASES["double-yawed"](GRID)
    lp = support_function_lp(support.polygon, GRID, 1.0, dt=DT, horizon=HORIZON, yaw=support.yaw)
    a, b = model(GRID, support.yaw)
    step = exact_step(a, b, DT)
    state = lp.states[0]
    dense = np.linspace(0.0, DT, 21)[1:-1]
    steps_inside = [exact_step(a, b, h) for h in dense]
    peak = np.zeros(2)
    for k, (cop, torque) in enumerate(zip(lp.cops, lp.torques, strict=True)):
        u = np.concatenate([cop, torque])
        assert float(support.polygon.signed_distance(*cop)) >= -FEAS
        for inside in steps_inside:
            peak = np.maximum(peak, np.abs(apply(inside, state, u)[2:4]))
        state = apply(step, state, u)
        assert np.allclose(state, lp.states[k + 1], rtol=0, atol=FEAS)
    limits = [(tau / inertia * (DT / 4) ** 2 / 8, angle) for tau, inertia, angle in axes_of(GRID)]
    for axis, (extra, angle) in enumerate(limits):
        assert peak[axis] <= angle + extra + FEAS
    xi = state[0:2] + state[4:6] / GRID.omega
    assert float(support.polygon.signed_distance(*xi)) >= -FEAS
    assert np.abs(state[6:8]).max() <= FEAS


def test_lp_approaches_paper_preset_from_below():
    # Paper preset: T_max = 0.316 s is not on the grid, the roll axis equals the pitch axis.
    # As dt shrinks the LP climbs to the closed form from below (never above it by more than
    # its interior-check slack).
    p = load_params()
    support = Support.from_params(p, "double")
    coarse_gaps, fine_gaps = [], []
    for angle in ANGLES:
        bound = closed_form(support, p, angle)
        coarse = support_function_lp(support.polygon, p, angle, dt=0.02, horizon=1.4).value
        fine = support_function_lp(support.polygon, p, angle, dt=0.01, horizon=1.4).value
        assert coarse < fine <= bound + slack_bound(p, unit(angle), 0.0, 0.01) + SOLVER
        coarse_gaps.append(bound - coarse)
        fine_gaps.append(bound - fine)
    # Measured: max gap 1.7e-5 m at dt = 0.02 s and 6.7e-6 m at 0.01 s (the 1-D LP: 5e-6 m);
    # halving dt at least halves it, and 1e-5 m is 0.02 % of the 5 cm the flywheels add.
    assert max(fine_gaps) < 1e-5
    assert max(fine_gaps) < 0.5 * max(coarse_gaps)


@pytest.mark.parametrize("torques", [(0.0, 0.0), (100.0, 0.0)])
def test_lp_without_hip_torque_on_an_axis_loses_that_axis(torques):
    # No torque at all: the LP region is the support polygon (Eq. 4 in the plane); no roll
    # torque: only the pitch box is left.
    p = load_params(
        overrides={
            "torque_max": torques[0],
            "torque_max_roll": torques[1],
            "flywheel_angle_max": 0.9,
        }
    )
    support = Support.from_params(p, "double")
    for angle in ANGLES:
        lp = support_function_lp(support.polygon, p, angle, dt=DT, horizon=HORIZON)
        expected = support.polygon.support(*unit(angle))
        if torques[0] > 0.0:
            expected += abs(math.cos(angle)) * eq15_offset(100.0, 10.0, 0.9, p)
        assert lp.value == pytest.approx(expected, abs=SOLVER)
        assert lp.value == pytest.approx(closed_form(support, p, angle), abs=SOLVER)


def test_lp_arguments_are_checked():
    support = Support.from_params(GRID, "left")
    for kwargs, name in (
        ({"dt": 0.0}, "dt"),
        ({"dt": float("nan")}, "dt"),
        ({"horizon": -1.0}, "horizon"),
        ({"yaw": float("inf")}, "yaw"),
        ({"horizon": 100.0, "dt": 0.001}, "horizon"),
    ):
        with pytest.raises(InvalidParameterError, match=name):
            support_function_lp(support.polygon, GRID, 0.0, **kwargs)
    with pytest.raises(InvalidParameterError, match="direction_angle"):
        support_function_lp(support.polygon, GRID, float("nan"))
    with pytest.raises(InvalidParameterError, match="polygon"):
        support_function_lp([(0, 0), (1, 0), (0, 1)], GRID, 0.0)
    with pytest.raises(InvalidParameterError, match="params"):
        support_function_lp(support.polygon, {"mass": 72.0}, 0.0)


# --- The planar model, written out -------------------------------------------------------------


def model(p, yaw):
    """Ẋ = A X + B U for X = (x, y, θp, θr, ẋ, ẏ, θ̇p, θ̇r), U = (px, py, τp, τr).

    r̈ = ω² (r − p − (τp e_p + τr e_r) / (m g)), I θ̈ = τ per axis (Eqs. 6, 7 per body axis).
    """
    w2 = p.omega**2
    e_p = np.array([math.cos(yaw), math.sin(yaw)])
    e_r = np.array([-math.sin(yaw), math.cos(yaw)])
    a = np.zeros((8, 8))
    a[0:4, 4:8] = np.eye(4)
    a[4:6, 0:2] = w2 * np.eye(2)
    b = np.zeros((8, 4))
    b[4:6, 0:2] = -w2 * np.eye(2)
    b[4:6, 2] = -w2 / p.weight * e_p
    b[4:6, 3] = -w2 / p.weight * e_r
    b[6, 2] = 1.0 / p.flywheel_inertia
    b[7, 3] = 1.0 / p.flywheel_inertia_roll
    return a, b


def exact_step(a, b, h):
    """Transition (Φ, Γ) over h with the input held: exp of the augmented matrix."""
    m = np.zeros((12, 12))
    m[:8, :8], m[:8, 8:] = a, b
    e = expm(m * h)
    return e[:8, :8], e[:8, 8:]


def apply(step, state, u):
    return step[0] @ state + step[1] @ u


def test_package_model_matches_equations_of_motion():
    # models.flywheel.plane (used by the LP) against the equations written out above.
    for yaw in (0.0, 0.4, -2.0):
        a, b = model(GRID, yaw)
        pa, pb = plane_continuous(GRID, yaw)
        assert np.array_equal(pa, a) and np.allclose(pb, b, rtol=1e-15, atol=0)
        phi, gamma = exact_step(a, b, 0.013)
        da, db = plane_discrete(GRID, 0.013, yaw)
        assert np.allclose(da, phi, rtol=1e-12, atol=1e-15)
        assert np.allclose(db, gamma, rtol=1e-10, atol=1e-15)


# --- Bang-bang simulations just inside and just outside ----------------------------------------

SIM = load_params(
    overrides={
        "foot_polygon": [
            (-0.05, -0.035),
            (0.08, -0.05),
            (0.15, -0.02),
            (0.15, 0.025),
            (0.09, 0.05),
            (-0.05, 0.035),
        ],
        "torque_max_roll": 60.0,
        "flywheel_inertia_roll": 6.0,
        "flywheel_angle_max_roll": 0.8,
    }
)
SIM_CASES = {
    "single-left": lambda: Support.from_params(SIM, "left", left=FootPose(0.0, 0.1, 0.25)),
    "double": lambda: Support.from_params(SIM, "double", **TOED_OUT),
}
TICK = 0.01  # control period of the capture-point feedback [s]
GAIN = 2.0  # capture-point feedback gain: ξ contracts by 1 − (e^{ω tick} − 1) k per tick
SETTLE = 8.0  # feedback time [s]: ~2.5 s to leave P's edge (room grows as e^{ωt}), then e^{−ωt}


def boundary(support, angle):
    """Point of the claimed region's boundary on the ray from P's centroid, and its normal.

    Checks that ξ ∓ ε n are ε inside / outside the claimed region (not near a corner).
    """
    region = cmp_polygon(support, SIM)
    origin = np.array(support.polygon.centroid)
    point = origin + region.ray_distance(*origin, angle) * unit(angle)
    edge = np.argmin(np.abs(region.offsets - region.normals @ point))
    normal = region.normals[edge]
    for side in (1.0, -1.0):
        depth = float(region.signed_distance(*(point - side * EPS * normal)))
        assert depth == pytest.approx(side * EPS, abs=1e-12), "too near a corner"
    return origin, point, normal


def half_period(c, tau, p):
    """T with (τ/mg)(1 − e^{−ωT})² = |c|: the bang-bang's contribution to ω∫e^{−ωs} c ds."""
    ratio = abs(c) * p.weight / tau
    assert ratio < 1.0
    return -math.log(1.0 - math.sqrt(ratio)) / p.omega


def bang_bang(t, half, sign, tau):
    if t < half:
        return sign * tau
    if t < 2 * half:
        return -sign * tau
    return 0.0


def segment_peak(state, torque, length):
    """max |θ| of each axis over a segment: θ is a parabola (θ0, θ̇0, τ/I), checked exactly."""
    peaks = []
    for j, inertia in enumerate((SIM.flywheel_inertia, SIM.flywheel_inertia_roll)):
        theta, rate, acc = state[2 + j], state[6 + j], torque[j] / inertia
        times = [0.0, length]
        if acc != 0.0 and 0.0 < -rate / acc < length:
            times.append(-rate / acc)
        peaks.append(max(abs(theta + rate * t + 0.5 * acc * t * t) for t in times))
    return np.array(peaks)


def run_open_loop(support, xi0, cop, profiles, duration):
    """Exact propagation with a constant CoP and bang-bang torques; returns states and |θ| peak.

    The CoM starts at rest over P's centroid and is pushed to the capture point ``xi0``;
    ``profiles`` are (half period, sign, τmax) of the pitch and roll axes.
    """
    a, b = model(SIM, support.yaw)
    origin = np.array(support.polygon.centroid)
    state = np.zeros(8)
    state[0:2], state[4:6] = origin, SIM.omega * (xi0 - origin)
    breaks = sorted({0.0, duration} | {t for half, _, _ in profiles for t in (half, 2 * half)})
    breaks = [t for t in breaks if t <= duration]
    peak = np.zeros(2)
    for start, end in itertools.pairwise(breaks):
        torque = [bang_bang(0.5 * (start + end), *profile) for profile in profiles]
        peak = np.maximum(peak, segment_peak(state, torque, end - start))
        state = apply(exact_step(a, b, end - start), state, np.concatenate([cop, torque]))
    return state, peak


def settle(support, states):
    """Capture-point feedback on the CoP, clipped to P, flywheels held: many runs at once.

    Each tick, p = ξ + k (ξ − g) with g P's centroid, pulled back along the segment from ξ
    until it lies in P (ξ itself must be in P). Returns the final states (runs, 8).
    """
    poly = support.polygon
    a, b = model(SIM, support.yaw)
    phi, gamma = exact_step(a, b, TICK)
    target = np.array(poly.centroid)
    states = np.array(states)
    for _ in range(round(SETTLE / TICK)):
        xi = states[:, 0:2] + states[:, 4:6] / SIM.omega
        room = poly.offsets[None, :] - xi @ poly.normals.T
        assert room.min() > 0.0  # ξ inside P: CoP balancing has authority
        push = GAIN * (xi - target)
        rate = push @ poly.normals.T
        with np.errstate(divide="ignore"):
            ratio = np.where(rate > 0.0, room / np.where(rate > 0.0, rate, 1.0), np.inf)
        cop = xi + np.minimum(1.0, ratio.min(axis=1))[:, None] * push
        assert (cop @ poly.normals.T - poly.offsets).max() <= 1e-12  # admissible CoP
        inputs = np.hstack([cop, np.zeros_like(cop)])
        states = states @ phi.T + inputs @ gamma.T
    return states


def decompose(support, xi0):
    """ξ0 = q + c_p e_p + c_r e_r with q deepest inside P and c inside the claimed box (LP)."""
    poly = support.polygon
    half = (cmp_offset(SIM), cmp_offset_roll(SIM))
    e = np.array(
        [
            [math.cos(support.yaw), -math.sin(support.yaw)],
            [math.sin(support.yaw), math.cos(support.yaw)],
        ]
    )
    # Variables (q_x, q_y, c_p, c_r, s): max s with n_i·q + s ≤ b_i, |c_j| + s ≤ a_j.
    rows = [np.concatenate([n, [0.0, 0.0, 1.0]]) for n in poly.normals]
    rhs = list(poly.offsets)
    for j in (0, 1):
        for sign in (1.0, -1.0):
            row = np.zeros(5)
            row[2 + j], row[4] = sign, 1.0
            rows.append(row)
            rhs.append(half[j])
    a_eq = np.hstack([np.eye(2), e, np.zeros((2, 1))])
    result = linprog(
        [0, 0, 0, 0, -1.0],
        A_ub=np.array(rows),
        b_ub=rhs,
        A_eq=a_eq,
        b_eq=xi0,
        bounds=[(None, None)] * 4 + [(None, 1.0)],
        method="highs",
    )
    assert result.status == 0
    q, c, s = result.x[0:2], result.x[2:4], result.x[4]
    return q, c, s


@pytest.mark.parametrize("case", sorted(SIM_CASES))
def test_just_inside_a_witness_recovers(case):
    # ξ0 = q + c_p e_p + c_r e_r with q in P and |c_j| < a_j (the claimed box): hold the CoP at
    # q and drive each flywheel bang-bang for the T_j < T_max whose integral is c_j; at
    # max 2 T_j the capture point is at q, then capture-point feedback brings the CoM to rest.
    support = SIM_CASES[case]()
    axes = axes_of(SIM)
    limits = np.array([angle_max for _, _, angle_max in axes])
    spun_states, pushes = [], []
    for angle in ANGLES:
        origin, point, normal = boundary(support, angle)
        xi0 = point - EPS * normal
        q, c, slack = decompose(support, xi0)
        assert slack > 0.0  # q strictly inside P and c strictly inside the box
        profiles = [
            (half_period(cj, tau, SIM), math.copysign(1.0, cj), tau)
            for cj, (tau, _, _) in zip(c, axes, strict=True)
        ]
        for (half, _, _), (tau, inertia, angle_max) in zip(profiles, axes, strict=True):
            assert half < spin_up(tau, inertia, angle_max)
        spun = max(2 * half for half, _, _ in profiles)
        state, peak = run_open_loop(support, xi0, q, profiles, spun)
        assert np.all(peak <= limits)  # joint limits, checked exactly over every segment
        assert np.abs(state[6:8]).max() < 1e-9  # both flywheels at rest
        xi = state[0:2] + state[4:6] / SIM.omega
        assert np.linalg.norm(xi - q) < 1e-9  # exact arithmetic: ξ(2T) = q; rounding only
        spun_states.append(state)
        pushes.append(np.linalg.norm(xi0 - origin) * SIM.omega)
    final = settle(support, spun_states)
    target = np.array(support.polygon.centroid)
    assert np.linalg.norm(final[:, 4:6], axis=1).max() < 1e-5  # at rest: 0.01 mm/s
    assert np.linalg.norm(final[:, 0:2] - target, axis=1).max() < 1e-5  # over P's centroid
    assert np.all(np.abs(final[:, 2:4]) <= limits)
    assert min(pushes) > 0.2  # real pushes, 0.2 m/s or more


@pytest.mark.parametrize("case", sorted(SIM_CASES))
def test_just_outside_the_best_controller_falls(case):
    support = SIM_CASES[case]()
    poly = support.polygon
    yaw = support.yaw
    body = np.array([[math.cos(yaw), math.sin(yaw)], [-math.sin(yaw), math.cos(yaw)]])
    axes = axes_of(SIM)
    for angle in ANGLES:
        _, point, normal = boundary(support, angle)
        xi0 = point + EPS * normal
        corner = poly.vertices[np.argmax(poly.vertices @ normal)]  # P's support point in n
        signs = np.sign(body @ normal)
        profiles = [
            (spin_up(tau, inertia, angle_max), sign, tau)
            for sign, (tau, inertia, angle_max) in zip(signs, axes, strict=True)
        ]
        spun = max(2 * half for half, _, _ in profiles)
        state, peak = run_open_loop(support, xi0, corner, profiles, spun)
        assert np.all(peak <= [angle_max * (1 + 1e-12) for _, _, angle_max in axes])
        ahead = normal @ (state[0:2] + state[4:6] / SIM.omega) - normal @ corner
        # n·ξ − h_P(n) = e^{ωt} (ε + h_C(n) − h_P(n) − Σ|n_j| a_j) = e^{ωt} ε if the box is
        # right: positive, so ξ has left P's half-plane for good. rel 1e-6: rounding of
        # O(0.1 m) positions (1e-17 m) against e^{ωt} ε ≈ 7e-4 m; a box off by 1e-9 m fails.
        assert ahead == pytest.approx(EPS * math.exp(SIM.omega * spun), rel=1e-6)
        # Flywheels spent, CoP at the edge: n·ξ − h_P(n) grows as e^{ωt}; the CoM falls.
        late, _ = run_open_loop(support, xi0, corner, profiles, 4.0)
        late_ahead = normal @ (late[0:2] + late[4:6] / SIM.omega) - normal @ corner
        assert late_ahead == pytest.approx(ahead * math.exp(SIM.omega * (4.0 - spun)), rel=1e-6)
        assert normal @ late[0:2] - normal @ corner > 1.0  # CoM a metre past the foot's edge
