"""MuJoCo backend (models ``foot`` and ``torso``): standing, pushes as forces, controllers
unchanged, and the critical pushes against the surfaces."""

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.control import Command, make_controller
from pushrecovery.sim.critical import critical_push
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.sim.validation import mujoco_corrected_prediction

P = load_params()


def run(controller, v=0.0, impulse=None, duration=6.0, model="foot"):
    plant = make_plant(model, P, "mujoco")
    state = plant.reset(0.0, v if impulse is None else 0.0)
    if impulse is not None:
        state = plant.apply_push(Push.from_impulse(impulse, P.mass))
    return plant, simulate(plant, make_controller(controller, P), state, duration=duration)


@pytest.mark.parametrize(("model", "controller"), [("foot", "ankle-pd"), ("torso", "mpc")])
def test_stands_still_for_two_seconds(model, controller):
    plant, result = run(controller, duration=2.0, model=model)
    assert result.outcome.value != "fell"
    assert np.abs(result.states[:, 0]).max() < 1e-3  # CoM stays over the ankle [m]
    assert abs(plant.data.qpos[plant._pitch]) < 1e-3  # the foot stays flat [rad]


@pytest.mark.parametrize("controller", ["ankle-pd", "ankle-saturated", "ankle-capture-point"])
def test_inside_recovers_outside_falls_same_as_analytic(controller):
    # Eq. (4) from x = 0: −0.157 … 0.470 m/s.
    for v, expected in ((0.3, True), (0.7, False), (-0.1, True), (-0.3, False)):
        _, mujoco_run = run(controller, v=v)
        analytic = simulate(
            make_plant("pendulum", P), make_controller(controller, P), np.array([0.0, v])
        )
        assert mujoco_run.recovered == expected == analytic.recovered, (controller, v)


@pytest.mark.parametrize("controller", ["mpc", "bang-bang"])
def test_torso_hip_strategy_same_as_analytic(controller):
    # Corrected Eq. (15) from x = 0: −0.332 … 0.645 m/s; Eq. (4): −0.157 … 0.470 m/s.
    for v, expected in ((0.55, True), (0.8, False), (-0.25, True), (-0.45, False)):
        _, mujoco_run = run(controller, v=v, model="torso")
        analytic = simulate(
            make_plant("flywheel", P),
            make_controller(controller, P),
            np.array([0.0, 0.0, v, 0.0]),
        )
        assert mujoco_run.recovered == expected == analytic.recovered, (controller, v)
        assert mujoco_run.stop_impacts == 0


def test_torso_without_hip_torque_is_the_ankle_strategy():
    # 0.55 m/s needs the hip: the ankle alone cannot hold it, on the torso model too.
    _, result = run("ankle-pd", v=0.55, model="torso")
    assert result.outcome.value == "fell"


def test_push_as_a_real_force():
    # 20 N s over 10 ms is a 0.28 m/s jump for 72 kg: inside; 50 N s (0.69 m/s): outside.
    _, inside = run("ankle-pd", impulse=20.0)
    _, outside = run("ankle-pd", impulse=50.0)
    assert inside.recovered and outside.outcome.value == "fell"
    _, back = run("ankle-pd", impulse=-5.0)
    assert back.recovered
    # 40 N s (0.56 m/s) needs the hip: the MPC recovers it on the torso model.
    _, hip = run("mpc", impulse=40.0, model="torso")
    assert hip.recovered


def test_push_ends_with_the_momentum_of_the_impulse():
    plant = make_plant("torso", P, "mujoco")
    plant.reset(0.0, 0.0)
    state = plant.apply_push(Push.from_impulse(36.0, P.mass))
    # The contact pushes back only through the ankle torque holding the CoP under the CoM:
    # over 10 ms the CoM gains J / m = 0.5 m/s to within the gravity moment's share (< 1 %).
    assert state[2] == pytest.approx(0.5, rel=0.01)
    # It travels v D / 2, plus half a 1 ms step from the semi-implicit integrator [m].
    assert state[0] == pytest.approx(0.5 * (0.01 + 0.001) / 2, rel=0.02)


@pytest.mark.parametrize(
    ("model", "controller", "strategy"), [("foot", "ankle-pd", "ankle"), ("torso", "mpc", "hip")]
)
@pytest.mark.parametrize("direction", ["forward", "backward"])
@pytest.mark.parametrize("x0", [0.0, 0.1])
def test_critical_push_against_the_surfaces(model, controller, strategy, direction, x0):
    # docs/validation.md. The corrected prediction (2 mm CoP margin, CoM travel during the
    # 10 ms push) within 1.5 %; the paper's surface within 6 % (the correction's size).
    found = critical_push(
        P, model, controller, x0, direction, tolerance=2e-3, duration=6.0, backend="mujoco"
    )
    sign = 1.0 if direction == "forward" else -1.0
    corrected = mujoco_corrected_prediction(strategy, x0, sign, P)
    assert abs(found.velocity) == pytest.approx(abs(corrected), rel=0.015), found
    assert -0.06 < found.relative_error() < 0.0, found


def test_bad_mujoco_requests():
    with pytest.raises(InvalidParameterError, match="for the mujoco backend"):
        make_plant("lipm", P, "mujoco")
    with pytest.raises(InvalidParameterError, match="backend must be"):
        make_plant("foot", P, "bullet")
    plant = make_plant("foot", P, "mujoco")
    plant.reset(0.0, 0.0)
    with pytest.raises(InvalidParameterError, match=r"duration must be >= the MuJoCo step 0\.001"):
        plant.apply_push(Push.from_impulse(10.0, P.mass, duration=4e-4))
    with pytest.raises(InvalidParameterError, match="impulse must be a finite number"):
        Push.from_impulse(float("nan"), P.mass)
    with pytest.raises(InvalidParameterError, match=r"duration must be a finite number > 0 \[s\]"):
        Push(0.1, duration=float("inf"))
    limit = r"xdot must satisfy \|xdot\| < 10 sqrt\(g L\)"
    for kind in ("force", "velocity"):
        with pytest.raises(InvalidParameterError, match=limit):
            plant.apply_push(Push(40.0, kind))
    with pytest.raises(InvalidParameterError, match="push kind must be 'force' or 'velocity'"):
        Push(0.1, "shove")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("model", "x0", "v0", "cop", "hip_torque"),
    [
        ("foot", 0.05, 0.0, 0.05, 0.0),
        ("foot", 0.0, 0.3, 0.10, 0.0),
        ("foot", 0.0, -0.1, -0.03, 0.0),
        ("torso", 0.0, 0.5, 0.10, 100.0),  # a hip strategy's start: CoP forward, τmax
        ("torso", 0.02, -0.3, -0.02, -100.0),
        ("torso", 0.05, 0.0, 0.05, 40.0),
    ],
)
def test_commanded_cop_is_where_mujoco_puts_it(model, x0, v0, cop, hip_torque):
    # The CoP → ankle torque map (errata E3, with the hip torque and the 1 cm ankle height and
    # its friction lever) against MuJoCo's own contact forces: within 0.3 mm once the soft
    # contact has followed the torque step at t = 0 (contact time constant 2 ms; the foot
    # rocks for ~35 ms, the CoP up to 9 mm off for a 70 N m step: checked from 40 ms on).
    plant = make_plant(model, P, "mujoco")
    plant.reset(x0, v0)
    for tick in range(80):  # 80 ms
        applied = plant.step(Command(cop, hip_torque), 1e-3).applied[0]
        if tick >= 40:
            assert plant.measured_cop() == pytest.approx(applied, abs=3e-4), tick


@pytest.mark.parametrize(
    ("model", "x0", "v0", "cop", "hip_torque"),
    [("foot", 0.0, 0.3, 0.10, 0.0), ("torso", 0.0, 0.5, 0.10, 100.0)],
)
def test_held_torques_keep_the_cop(model, x0, v0, cop, hip_torque):
    # With the MPC's 20 ms ticks the torques are held for 10 ms (TORQUE_HOLD): at the end of
    # each hold, where the lean has drifted most from the one the torque was computed for,
    # the CoP is still within the 0.3 mm of a refresh at every step (a 20 ms hold is 0.5 mm
    # off on the torso).
    plant = make_plant(model, P, "mujoco")
    plant.reset(x0, v0)
    plant.measure()
    for tick in range(15):
        applied = plant.step(Command(cop, hip_torque), 0.02).applied[0]
        if tick >= 1:  # after the contact has followed the torque step at t = 0
            assert plant.measured_cops[-1] == pytest.approx(applied, abs=3e-4), tick


def cli_json(*args):
    import json

    from click.testing import CliRunner

    from pushrecovery.cli.app import cli

    result = CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_cli_validate_json():
    data = cli_json(
        "validate",
        "--strategy",
        "ankle",
        "--x0",
        "0",
        "--tolerance",
        "0.01",
        "--grid",
        "0.2",
        "0.6",
        "0.4",
    )
    assert [row["direction"] for row in data["critical"]] == ["forward", "backward"]
    row = data["critical"][0]
    assert row["predicted"] == pytest.approx(0.4698, abs=1e-4)  # Eq. (4) from x0 = 0
    assert abs(row["measured"] - row["corrected"]) < 0.01
    assert data["confusion"]["labels"] == ["ankle", "hip", "step", "fall"]
    # 0.2 m/s: ankle, as predicted; 0.6 m/s: the hip surface says hip, but --strategy ankle
    # leaves only the ankle to try, so it falls.
    assert data["confusion"]["counts"][0][0] == 1 and data["confusion"]["counts"][1][3] == 1


def test_cli_simulate_mujoco_render_and_measured_cop(tmp_path):
    data = cli_json(
        "simulate",
        "--backend",
        "mujoco",
        "--model",
        "torso",
        "--controller",
        "mpc",
        "--impulse",
        "40",
        "--render",
        str(tmp_path / "run.png"),
    )
    assert data["recovered"] and data["predicted"]["strategy"] == "hip"
    assert data["after_push"]["xdot"] == pytest.approx(40 / 72, rel=0.01)
    # The measured CoP reaches the toe the controller asks for (2 mm inside the edge).
    assert data["measured_cop"]["max"] == pytest.approx(0.148, abs=2e-3)
    assert {p.split("/")[-1] for p in data["render"]} == {"run.png", "run.gif"}
    assert (tmp_path / "run.png").stat().st_size > 1000


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["simulate", "--render", "x.png"], "--render needs --backend mujoco"),
        (["simulate", "--backend", "mujoco", "--model", "foot", "--x", "1.5"], "|x| < com_height"),
        (["simulate", "--backend", "mujoco", "--model", "foot", "--impulse", "1e6"], "xdot"),
        (["validate", "--strategy", "ankle", "--tolerance", "0"], "tolerance must be"),
        (["validate", "--x0", "0.2"], "--x0 must lie on the foot"),
        (["validate", "--grid", "1", "0", "0.1"], "--grid needs START <= STOP"),
        (["validate", "--grid", "0", "1", "1e-6"], "--grid gives 1000001 values; at most"),
        (
            ["simulate", "--backend", "mujoco", "--model", "foot", "--control-period", "0.0004"],
            "control_period must be >= half the MuJoCo step",
        ),
        (
            ["simulate", "--backend", "mujoco", "--model", "foot", "--controller", "mpc"],
            "use the flywheel model",
        ),
    ],
)
def test_cli_mujoco_bad_input_is_one_line(capsys, args, words):
    from pushrecovery.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err, err


def test_push_a_named_body():
    plant = make_plant("torso", P, "mujoco")
    plant.reset(0.0, 0.0)
    at_com = plant.apply_push(Push.from_impulse(20.0, P.mass))
    plant.reset(0.0, 0.0)
    # The CoM body by name: the same push.
    named = plant.apply_push(Push.from_impulse(20.0, P.mass, body="torso"))
    np.testing.assert_array_equal(at_com, named)
    with pytest.raises(InvalidParameterError, match="body must be one of"):
        plant.apply_push(Push.from_impulse(20.0, P.mass, body="head"))
    with pytest.raises(InvalidParameterError, match="body must be a body name of 1 to 100"):
        Push(0.1, body="")


def test_scheduled_push_acts_from_the_next_step():
    plant = make_plant("torso", P, "mujoco")
    before = plant.reset(0.0, 0.0)
    now = plant.apply_push(Push.from_impulse(20.0, P.mass, duration=0.0104, scheduled=True))
    np.testing.assert_array_equal(now, before)  # nothing moves yet
    assert plant.push_left == pytest.approx(0.010)  # 10 whole 1 ms steps
    plant.step(Command(0.0), 0.004)
    assert plant.push_left == pytest.approx(0.006)
    pushed = plant.step(Command(0.0), 0.006).state
    assert plant.push_left == 0.0 and plant.push_now == 0.0
    assert pushed[2] > 0.2  # J / m = 0.28 m/s, less what the ankle held
    # A velocity jump is now, the pose kept.
    jumped = plant.apply_push(Push(0.2, "velocity"))
    # The CoM velocity, the pose restored (the foot's rate stays, the torso upright and at rest).
    assert jumped[2] == pytest.approx(pushed[2] + 0.2, abs=1e-3)
    assert jumped[0] == pytest.approx(pushed[0], abs=1e-12)


@pytest.mark.parametrize("model", ["foot", "torso", "biped"])
def test_models_are_specs_whose_mjcf_compiles_to_the_same_model(model):
    # Built with mujoco.MjSpec (named elements, no MJCF text); the MJCF MuJoCo writes from the
    # spec compiles to the same masses, inertias, geometry and joints.
    import mujoco

    from pushrecovery.sim.registry import PLANTS

    module, _, name = PLANTS["mujoco"][model].partition(":")
    cls = getattr(__import__(module, fromlist=[name]), name)
    compiled = cls.build(P).compile()
    again = mujoco.MjModel.from_xml_string(cls.xml(P))
    for field in ("body_mass", "body_inertia", "body_pos", "geom_size", "geom_pos", "jnt_range"):
        np.testing.assert_allclose(getattr(again, field), getattr(compiled, field), atol=1e-12)
    assert compiled.body("torso" if model != "foot" else "body").mass[0] > 0.0
