"""Your own robot from an MJCF file (issue 33, item 3, first part): parameters, runs, refusals."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from pushrecovery import load_params
from pushrecovery.cli import main
from pushrecovery.errors import InvalidParameterError

mujoco = pytest.importorskip("mujoco")

from pushrecovery.sim.mujoco.humanoid3d.biped3d import bent_knee_qpos, build_biped3d  # noqa: E402
from pushrecovery.sim.mujoco.humanoid3d.mjcf import MjcfPlant, describe_mjcf  # noqa: E402
from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant  # noqa: E402
from pushrecovery.sim.mujoco.humanoid3d.runs3d import critical_push3d  # noqa: E402

FEET = ("left_foot", "right_foot")
#: The body parameters an MJCF file gives back (the rest are the planner's, not the body's).
MEASURED = ("mass", "com_height", "gravity", "heel", "toe", "foot_width", "stance_width",
            "flywheel_inertia", "flywheel_inertia_roll", "torque_max", "torque_max_roll",
            "flywheel_angle_max", "flywheel_angle_max_roll", "leg_length")  # fmt: skip


@pytest.fixture(scope="module")
def biped_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The generated biped3d written to an MJCF file, with its bent-knee stance as a keyframe."""
    spec = build_biped3d(load_params())
    spec.add_key(name="bent", qpos=list(bent_knee_qpos(spec.compile())))
    path = tmp_path_factory.mktemp("mjcf") / "biped3d.xml"
    path.write_text(spec.to_xml())
    return path


def test_the_biped_written_to_mjcf_gives_back_its_body(biped_file: Path) -> None:
    # Straight-legged ("stand"), the measured body is the one the model was generated from.
    params = load_params()
    found = describe_mjcf(biped_file, feet=FEET, torso="torso", keyframe="stand").params
    for name in MEASURED:
        assert getattr(found, name) == pytest.approx(getattr(params, name), rel=1e-6), name


def test_the_biped_written_to_mjcf_has_the_built_in_critical_push(biped_file: Path) -> None:
    built_in = Biped3DPlant(load_params())
    mine = MjcfPlant(biped_file, FEET, "torso", keyframe="bent")
    assert mine.qpos == pytest.approx(built_in.qpos, abs=1e-12)
    pushes = [critical_push3d(plant, 0.0, tolerance=1.0, duration=1.0, hip=False)
              for plant in (built_in, mine)]  # fmt: skip
    assert pushes[0].impulse == pushes[1].impulse and pushes[0].bracket == pushes[1].bracket


def run_cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as caught:
        main(list(args))
    out, err = capsys.readouterr()
    code = caught.value.code
    return (0 if code is None else int(code)), out, err


def test_humanoid_simulate_runs_an_mjcf_file(biped_file: Path, capsys) -> None:
    code, out, err = run_cli(
        capsys, "humanoid", "simulate", "--model", str(biped_file), "--left-foot-body",
        "left_foot", "--right-foot-body", "right_foot", "--torso-body", "torso", "--keyframe",
        "bent", "--push", "10", "--duration", "4", "--no-stepping", "--json",
    )  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert data["model"] == str(biped_file) and data["outcome"] == "recovered"
    assert data["hip_task"] is False and data["physics"]["violations"] == []


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (("--left-foot-body", "left_foot"), "give both --left-foot-body and --right-foot-body"),
        (("--left-foot-body", "torso_x", "--right-foot-body", "right_foot"),
         "left foot must be a body of the model, got 'torso_x'; candidates: left_foot, "
         "right_foot"),
        (("--left-foot-body", "left_foot", "--right-foot-body", "right_foot", "--torso-body",
          "head"), "torso must be a body of the model, got 'head'; candidates: torso"),
        (("--left-foot-body", "left_foot", "--right-foot-body", "right_foot", "--torso-body",
          "torso", "--keyframe", "sit"), "keyframe must be one of the model's ['stand', 'bent']"),
        (("--left-foot-body", "left_foot", "--right-foot-body", "right_foot", "--torso-body",
          "torso", "--mass", "50"), "has the model's own body"),
    ],
)  # fmt: skip
def test_an_mjcf_model_is_refused_in_one_line(biped_file: Path, capsys, extra, words) -> None:
    code, _, err = run_cli(capsys, "humanoid", "simulate", "--model", str(biped_file), *extra)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1


def test_bad_files_and_misplaced_options_are_refused(
    biped_file: Path, tmp_path: Path, capsys
) -> None:
    ball = tmp_path / "ball.xml"
    ball.write_text("<mujoco><worldbody><body><geom size='0.1'/></body></worldbody></mujoco>")
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><body>")
    cases = ((tmp_path / "none.xml", "must be an MJCF file"),
             (ball, "must have a free joint first"), (broken, "broken.xml"))  # fmt: skip
    for path, words in cases:
        code, _, err = run_cli(capsys, "humanoid", "simulate", "--model", str(path))
        assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    code, _, err = run_cli(capsys, "humanoid", "simulate", "--torso-body", "torso")
    assert code == 2 and "--torso-body needs --model PATH.xml" in err
    with pytest.raises(InvalidParameterError, match="feet"):
        describe_mjcf(biped_file, feet=("left_foot",), torso="torso")  # type: ignore[arg-type]
    # A "foot" whose chain holds only the hip's joints: no ankle pitch, refused naming it.
    with pytest.raises(InvalidParameterError, match="left foot: its leg needs a hip and an ankle"):
        describe_mjcf(biped_file, feet=("left_thigh", "right_thigh"), torso="torso")


def test_the_g1_from_its_mjcf_file_has_the_robots_parameters() -> None:
    from pushrecovery.sim.mujoco.humanoid3d import robots

    try:
        path = robots.robot_path("g1")
    except robots.RobotsExtraMissing:
        pytest.skip("the robots extra is not installed")
    found = describe_mjcf(path, feet=("left_ankle_roll_link", "right_ankle_roll_link"),
                          torso="torso_link", keyframe="stand").params  # fmt: skip
    known = robots.robot_params("g1")
    for name in MEASURED:
        assert getattr(found, name) == pytest.approx(getattr(known, name), rel=1e-9), name
    assert found.foot_polygon == known.foot_polygon
    assert not math.isnan(found.com_height)


def test_bounds_of_an_mjcf_file_are_those_of_its_body(biped_file: Path, capsys) -> None:
    code, out, err = run_cli(
        capsys, "bounds", "--model", str(biped_file), "--left-foot-body", "left_foot",
        "--right-foot-body", "right_foot", "--torso-body", "torso", "--keyframe", "stand",
        "--json",
    )  # fmt: skip
    assert code == 0, err
    mine = json.loads(out)
    code, out, err = run_cli(capsys, "bounds", "--json")  # the preset it was generated from
    preset = json.loads(out)
    for name in ("ankle", "hip"):
        assert mine["thresholds"][name] == pytest.approx(preset["thresholds"][name], rel=1e-6)
    assert mine["params"]["mass"] == preset["params"]["mass"]
    for args, words in ((("--keyframe", "stand"), "--keyframe needs --model PATH.xml"),
                        (("--model", "robot.urdf"), "must be an MJCF file PATH.xml")):  # fmt: skip
        code, _, err = run_cli(capsys, "bounds", *args)
        assert code == 2 and words in err


def test_humanoid_validate_measures_an_mjcf_file(biped_file: Path, tmp_path: Path, capsys) -> None:
    body = ("--model", str(biped_file), "--left-foot-body", "left_foot", "--right-foot-body",
            "right_foot", "--torso-body", "torso", "--keyframe", "bent")  # fmt: skip
    code, out, err = run_cli(
        capsys, "humanoid", "validate", *body, "--azimuth", "0", "--strategy", "ankle",
        "--rel-tolerance", "0.2", "--duration", "1", "--no-confusion", "--out", str(tmp_path),
        "--json",
    )  # fmt: skip
    assert code == 0, err
    (row,) = json.loads(out)["critical"]
    assert row["strategy"] == "ankle" and 0.5 * row["predicted"] < row["measured"]
    assert (tmp_path / "validation3d_biped3d.md").exists()


def test_a_campaign_on_an_mjcf_file_is_the_built_in_campaign(biped_file: Path, tmp_path) -> None:
    # The same pushes on the biped3d and on its MJCF file (the same standing pose): the same
    # outcomes and strategies (the file's body is measured in its bent-knee pose, so its
    # predictions and the controller's gains differ in the last digits); the spec keeps the
    # file and its bodies, so that the workers build it and a resumed campaign is the same.
    import pyarrow.parquet as pq

    from pushrecovery.campaign import CampaignSpec, run_campaign
    from pushrecovery.sim.mjcf_source import MjcfSource

    source = MjcfSource(str(biped_file), FEET, "torso", "bent")
    mine = source.plant()
    grid = dict(backend="mujoco", controller="wbc-ankle", x0=(0.0, 0.0, 1.0),
                fraction=(0.6, 1.4, 0.8), azimuths=(0.0, 90.0), duration=3.0)  # fmt: skip
    specs = {
        "built-in": CampaignSpec(model="biped3d", params=load_params(), **grid),
        "mjcf": CampaignSpec(model="mjcf", mjcf=source, params=mine.params, **grid),
    }
    assert specs["mjcf"].model_name == "biped3d"
    stored = specs["mjcf"].to_dict()
    assert CampaignSpec.from_dict(stored).to_dict() == stored and stored["mjcf"]["feet"] == list(
        FEET
    )
    rows = {}
    for name, spec in specs.items():
        result = run_campaign(spec, tmp_path / name, workers=1, isolated=False)
        assert result is not None
        rows[name] = pq.read_table(result.pushes_file).to_pylist()
    assert len(rows["mjcf"]) == 4
    keys = ("azimuth", "fraction", "predicted", "outcome", "used", "steps")
    for built_in, file in zip(rows["built-in"], rows["mjcf"], strict=True):
        assert {k: file[k] for k in keys} == {k: built_in[k] for k in keys}
        assert file["impulse"] == pytest.approx(built_in["impulse"], rel=0.02)
    assert {row["outcome"] for row in rows["mjcf"]} == {"recovered", "fell"}
    with pytest.raises(InvalidParameterError, match="needs its file"):
        CampaignSpec(model="mjcf", params=mine.params, **grid)
    with pytest.raises(InvalidParameterError, match="an MJCF model has the robot's own body"):
        CampaignSpec(model="mjcf", mjcf=source, params=mine.params, sweeps={"mass": (60, 70, 10)},
                     **grid)  # fmt: skip


def test_humanoid_campaign_and_validate_take_an_mjcf_file(
    biped_file: Path, tmp_path: Path, capsys
) -> None:
    body = ("--model", str(biped_file), "--left-foot-body", "left_foot", "--right-foot-body",
            "right_foot", "--torso-body", "torso", "--keyframe", "bent")  # fmt: skip
    code, out, err = run_cli(
        capsys, "humanoid", "campaign", *body, "--azimuth", "0", "--fraction", "0.5", "1.5",
        "1.0", "--strategy", "ankle", "--duration", "1", "--workers", "1", "--out",
        str(tmp_path / "c"), "--json",
    )  # fmt: skip
    assert code == 0, err
    assert json.loads(out)["pushes"] == 2 and (tmp_path / "c" / "confusion3d.csv").exists()
    code, out, err = run_cli(
        capsys, "humanoid", "validate", *body, "--azimuth", "0", "--no-critical",
        "--fractions", "0.5,1.5", "--duration", "1", "--out", str(tmp_path / "v"), "--json",
    )  # fmt: skip
    assert code == 0, err
    confusion = json.loads(out)["confusion"]
    apart = sum(map(sum, confusion["apart"].values()))
    assert sum(map(sum, confusion["counts"])) + apart == 2
    assert (tmp_path / "v" / "confusion_biped3d").is_dir()
    code, _, err = run_cli(
        capsys, "humanoid", "campaign", *body, "--param", "mass=60:70:10", "--fraction", "0.5",
        "1.5", "1.0", "--out", str(tmp_path / "d"),
    )  # fmt: skip
    assert code == 2 and "an MJCF model has the robot's own body" in err


def test_feet_and_torso_are_found_by_their_names(biped_file: Path, tmp_path: Path) -> None:
    # The rules (mjcf module docstring) find what the options would name, on the biped's file
    # and on the robots' own files (the G1's ankle roll link, below its ankle pitch link).
    named = describe_mjcf(biped_file, feet=FEET, torso="torso", keyframe="stand")
    found = describe_mjcf(biped_file, keyframe="stand")
    assert found.feet == named.feet and found.torso == "torso" and found.params == named.params
    from pushrecovery.sim.mujoco.humanoid3d import robots

    try:
        paths = {name: robots.robot_path(name) for name in ("g1", "h1")}
    except robots.RobotsExtraMissing:
        paths = {}
    expected = {"g1": ("left_ankle_roll_link", "right_ankle_roll_link"),
                "h1": ("left_ankle_link", "right_ankle_link")}  # fmt: skip
    for name, path in paths.items():
        robot = describe_mjcf(path)
        assert tuple(robot.model.body(i).name for i in robot.feet) == expected[name]
        assert robot.torso == "torso_link"


def test_bodies_the_rules_cannot_decide_are_refused_listing_the_candidates(
    tmp_path: Path,
) -> None:
    def variant(edit) -> Path:
        spec = build_biped3d(load_params())
        edit(spec)
        path = tmp_path / "variant.xml"
        path.write_text(spec.to_xml())
        return path

    def camera(spec) -> None:  # a second body whose name holds "torso"
        spec.body("torso").add_body(name="torso_camera", pos=[0, 0, 0.3]).add_geom(size=[0.02])

    def hand(spec) -> None:  # a second left "foot": a hand with a sole
        spec.body("torso").add_body(name="left_hand_sole", pos=[0, 0.3, 0.3]).add_geom(size=[0.02])

    def rename(spec) -> None:
        spec.body("torso").name = "upper"

    cases = ((camera, "torso could not be found by its name: torso, torso_camera"),
             (hand, "feet could not be found by their names (left: ['left_foot', "
                    "'left_hand_sole'], right: ['right_foot'])"),
             (rename, "torso could not be found by its name (none holds"))  # fmt: skip
    for edit, words in cases:
        with pytest.raises(InvalidParameterError) as caught:
            describe_mjcf(variant(edit))
        assert words in str(caught.value)


def test_bad_mjcf_sources_are_refused_by_name(biped_file: Path) -> None:
    from pushrecovery.errors import ParameterTypeError
    from pushrecovery.sim.mjcf_source import MjcfSource, model_name

    for kwargs, words in (
        ({"path": "", "feet": FEET, "torso": "torso"}, "path must be an MJCF file's path"),
        ({"path": str(biped_file), "feet": ("left_foot",), "torso": "torso"}, "feet must be two"),
        ({"path": str(biped_file), "feet": FEET, "torso": ""}, "must be non-empty names"),
        ({"path": str(biped_file), "feet": FEET, "torso": "torso", "keyframe": 3}, "non-empty"),
    ):
        with pytest.raises(InvalidParameterError, match=words):
            MjcfSource(**kwargs)
    with pytest.raises(InvalidParameterError, match="malformed MJCF source"):
        MjcfSource.from_dict({"path": str(biped_file)})
    with pytest.raises(ParameterTypeError, match="path must be a str or a Path"):
        model_name(3.0)  # type: ignore[arg-type]
    assert model_name("robots/unitree_h1/scene.xml") == "unitree_h1"
    assert model_name("my_robot.xml") == "my_robot"
    # A source builds its plant; a missing body is the plant's one-line refusal.
    with pytest.raises(InvalidParameterError, match="torso must be a body of the model"):
        MjcfSource(str(biped_file), FEET, "head").plant()


def test_a_robot_standing_off_the_world_origin_has_the_same_prediction(tmp_path: Path) -> None:
    # The prediction's frame is the ankles' midpoint (Support.from_params), not the world:
    # the biped3d's file standing 5 cm forward and 3 cm left of the origin has the same r0 and
    # the same predicted critical impulses as standing on it (the H1's ankles are 4 cm ahead
    # of its world origin: before, its backward limit was predicted 4 cm of CoM travel long).
    from pushrecovery.experiments.validation3d.predict import predicted_critical_impulses

    plants = []
    for shift in ((0.0, 0.0), (0.05, 0.03)):
        spec = build_biped3d(load_params())
        model = spec.compile()
        qpos = list(bent_knee_qpos(model))
        qpos[0] += shift[0]
        qpos[1] += shift[1]
        spec.add_key(name="bent", qpos=qpos)
        path = tmp_path / f"biped_{shift[0]}.xml"
        path.write_text(spec.to_xml())
        plants.append(MjcfPlant(path, FEET, "torso", keyframe="bent"))
    here, there = plants
    assert there.ankle == pytest.approx((0.05, 0.03), abs=1e-9)
    assert there.standing_origin == pytest.approx(here.standing_origin, abs=1e-9)
    for azimuth in (0.0, 90.0, 180.0):
        predicted = [predicted_critical_impulses(p.params, azimuth, origin=p.standing_origin)
                     for p in plants]  # fmt: skip
        assert predicted[1]["ankle"] == pytest.approx(predicted[0]["ankle"], rel=1e-9)


def test_a_bad_ankle_origin_is_refused_by_name(biped_file: Path) -> None:
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant

    described = describe_mjcf(biped_file, keyframe="bent")
    for ankle, words in ((("a", 0.0), "ankle x must be"), ((0.0, math.nan), "ankle y must be"),
                         ((0.0,), "ankle must be")):  # fmt: skip
        with pytest.raises(InvalidParameterError, match=words):
            Humanoid3DPlant(described.params, described.model, described.qpos, FEET, "torso",
                            "torso", ankle=ankle)  # fmt: skip
