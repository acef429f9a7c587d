"""What a plan says about itself: crossover, landing yaw, ankle torque and friction (issue 32).

Each key against an independent computation: crossovers built by hand in the stance foot's
frame, torques recomputed from the CoPs, the peak ground force against a numerical
integration of the LIPM, a landing yaw's plan against the capture identity.
"""

import dataclasses
import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.integrate import solve_ivp

from pushrecovery import load_params
from pushrecovery.cli import main
from pushrecovery.cli.app import cli
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground import FootPose, Support
from pushrecovery.ground.support import Stance
from pushrecovery.surfaces.capture.plan import CapturePlan, capture_plan, plan_loads
from pushrecovery.surfaces.classify import Strategy, classify
from pushrecovery.surfaces.n_step import landing_foot, step_options, viable_region
from pushrecovery.surfaces.step.regions import StepRegions

#: The keys of a plan's JSON before the checks: kept, in this order, with the same values.
OLD_KEYS = ["steps", "swing", "footholds", "touchdowns", "cops", "hip", "margin", "ankle"]
NEW_KEYS = [
    "crossover",
    "landing_yaw",
    "ankle_torque_peak",
    "ankle_torque_ok",
    "horizontal_force_peak",
    "friction_ratio_peak",
    "friction_ok",
]


@pytest.fixture(scope="module")
def params():
    return load_params("paper")


def _hand_plan(swing, foothold, yaw=0.0, ankle=(0.0, -0.1)):
    """A one-step plan built by hand (only the geometry matters for crossovers)."""
    return CapturePlan(
        1,
        (swing,),
        np.array([foothold], dtype=float),
        np.array([0.2]),
        np.array([ankle, foothold], dtype=float),
        np.zeros(2),
        0.1,
        np.array(ankle, dtype=float),
        yaw,
        yaw,
    )


@pytest.mark.parametrize("yaw", [0.0, 0.4, -2.5])
@pytest.mark.parametrize("swing", [Stance.LEFT, Stance.RIGHT])
def test_crossover_is_a_landing_across_the_stance_midline(swing, yaw):
    ankle = np.array([0.3, -0.2])
    left = np.array([-math.sin(yaw), math.cos(yaw)])  # the stance foot's y axis
    ahead = np.array([math.cos(yaw), math.sin(yaw)])
    own = 1.0 if swing is Stance.LEFT else -1.0  # the swing foot's own side
    for lateral, crosses in ((0.05, False), (0.0, False), (-0.05, True), (-2e-9, True)):
        foothold = ankle + 0.3 * ahead + own * lateral * left
        plan = _hand_plan(swing, foothold, yaw, tuple(ankle))
        assert plan.crossovers == (crosses,)
        assert plan.crossover is crosses
        assert plan.to_dict()["crossover"] is crosses


def test_a_later_step_crosses_over_in_its_own_stance_frame():
    # The second stance is the landed left foot at yaw 0.5; the right foot lands on its left.
    yaw = 0.5
    first = np.array([0.3, 0.1])
    second = first + 0.2 * np.array([-math.sin(yaw), math.cos(yaw)])  # left of the left foot
    plan = CapturePlan(
        2,
        (Stance.LEFT, Stance.RIGHT),
        np.array([first, second]),
        np.array([0.2, 0.4]),
        np.array([[0.0, -0.1], first, second]),
        np.zeros(2),
        0.1,
        np.array([0.0, -0.1]),
        0.0,
        yaw,
    )
    assert plan.crossovers == (False, True)


def test_a_sideways_push_plans_a_crossover_unless_min_step_width_forbids_it(params):
    support = Support.from_params(params, Stance.RIGHT)
    found = classify(0.0, 0.0, params, y=0.0, ydot=-1.0, support=support)
    assert found.strategy is Strategy.STEP and found.plan is not None
    assert found.plan.crossover  # the left foot lands right of the right ankle
    assert float(found.plan.footholds[0, 1]) < -0.1
    narrow = dataclasses.replace(params, min_step_width=0.12)
    found = classify(0.0, 0.0, narrow, y=0.0, ydot=-1.0, support=support)
    assert found.plan is None or not found.plan.crossover


@pytest.mark.parametrize("width", [0.0, 0.12])
def test_min_step_width_leaves_no_crossover(params, width):
    body = dataclasses.replace(params, min_step_width=width)
    rng = np.random.default_rng(3)
    seen = 0
    for stance in (Stance.DOUBLE, Stance.LEFT, Stance.RIGHT):
        for yaw in (0.0, 0.6):
            support = Support.from_params(
                body,
                stance,
                left=FootPose(0.0, 0.1, yaw),
                right=FootPose(0.0, -0.1, yaw),
            )
            for xdot, ydot in rng.uniform(-1.2, 1.2, size=(12, 2)):
                found = classify(0.0, float(xdot), body, y=0.0, ydot=float(ydot), support=support)
                if found.plan is not None:
                    seen += 1
                    assert found.plan.crossovers == (False,) * found.plan.steps
    assert seen > 10


def test_ankle_torques_are_the_weight_times_the_cop_offsets(params):
    body = dataclasses.replace(params, ankle_torque_max=30.0)
    support = Support.from_params(body, Stance.LEFT, left=FootPose(0.1, 0.1, 0.3))
    found = classify(0.0, 1.1, body, y=0.05, ydot=0.4, support=support)
    plan = found.plan
    assert plan is not None and plan.loads is not None and plan.steps >= 1
    ankles = [plan.ankle, *plan.footholds]
    torques = [
        body.mass * body.gravity * math.dist(cop, ankle)
        for cop, ankle in zip(plan.cops, ankles, strict=True)
    ]
    assert plan.loads.ankle_torques == pytest.approx(torques, rel=1e-12)
    assert plan.loads.ankle_torque_peak == pytest.approx(max(torques), rel=1e-12)
    assert plan.loads.ankle_torque_ok is (max(torques) <= 30.0)
    higher = plan_loads(plan, dataclasses.replace(body, ankle_torque_max=1e3))
    assert higher.ankle_torque_ok is True
    assert plan_loads(plan, params).ankle_torque_ok is None


def _peak_force_integrated(plan, params, position, velocity):
    """The largest ‖m r̈‖ along the plan from a numerical integration of the LIPM."""
    omega2 = params.omega**2
    first = math.exp(-params.omega * float(plan.touchdowns[0]))
    offset = plan.hip / (1.0 - first)
    state = np.array([*position, *velocity], dtype=float)
    start, peak = 0.0, 0.0
    ends = [*map(float, plan.touchdowns), float(plan.touchdowns[-1]) + 1.0]
    for k, end in enumerate(ends):
        cmp = plan.cops[k] + (offset if k == 0 else 0.0)

        def lipm(_, s, cmp=cmp):
            return [s[2], s[3], omega2 * (s[0] - cmp[0]), omega2 * (s[1] - cmp[1])]

        times = np.linspace(start, end, 201)
        path = solve_ivp(lipm, (start, end), state, t_eval=times, rtol=1e-11, atol=1e-13)
        r = path.y[:2].T
        peak = max(peak, float(np.max(np.hypot(*(r - cmp).T))) * params.mass * omega2)
        state, start = path.y[:, -1], end
    return peak


@pytest.mark.parametrize(
    ("x", "xdot", "y", "ydot", "stance"),
    [
        (0.0, 0.7, None, None, None),
        (0.02, 1.1, 0.0, -0.3, Stance.RIGHT),
        (0.0, 1.6, 0.1, 0.5, None),
    ],
)
def test_the_peak_ground_force_and_friction_ratio_against_the_integrated_lipm(
    params, x, xdot, y, ydot, stance
):
    body = dataclasses.replace(params, friction=0.6)
    support = None if stance is None else Support.from_params(body, stance)
    found = classify(x, xdot, body, y=y, ydot=ydot, support=support)
    plan = found.plan
    assert found.strategy is Strategy.STEP and plan is not None and plan.loads is not None
    position = (x, 0.0 if y is None else y)
    velocity = (xdot, 0.0 if ydot is None else ydot)
    integrated = _peak_force_integrated(plan, body, position, velocity)
    assert plan.loads.horizontal_force_peak == pytest.approx(integrated, rel=1e-6)
    ratio = integrated / (0.6 * body.mass * body.gravity)
    assert plan.loads.friction_ratio_peak == pytest.approx(ratio, rel=1e-6)
    assert plan.loads.friction_ok is (plan.loads.friction_ratio_peak <= 1.0)
    slippery = plan_loads(plan, dataclasses.replace(body, friction=0.01), position, velocity)
    assert slippery.friction_ok is False
    unlimited = plan_loads(plan, params, position, velocity)
    assert unlimited.friction_ratio_peak is None and unlimited.friction_ok is None
    assert unlimited.horizontal_force_peak == plan.loads.horizontal_force_peak


def test_a_landing_yaw_plan_captures_with_turned_feet(params):
    support = Support.from_params(params, Stance.RIGHT)
    regions = StepRegions.of(params, support)
    xi = (0.45, -0.05)
    steps, _ = regions.locate(*xi)
    default = regions.plan(*xi, steps)
    assert default.landing_yaw == default.yaw == 0.0
    same = regions.plan(*xi, steps, landing_yaw=0.0)
    assert repr(same) == repr(default)
    turned = regions.plan(*xi, steps, landing_yaw=0.5)
    assert turned.landing_yaw == 0.5 and turned.margin > 0.0
    assert not np.array_equal(turned.footholds, default.footholds)
    # The capture identity: ξ carried through each phase with its CoP ends on the last CoP.
    omega, capture = params.omega, np.array(xi)
    first = math.exp(-omega * float(turned.touchdowns[0]))
    hip = turned.hip / (1.0 - first)
    start = 0.0
    for k, t in enumerate(turned.touchdowns):
        cmp = turned.cops[k] + (hip if k == 0 else 0.0)
        capture = cmp + (capture - cmp) * math.exp(omega * (float(t) - start))
        start = float(t)
    assert capture == pytest.approx(turned.cops[-1], abs=1e-12)
    # Every later CoP lies in its landing foot, turned by the landing yaw.
    for k in range(turned.steps):
        foot = landing_foot(params, turned.swings[k], 0.5).transformed(*turned.footholds[k], 0.0)
        assert float(foot.signed_distance(*turned.cops[k + 1])) >= -1e-12
    # The margin is that of C_N with the turned feet.
    option = step_options(params, support)[0]
    times = tuple(params.min_step_time * (k + 1) for k in range(steps))
    region = viable_region(params, option, times, landing_yaw=0.5)
    assert turned.margin == pytest.approx(float(region.signed_distance(*xi)), abs=1e-12)
    assert turned.margin != pytest.approx(default.margin, abs=1e-6)


def test_the_landing_yaw_is_world_yaw_on_a_yawed_stance(params):
    yaw = 0.4
    support = Support.from_params(params, Stance.LEFT, left=FootPose(0.0, 0.1, yaw))
    regions = StepRegions.of(params, support)
    xi = (0.4, 0.2)
    steps, _ = regions.locate(*xi)
    default = regions.plan(*xi, steps)
    assert default.yaw == default.landing_yaw == yaw
    assert repr(regions.plan(*xi, steps, landing_yaw=yaw)) == repr(default)
    option = step_options(params, support)[0]
    straight = capture_plan(np.array(xi), params, option, steps, landing_yaw=0.0)
    turned = regions.plan(*xi, steps, landing_yaw=0.0)
    np.testing.assert_allclose(turned.footholds, straight.footholds, atol=1e-12)
    assert turned.landing_yaw == straight.landing_yaw == 0.0


@pytest.mark.parametrize("bad", [math.pi + 1e-9, -4.0, 10.0, math.nan, "left"])
def test_a_landing_yaw_outside_pi_is_refused_naming_radians(params, bad):
    support = Support.from_params(params, Stance.RIGHT)
    option = step_options(params, support)[0]
    with pytest.raises(InvalidParameterError, match=r"landing_yaw.*rad"):
        capture_plan(np.array([0.4, 0.0]), params, option, 1, landing_yaw=bad)
    with pytest.raises(InvalidParameterError, match=r"landing_yaw.*rad"):
        StepRegions.of(params, support).plan(0.4, 0.0, 1, landing_yaw=bad)
    with pytest.raises(InvalidParameterError, match=r"landing_yaw.*rad"):
        classify(0.0, 1.0, params, landing_yaw=bad)
    with pytest.raises(InvalidParameterError, match=r"landing_yaw.*rad"):
        viable_region(params, option, (0.2,), landing_yaw=bad)


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        (("a", 0.0, 1), {}, r"px must be a finite number \[m\]"),
        ((0.4, math.nan, 1), {}, r"py must be a finite number \[m\]"),
        ((0.4, 0.0, 0), {}, r"steps must be a whole number in \[1, 11\]"),
        ((0.4, 0.0, 12), {}, r"steps must be a whole number in \[1, 11\]"),
        ((0.4, 0.0, 1.5), {}, r"steps must be a whole number in \[1, 11\]"),
        ((0.4, 0.0, True), {}, r"steps must be a whole number in \[1, 11\]"),
        ((3e3, 0.0, 1), {}, r"\(px, py\) must lie within ±2000 m of the stance ankle"),
        ((0.4, 0.0, 1), {"com": (2e3, 0.0)}, r"com must have entries in \[-1000, 1000\] \[m\]"),
    ],
)
def test_a_plan_of_the_regions_refuses_bad_input_naming_it(params, args, kwargs, message):
    regions = StepRegions.of(params, Support.from_params(params, Stance.RIGHT))
    assert params.max_steps == 11
    with pytest.raises((InvalidParameterError, ParameterTypeError), match=message):
        regions.plan(*args, **kwargs)
    # Numbers numpy gives are numbers: the same plan as Python's.
    plan = regions.plan(np.float64(0.4), np.float64(0.0), np.int64(1))
    assert repr(plan) == repr(regions.plan(0.4, 0.0, 1))


def test_plan_loads_refuses_half_a_state(params):
    plan = classify(0.0, 0.8, params).plan
    assert plan is not None
    with pytest.raises(InvalidParameterError, match="both position and velocity"):
        plan_loads(plan, params, (0.0, 0.0))
    with pytest.raises(InvalidParameterError, match="velocity"):
        plan_loads(plan, params, (0.0, 0.0), (math.inf, 0.0))
    option = step_options(params, Support.from_params(params, Stance.RIGHT))[0]
    with pytest.raises(InvalidParameterError, match="com"):
        capture_plan(np.array([0.4, 0.0]), params, option, 1, com=(math.nan, 0.0))


def test_the_plan_json_adds_keys_after_the_old_ones(params):
    for state in ({}, {"y": 0.0, "ydot": 0.3}):
        data = classify(0.0, 0.9, params, **state).to_dict()["plan"]
        assert list(data)[: len(OLD_KEYS)] == OLD_KEYS
        assert list(data)[len(OLD_KEYS) : len(OLD_KEYS) + len(NEW_KEYS)] == NEW_KEYS
        assert data["ankle_torque_ok"] is None and data["friction_ok"] is None
        assert data["crossover"] is False and isinstance(data["ankle_torque_peak"], float)
        json.dumps(data, allow_nan=False)
    limited = dataclasses.replace(params, ankle_torque_max=50.0, friction=0.8)
    data = classify(0.0, 0.9, limited).to_dict()["plan"]
    assert data["ankle_torque_ok"] is True and isinstance(data["friction_ok"], bool)
    # A plan made without loads (built by hand) keeps every key, null.
    bare = _hand_plan(Stance.LEFT, (0.3, 0.1)).to_dict()
    assert [bare[key] for key in NEW_KEYS[2:]] == [None] * 5


def test_cli_classify_reports_and_notes_a_crossover():
    args = ["classify", "--x", "0", "--xdot", "0", "--ydot", "-1.0", "--stance", "right"]
    data = json.loads(CliRunner().invoke(cli, [*args, "--json"]).output)
    assert data["plan"]["crossover"] is True and "note" not in data
    table = CliRunner().invoke(cli, args).output
    assert "crossover              True" in table and "note" in table
    straight = CliRunner().invoke(cli, ["classify", "--x", "0", "--xdot", "0.7"]).output
    assert "crossover              False" in straight and "note" not in straight
    data = json.loads(
        CliRunner()
        .invoke(cli, ["classify", "--x", "0", "--xdot", "0.9", "--landing-yaw", "0.3", "--json"])
        .output
    )
    assert data["plan"]["landing_yaw"] == 0.3 and "capture_point_xy" in data


def test_cli_landing_yaw_out_of_range_is_one_line_exit_2(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["classify", "--x", "0", "--xdot", "0.9", "--landing-yaw", "4"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "landing_yaw" in err and "rad" in err


def test_cli_capture_region_says_whether_its_foothold_crosses_over():
    base = ["capture-region", "--x", "0", "--xdot", "0.3", "--stance", "right", "--json"]
    across = json.loads(CliRunner().invoke(cli, [*base, "--ydot", "-0.9"]).output)
    assert across["swing"] == "left" and across["crossover"] is True
    assert across["foothold"][1] < -0.1  # the left foot lands right of the right ankle
    outward = json.loads(CliRunner().invoke(cli, [*base, "--ydot", "0.6"]).output)
    assert outward["crossover"] is False
    narrow = [*base, "--ydot", "-0.9", "--min-step-width", "0.12"]
    empty = json.loads(CliRunner().invoke(cli, narrow).output)
    assert empty["foothold"] is None and empty["crossover"] is None


def test_turned_terms_of_the_stance_yaw_are_step_terms(params):
    from pushrecovery.surfaces.capture.plan import _turned_terms
    from pushrecovery.surfaces.capture.region import step_terms

    option = step_options(params, Support.from_params(params, Stance.RIGHT))[0]
    key = (option.stance.vertices - option.ankle).tobytes()
    for steps, hip in ((1, True), (3, False)):
        same = step_terms(params, Stance.LEFT, 0.0, steps, 0.2, hip, key)
        turned = _turned_terms(params, Stance.LEFT, 0.0, 0.0, steps, 0.2, hip, key)
        for name in ("foot_shapes", "foot_weights", "window_offsets", "split_total"):
            np.testing.assert_array_equal(getattr(turned, name), getattr(same, name))


def test_capture_plan_with_the_com_reports_the_forces_of_that_state(params):
    option = step_options(params, Support.from_params(params, Stance.RIGHT))[0]
    xi, com = np.array([0.45, -0.1]), (0.05, -0.08)
    plan = capture_plan(xi, params, option, 1, com=com)
    velocity = params.omega * (xi - np.array(com))
    again = plan_loads(plan, params, com, tuple(velocity.tolist()))
    assert plan.loads == again and plan.loads.horizontal_force_peak is not None
    assert capture_plan(xi, params, option, 1).loads.horizontal_force_peak is None
