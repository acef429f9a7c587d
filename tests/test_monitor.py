"""The monitor's supports: regions turned and moved from a stance foot's frame, the same as built.

``StepRegions.of`` places regions built once per body (stance ankle at the origin, yaw 0) at
the feet; here every region is checked against the Minkowski sums of (S1) built directly for
the placed feet (``viable_region``), on random poses and yaws, for several bodies; the
monitor's CMP region against ``cmp_polygon``; plans against ``capture_plan`` in the world
frame.
"""

import dataclasses
import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.support import FootPose, Support
from pushrecovery.surfaces.capture.plan import capture_plan
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.cmp import cmp_offset_from
from pushrecovery.surfaces.monitor import BalanceMonitor
from pushrecovery.surfaces.n_step import step_options, viable_region
from pushrecovery.surfaces.plane import cmp_polygon, cmp_polygon_from
from pushrecovery.surfaces.step.regions import StepRegions

P = load_params()
SOLE = [
    [-0.05, -0.04], [0.1, -0.05], [0.18, -0.03], [0.21, 0.0],
    [0.18, 0.035], [0.1, 0.05], [-0.05, 0.045], [-0.07, 0.0],
]  # fmt: skip
BODIES = {
    "default": P,
    "min-step-width": dataclasses.replace(P, min_step_width=0.12),
    "8-vertex sole": load_params(overrides={"foot_polygon": SOLE}),
    "no roll torque": dataclasses.replace(P, torque_max_roll=0.0),
    "no hip, one step": load_params(
        overrides={"torque_max": 0.0, "torque_max_roll": 0.0, "max_steps": 1}
    ),
    "16-vertex sole": load_params(
        overrides={
            "foot_polygon": [
                [0.07 + 0.1 * math.cos(a), 0.06 * math.sin(a)]
                for a in np.linspace(0.0, 2.0 * math.pi, 17)[:-1]
            ]
        }
    ),
}


def random_supports(params, count, seed):
    """Supports of every stance on random poses and yaws (the right foot turned a little)."""
    rng = np.random.default_rng(seed)
    supports = []
    for i in range(count):
        yaw = 0.0 if i % 4 == 0 else rng.uniform(-math.pi, math.pi)
        x, y = rng.uniform(-3.0, 3.0, 2)
        half = rng.uniform(0.1, 0.2)
        turn = min(math.pi, max(-math.pi, yaw + rng.uniform(-0.3, 0.3)))
        left = FootPose(x - half * math.sin(yaw), y + half * math.cos(yaw), yaw)
        right = FootPose(x + half * math.sin(yaw), y - half * math.cos(yaw), turn)
        stance = ("left", "right", "double")[i % 3]
        supports.append(Support.from_params(params, stance, left=left, right=right))
    return supports


def built(params, support):
    """The regions as (S1) builds them for the placed feet: by N, each lifting foot."""
    polygons = []
    for n in range(1, params.max_steps + 1):
        times = tuple(params.min_step_time * (k + 1) for k in range(n))
        polygons += [viable_region(params, o, times) for o in step_options(params, support)]
    return polygons


def same_loop(a, b, tolerance):
    """The same counter-clockwise vertex loop, up to where it starts: return b's start."""
    assert len(a) == len(b)
    start = int(np.argmin(np.hypot(*(b - a[0]).T)))
    assert np.abs(np.roll(b, -start, axis=0) - a).max() <= tolerance
    return start


@pytest.mark.parametrize("name", list(BODIES))
def test_placed_regions_are_the_regions_built_for_the_feet(name):
    params = BODIES[name]
    for support in random_supports(params, 12, seed=len(name)):
        regions = StepRegions.of(params, support)
        expected = built(params, support)
        scale = max(1.0, abs(support.left.x), abs(support.left.y))
        assert len(regions.polygons) == len(expected) == len(regions.steps)
        for polygon, reference, count, edges in zip(
            regions.polygons, expected, regions.counts, regions.table, strict=True
        ):
            start = same_loop(reference.vertices, polygon.vertices, 1e-12 * scale)
            assert count == len(reference.vertices)
            # The table holds the same edges (row i: the edge from vertex i), in loop order.
            table = np.roll(edges[:count], -start, axis=0)
            assert np.abs(table - reference.edge_table).max() <= 1e-12 * scale
            assert (edges[count:] == edges[count - 1]).all()  # padded by the last edge
        nested = all(
            float(expected[i + len(regions.options) // params.max_steps].signed_distance(
                *expected[i].vertices.T).min()) >= -1e-12
            for i in range(len(expected) - len(regions.options) // params.max_steps)
        )  # fmt: skip
        assert regions.outer.tolist() == [
            not nested or n == params.max_steps for n in regions.steps
        ]
        options = step_options(params, support)
        for row, option in enumerate(regions.options):
            mine = options[row % len(options)]
            assert option.swing is mine.swing and option.yaw == mine.yaw
            assert np.array_equal(option.ankle, mine.ankle)


def test_plans_in_the_stance_frame_are_the_world_plans():
    params = BODIES["min-step-width"]
    rng = np.random.default_rng(7)
    for support in random_supports(params, 6, seed=3):
        regions = StepRegions.of(params, support)
        ax, ay = support.ankle
        for _ in range(4):
            px, py = ax + rng.uniform(-0.8, 0.8), ay + rng.uniform(-0.8, 0.8)
            steps, _ = regions.locate(px, py)
            if not steps:
                continue
            plan = regions.plan(px, py, steps)
            option = next(o for o in step_options(params, support) if o.swing is plan.swings[0])
            world = capture_plan(np.array([px, py]), params, option, steps)
            assert plan.swings == world.swings
            for key in ("footholds", "cops", "hip", "ankle", "touchdowns"):
                assert np.abs(getattr(plan, key) - getattr(world, key)).max() <= 1e-9, key
            assert plan.margin == pytest.approx(world.margin, abs=1e-12)


@pytest.mark.parametrize("name", list(BODIES))
def test_the_monitor_on_turned_and_moved_supports_equals_classify(name):
    params = BODIES[name]
    monitor = BalanceMonitor(params)
    rng = np.random.default_rng(11)
    for support in random_supports(params, 6, seed=5):
        monitor.set_support(support)
        assert monitor.support is support
        hip = cmp_polygon(support, params)
        ax, ay = support.ankle
        for _ in range(15):
            x, y = ax + rng.uniform(-0.1, 0.1), ay + rng.uniform(-0.1, 0.1)
            xdot, ydot = rng.uniform(-2.5, 2.5, 2)
            fast = monitor.query(x, y, xdot, ydot)
            slow = classify(x, xdot, params, y=y, ydot=ydot, support=support)
            assert fast.strategy == slow.strategy
            for mine, theirs in ((fast.cop_margin, slow.margins["cop"]),
                                 (fast.cmp_margin, slow.margins["cmp"]),
                                 (fast.step_margin, slow.margins["step"])):  # fmt: skip
                assert abs(mine - theirs) <= 1e-12
            xi = (fast.capture_point_x, fast.capture_point_y)
            assert abs(fast.cmp_margin - float(hip.signed_distance(*xi))) <= 1e-12


def test_bad_supports_are_refused():
    monitor = BalanceMonitor(P)
    with pytest.raises(ParameterTypeError, match="support"):
        monitor.set_support("double")  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="yaw must be within"):
        FootPose(0.0, 0.09, 10.0)  # degrees by mistake
    assert monitor.support.stance.value == "double"  # a refused change changes nothing


def torso_states(params, count, rng):
    """Upper-body (pitch, roll) states across each axis's range: angles in [−θmax, θmax], rates
    up to those the flywheel can still stop, the range's corners among them."""
    states = []
    for i in range(count):
        pair = []
        for torque, inertia, angle_max in (
            (params.torque_max, params.flywheel_inertia, params.flywheel_angle_max),
            (params.torque_max_roll, params.flywheel_inertia_roll, params.flywheel_angle_max_roll),
        ):
            angle = (angle_max, -angle_max, 0.0)[i] if i < 3 else rng.uniform(-1, 1) * angle_max
            accel = torque / inertia
            low = -math.sqrt(2.0 * accel * (angle_max + angle))
            high = math.sqrt(2.0 * accel * (angle_max - angle))
            rate = (low, high)[i % 2] if i < 6 else rng.uniform(low, high)
            pair.append((angle, rate))
        states.append(tuple(pair))
    return states


@pytest.mark.parametrize("name", ["default", "8-vertex sole", "no roll torque", "16-vertex sole"])
def test_the_torso_state_margin_is_the_distance_to_cmp_polygon_from(name):
    params = BODIES[name]
    monitor = BalanceMonitor(params)
    rng = np.random.default_rng(13)
    for support in random_supports(params, 9, seed=17):
        monitor.set_support(support)
        ax, ay = support.ankle
        for pitch, roll in torso_states(params, 8, rng):
            region = cmp_polygon_from(support, params, pitch, roll)
            for _ in range(12):
                x, y = ax + rng.uniform(-0.35, 0.35), ay + rng.uniform(-0.35, 0.35)
                xdot, ydot = rng.uniform(-0.5, 0.5, 2)
                verdict = monitor.query(x, y, xdot, ydot, pitch=pitch, roll=roll)
                at_rest = monitor.query(x, y, xdot, ydot)
                xi = (verdict.capture_point_x, verdict.capture_point_y)
                assert abs(verdict.cmp_margin - float(region.signed_distance(*xi))) <= 1e-12
                # The CoP margin and the steps do not depend on the upper body.
                assert xi == (at_rest.capture_point_x, at_rest.capture_point_y)
                assert verdict.cop_margin == at_rest.cop_margin
                assert verdict.step_margin == at_rest.step_margin
                cop, cmp = verdict.cop_margin, verdict.cmp_margin
                expected = (
                    "ankle" if cop > 0.0 and cmp > 0.0 else "hip" if cmp > 0.0
                    else "step" if at_rest.step_margin > 0.0 else "fall"
                )  # fmt: skip
                assert verdict.strategy.value == expected


def test_an_upright_resting_torso_gives_the_verdict_without_one():
    monitor = BalanceMonitor(P)
    rng = np.random.default_rng(19)
    for support in random_supports(P, 6, seed=23):
        monitor.set_support(support)
        ax, ay = support.ankle
        for _ in range(20):
            state = (ax + rng.uniform(-0.2, 0.2), ay + rng.uniform(-0.2, 0.2),
                     *rng.uniform(-1.5, 1.5, 2))  # fmt: skip
            verdict = monitor.query(*state)
            for torso in (
                {"pitch": None, "roll": None},
                {"pitch": (0.0, 0.0)},
                {"roll": (0, 0.0)},
                {"pitch": (0.0, 0.0), "roll": (0.0, 0.0)},
            ):
                assert monitor.query(*state, **torso) == verdict


def crossing(monitor, support, direction, torso):
    """Distances d along ``direction`` (stance axes) from the ankle at which ξ = ankle + d e
    is ``hip`` for the body at rest and not with ``torso``, and the reverse."""
    c, s = math.cos(support.yaw), math.sin(support.yaw)
    ex, ey = c * direction[0] - s * direction[1], s * direction[0] + c * direction[1]
    ax, ay = support.ankle
    lost, gained = [], []
    for d in np.arange(0.0, 0.6, 0.002):
        x, y = ax + d * ex, ay + d * ey
        rest, moved = monitor.query(x, y, 0.0, 0.0), monitor.query(x, y, 0.0, 0.0, **torso)
        if rest.strategy.value == "hip" and moved.strategy.value == "step":
            lost.append(d)
        if rest.strategy.value == "step" and moved.strategy.value == "hip":
            gained.append(d)
    return lost, gained


@pytest.mark.parametrize("stance", ["double", "left"])
def test_a_torso_leaning_or_turning_toward_the_push_needs_a_step_sooner(stance):
    monitor = BalanceMonitor(P)
    feet = {"left": FootPose(0.3, 0.5, 0.6), "right": FootPose(0.4, 0.32, 0.5)}
    support = Support.from_params(P, stance, **feet)
    monitor.set_support(support)
    lean, roll_max = 0.9 * P.flywheel_angle_max, 0.9 * P.flywheel_angle_max_roll
    rate = 0.5 * math.sqrt(2.0 * P.torque_max / P.flywheel_inertia * P.flywheel_angle_max)
    for direction, toward, away in (
        ((1.0, 0.0), {"pitch": (lean, 0.0)}, {"pitch": (-lean, 0.0)}),  # pushed forward
        ((1.0, 0.0), {"pitch": (0.0, rate)}, {"pitch": (0.0, -rate)}),  # turning forward
        ((-1.0, 0.0), {"pitch": (-lean, 0.0)}, {"pitch": (lean, 0.0)}),  # pushed backward
        ((0.0, 1.0), {"roll": (roll_max, 0.0)}, {"roll": (-roll_max, 0.0)}),  # to the left
    ):
        lost, gained = crossing(monitor, support, direction, toward)
        assert lost and not gained  # hip at rest, step leaning toward the push
        lost, gained = crossing(monitor, support, direction, away)
        assert gained and not lost  # step at rest, hip leaning away from it


def test_a_torso_to_be_braked_against_the_push_shrinks_the_region_inside_the_foot():
    monitor = BalanceMonitor(P)  # default double support, yaw 0: the toe at x = P.toe
    rate = math.sqrt(2.0 * P.torque_max / P.flywheel_inertia * P.flywheel_angle_max)
    _, plus = cmp_offset_from(P, 0.0, rate)
    assert plus < 0.0  # full speed forward: it must be braked, the CMP moves back first
    x = P.toe + 0.5 * plus  # on the foot, beyond what the braked torso leaves
    at_rest, moving = monitor.query(x, 0.0, 0.0, 0.0), monitor.query(x, 0, 0, 0, pitch=(0, rate))
    assert at_rest.strategy.value == "ankle" and moving.cop_margin > 0.0
    assert moving.cmp_margin == pytest.approx(0.5 * plus, abs=1e-12)
    assert moving.strategy.value == "step"


def test_bad_torso_states_are_refused_naming_the_axis_and_the_value():
    monitor = BalanceMonitor(P)
    fast = math.sqrt(2.0 * P.torque_max / P.flywheel_inertia * P.flywheel_angle_max) * 1.01
    for torso, words in (
        ({"pitch": (math.nan, 0.0)}, "pitch: theta0"),
        ({"roll": (0.0, math.inf)}, "roll: thetadot0"),
        ({"pitch": (1.01 * P.flywheel_angle_max, 0.0)}, "pitch: theta0 must be in"),
        ({"roll": (-1.01 * P.flywheel_angle_max_roll, 0.0)}, "roll: theta0 must be in"),
        ({"pitch": (0.0, fast)}, "pitch: thetadot0 must be in"),
        ({"pitch": (0.0, "fast")}, "pitch: thetadot0"),
        ({"pitch": 0.1}, "pitch must be an"),
        ({"roll": (0.1, 0.0, 0.0)}, "roll must be an"),
    ):
        with pytest.raises(InvalidParameterError, match=words.replace("(", r"\(")):
            monitor.query(0.0, 0.0, 0.1, 0.0, **torso)
    assert monitor.query(0.0, 0.0, 0.1, 0.0, pitch=(0.1, 0.0)).strategy.value == "ankle"
    # Without roll torque the roll rate is not used: any finite rate is accepted.
    still = BalanceMonitor(BODIES["no roll torque"])
    spinning = still.query(0.3, 0.0, 0.1, 0.0, roll=(0.0, 1e3))
    upright = still.query(0.3, 0.0, 0.1, 0.0)
    assert spinning.strategy == upright.strategy
    assert spinning.cmp_margin == pytest.approx(upright.cmp_margin, abs=1e-12)


def test_numpy_scalars_and_ints_give_the_verdict_of_python_floats():
    monitor = BalanceMonitor(P)
    rng = np.random.default_rng(29)
    for state in rng.uniform(-0.5, 0.5, (20, 4)):
        verdict = monitor.query(*(float(v) for v in state))
        assert monitor.query(*state) == verdict  # numpy float64
        assert type(monitor.query(*state).capture_point_x) is float
    assert monitor.query(0, 0, 1, 0) == monitor.query(0.0, 0.0, 1.0, 0.0)
    with pytest.raises(ParameterTypeError, match="must be numbers"):
        monitor.query(np.array([0.1]), 0.0, 0.0, 0.0)
