"""The inputs a robot has: the stance and foot poses a run starts on (plant, loop, CLI, TOML)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from pushrecovery.cli import main
from pushrecovery.cli.app import cli
from pushrecovery.control.base import Controller
from pushrecovery.control.recovery.plane import PlaneRecoveryController
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.presets import load_params, load_support
from pushrecovery.sim.plane_stepping import PlaneSteppingPlant
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import classify

P = load_params()
#: On the left foot, pushed to the right: one step on one foot, the ankle's on both feet.
ONE_STEP = (0.0, 0.1, 0.0, -0.5)  # x, y [m], xdot, ydot [m/s]


class BlindController(PlaneRecoveryController):
    """recovery-plane without its observe: the feet it commands, never the plant's."""

    observe = Controller.observe


@pytest.fixture(scope="module")
def blind() -> BlindController:
    return BlindController(P)


@pytest.fixture(scope="module")
def controller() -> PlaneRecoveryController:
    return PlaneRecoveryController(P)


def test_every_run_starts_on_the_support_given() -> None:
    left = Support.from_params(P, "left")
    plant = PlaneSteppingPlant(P, support=left)
    for _ in range(2):  # a second run starts there too
        plant.reset(0.0, 0.0, 0.1, 0.0)
        assert plant.support.stance is Stance.LEFT
        info = plant.info()
        assert info.feet is plant.support
        assert info.footholds_xy == (left.ankle,) and info.footholds == (left.ankle[0],)
    right = Support.from_params(P, "right", right=FootPose(0.3, -0.2, 0.2))
    plant.reset(0.3, 0.0, -0.2, 0.0, support=right)
    assert plant.start_support.right == FootPose(0.3, -0.2, 0.2)
    assert plant.info().feet is plant.support and plant.support.stance is Stance.RIGHT
    assert make_plant("stepping-plane", P, support=left).start_support.stance is Stance.LEFT


def test_the_default_start_is_both_feet() -> None:
    plant = PlaneSteppingPlant(P)
    plant.reset(0.0, 0.0)
    assert plant.support is Support.from_params(P, Stance.DOUBLE)


def test_a_support_is_this_bodys_feet_at_its_poses() -> None:
    wide = load_params(overrides={"foot_width": 0.3})
    given = Support.from_params(wide, "left", left=FootPose(0.1, 0.2, 0.1))
    plant = PlaneSteppingPlant(P, support=given)
    assert plant.start_support.left == given.left
    assert plant.start_support.polygon.area == pytest.approx(0.2 * 0.1)


def test_the_start_state_is_checked_from_the_starting_ankle() -> None:
    far = Support.from_params(P, "left", left=FootPose(5.0, 1.0, 0.0))
    plant = PlaneSteppingPlant(P, support=far)
    plant.reset(5.0, 0.0, 1.0, 0.0)
    with pytest.raises(InvalidParameterError, match=r"x - ankle x must satisfy"):
        plant.reset(0.0, 0.0, 1.0, 0.0)


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (lambda: PlaneSteppingPlant(P, support="left"), ParameterTypeError, "support"),  # type: ignore[arg-type]
        (
            lambda: make_plant("flywheel", P, support=Support.from_params(P, "left")),
            InvalidParameterError,
            "stepping-plane model only",
        ),
        (
            lambda: PlaneSteppingPlant(
                load_params(overrides={"foot_width": 0.25}), support=Support.from_params(P)
            ),
            InvalidParameterError,
            "overlap",
        ),
    ],
)
def test_a_bad_support_is_refused(call: object, error: type[Exception], match: str) -> None:
    with pytest.raises(error, match=match):
        call()  # type: ignore[operator]


def test_the_reported_feet_change_no_default_run(
    controller: PlaneRecoveryController, blind: BlindController
) -> None:
    """Runs from both feet: bit for bit with and without the plant's reports of the feet."""
    for x, y, xdot, ydot in [(0.02, 0.01, 0.9, 0.2), (0.0, 0.0, 1.6, -0.5), (0.0, 0.0, 0.2, 1.2)]:
        runs = []
        for each in (controller, blind):
            plant = make_plant("stepping-plane", P)
            runs.append(simulate(plant, each, plant.reset(x, xdot, y, ydot), duration=2.0))
        assert np.array_equal(runs[0].states, runs[1].states)
        assert runs[0].footholds_xy == runs[1].footholds_xy and len(runs[0].footholds_xy) > 1


def test_a_run_from_one_foot_takes_the_step_the_verdict_promises(
    controller: PlaneRecoveryController,
) -> None:
    """On the left foot pushed right: the verdict's one step, landed where its plan puts it."""
    x, y, xdot, ydot = ONE_STEP
    left = Support.from_params(P, "left")
    verdict = classify(x, xdot, P, y=y, ydot=ydot, support=left)
    assert verdict.strategy == "step" and verdict.steps == 1
    assert classify(x, xdot, P, y=y, ydot=ydot).strategy == "ankle"  # on both feet
    plant = make_plant("stepping-plane", P, support=left)
    result = simulate(plant, controller, plant.reset(x, xdot, y, ydot), duration=3.0)
    assert result.outcome.value == "recovered"
    assert result.footholds_xy[0] == left.ankle and len(result.footholds_xy) == 2
    planned = verdict.to_dict()["plan"]["footholds"][0]
    assert result.footholds_xy[1] == pytest.approx(tuple(planned), abs=1e-9)


def invoke(*args: str) -> str:
    result = CliRunner().invoke(cli, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.output


# --- the CLI: simulate --stance, --left-foot, --right-foot; a --params file's [feet] ---------


def _fails(capsys: pytest.CaptureFixture[str], args: list[str]) -> str:
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("pushrecovery: error: ")
    assert "Traceback" not in err
    return err


PLANE = ["simulate", "--model", "stepping-plane", "--duration", "0.2"]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["simulate", "--stance", "left"], "--stance needs --model stepping-plane"),
        (["simulate", "--left-foot", "0,0.1"], "--left-foot needs --model stepping-plane"),
        (
            ["simulate", "--model", "flywheel", "--right-foot", "0,-0.1,0.1"],
            "--right-foot needs --model stepping-plane (the feet on the ground plane), "
            "got --model flywheel",
        ),
        ([*PLANE, "--stance", "both"], "Invalid value for '--stance'"),
        ([*PLANE, "--left-foot", "0"], "--left-foot must be X,Y or X,Y,YAW"),
        ([*PLANE, "--left-foot", "0,a"], "--left-foot must be X,Y or X,Y,YAW numbers"),
        ([*PLANE, "--left-foot", "0,0.1,nan"], "--left-foot must be finite"),
        ([*PLANE, "--right-foot", "0,-0.1,10"], "yaw must be within [−π, π] rad"),
        ([*PLANE, "--right-foot", "0,-0.1,0,1"], "--right-foot must be X,Y or X,Y,YAW"),
        ([*PLANE, "--left-foot", "0,-0.05"], "the feet overlap"),
        ([*PLANE, "--stance", "left", "--left-foot", "3,0.1"], "x - ankle x must satisfy"),
    ],
)
def test_simulate_support_bad_input_is_one_line_exit_2(
    capsys: pytest.CaptureFixture[str], args: list[str], words: str
) -> None:
    assert words in _fails(capsys, args)


def test_simulate_starts_on_the_feet_given(tmp_path: Path) -> None:
    args = [*PLANE, "--controller", "ankle-capture-point", "--y", "0.1", "--json"]
    data = json.loads(invoke("simulate", *args[1:], "--stance", "left"))
    assert data["support"]["stance"] == "left"
    assert data["footholds_xy"] == [[0.0, 0.1]] and data["predicted"]["strategy"] == "ankle"
    feet = tmp_path / "robot.toml"
    feet.write_text('mass = 60.0\n[feet]\nstance = "left"\nleft = {x = 0.5, y = 0.1, yaw = 0.2}\n')
    data = json.loads(invoke("simulate", *args[1:], "--x", "0.5", "--params", str(feet)))
    assert data["support"]["left"] == {"x": 0.5, "y": 0.1, "yaw": 0.2}
    assert data["footholds_xy"] == [[0.5, 0.1]]
    flags = ["--x", "0.5", "--params", str(feet), "--stance", "double", "--right-foot", "0.5,-0.1"]
    assert json.loads(invoke("simulate", *args[1:], *flags))["support"]["stance"] == "double"
    # Sagittal models ignore a file's feet; the ground-plane commands read them.
    assert invoke("simulate", "--params", str(feet), "--duration", "0.1")
    bounds = json.loads(invoke("bounds", "--params", str(feet), "--json"))
    assert bounds["plane"]["support"]["stance"] == "left"


def test_the_default_simulate_output_is_unchanged_but_for_the_support() -> None:
    data = json.loads(invoke(*PLANE, "--controller", "ankle-capture-point", "--json"))
    assert data["support"] == Support.from_params(P).to_dict()
    assert data["footholds_xy"] == [[0.0, 0.0]]


# --- a TOML file's [feet] -------------------------------------------------------------------


def test_feet_table_loads(tmp_path: Path) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(
        'mass = 48.0\n[feet]\nstance = "right"\n'
        "left = {x = 0.0, y = 0.1, yaw = 0.1745}\nright = {x = 0.05, y = -0.1}\n"
    )
    params = load_params(file=path)  # the body ignores where it stands
    assert params.mass == 48.0
    support = load_support(params, path)
    assert support.stance is Stance.RIGHT
    assert (support.left, support.right) == (FootPose(0.0, 0.1, 0.1745), FootPose(0.05, -0.1))
    over = load_support(params, path, {"stance": "left", "right": None})
    assert over.stance is Stance.LEFT and over.right == support.right
    assert load_support(params) is Support.from_params(params)
    plain = tmp_path / "plain.toml"
    plain.write_text("mass = 48.0\n")
    assert load_support(params, plain) is Support.from_params(params)


def test_the_documented_feet_load(tmp_path: Path) -> None:
    text = (Path(__file__).parents[1] / "docs" / "conventions.md").read_text()
    blocks = [b for b in re.findall(r"```toml\n(.*?)```", text, flags=re.S) if "[feet]" in b]
    assert blocks
    for index, block in enumerate(blocks):
        path = tmp_path / f"{index}.toml"
        path.write_text(block)
        load_support(load_params(file=path), path)


@pytest.mark.parametrize(
    ("feet", "words"),
    [
        ("feet = 3", "[feet] must be a table"),
        ('[feet]\nstance = "both"', "[feet] stance must be one of ['double', 'left', 'right']"),
        ("[feet]\nstance = 1", "[feet] stance must be one of"),
        ("[feet]\nlefts = {x = 0, y = 0.1}", "unknown key 'lefts' in [feet]"),
        ("[feet]\nleft = [0, 0.1]", "[feet] left must be a table {x = ..., y = ..., yaw = ...}"),
        ("[feet]\nleft = {x = 0}", "[feet] left needs y [m]"),
        ("[feet]\nright = {y = -0.1}", "[feet] right needs x [m]"),
        ("[feet]\nleft = {x = 0, y = 0.1, z = 0}", "unknown key 'z' in [feet] left"),
        ('[feet]\nleft = {x = "0", y = 0.1}', "[feet] left.x must be a number [m]"),
        ("[feet]\nleft = {x = 0, y = 0.1, yaw = true}", "[feet] left.yaw must be a number [rad]"),
        ("[feet]\nleft = {x = 0, y = 0.1, yaw = 10.0}", "yaw must be within [−π, π] rad"),
        ("[feet]\nleft = {x = 0, y = 0.1, yaw = nan}", "[feet] left: foot pose yaw"),
        ("[feet]\nleft = {x = 1e9, y = 0.1}", "[feet] left: foot pose x must be within"),
        ("[feet]\nleft = {x = 0, y = -0.05}", "the feet overlap"),
    ],
)
def test_a_malformed_feet_table_is_refused(tmp_path: Path, feet: str, words: str) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(f"mass = 60.0\n{feet}\n")
    with pytest.raises(InvalidParameterError) as error:
        load_support(P, path)
    assert words in str(error.value)
    if "overlap" not in words:  # every command refuses a malformed table, not only the plane's
        with pytest.raises(InvalidParameterError):
            load_params(file=path)


def test_a_malformed_feet_table_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "robot.toml"
    path.write_text("[feet]\nleft = {x = 0, y = 0.1, yaw = 10.0}\n")
    for args in (["bounds"], ["simulate", "--duration", "0.1"], [*PLANE]):
        assert "yaw must be within" in _fails(capsys, [*args, "--params", str(path)])


@pytest.mark.parametrize(
    ("overrides", "error", "words"),
    [
        ({"stance": "both"}, InvalidParameterError, "stance must be one of"),
        ({"feet": "left"}, InvalidParameterError, "unknown support override 'feet'"),
        ({"left": (0.0, 0.1)}, ParameterTypeError, "left"),
        ([("stance", "left")], ParameterTypeError, "overrides must be a mapping"),
    ],
)
def test_bad_support_overrides(overrides: object, error: type[Exception], words: str) -> None:
    with pytest.raises(error, match=re.escape(words)):
        load_support(P, None, overrides)  # type: ignore[arg-type]
