"""Verdicts on the ground plane: the sagittal special case, vectorised and real-time paths."""

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.cli import main
from pushrecovery.cli.app import cli
from pushrecovery.ground import FootPose, Support
from pushrecovery.surfaces.bounds import bounds_data
from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy, classify, classify_states
from pushrecovery.surfaces.monitor import BalanceMonitor
from pushrecovery.surfaces.step import step_thresholds

P = load_params()
GRID_X = np.linspace(-0.3, 0.45, 31)
GRID_XDOT = np.linspace(-3.0, 3.0, 61)
SUPPORTS = {
    "double": Support.from_params(P),
    "left": Support.from_params(P, "left"),
    "right": Support.from_params(P, "right"),
    "yawed": Support.from_params(
        P, "double", left=FootPose(0.05, 0.12, 0.4), right=FootPose(-0.05, -0.1, -0.1)
    ),
}


def test_sagittal_special_case_is_identical():
    # y = ẏ = 0 on the default double support: the same numbers as the sagittal model, to
    # 1e-12 m (the centroid of the hull carries ~1e-17 of rounding in y).
    for x in GRID_X:
        for xdot in GRID_XDOT:
            line = classify(x, xdot, P)
            plane = classify(x, xdot, P, y=0.0, ydot=0.0)
            assert plane.strategy == line.strategy, (x, xdot)
            assert plane.capture_point == pytest.approx(line.capture_point, abs=1e-15)
            for key in ("cop", "cmp"):
                a, b = line.margins[key], plane.margins[key]
                assert (a == b) or abs(a - b) <= 1e-12, (x, xdot, key, a, b)
            # The step regions are intervals on the line and polygons in the plane (their x
            # extent at y = 0 is the interval's): the same verdicts and steps, the same sign of
            # the step margin, but a Euclidean distance in the plane.
            assert plane.steps == line.steps, (x, xdot)
            assert (plane.margins["step"] > 0.0) == (line.margins["step"] > 0.0), (x, xdot)
            if line.step is not None:
                assert math.copysign(1.0, plane.step["step_length"]) == math.copysign(
                    1.0, line.step["step_length"]
                )
    x, xdot = np.meshgrid(GRID_X, GRID_XDOT)
    np.testing.assert_array_equal(
        classify_states(x, xdot, P), classify_states(x, xdot, P, y=0.0, ydot=0.0)
    )


def test_sagittal_cli_numbers_unchanged():
    # Without planar flags the CLI is the sagittal model, numbers and keys; with them the plane,
    # whose margins equal the sagittal ones for the paper preset at y = ẏ = 0.
    runner = CliRunner()
    args = ["classify", "--x", "0", "--xdot", "1.2", "--json"]
    out = json.loads(runner.invoke(cli, args).output)
    assert out == {**classify(0.0, 1.2, P).to_dict(), "state": {"x": 0.0, "xdot": 1.2}}
    long_foot = ["--heel", "-0.2", "--toe", "0.25"]
    out = json.loads(runner.invoke(cli, [*args, *long_foot]).output)
    body = load_params(overrides={"heel": -0.2, "toe": 0.25})
    assert out["margins"]["cop"] == classify(0.0, 1.2, body).margins["cop"]
    plane = json.loads(runner.invoke(cli, [*args, "--stance", "double"]).output)
    line = classify(0.0, 1.2, P).to_dict()
    for key, value in line.items():
        if key in ("step", "plan"):  # the plane adds keys inside them, never drops one
            assert set(value) <= set(plane[key])
        elif key == "margins":
            for k in ("cop", "cmp"):
                assert plane[key][k] == pytest.approx(value[k], abs=1e-12)
            assert (plane[key]["step"] > 0.0) == (value["step"] > 0.0)  # a distance in 2-D
        elif key == "step_length":
            assert math.copysign(1.0, plane[key]) == math.copysign(1.0, value)
        elif key != "strategy":
            assert plane[key] == pytest.approx(value, abs=1e-12)
    assert plane["strategy"] == line["strategy"]
    assert plane["state"] == {"x": 0.0, "xdot": 1.2, "y": 0.0, "ydot": 0.0}
    assert plane["capture_point_xy"] == [plane["capture_point"], 0.0]
    assert len(plane["support"]["vertices"]) == 4


def random_states(n, seed):
    rng = np.random.default_rng(seed)
    return (
        rng.uniform(-0.3, 0.4, n),
        rng.uniform(-0.35, 0.35, n),
        rng.uniform(-2.5, 2.5, n),
        rng.uniform(-2.5, 2.5, n),
    )


@pytest.mark.parametrize("name", list(SUPPORTS))
def test_vectorised_and_monitor_equal_classify(name):
    support = SUPPORTS[name]
    # A fixed seed per support (str hashes change between processes), and the support's own
    # ankle at rest and just pushed, so that ankle, hip and beyond are all in the sample.
    x, y, xdot, ydot = random_states(400, seed=11 + list(SUPPORTS).index(name))
    ax, ay = support.ankle
    x, y = np.append(x, [ax, ax, ax]), np.append(y, [ay, ay, ay])
    xdot, ydot = np.append(xdot, [0.0, 0.5, 3.0]), np.append(ydot, [0.0, 0.1, 0.0])
    codes = classify_states(x, xdot, P, y=y, ydot=ydot, support=support)
    monitor = BalanceMonitor(P, support)
    seen = set()
    for i in range(x.size):
        one = classify(x[i], xdot[i], P, y=y[i], ydot=ydot[i], support=support)
        seen.add(one.strategy)
        assert STRATEGY_CODES[codes[i]] == one.strategy, i
        fast = monitor.query(x[i], y[i], xdot[i], ydot[i])
        assert fast.strategy == one.strategy
        assert (fast.capture_point_x, fast.capture_point_y) == pytest.approx(
            one.capture_point_xy, abs=1e-15
        )
        for key, value in (
            ("cop", fast.cop_margin),
            ("cmp", fast.cmp_margin),
            ("step", fast.step_margin),
        ):
            # Same formulas in the same order; the compiled planner may round differently.
            assert value == one.margins[key] or abs(value - one.margins[key]) <= 1e-12
    assert len(seen) >= 3  # the sample spans ankle, hip and beyond


@settings(max_examples=60, deadline=None)
@given(
    heading=st.floats(-math.pi, math.pi),
    stance=st.sampled_from(["double", "left", "right"]),
)
def test_verdict_escalates_with_push_size(heading, stance):
    support = SUPPORTS[stance]
    ax, ay = support.ankle
    order = {s: i for i, s in enumerate(Strategy)}
    last = 0
    for speed in np.linspace(0.0, 3.0, 61):
        found = classify(
            ax,
            speed * math.cos(heading),
            P,
            y=ay,
            ydot=speed * math.sin(heading),
            support=support,
        )
        assert order[found.strategy] >= last, (speed, found.strategy)
        last = order[found.strategy]


def test_margins_agree_with_verdicts():
    x, y, xdot, ydot = random_states(300, seed=5)
    for i in range(x.size):
        one = classify(x[i], xdot[i], P, y=y[i], ydot=ydot[i])
        m = one.margins
        assert (one.strategy == Strategy.ANKLE) == (m["cop"] > 0)
        assert (one.strategy in (Strategy.ANKLE, Strategy.HIP)) == (m["cmp"] > 0)
        assert m["cmp"] >= m["cop"]


def test_plane_bounds_along_x_are_the_sagittal_thresholds():
    data = bounds_data(P)
    plane, line = data["plane"]["thresholds"], data["thresholds"]
    for strategy in ("ankle", "hip"):
        assert plane[strategy]["forward"] == pytest.approx(line[strategy][1], abs=1e-12)
        assert plane[strategy]["backward"] == pytest.approx(-line[strategy][0], abs=1e-12)
    assert plane["step"]["forward"] == pytest.approx(line["step"][1], abs=1e-12)
    assert plane["step"]["backward"] == pytest.approx(-line["step"][0], abs=1e-12)
    back, forward = step_thresholds(P)  # Sec. IV's single step, on the line and in the plane
    assert plane["step_sec4"]["forward"] == pytest.approx(forward, abs=2e-9)
    assert plane["step_sec4"]["backward"] == pytest.approx(-back, abs=2e-9)
    # Sideways the double support is 0.15 m to its edge, the hip adds the roll offset.
    assert plane["ankle"]["left"] == pytest.approx(P.omega * 0.15)
    assert plane["hip"]["left"] == pytest.approx(P.omega * (0.15 + data["cmp"]["margin"]))
    assert plane["ankle"]["left"] == pytest.approx(plane["ankle"]["right"])


def test_bad_planar_input():
    with pytest.raises(InvalidParameterError, match="y must be a finite"):
        classify(0.0, 0.0, P, y=float("nan"))
    with pytest.raises(InvalidParameterError, match="ydot must be a finite"):
        classify(0.0, 0.0, P, ydot=float("inf"))
    with pytest.raises(InvalidParameterError, match="must be finite"):
        BalanceMonitor(P).query(0.0, float("nan"), 0.0, 0.0)
    with pytest.raises(InvalidParameterError, match="ydot must be finite"):
        classify_states([0.0], [0.0], P, y=[0.0], ydot=[float("nan")])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--left-foot", "0.1"], "--left-foot must be X,Y or X,Y,YAW"),
        (["--right-foot", "a,b"], "--right-foot must be X,Y or X,Y,YAW numbers"),
        (["--foot-width", "-1"], "foot_width must be > 0"),
        (["--y", "nan"], "y must be a finite number"),
    ],
)
def test_cli_planar_bad_input_is_one_line(args, message, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["classify", "--x", "0", "--xdot", "0", *args])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1


def test_cli_side_push_and_stance():
    result = CliRunner().invoke(
        cli,
        ["classify", "--x", "0", "--y", "0.1", "--xdot", "0", "--ydot", "0.3", "--stance", "left"],
    )
    assert result.exit_code == 0, result.output
    assert "strategy          hip" in result.output
    bounds = CliRunner().invoke(cli, ["bounds", "--stance", "right", "--json"])
    plane = json.loads(bounds.output)["plane"]
    assert plane["support"]["stance"] == "right"
    assert plane["reference"] == [0.0, -0.1]


def test_large_sagittal_batches_equal_the_definition():
    # Above the chunk size the codes come from one compiled pass over the four intervals; the
    # definition is the scalar classify of each state.
    rng = np.random.default_rng(4)
    x, xdot = rng.normal(0.05, 0.2, 300_000), rng.normal(0.0, 1.0, 300_000)
    codes = classify_states(x, xdot, P)
    sample = rng.choice(x.size, 400, replace=False)
    for i in sample:
        assert STRATEGY_CODES[codes[i]] == classify(x[i], xdot[i], P).strategy
    small = np.concatenate(
        [
            classify_states(x[i : i + 50_000], xdot[i : i + 50_000], P)
            for i in range(0, x.size, 50_000)
        ]
    )
    np.testing.assert_array_equal(codes, small)  # the numpy path of small arrays
    assert len(np.unique(codes)) == 4
    with pytest.raises(InvalidParameterError, match="xdot must be finite"):
        classify_states(x, np.where(np.arange(x.size) == 7, np.nan, xdot), P)


@pytest.mark.parametrize("name", ["double", "left", "yawed"])
def test_large_planar_batches_equal_the_small_path(name):
    # Above the chunk size the planar codes come from the compiled region and step tests;
    # below it from the exact margins and the full plan: the same verdicts.
    support = SUPPORTS[name]
    x, y, xdot, ydot = random_states(150_000, seed=7)
    big = classify_states(x, xdot, P, y=y, ydot=ydot, support=support)
    pieces = [
        classify_states(
            x[i : i + 30_000],
            xdot[i : i + 30_000],
            P,
            y=y[i : i + 30_000],
            ydot=ydot[i : i + 30_000],
            support=support,
        )
        for i in range(0, x.size, 30_000)
    ]
    np.testing.assert_array_equal(big, np.concatenate(pieces))
    assert len(np.unique(big)) == 4
    scalar_y = classify_states(x, xdot, P, y=0.05, ydot=0.0, support=support)
    one = classify(x[3], xdot[3], P, y=0.05, ydot=0.0, support=support)
    assert STRATEGY_CODES[scalar_y[3]] == one.strategy
