"""Capture regions of one and several steps against exact programs and simulation.

Ground truth: the N-step viability LP (surfaces.capture.lp.steps: CoP, foothold and flywheel
torque sequences with the touchdowns fixed on its grid), a 1-D LP for the point and disc feet
of Koolen et al. (2012), and closed-loop simulations of the LIPM following a plan.
"""

import math

import numpy as np
import pytest
from scipy.optimize import linprog

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground import FootPose, Support
from pushrecovery.ground.minkowski import minkowski_sum, regular_polygon
from pushrecovery.surfaces.capture.lp.steps import step_lp
from pushrecovery.surfaces.capture.plan import capture_plan
from pushrecovery.surfaces.capture.region import capture_region
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.n_step import (
    capturability_distance,
    default_max_steps,
    landing_foot,
    step_options,
    viable_region,
)

# The closed forms and the LP compute the same O(1 m) quantities through different sums
# (a few dozen terms): agreement within 1e-9 m leaves room for rounding only.
EXACT = 1e-9
DIRECTIONS = np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False) + 0.1

# T_max = sqrt(I θmax / τmax) = 0.3 s on the LP's 0.05 s grid (pitch 9 kg m², roll 4.5 kg m²
# at half the torque): the bang-bang flywheel is on the grid, so the LP reaches the supremum.
ON_GRID = {"flywheel_inertia": 9.0, "torque_max_roll": 50.0, "flywheel_inertia_roll": 4.5}
NO_HIP = {"torque_max": 0.0, "torque_max_roll": 0.0}


def support_value(polygon, angle):
    return float((polygon.vertices @ np.array([math.cos(angle), math.sin(angle)])).max())


def touchdowns(params, steps, first=None):
    start = params.min_step_time if first is None else first
    return tuple(round(start + params.min_step_time * k, 12) for k in range(steps))


@pytest.mark.parametrize("stance", ["left", "right", "double"])
@pytest.mark.parametrize("steps", [0, 1, 2, 3])
def test_n_step_regions_equal_the_lp_without_hip(stance, steps):
    params = load_params(overrides={**NO_HIP, "min_step_width": 0.05})
    support = Support.from_params(params, stance, left=FootPose(0.02, 0.11, 0.2))
    for option in step_options(params, support):
        times = touchdowns(params, steps)
        region = viable_region(params, option, times, hip=False)
        for angle in DIRECTIONS:
            lp = step_lp(params, option, times, angle, tail=0.3 if steps == 0 else 0.0)
            assert support_value(region, angle) == pytest.approx(lp.value, abs=EXACT)


@pytest.mark.parametrize("steps", [0, 1, 2])
def test_n_step_regions_with_the_hip_equal_the_lp(steps):
    # The flywheel manoeuvre (0.6 s) outlasts the first touchdown (0.3 s): the LP lets it
    # run through the touchdowns, and (S1) keeps the whole box H: they agree, so the hip is
    # not cut at the first step.
    params = load_params(overrides=ON_GRID)
    support = Support.from_params(params, "left")
    option = step_options(params, support)[0]
    times = touchdowns(params, steps)
    region = viable_region(params, option, times)
    without = viable_region(params, option, times, hip=False)
    for angle in DIRECTIONS[::2]:
        lp = step_lp(params, option, times, angle, tail=0.6, hip=True)
        assert support_value(region, angle) == pytest.approx(lp.value, abs=EXACT)
        assert support_value(region, angle) > support_value(without, angle) + 0.02


@pytest.mark.parametrize("steps", [1, 2])
@pytest.mark.parametrize(
    "state", [(0.0, 0.0, 1.5, -0.3), (0.05, 0.02, 1.0, 0.8), (-0.02, 0.05, -1.1, -0.4)]
)
def test_foothold_regions_equal_the_lp(state, steps):
    params = load_params(overrides=ON_GRID)
    support = Support.from_params(params, "left")
    option = step_options(params, support)[0]
    x, y, xdot, ydot = state
    xi = (x + xdot / params.omega, y + ydot / params.omega)
    for swing_time in (0.3, 0.45):
        region = capture_region(*state, params, support, swing_time, steps=steps)
        times = touchdowns(params, steps, first=swing_time)
        if region.polygon is None:  # too late for one step: no foothold at all
            with pytest.raises(InvalidParameterError, match="infeasible"):
                step_lp(params, option, times, 0.0, tail=0.6, hip=True, capture_point=xi)
            continue
        for angle in DIRECTIONS[::3]:
            lp = step_lp(params, option, times, angle, tail=0.6, hip=True, capture_point=xi)
            assert support_value(region.polygon, angle) == pytest.approx(lp.value, abs=EXACT)
        # The recommended foothold is the deepest point: every edge is at least as far.
        depth = float(region.polygon.signed_distance(*region.foothold))
        assert depth > 0.0
        assert np.all(
            region.polygon.offsets - region.polygon.normals @ region.foothold >= depth - 1e-9
        )


def test_footholds_for_a_later_touchdown_are_the_union_over_touchdown_times():
    params = load_params()
    support = Support.from_params(params, "right")
    state = (0.0, -0.1, 0.9, 0.2)
    after = capture_region(*state, params, support, 0.2, timing="after")
    exact = [
        capture_region(*state, params, support, t, timing="exact")
        for t in np.linspace(0.2, 1.2, 201)
    ]
    polygons = [r.polygon for r in exact if r.polygon is not None]
    assert after.area > max(p.area for p in polygons) + 1e-3  # strictly more than any one time
    for polygon in polygons[::20]:  # each exact region lies in the union
        corners = polygon.vertices + 1e-9 * (polygon.centroid - polygon.vertices)
        assert np.all(after.polygon.signed_distance(corners[:, 0], corners[:, 1]) > -1e-9)
    # ... and every foothold of the union is captured by some touchdown time (on a fine grid).
    samples = after.polygon.vertices[:, None, :] * 0.98 + 0.02 * np.array(after.polygon.centroid)
    for q in samples[:, 0, :]:
        best = max(float(p.signed_distance(*q)) for p in polygons)
        assert best > -2e-3  # the grid of times is 5 ms: the union's edge moves < 2 mm


def test_a_captured_state_may_step_anywhere_later():
    params = load_params()
    support = Support.from_params(params, "left")
    region = capture_region(0.0, 0.1, 0.05, 0.0, params, support, 0.3, timing="after")
    window = regular_polygon(params.max_step_length, 64, (0.0, 0.1))
    assert region.area == pytest.approx(window.area, rel=1e-12)


def simulate(params, plan, xi0, horizon=4.0):
    """LIPM capture point under the plan's CoPs, held phase by phase (exact exponentials)."""
    xi = np.array(xi0, dtype=float)
    times = [*plan.touchdowns, horizon]
    start = 0.0
    for cop, end in zip(plan.cops, times, strict=True):
        xi = cop + (xi - cop) * math.exp(params.omega * (end - start))
        start = end
    return xi


@pytest.mark.parametrize("steps", [1, 2, 3])
def test_plans_capture_just_inside_and_nothing_captures_just_outside(steps):
    params = load_params(overrides=NO_HIP)
    support = Support.from_params(params, "left")
    option = step_options(params, support)[0]
    times = touchdowns(params, steps)
    region = viable_region(params, option, times, hip=False)
    for angle in DIRECTIONS[::1]:
        d = np.array([math.cos(angle), math.sin(angle)])
        reach = region.ray_distance(*option.ankle, angle)
        inside = option.ankle + 0.999 * reach * d
        plan = capture_plan(inside, params, option, steps, hip=False)
        assert plan.margin > 0.0
        end = simulate(params, plan, inside)
        np.testing.assert_allclose(end, plan.cops[-1], atol=1e-6)  # at rest over the CoP
        last = landing_foot(params, plan.swings[-1], option.yaw).transformed(*plan.footholds[-1], 0)
        assert float(last.signed_distance(*plan.cops[-1])) >= -1e-12  # rest on the last foot
        gaps = np.diff(np.vstack([option.ankle, plan.footholds]), axis=0)
        assert np.all(np.hypot(gaps[:, 0], gaps[:, 1]) <= params.max_step_length + 1e-12)
        assert np.all(np.diff(plan.touchdowns) >= params.min_step_time - 1e-12)
        outside = option.ankle + 1.001 * reach * d
        assert capture_plan(outside, params, option, steps, hip=False).margin < 0.0
        assert (
            np.linalg.norm(
                simulate(params, capture_plan(outside, params, option, steps, hip=False), outside)
            )
            > 1.0
        )
        with pytest.raises(InvalidParameterError, match="infeasible"):
            step_lp(params, option, times, angle, capture_point=tuple(outside))


def one_d_lp(steps, omega, step_time, reach, radius):
    """max ξ0 over N steps on a line: CoP in [−r, r] about each ankle, steps within ±l."""
    dt = step_time
    m = steps  # one CoP per phase (the LP of a line, phases of Δt_s)
    # Variables: ξ0, p_0..p_N (CoPs per phase, relative to the ankle), r_1..r_N (steps).
    size = 1 + (m + 1) + m
    a = [math.exp(-omega * dt * (k + 1)) for k in range(m)] + [0.0]
    # ξ0 = (1 − a1) p_0 + Σ (a_k − a_{k+1})(q_k + p_k), q_k = Σ_{j≤k} r_j.
    eq = np.zeros(size)
    eq[0] = 1.0
    eq[1] = -(1.0 - a[0])
    for k in range(1, m + 1):
        eq[1 + k] = -(a[k - 1] - a[k])
        for j in range(1, k + 1):
            eq[1 + m + j] -= a[k - 1] - a[k]
    bounds = [(None, None)] + [(-radius, radius)] * (m + 1) + [(-reach, reach)] * m
    cost = np.zeros(size)
    cost[0] = -1.0
    result = linprog(cost, A_eq=eq[None, :], b_eq=[0.0], bounds=bounds, method="highs")
    return -result.fun


@pytest.mark.parametrize("radius", [0.0, 0.07])
@pytest.mark.parametrize("step_time", [0.15, 0.3, 0.5])
def test_koolen_distances_equal_the_line_lp(radius, step_time):
    omega, reach = 3.13, 0.8
    previous = capturability_distance(0, omega, step_time, reach, radius)
    assert previous == radius
    for steps in range(1, 7):
        closed = capturability_distance(steps, omega, step_time, reach, radius)
        assert closed == pytest.approx(one_d_lp(steps, omega, step_time, reach, radius), abs=EXACT)
        beta = math.exp(-omega * step_time)
        assert closed == pytest.approx((previous - radius + reach) * beta + radius, abs=1e-15)
        previous = closed
    limit = capturability_distance(math.inf, omega, step_time, reach, radius)
    assert limit == pytest.approx(capturability_distance(400, omega, step_time, reach, radius))


def test_polygon_regions_reduce_to_koolen_along_an_axis():
    # Nearly point feet (1.2 mm squares: the smallest foot accepted is 1 mm²), a disc reach:
    # the regions' support along +x is Koolen's d_N with r the half side.
    half = 0.6e-3
    square = [[-half, -half], [half, -half], [half, half], [-half, half]]
    params = load_params(overrides={**NO_HIP, "foot_polygon": square})
    support = Support.from_params(params, "left", left=FootPose(0.0, 0.0))
    option = step_options(params, support)[0]
    for steps in range(1, 5):
        region = viable_region(params, option, touchdowns(params, steps), hip=False)
        closed = capturability_distance(
            steps, params.omega, params.min_step_time, params.max_step_length, half
        )
        assert support_value(region, 0.0) == pytest.approx(closed, abs=EXACT)


def test_default_max_steps_is_where_growth_stops():
    params = load_params()
    steps = default_max_steps(params)
    assert steps == params.max_steps
    support = Support.from_params(params, "left")
    option = step_options(params, support)[0]
    regions = [viable_region(params, option, touchdowns(params, n)) for n in (steps, steps + 1)]
    previous = regions[0]
    growth = max(support_value(regions[1], a) - support_value(previous, a) for a in DIRECTIONS)
    assert growth < 1e-3
    before = viable_region(params, option, touchdowns(params, steps - 1))
    assert max(support_value(previous, a) - support_value(before, a) for a in DIRECTIONS) > 5e-4
    assert load_params(overrides={"min_step_time": 0.0}).max_steps == 1


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"min_step_time": -0.1}, "min_step_time must be in"),
        ({"min_step_time": float("nan")}, "min_step_time"),
        ({"min_step_time": 6.0}, "min_step_time must be in"),
        ({"max_steps": 0}, "max_steps must be in"),
        ({"max_steps": 2.5}, "max_steps must be a whole number"),
        ({"max_steps": 51}, "max_steps must be in"),
        ({"min_step_width": -0.01}, "min_step_width must be in"),
        ({"min_step_width": 5.0}, "min_step_width must be in"),
    ],
)
def test_bad_step_parameters_are_refused(overrides, match):
    with pytest.raises(InvalidParameterError, match=match):
        load_params(overrides=overrides)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"swing_time": -0.1}, "swing_time must be in"),
        ({"swing_time": float("inf")}, "swing_time"),
        ({"steps": 0}, "steps must be"),
        ({"steps": 1.5}, "steps must be"),
        ({"timing": "later"}, "timing must be"),
        ({"swing": "double"}, "swing must be"),
        ({"swing": "left"}, "swing must be the free foot"),
        ({"swing": ["right"]}, "swing must be 'left' or 'right'"),
        ({"swing": 3}, "swing must be 'left' or 'right'"),
    ],
)
def test_bad_region_arguments_are_refused(kwargs, match):
    params = load_params()
    support = Support.from_params(params, "left")
    with pytest.raises(InvalidParameterError, match=match):
        capture_region(0.0, 0.0, 1.0, 0.0, params, support, **kwargs)


def test_bad_states_are_refused():
    params = load_params()
    support = Support.from_params(params)
    with pytest.raises(InvalidParameterError, match="xdot"):
        capture_region(0.0, 0.0, float("nan"), 0.0, params, support)
    with pytest.raises(InvalidParameterError, match="x must be in"):
        capture_region(1e9, 0.0, 0.0, 0.0, params, support)


def test_minkowski_sums_are_exact():
    square = regular_polygon(1.0, 4, phase=math.pi / 4)
    triangle = regular_polygon(0.5, 3)
    total = minkowski_sum([(2.0, square), (-1.0, triangle)], (0.3, -0.2))
    for angle in DIRECTIONS:
        expected = (
            2.0 * support_value(square, angle)
            + support_value(regular_polygon(0.5, 3, phase=math.pi), angle)
            + 0.3 * math.cos(angle)
            - 0.2 * math.sin(angle)
        )
        assert support_value(total, angle) == pytest.approx(expected, abs=1e-12)
    assert len(total.vertices) == 6  # 4 + 3 edges, one pair parallel


def test_the_impact_at_a_symmetric_touchdown_is_sec4s():
    # Legs at ±θ about the CoM (stance ankle a = 0, CoM at L tan θ, new foot at 2 L tan θ), the
    # velocity perpendicular to the stance leg: Eqs. (18)-(20) give v⁺ = l θ̇ cos 2θ / cos θ.
    from pushrecovery.ground.support import Stance
    from pushrecovery.models.stepping import impact_velocities
    from pushrecovery.surfaces.capture.plan import CapturePlan
    from pushrecovery.surfaces.step.impact import plan_impacts

    params = load_params(overrides={"min_step_time": 0.0})
    height = params.com_height
    for theta in (0.1, 0.3, 0.6):
        leg = height / math.cos(theta)
        rate = 1.7
        before, _, after = impact_velocities(theta, rate, leg)
        com = height * math.tan(theta)
        plan = CapturePlan(
            1,
            (Stance.LEFT,),
            np.array([[2.0 * com, 0.0]]),
            np.array([0.0]),  # touchdown now: the state is the touchdown state
            np.zeros((2, 2)),
            np.zeros(2),
            0.0,
        )
        (impact,) = plan_impacts(plan, (com, 0.0), (float(before), 0.0), params)
        assert impact.speed_ratio * float(before) == pytest.approx(float(after), rel=1e-12)
        omega = params.omega
        assert impact.capture_point_impact[0] == pytest.approx(com + float(after) / omega)


def test_plans_keep_positive_margins_at_every_touchdown():
    # The plan's CoPs (and the hip's share as a CMP offset until the first touchdown) carry the
    # LIPM into each landing foot's remaining capture region: every touchdown margin >= 0.
    for xdot in (1.2, 2.0, 2.8, 3.6):
        found = classify(0.0, xdot, load_params())
        plan = found.to_dict()["plan"]
        assert all(i["margin"] >= -1e-9 for i in plan["impact"]), xdot
        assert len(plan["impact"]) == found.steps


def test_ray_distances_from_the_support_function_equal_the_polygon():
    # bounds measures the thresholds from (S2) without building C_N: the same distances.
    from pushrecovery.surfaces.n_step import _ray_distances

    headings = np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)
    for overrides in ({}, {"min_step_width": 0.05}, {"torque_max_roll": 0.0}, NO_HIP):
        params = load_params(overrides=overrides)
        support = Support.from_params(params, "double", left=FootPose(0.02, 0.11, 0.2))
        for option in step_options(params, support):
            for steps in (0, 1, 3):
                times = touchdowns(params, steps)
                region = viable_region(params, option, times)
                fast = _ray_distances(params, option, times, support.ankle, headings)
                inside = float(region.signed_distance(*support.ankle)) > 0.0
                for heading, value in zip(headings, fast, strict=True):
                    exact = region.ray_distance(*support.ankle, heading) if inside else 0.0
                    assert value == pytest.approx(exact, abs=1e-12)


def test_minkowski_sums_with_a_point_term_keep_every_vertex():
    # A point adds no edge; a vertex repeated by the sum must not take its twin with it.
    square = regular_polygon(0.1, 4, centre=(0.3, 0.8), phase=0.4)
    total = minkowski_sum([(1.9, np.array([[0.2, -0.1]])), (0.9, square)])
    assert len(total.vertices) == 4
    for angle in DIRECTIONS:
        d = np.array([math.cos(angle), math.sin(angle)])
        expected = 1.9 * (d @ [0.2, -0.1]) + 0.9 * support_value(square, angle)
        assert support_value(total, angle) == pytest.approx(expected, abs=1e-12)


def test_the_compiled_chebyshev_centre_equals_highs():
    # The dual simplex behind the recommended foothold against scipy's HiGHS on random hulls.
    from pushrecovery.ground import convex_hull
    from pushrecovery.kernels.polygons import chebyshev_centre

    rng = np.random.default_rng(7)
    solved = 0
    for _ in range(400):
        points = rng.normal(size=(int(rng.integers(3, 60)), 2)) * rng.uniform(0.05, 2.0, 2)
        try:
            polygon = convex_hull(points)
        except InvalidParameterError:
            continue
        qx, qy, radius, ok = chebyshev_centre(polygon.normals, polygon.offsets)
        a_ub = np.column_stack([polygon.normals, np.ones(len(polygon.offsets))])
        bounds = [(None, None), (None, None), (0.0, None)]
        exact = linprog([0.0, 0.0, -1.0], A_ub=a_ub, b_ub=polygon.offsets, bounds=bounds)
        assert ok and radius == pytest.approx(exact.x[2], abs=1e-10)
        slack = polygon.offsets - polygon.normals @ [qx, qy]
        assert slack.min() == pytest.approx(radius, abs=1e-10)  # a largest disc, inside
        solved += 1
    assert solved > 350


def test_the_compiled_decomposition_and_sum_equal_numpys():
    # The plan's compiled twins (kernels.polygons) against ground.minkowski on random sums.
    from pushrecovery.ground import convex_hull
    from pushrecovery.ground.minkowski import decompose, stacked_shapes
    from pushrecovery.kernels.polygons import decompose_loop, minkowski_loop

    rng = np.random.default_rng(5)
    for _ in range(100):
        terms = [
            (float(rng.uniform(0.0, 2.0)), convex_hull(rng.normal(size=(8, 2)))) for _ in range(3)
        ]
        terms.append((float(rng.uniform(0.1, 2.0)), np.array([[0.3, -0.2]])))
        offset = rng.normal(size=2)
        total = minkowski_sum(terms, offset)
        stacked, counts, weights = stacked_shapes(terms)
        loop = minkowski_loop(stacked, counts, weights, offset)
        np.testing.assert_allclose(loop, total.vertices, atol=1e-12)
        point = total.centroid + rng.uniform(-1.0, 1.0, 2) * 0.5
        expected, share = decompose(point, terms, offset, total)
        found, found_share = decompose_loop(
            np.asarray(point), stacked, counts, weights, offset, loop
        )
        assert found_share == pytest.approx(share, rel=1e-12)
        np.testing.assert_allclose(found, np.array(expected), atol=1e-12)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda p, o: capture_plan(np.array([0.5, 0.0]), p, o, 0), "steps must be"),
        (lambda p, o: capture_plan(np.array([0.5, 0.0]), p, o, 2.0), "steps must be"),
        (
            lambda p, o: capture_plan(np.array([0.5, 0.0]), p, o, 1, first_touchdown=math.nan),
            "first_touchdown",
        ),
        (lambda p, o: viable_region(p, o, (0.3, 0.35)), "sooner than min_step_time"),
        (lambda p, o: viable_region(p, o, (math.inf,)), "touchdown"),
    ],
)
def test_bad_plan_and_region_arguments_are_refused(call, match):
    params = load_params()
    option = step_options(params, Support.from_params(params, "left"))[0]
    with pytest.raises(InvalidParameterError, match=match):
        call(params, option)


def test_line_steps_all_levels_at_once_equal_level_by_level(monkeypatch):
    # Small inputs test every N at once; large ones loop over N: the same numbers.
    from pushrecovery.surfaces.step import regions as step_regions

    P = load_params()
    rng = np.random.default_rng(11)
    capture = rng.normal(0.0, 1.5, 3000)
    ankle = rng.normal(0.0, 0.05, 3000)
    at_once = step_regions.line_steps(capture, P.heel, P.toe, ankle, P)
    monkeypatch.setattr(step_regions, "_LEVELS_AT_ONCE", 0)
    one_by_one = step_regions.line_steps(capture, P.heel, P.toe, ankle, P)
    for name in ("steps", "margin", "step_length", "shortest", "longest"):
        np.testing.assert_array_equal(getattr(at_once, name), getattr(one_by_one, name))
    assert set(np.unique(at_once.steps)) >= {0, 1, 2, 3}
