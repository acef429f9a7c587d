"""Single-state paths (issue 32) against the full ones they stand for, to the bit.

classify's verdict on floats (sagittal) and in one compiled call (plane) against the
vectorised verdicts and the polygons' numpy signed distances; its step, plan and impacts, built
on first read, against the functions that build them; the compiled single-point distance
against ConvexPolygon.signed_distance; plan_impacts on floats against its 2-vector form;
capture_region's lazily built polygon and per-touchdown terms against a build from scratch.
No timings here (benchmarks/plane.py and benchmarks/steps.py measure them).
"""

import dataclasses
import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground import FootPose, Support
from pushrecovery.ground.minkowski import stacked_shapes
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.kernels.polygons import minkowski_loop
from pushrecovery.kernels.single_margins import edge_rows, signed_distance
from pushrecovery.surfaces.capture.plan import plan_loads
from pushrecovery.surfaces.capture.region import (
    ORIGIN,
    _region_loop,
    capture_region,
    step_terms,
)
from pushrecovery.surfaces.classify import Strategy, classify
from pushrecovery.surfaces.cop import capture_point
from pushrecovery.surfaces.n_step import hip_box, landing_viable, reach_polygon, step_options
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.step.impact import plan_impacts
from pushrecovery.surfaces.step.regions import StepRegions, _sagittal_plan, line_steps
from pushrecovery.surfaces.verdicts import sagittal_verdict, sagittal_verdicts


def _states(n: int, seed: int) -> list[list[float]]:
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [
            rng.normal(0.05, 0.08, n),
            rng.normal(0.0, 0.08, n),
            rng.normal(0.0, 1.5, n),
            rng.normal(0.0, 1.5, n),
        ]
    ).tolist()


def _same(a: float, b: float) -> bool:
    """The same float to the bit (the sign of a zero included)."""
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


def _supports(params):
    yawed = FootPose(0.05, 0.11, 0.17)
    return [
        Support.from_params(params),
        Support.from_params(params, "left"),
        Support.from_params(params, "right", right=FootPose(0.0, -0.1, -0.2)),
        Support.from_params(params, "double", left=yawed, right=FootPose(-0.03, -0.1, -0.1)),
    ]


def test_the_sagittal_verdict_on_floats_is_the_vectorised_one(params):
    states = _states(400, 1)
    x, xdot = np.array([s[0] for s in states]), np.array([s[2] for s in states])
    full = sagittal_verdicts(x, xdot, params)
    strategies = set()
    for k in range(len(x)):
        one = sagittal_verdict(x[k], xdot[k], params)
        assert _same(one.capture_point, float(full.capture_point[k]))
        assert _same(one.cop_margin, float(full.cop_margin[k]))
        assert _same(one.cmp_margin, float(full.cmp_margin[k]))
        assert _same(one.step_margin, float(full.line.margin[k]))
        assert one.steps == int(full.line.steps[k])
        assert one.strategy is full.strategies[k]
        strategies.add(one.strategy)
    assert strategies == set(Strategy)


def test_sagittal_classify_builds_the_plan_the_full_functions_build(params):
    for x, _, xdot, _ in _states(120, 2):
        found = classify(x, xdot, params)
        if found.strategy is not Strategy.STEP:
            assert found.plan is None and found.step is None and found.impacts == ()
            continue
        assert found.steps is not None
        plan = _sagittal_plan(found.capture_point, params, found.steps)
        loads = plan_loads(plan, params, (x, 0.0), (xdot, 0.0))
        assert repr(found.plan) == repr(dataclasses.replace(plan, loads=loads))
        line = line_steps(np.array([found.capture_point]), params.heel, params.toe, 0.0, params)
        assert found.step is not None
        low, high = found.step["step_length_range"]  # type: ignore[misc]
        assert _same(low, float(line.shortest[0])) and _same(high, float(line.longest[0]))
        impacts = plan_impacts(plan, (x, 0.0), (xdot, 0.0), params)
        assert found.impacts == tuple(impacts)
        assert found.plan is found.plan  # built once, then kept


def _octagon_sole():
    angles = 2.0 * np.pi * (np.arange(8) + 0.5) / 8
    sole = [(0.06 + 0.12 * math.cos(a), 0.05 * math.sin(a)) for a in angles]
    return {"foot_polygon": sole, "heel": None, "toe": None, "foot_width": None}


@pytest.mark.parametrize("sole", [{}, _octagon_sole()], ids=["rectangle", "octagon"])
def test_plane_classify_margins_are_the_polygons_distances(sole):
    params = load_params("paper", overrides={"mass": 48.0, "com_height": 0.78, **sole})
    for support in _supports(params):
        hip = cmp_polygon(support, params)
        regions = StepRegions.of(params, support)
        for x, y, xdot, ydot in _states(60, 3):
            found = classify(x, xdot, params, y=y, ydot=ydot, support=support)
            xi = (capture_point(x, xdot, params.omega), capture_point(y, ydot, params.omega))
            assert found.capture_point_xy == xi
            assert _same(found.margins["cop"], float(support.polygon.signed_distance(*xi)))
            assert _same(found.margins["cmp"], float(hip.signed_distance(*xi)))
            steps, margin = regions.locate(*xi)
            assert _same(found.margins["step"], margin)
            assert found.cmp_region == hip.to_list()
            if found.strategy is Strategy.STEP:
                assert found.steps == steps
                plan = regions.plan(*xi, steps)
                loads = plan_loads(plan, params, (x, y), (xdot, ydot))
                assert repr(found.plan) == repr(dataclasses.replace(plan, loads=loads))
                option = next(o for o in regions.options if o.swing is plan.swings[0])
                impacts = plan_impacts(plan, (x, y), (xdot, ydot), params, option.yaw)
                assert found.impacts == tuple(impacts)


def test_the_compiled_point_distance_is_numpys_to_the_bit():
    rng = np.random.default_rng(4)
    params = load_params()
    polygons = [s.polygon for s in _supports(params)]
    polygons += [cmp_polygon(s, params) for s in _supports(params)]
    polygons += list(StepRegions.of(params, _supports(params)[3]).polygons[:4])
    for polygon in polygons:
        rows = edge_rows(polygon.vertices, polygon.normals, polygon.offsets)
        points = rng.normal(0.0, 0.3, (300, 2))
        points[:20] = polygon.vertices[rng.integers(len(polygon.vertices), size=20)]
        points[20:30] = 1e300 * rng.normal(size=(10, 2))
        for px, py in points.tolist():
            assert _same(signed_distance(rows, px, py), float(polygon.signed_distance(px, py)))
        for px, py in ((math.nan, 0.0), (math.inf, 0.0), (0.0, -math.inf)):
            expected = float(polygon.signed_distance(px, py))
            found = signed_distance(rows, px, py)
            assert math.isnan(found) == math.isnan(expected)
            assert math.isnan(found) or found == expected


def _impacts_as_vectors(plan, position, velocity, params, yaw):
    """plan_impacts' 2-vector form: (time, com, velocity, ξ, ξ⁺, margins, speed ratio)."""
    omega, height = params.omega, params.com_height
    r, v = np.array(position, dtype=float), np.array(velocity, dtype=float)
    ankle, start, found = np.array(plan.ankle, dtype=float), 0.0, []
    first = math.exp(-omega * float(plan.touchdowns[0]))
    hip = plan.hip / (1.0 - first) if first < 1.0 else np.zeros(2)
    for k in range(plan.steps):
        t = float(plan.touchdowns[k])
        p = plan.cops[k] + (hip if k == 0 else 0.0)
        c, s = math.cosh(omega * (t - start)), math.sinh(omega * (t - start))
        r, v = p + (r - p) * c + v / omega * s, (r - p) * omega * s + v * c
        start, q = t, plan.footholds[k]
        after = v + (v @ (r - ankle)) / height**2 * (r - q)
        xi, xi_impact = capture_point(r, v, omega), capture_point(r, after, omega)
        remaining = landing_viable(params, plan.swings[k], yaw, plan.steps - 1 - k)
        region = remaining.transformed(float(q[0]), float(q[1]), 0.0)
        speed = float(np.hypot(*v))
        found.append(
            (
                t,
                tuple(r.tolist()),
                tuple(v.tolist()),
                tuple(xi.tolist()),
                tuple(xi_impact.tolist()),
                float(region.signed_distance(*xi)),
                float(region.signed_distance(*xi_impact)),
                float(np.hypot(*after)) / speed if speed > 0.0 else 1.0,
            )
        )
        ankle = np.array(q, dtype=float)
    return found


def test_plan_impacts_on_floats_are_the_vector_form(params):
    checked = 0
    for support in _supports(params):
        regions = StepRegions.of(params, support)
        for x, y, xdot, ydot in _states(40, 5):
            found = classify(x, xdot, params, y=y, ydot=ydot, support=support)
            if found.plan is None:
                continue
            for yaw in (0.0, 0.17):
                impacts = plan_impacts(found.plan, (x, y), (xdot, ydot), params, yaw)
                expected = _impacts_as_vectors(found.plan, (x, y), (xdot, ydot), params, yaw)
                assert repr([dataclasses.astuple(i) for i in impacts]) == repr(expected)
                checked += 1
        assert regions.polygons
    assert checked > 50


def test_capture_region_builds_its_polygon_on_first_read(params):
    support = _supports(params)[3]
    for x, y, xdot, ydot in _states(40, 6):
        region = capture_region(x, y, xdot, ydot, params, support)
        option = step_options(params, support, region.swing)[0]
        ankle = np.asarray(option.ankle, dtype=np.float64)
        key = (option.stance.vertices - ankle).tobytes()
        xi = np.array([x + xdot / params.omega, y + ydot / params.omega])  # as capture_region
        loop, foothold = _region_loop(xi, params, option, ankle, key, region.touchdown, 1, True)
        if loop is None:
            assert region.polygon is None and region.foothold is None and region.area == 0.0
            continue
        assert isinstance(loop, np.ndarray) and foothold is not None
        polygon = region.polygon
        assert polygon is not None and region.polygon is polygon  # built once, then kept
        built = ConvexPolygon._from_ccw(loop)
        for mine, theirs in zip(
            (polygon.vertices, polygon.normals, polygon.offsets),
            (built.vertices, built.normals, built.offsets),
            strict=True,
        ):
            assert np.array_equal(mine, theirs)
        assert region.foothold is not None and np.array_equal(region.foothold, foothold)


@pytest.mark.parametrize("hip", [True, False])
def test_step_terms_of_a_new_touchdown_equal_a_build_from_scratch(params, hip):
    option = step_options(params, Support.from_params(params, "left"))[0]
    key = (option.stance.vertices - np.asarray(option.ankle)).tobytes()
    stance = np.frombuffer(key).reshape(-1, 2)
    for touchdown in (0.0, 0.13, 0.2, 0.35):
        terms = step_terms(params, option.swing, option.yaw, 2, touchdown, hip, key)
        landing = landing_viable(params, option.swing, option.yaw, 1)
        box = hip_box(params, option.yaw) if hip else None
        scale = math.exp(params.omega * touchdown)
        foot = [(1.0 - scale, stance), (-1.0, landing)]
        if box is not None:
            foot.append((-scale, box))
        split = [(scale, box if box is not None else np.zeros((1, 2))), (scale - 1.0, stance)]
        split.append((1.0, landing))
        window = reach_polygon(params, option.swing, option.yaw)
        shapes, counts, weights = stacked_shapes(foot)
        split_shapes, split_counts, split_weights = stacked_shapes(split)
        total = minkowski_loop(split_shapes, split_counts, split_weights, ORIGIN)
        assert terms.scale == scale and terms.has_box is (box is not None)
        expected = (shapes, counts, weights, window.normals, window.offsets)
        expected += (split_shapes, split_counts, split_weights, total)
        found = (terms.foot_shapes, terms.foot_counts, terms.foot_weights, terms.window_normals)
        found += (terms.window_offsets, terms.split_shapes, terms.split_counts)
        found += (terms.split_weights, terms.split_total)
        for mine, theirs in zip(found, expected, strict=True):
            assert np.array_equal(mine, theirs)


@pytest.mark.parametrize(
    ("x", "xdot", "error", "match"),
    [
        (math.nan, 0.0, InvalidParameterError, "x must be a finite number"),
        (0.0, math.inf, InvalidParameterError, "xdot must be a finite number"),
        ("a", 0.0, InvalidParameterError, "x must be a finite number"),
        (0.0, None, InvalidParameterError, "xdot must be a finite number"),
        (1.7e308, 1.7e308, InvalidParameterError, "margin overflows"),
    ],
)
def test_bad_single_sagittal_states_are_refused(params, x, xdot, error, match):
    with pytest.raises(error, match=match):
        sagittal_verdict(x, xdot, params)
    with pytest.raises(error, match=match):
        classify(x, xdot, params)


def test_bad_single_plane_arguments_are_refused(params):
    with pytest.raises(ParameterTypeError, match="params must be a BodyParams"):
        sagittal_verdict(0.0, 0.0, "paper")  # type: ignore[arg-type]
    with pytest.raises(ParameterTypeError, match="params must be a BodyParams"):
        classify(0.0, 0.0, "paper", y=0.0)  # type: ignore[arg-type]
    with pytest.raises(ParameterTypeError, match="support must be a Support"):
        classify(0.0, 0.0, params, support="left")  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="ydot must be a finite number"):
        classify(0.0, 0.0, params, ydot=math.nan)
    with pytest.raises(InvalidParameterError, match="capture point must be within"):
        classify(1.7e308, 1.7e308, params, y=0.0)


def test_a_classification_pickles_with_its_plan(params):
    import copy
    import json
    import pickle

    for kw in ({}, {"y": 0.05, "ydot": 0.4}, {"y": 0.0, "ydot": 0.0}):
        found = classify(0.0, 1.2 if kw.get("ydot") else 0.1, params, **kw)
        for again in (pickle.loads(pickle.dumps(found)), copy.deepcopy(found)):
            assert json.dumps(again.to_dict()) == json.dumps(found.to_dict())
            assert repr(again.plan) == repr(found.plan)


@pytest.mark.parametrize(
    ("x", "y", "speed", "plane", "match"),
    [
        (1500.0, 0.0, 0.0, False, "position must have entries in"),
        (50.0, 0.0, 0.0, False, "velocity must have entries in"),
        (1500.0, 0.0, 0.0, True, "x must be in"),
        (50.0, 0.1, 0.0, True, "xdot must be in"),
    ],
)
def test_a_step_state_beyond_the_plans_range_is_refused_by_classify_itself(
    params, x, y, speed, plane, match
):
    """The plan is built lazily, but its state check is not deferred (as when built eagerly)."""
    xdot = -(x - 0.3) * params.omega  # ξ 0.3 m ahead: a step verdict
    with pytest.raises(InvalidParameterError, match=match):
        classify(x, xdot, params, **({"y": y, "ydot": speed} if plane else {}))


@pytest.mark.parametrize(
    ("position", "velocity", "match"),
    [
        ((1500.0, 0.0), (0.0, 0.0), r"position must have entries in \[-1000, 1000\]"),
        ((0.0, math.nan), (0.0, 0.0), "position must be finite"),
        ((0.0,), (1.0, 0.0), r"position must be 2 numbers \(shape \(2,\)\)"),
        ((0.0, 0.0), (200.0, 0.0), r"velocity must have entries in \[-100, 100\]"),
        ((0.0, 0.0), (math.inf, 0.0), "velocity must be finite"),
    ],
)
def test_plan_impacts_refuse_bad_states_by_name(params, position, velocity, match):
    plan = classify(0.0, 1.0, params).plan
    assert plan is not None
    with pytest.raises(InvalidParameterError, match=match):
        plan_impacts(plan, position, velocity, params)
