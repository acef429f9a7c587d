"""The CLI: JSON contract keys, readable tables, and one-line errors with exit status 2."""

import json
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from pushrecovery.cli import main
from pushrecovery.cli.app import cli


def invoke(*args):
    result = CliRunner().invoke(cli, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.output


def run_json(*args):
    return json.loads(invoke(*args, "--json"))


def test_bounds_contract():
    data = run_json("bounds")
    assert set(data) >= {"params", "omega", "cop"}
    assert data["cop"] == {"lower": -0.05, "upper": 0.15}
    assert data["params"]["mass"] == 72.0
    assert data["omega"] == pytest.approx(9.81**0.5)


def test_bounds_cmp_keys():
    cmp = run_json("bounds")["cmp"]
    assert set(cmp) >= {"lower", "upper", "margin", "t_max"}
    assert cmp["t_max"] == pytest.approx((10.0 * 1.0 / 100.0) ** 0.5)
    assert cmp["upper"] == pytest.approx(0.15 + cmp["margin"])
    assert cmp["lower"] == pytest.approx(-0.05 - cmp["margin"])
    assert run_json("bounds", "--torque-max", "0")["cmp"]["t_max"] is None


def test_step_contract():
    one = run_json("step", "--v0", "1.0")
    keys = {
        "theta",
        "theta_rate",
        "time_to_impact",
        "step_length",
        "com_to_foot",
        "velocity_before",
        "velocity_after",
        "height_after",
        "theta_range",
        "step_length_range",
        "centred_step_length",
        "stance_leg_in_compression",
    }
    assert set(one) >= keys and set(one["velocity_before"]) == {"x", "z"}
    low, high = one["step_length_range"]
    assert low < one["step_length"] < high
    assert one["step_length"] == pytest.approx(2 * one["com_to_foot"])
    several = run_json("step", "--v0", "0.5", "--v0", "1.5")
    assert [row["v0"] for row in several] == [0.5, 1.5]
    ranged = run_json("step", "--v0-range", "0.5", "1.5", "0.25")
    assert [row["v0"] for row in ranged] == pytest.approx([0.5, 0.75, 1.0, 1.25, 1.5])


def test_bounds_thresholds_and_classify_step():
    thresholds = run_json("bounds")["thresholds"]
    assert set(thresholds) >= {"ankle", "hip"}
    for name in ("ankle", "hip", "step"):
        back, forward = thresholds[name]
        assert back < 0 < forward
    assert thresholds["ankle"][1] < thresholds["hip"][1] < thresholds["step"][1]
    stepped = run_json("classify", "--x", "0", "--xdot", "1.2")
    assert stepped["strategy"] == "step" and stepped["step_length"] > 0.3
    assert run_json("classify", "--x", "0", "--xdot", "4.3")["strategy"] == "fall"
    assert stepped["steps"] == 1 and stepped["plan"]["touchdowns"] == [0.2]
    # The stepping model's controller takes Sec. IV's instantaneous step (bounds' step_sec4).
    run = run_json("simulate", "--model", "stepping", "--controller", "recovery", "--xdot", "1.2")
    assert run["recovered"] and len(run["footholds"]) == 2
    from pushrecovery import load_params
    from pushrecovery.surfaces.step import plan_step

    assert run["footholds"][1] == pytest.approx(plan_step(0.0, 1.2, load_params()).step_length)
    assert thresholds["step_sec4"][1] < thresholds["step"][1] < thresholds["steps"]["inf"][1]


def test_the_string_registries_name_real_classes():
    import importlib

    from pushrecovery.cli.app import COMMANDS
    from pushrecovery.control import CONTROLLERS
    from pushrecovery.control.registry import CONTROLLER_PATHS
    from pushrecovery.sim.registry import PLANTS

    def load(path):
        module, _, attribute = path.partition(":")
        return getattr(importlib.import_module(module), attribute)

    for name, path in CONTROLLER_PATHS.items():
        assert load(path).name == name and CONTROLLERS[name] is load(path)
    for backend, models in PLANTS.items():
        for name, path in models.items():
            assert hasattr(load(path), "state_labels"), (backend, name)
    for name, (path, short) in COMMANDS.items():
        command = load(path)
        assert command.name == name and command.get_short_help_str(200) == short


def test_help_loads_no_command_and_no_numpy():
    script = (
        "import sys\n"
        "from pushrecovery.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "print(sorted(m for m in sys.modules if m == 'numpy' or m.startswith('pushrecovery.cli.')))"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "Commands:" in run.stdout and "capture-region" in run.stdout
    assert run.stdout.strip().splitlines()[-1] == "['pushrecovery.cli.app']"


def test_hip_commands():
    hip = run_json("classify", "--x", "0", "--xdot", "0.55")
    assert hip["strategy"] == "hip" and set(hip["margins"]) >= {"cop", "cmp"}
    run = run_json("simulate", "--model", "flywheel", "--controller", "mpc", "--xdot", "0.6")
    assert run["recovered"] is True and set(run["final_state"]) >= {"x", "xdot", "theta"}
    assert run["peak_torque"] == pytest.approx(100.0)
    found = run_json(
        "critical-push", "--model", "flywheel", "--controller", "bang-bang", "--tolerance", "1e-3"
    )
    assert found["velocity"] == pytest.approx(found["predicted_velocity"], abs=1e-3)
    # The MPC runs at its own dt = 0.02 s unless told otherwise: 1 tick per 20 ms.
    assert run["duration"] == pytest.approx(round(run["duration"] / 0.02) * 0.02, abs=1e-9)
    bang = run_json("simulate", "--model", "flywheel", "--controller", "bang-bang", "--xdot", "0.6")
    assert abs(bang["final_state"]["theta_dot"]) < 1e-12  # both pulses equally long (Eq. 10)
    short = run_json(
        "simulate",
        "--model",
        "flywheel",
        "--controller",
        "mpc",
        "--xdot",
        "0.3",
        "--option",
        "horizon=20",
        "--option",
        "gamma=1",
    )
    assert short["recovered"] is True


def test_parameter_flags_override(tmp_path):
    data = run_json("bounds", "--toe", "0.2", "--com-height", "0.81")
    assert data["cop"]["upper"] == 0.2
    assert data["params"]["leg_length"] == 0.81
    assert data["omega"] == pytest.approx((9.81 / 0.81) ** 0.5)
    toml = tmp_path / "p.toml"
    toml.write_text("heel = -0.1\n")
    assert run_json("bounds", "--params", str(toml))["cop"]["lower"] == -0.1


def test_classify_contract():
    inside = run_json("classify", "--x", "0", "--xdot", "0.3")
    assert set(inside) >= {"capture_point", "strategy", "margins"}
    assert inside["strategy"] == "ankle"
    assert inside["margins"]["cop"] > 0
    outside = run_json("classify", "--x", "0", "--xdot", "0.6")
    assert outside["strategy"] != "ankle" and outside["margins"]["cop"] < 0


def test_simulate_contract_and_plot(tmp_path):
    plot = tmp_path / "run.png"
    data = run_json(
        "simulate",
        "--model",
        "pendulum",
        "--controller",
        "ankle-pd",
        "--x",
        "0",
        "--xdot",
        "0.3",
        "--duration",
        "5",
        "--plot",
        str(plot),
    )
    assert data["recovered"] is True
    assert set(data["final_state"]) == {"x", "xdot"}
    assert data["predicted"]["strategy"] == "ankle"
    assert plot.stat().st_size > 0
    fell = run_json(
        "simulate", "--model", "lipm", "--controller", "ankle-saturated", "--impulse", "40"
    )
    assert fell["recovered"] is False and fell["initial_state"]["xdot"] == pytest.approx(40 / 72)


def test_critical_push_contract():
    data = run_json(
        "critical-push",
        "--model",
        "lipm",
        "--controller",
        "ankle-pd",
        "--x",
        "0.0",
        "--direction",
        "backward",
        "--tolerance",
        "1e-4",
    )
    assert set(data) >= {"velocity", "impulse", "predicted_velocity"}
    assert data["velocity"] == pytest.approx(data["predicted_velocity"], abs=1e-4)
    assert data["impulse"] == pytest.approx(72 * data["velocity"])


def test_figures(tmp_path):
    files = run_json("figures", "--out", str(tmp_path))["files"]
    names = sorted(p.rsplit("/", 1)[1] for p in files)
    expected = [
        f"fig{n}.{ext}"
        for n in ("3a", "3b", "5a", "5b", "6a", "6b", "9", "10")
        for ext in ("png", "svg")
    ] + [
        f"{stem}.{ext}"
        for stem in ("plane", "steps-regions", "steps-map")
        for ext in ("png", "svg")
    ]
    assert names == sorted(expected)
    assert all((tmp_path / name).stat().st_size > 1000 for name in names)


def test_table_output_is_readable():
    text = invoke("classify", "--x", "0", "--xdot", "0.3")
    assert "strategy" in text and "ankle" in text and "{" not in text


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["bounds", "--mass", "-1"], "mass must be in [0.01, 10000] [kg], got mass=-1"),
        (["bounds", "--mass", "nan"], "mass must be a finite number"),
        (["bounds", "--com-height", "0"], "com_height must be in [0.01, 10] [m]"),
        (["bounds", "--heel", "0.2"], "heel must be < toe"),
        (["bounds", "--preset", "moon"], "preset must be one of"),
        (["bounds", "--frobnicate"], "No such option"),
        (["bounds", "--mass", "heavy"], "not a valid float"),
        (["classify", "--x", "inf", "--xdot", "0"], "x must be a finite number"),
        (["classify", "--x", "0"], "Missing option '--xdot'"),
        (["simulate", "--xdot", "0.1", "--impulse", "3"], "either --xdot"),
        (["simulate", "--duration", "-1"], "duration must be > 0"),
        (["simulate", "--model", "humanoid"], "Invalid value for '--model'"),
        (["simulate", "--xdot", "0.1", "--plot", "run.gif"], "plot must end in one of"),
        (["critical-push", "--x", "0.3"], "x must lie on the foot"),
        (["critical-push", "--kp", "100"], "stiffness must be > m g L"),
        (["bounds", "--params", "/nonexistent.toml"], "not found"),
        (["nonsense"], "No such command"),
        (["step"], "give --v0"),
        (["step", "--v0", "-1"], "v0 must be >= 1e-6"),
        (["step", "--v0", "1e-300"], "v0 must be >= 1e-6"),
        (["step", "--v0", "nan"], "v0 must be finite"),
        (["step", "--v0-range", "1", "0", "0.1"], "START <= STOP"),
        (["step", "--v0-range", "0.1", "1e9", "1e-9"], "at most 100000"),
        (["bounds", "--max-step-length", "3"], "max_step_length must be < 2 leg_length"),
        (["simulate", "--model", "flywheel", "--controller", "recovery"], "stepping model"),
        (["simulate", "--duration", "1e12"], "duration must be in (0, 60] s, got duration=1e+12"),
        (["simulate", "--duration", "60", "--control-period", "1e-6"], "must be <= 1e+07 steps"),
        (["simulate", "--control-period", "5e-324"], "must be <= 1e+07 steps, got inf"),
        (
            ["simulate", "--model", "flywheel", "--controller", "mpc", "--option", "horizon=3000"],
            "horizon must be an integer in [1, 200], got 3000",
        ),
        (["simulate", "--x", "1.79e308"], "x must satisfy |x| < com_height"),
        (["simulate", "--xdot", "3000"], "xdot must satisfy"),
        (
            ["classify", "--x", "0", "--xdot", "0", "--com-height", "1e308", "--gravity", "5e-324"],
            "com_height must be in [0.01, 10] [m], got com_height=1e+308",
        ),
        (["classify", "--x", "1.7e308", "--xdot", "1e308"], "too large"),
        (["simulate", "--mass", "1e308"], "mass must be in [0.01, 10000]"),
        (["bounds", "--gravity", "1e15", "--json"], "gravity must be in [0.1, 100] [m/s^2]"),
        (["step", "--v0-range", "0.717", "2.67", "0.5", "--leg-length", "1e300"], "leg_length"),
        (["critical-push", "--tolerance", "100"], "tolerance must be in"),
        (["critical-push", "--tolerance", "1e-300"], "tolerance must be in"),
        (["simulate", "--control-period", "0.2"], "control_period must be <="),
        (["simulate", "--xdot", "0.1", "--plot", "/proc/version/x.png"], "cannot write"),
        (["figures", "--out", "/proc/version/sub"], "cannot write"),
        (["simulate", "--model", "lipm", "--controller", "mpc"], "use the flywheel model"),
        (
            ["simulate", "--model", "flywheel", "--controller", "mpc", "--option", "horizon=x"],
            "must be a number",
        ),
        (
            ["simulate", "--model", "flywheel", "--controller", "mpc", "--option", "horizon"],
            "NAME=VALUE",
        ),
        (
            ["simulate", "--model", "flywheel", "--controller", "mpc", "--option", "gamma=2"],
            "gamma must be in",
        ),
        (
            ["simulate", "--model", "flywheel", "--controller", "mpc", "--option", "bogus=1"],
            "has no option 'bogus'",
        ),
        (["simulate", "--controller", "ankle-saturated", "--kp", "2000"], "apply to ankle-pd"),
        (["classify", "--x", "0", "--xdot", "1.2", "--friction", "0"], "friction must be in"),
        (["classify", "--x", "0", "--xdot", "1.2", "--ankle-torque-max", "-1"], "ankle_torque_max"),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, args, words):
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("pushrecovery: error: ")
    assert words in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"\xff\xfe=1", "not UTF-8"),
        (b"mass = 1" + b"0" * 400, "mass must be a finite number"),
        (b"mass = [", "malformed TOML"),
        (b"[body]\nmass = {a = 1}", "mass must be a number"),
        (b"", None),  # an empty file keeps the preset
    ],
)
def test_parameter_files(tmp_path, capsys, content, words):
    path = tmp_path / "p.toml"
    path.write_bytes(content)
    if words is None:
        assert run_json("bounds", "--params", str(path))["params"]["mass"] == 72.0
        return
    with pytest.raises(SystemExit) as exit_info:
        main(["bounds", "--params", str(path)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1


def test_parameter_file_is_a_directory(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["bounds", "--params", str(tmp_path)])
    assert capsys.readouterr().err.startswith("pushrecovery: error: ")


def test_malformed_toml(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("mass = [\n")
    with pytest.raises(SystemExit) as exit_info:
        main(["bounds", "--params", str(bad)])
    assert exit_info.value.code == 2
    assert "malformed TOML" in capsys.readouterr().err


def test_real_subprocess_and_module_entry_point():
    done = subprocess.run(
        [sys.executable, "-m", "pushrecovery", "bounds", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert json.loads(done.stdout)["cop"]["upper"] == 0.15
    bad = subprocess.run(
        [sys.executable, "-m", "pushrecovery", "bounds", "--toe", "-1"],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.strip().startswith("pushrecovery: error: ")


def test_figures_report_their_progress(monkeypatch):
    # `figures` takes about 10 s: its bar advances once per figure (drawers stubbed here).
    from pushrecovery import load_params
    from pushrecovery.plots import figures as module

    for name in ("fig3a", "fig3b", "fig5", "fig6", "fig9", "fig10", "plane", "steps"):
        monkeypatch.setattr(module, name, lambda *args, **kwargs: [])
    from pushrecovery.experiments.paper_figures import PaperRuns

    runs = PaperRuns(fig3a=[], fig3b=[], fig5=[], fig5_worst=[], fig6=[])
    calls = []
    module.write_figures(load_params(), runs, Path("unused"), progress=calls.append)
    assert calls == [1] * module.FIGURE_COUNT
