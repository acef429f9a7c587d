"""Properties of the step verdict and the capture regions (hypothesis, derandomised).

The regions grow with the reach and shrink with the step time; they mirror with the body; a
later first touchdown only removes footholds; verdicts escalate with push size along any
direction (no ``fall`` below a ``step``), and the step margin agrees with the verdict.
"""

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from pushrecovery import load_params
from pushrecovery.cli.app import cli
from pushrecovery.ground import FootPose, Support
from pushrecovery.surfaces.capture.region import capture_region
from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy, classify, classify_states
from pushrecovery.surfaces.n_step import step_options, viable_region

P = load_params()
ANGLES = np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)
ROUND = 1e-12


def support_values(polygon):
    return np.array([(polygon.vertices @ [math.cos(a), math.sin(a)]).max() for a in ANGLES])


def times(params, steps):
    return tuple(params.min_step_time * (k + 1) for k in range(steps))


@settings(max_examples=25, deadline=None)
@given(
    reach=st.tuples(st.floats(0.2, 1.2), st.floats(0.2, 1.2)),
    steps=st.integers(1, 4),
    stance=st.sampled_from(["left", "right"]),
)
def test_regions_grow_with_the_reach(reach, steps, stance):
    short, long = sorted(reach)
    regions = []
    for length in (short, long):
        params = load_params(overrides={"max_step_length": length})
        option = step_options(params, Support.from_params(params, stance))[0]
        regions.append(viable_region(params, option, times(params, steps)))
    assert np.all(support_values(regions[1]) >= support_values(regions[0]) - ROUND)


@settings(max_examples=25, deadline=None)
@given(step_time=st.tuples(st.floats(0.05, 0.6), st.floats(0.05, 0.6)), steps=st.integers(1, 4))
def test_regions_shrink_with_the_step_time(step_time, steps):
    quick, slow = sorted(step_time)
    regions = []
    for value in (quick, slow):
        params = load_params(overrides={"min_step_time": value})
        option = step_options(params, Support.from_params(params, "left"))[0]
        regions.append(viable_region(params, option, times(params, steps)))
    assert np.all(support_values(regions[1]) <= support_values(regions[0]) + ROUND)


@settings(max_examples=25, deadline=None)
@given(
    state=st.tuples(
        st.floats(-0.1, 0.1), st.floats(-0.1, 0.1), st.floats(-2.5, 2.5), st.floats(-2.5, 2.5)
    ),
    steps=st.integers(1, 3),
)
def test_regions_mirror_with_the_body(state, steps):
    x, y, xdot, ydot = state
    left = Support.from_params(P, "left")
    right = Support.from_params(P, "right")
    region = capture_region(x, y, xdot, ydot, P, left, steps=steps)
    mirror = capture_region(x, -y, xdot, -ydot, P, right, steps=steps)
    assert (region.polygon is None) == (mirror.polygon is None)
    if region.polygon is not None:
        flipped = mirror.polygon.vertices * [1.0, -1.0]
        assert region.area == pytest.approx(mirror.area, abs=1e-12)
        assert np.all(region.polygon.signed_distance(*flipped.T) > -1e-9)
        np.testing.assert_allclose(region.foothold, mirror.foothold * [1.0, -1.0], atol=1e-7)
    verdicts = [
        classify(x, xdot, P, y=s * y, ydot=s * ydot, support=sup)
        for s, sup in ((1, left), (-1, right))
    ]
    assert verdicts[0].strategy == verdicts[1].strategy
    assert verdicts[0].steps == verdicts[1].steps


@settings(max_examples=20, deadline=None)
@given(
    state=st.tuples(
        st.floats(-0.1, 0.1), st.floats(-0.1, 0.1), st.floats(-2.5, 2.5), st.floats(-2.5, 2.5)
    ),
    start=st.floats(0.0, 0.4),
    later=st.floats(0.0, 0.4),
)
def test_a_later_touchdown_only_removes_footholds(state, start, later):
    support = Support.from_params(P, "right")
    early = capture_region(*state, P, support, start, timing="after")
    late = capture_region(*state, P, support, start + later, timing="after")
    exact = capture_region(*state, P, support, start + later, timing="exact")
    for inner in (late, exact):
        if inner.polygon is None:
            continue
        assert early.polygon is not None
        corners = inner.polygon.vertices
        assert np.all(early.polygon.signed_distance(*corners.T) > -1e-9)
    if exact.polygon is not None:
        assert late.polygon is not None
        assert np.all(late.polygon.signed_distance(*exact.polygon.vertices.T) > -1e-9)


@settings(max_examples=40, deadline=None)
@given(
    state=st.tuples(
        st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), st.floats(-5.0, 5.0), st.floats(-5.0, 5.0)
    ),
    stance=st.sampled_from(["double", "left", "right"]),
)
def test_the_step_margin_agrees_with_the_verdict(state, stance):
    x, y, xdot, ydot = state
    found = classify(x, xdot, P, y=y, ydot=ydot, support=Support.from_params(P, stance))
    captured = found.margins["step"] > 0.0
    assert (found.steps is not None) == (found.strategy is not Strategy.FALL)
    if found.strategy is Strategy.STEP:
        assert captured and found.steps >= 1 and found.plan is not None
        assert found.plan.margin > 0.0
    if found.strategy is Strategy.FALL:
        assert not captured and found.to_dict()["margins"]["step"] is None
    line = classify(x, xdot, P)
    assert (line.margins["step"] > 0.0) == (line.strategy is not Strategy.FALL)


def test_no_fall_below_a_step_on_the_strategy_map():
    # Along every column of the map (x fixed), the verdict escalates with |ẋ| away from the
    # ankle band: ankle < hip < step (N rising) < fall.
    x, xdot = np.meshgrid(np.linspace(-0.4, 0.6, 41), np.linspace(-6.0, 6.0, 601))
    codes = classify_states(x, xdot, P)
    order = np.array([0, 1, 2, 3])[codes]  # STRATEGY_CODES is in escalation order
    assert [s.value for s in STRATEGY_CODES] == ["ankle", "hip", "step", "fall"]
    for column in range(x.shape[1]):
        ankle = np.flatnonzero(codes[:, column] == 0)
        top, bottom = ankle.max(), ankle.min()
        assert np.all(np.diff(order[top:, column]) >= 0)
        assert np.all(np.diff(order[: bottom + 1, column]) <= 0)
    steps = [classify(0.0, v, P).steps for v in np.linspace(0.7, 4.2, 30)]
    assert steps == sorted(steps)


def test_capture_region_cli(tmp_path):
    runner = CliRunner()
    args = ["capture-region", "--x", "0", "--xdot", "1.5", "--ydot", "0.4", "--stance", "left"]
    data = json.loads(runner.invoke(cli, [*args, "--json"]).output)
    assert data["swing"] == "right" and data["steps"] == 1 and data["timing"] == "exact"
    assert data["area"] > 0.01 and len(data["vertices"]) >= 3
    region = capture_region(0.0, 0.0, 1.5, 0.4, P, Support.from_params(P, "left"))
    assert data["foothold"] == pytest.approx(list(region.foothold), abs=1e-12)
    later = json.loads(
        runner.invoke(cli, [*args, "--swing-time", "0.1", "--timing", "after", "--json"]).output
    )
    assert later["touchdown"] == 0.1 and later["area"] >= data["area"]
    two = json.loads(runner.invoke(cli, [*args, "--steps", "2", "--json"]).output)
    assert two["area"] > data["area"]
    plot = tmp_path / "regions.png"
    done = runner.invoke(cli, [*args, "--plot", str(plot)])
    assert done.exit_code == 0 and plot.read_bytes().startswith(b"\x89PNG")
    empty = json.loads(
        runner.invoke(cli, ["capture-region", "--x", "0", "--xdot", "9", "--json"]).output
    )
    assert empty["vertices"] is None and empty["foothold"] is None and empty["area"] == 0.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--swing-time", "-1"], "swing_time must be in"),
        (["--swing-time", "nan"], "swing_time"),
        (["--steps", "0"], "--steps"),
        (["--timing", "later"], "--timing"),
        (["--swing", "left", "--stance", "left"], "swing must be the free foot"),
        (["--plot", "out.txt"], "--plot must end in"),
        (["--min-step-time", "-0.1"], "min_step_time must be in"),
        (["--max-steps", "0"], "max_steps must be in"),
        (["--min-step-width", "2"], "min_step_width must be in"),
        (["--left-foot", "0,-0.05"], "overlap"),
    ],
)
def test_capture_region_cli_bad_input(args, message):
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "pushrecovery", "capture-region", "--x", "0", "--xdot", "1", *args],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2, done.stderr
    assert message in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_double_support_lifts_the_foot_on_the_push_side():
    double = Support.from_params(P, "double", left=FootPose(0.0, 0.1), right=FootPose(0.0, -0.1))
    for ydot, side in ((1.2, "left"), (-1.2, "right")):
        found = classify(0.0, 0.0, P, y=0.0, ydot=ydot, support=double)
        assert found.strategy is Strategy.STEP and found.plan.swings[0].value == side
