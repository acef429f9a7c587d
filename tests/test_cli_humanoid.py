"""``pushrecovery humanoid``: the 3-D humanoids' commands, and the planar ones without them.

Issue 31: each help page lists only options that work for the models it lists; a model or an
option of the other family is refused in one line (exit 2) naming the command that takes it.
"""

from __future__ import annotations

import json

import pytest

from pushrecovery.cli import main

#: The JSON keys of ``humanoid simulate``, in order (a public contract: the same as
#: ``simulate --backend mujoco --model biped3d`` printed before the humanoid group).
SIMULATE_KEYS = [
    "recovered", "outcome", "model", "controller", "duration", "final_state", "max_excursion",
    "peak_torque", "stop_impacts", "initial_state", "predicted", "after_push", "backend",
    "azimuth", "impulse", "push_body", "delta_velocity", "steps", "stepping", "strategy",
    "peak_hip_torque", "peak_hip_motor_torque", "max_torso_tilt", "failed_ticks", "hip_task",
    "physics", "predicted_corrected",
]  # fmt: skip
CRITICAL_KEYS = [
    "velocity", "impulse", "bracket", "impulse_bracket", "simulations", "model", "controller",
    "x", "azimuth", "backend", "strategy", "hip_task", "foot_slip", "predicted",
    "predicted_corrected", "compared_with", "relative_error", "corrected_error", "stepping",
]  # fmt: skip


def run_cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as caught:
        main(list(args))
    out, err = capsys.readouterr()
    code = caught.value.code
    return (0 if code is None else int(code)), out, err


def test_humanoid_simulate_runs_and_keeps_its_json(capsys) -> None:
    code, out, err = run_cli(capsys, "humanoid", "simulate", "--azimuth", "30", "--push", "5",
                             "--duration", "0.3", "--json")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert list(data) == SIMULATE_KEYS
    assert data["model"] == "biped3d" and data["azimuth"] == 30.0 and data["impulse"] == 5.0
    assert data["controller"] == "wbc" and data["backend"] == "mujoco"


def test_humanoid_critical_push_runs_and_keeps_its_json(capsys) -> None:
    code, out, err = run_cli(capsys, "humanoid", "critical-push", "--model", "biped3d",
                             "--azimuth", "90", "--duration", "0.3", "--tolerance", "0.5",
                             "--json")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert list(data) == CRITICAL_KEYS
    assert data["azimuth"] == 90.0 and data["impulse"] > 0.0
    # The prediction it is compared with: the biped3d's own controller has the hip task.
    assert data["compared_with"] == "hip" and set(data["predicted"]) == {"ankle", "hip", "step"}
    ratio = data["predicted_corrected"]["hip"] / data["predicted"]["hip"]
    assert 0.7 < ratio < 1.0  # 1 / (1 + d/z0), the push 0.2 m above the CoM
    expected = data["impulse"] / data["predicted"]["hip"] - 1.0
    assert data["relative_error"] == pytest.approx(expected)


def test_humanoid_critical_push_measures_the_strategy_asked(capsys) -> None:
    code, out, err = run_cli(capsys, "humanoid", "critical-push", "--model", "biped3d",
                             "--azimuth", "0", "--duration", "0.3", "--tolerance", "0.5",
                             "--strategy", "ankle", "--json")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert data["compared_with"] == "ankle" and data["hip_task"] is False
    assert data["stepping"] is False and data["strategy"] == "ankle"
    code, out, err = run_cli(capsys, "humanoid", "critical-push", "--strategy", "jump")
    assert code == 2 and "jump" in err


def test_humanoid_validate_runs(capsys, tmp_path) -> None:
    code, out, err = run_cli(capsys, "humanoid", "validate", "--azimuth", "0", "--strategy",
                             "ankle", "--rel-tolerance", "0.2", "--duration", "0.5",
                             "--no-confusion", "--out", str(tmp_path))  # fmt: skip
    assert code == 0, err
    assert out.startswith("ankle") and "polar" in out
    assert (tmp_path / "validation3d_biped3d.md").exists()


def test_humanoid_campaign_runs_and_writes_the_3d_files(capsys, tmp_path) -> None:
    out = tmp_path / "c3d"
    code, text, err = run_cli(capsys, "humanoid", "campaign", "--azimuth", "90", "--impulse",
                              "4", "4", "1", "--strategy", "ankle", "--duration", "0.3",
                              "--no-plot", "--out", str(out), "--workers", "1")  # fmt: skip
    assert code == 0, err
    assert text.startswith("1 pushes (1 of 1 batches run now)") and "where they differ" in text
    spec = json.loads((out / "spec.json").read_text())
    assert spec["model"] == "biped3d" and spec["controller"] == "wbc-ankle"
    assert spec["azimuths"] == [90.0] and spec["backend"] == "mujoco"
    assert (out / "confusion3d.parquet").exists() and not (out / "confusion3d.png").exists()
    # --resume alone completes the stored campaign; the planar command points here for it
    code, text, err = run_cli(capsys, "humanoid", "campaign", "--resume", "--out", str(out),
                              "--workers", "1", "--no-plot", "--json")  # fmt: skip
    assert code == 0, err
    assert json.loads(text)["pushes"] == 1
    code, _, err = run_cli(capsys, "campaign", "--resume", "--out", str(out))
    assert code == 2 and err.count("\n") == 1
    assert f"use 'pushrecovery humanoid campaign --resume --out {out}'" in err


def test_the_humanoid_group_lists_its_commands(capsys) -> None:
    code, out, _ = run_cli(capsys, "humanoid", "--help")
    assert code == 0
    assert all(name in out for name in ("simulate", "critical-push", "validate", "campaign"))
    code, out, _ = run_cli(capsys, "--help")
    assert code == 0 and "The 3-D humanoids (biped3d, g1) under the whole-body" in out


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("simulate", "--backend", "mujoco", "--model", "biped3d", "--azimuth", "30"),
         "--model biped3d is a 3-D humanoid: use 'pushrecovery humanoid simulate --model "
         "biped3d'"),
        (("simulate", "--model", "g1"), "use 'pushrecovery humanoid simulate --model g1'"),
        (("simulate", "--azimuth", "30"), "use 'pushrecovery humanoid simulate --azimuth 30'"),
        (("simulate", "--azimuth", "abc"), "use 'pushrecovery humanoid simulate --azimuth abc'"),
        (("simulate", "--stepping"), "use 'pushrecovery humanoid simulate --stepping'"),
        (("simulate", "--view-azimuth", "10"), "'pushrecovery humanoid simulate --view-azimuth"),
        (("simulate", "--view-elevation", "10"), "'pushrecovery humanoid simulate --view-elev"),
        (("critical-push", "--model", "biped3d"),
         "use 'pushrecovery humanoid critical-push --model biped3d'"),
        (("critical-push", "--azimuth", "0"),
         "use 'pushrecovery humanoid critical-push --azimuth 0'"),
        (("validate", "--model", "g1"), "use 'pushrecovery humanoid validate --model g1'"),
        (("validate", "--model", "foot"), "validate takes no --model"),
        (("validate", "--quick"), "use 'pushrecovery humanoid validate --quick'"),
        (("validate", "--no-critical"), "use 'pushrecovery humanoid validate --no-critical'"),
        (("validate", "--fractions", "0.5"), "'pushrecovery humanoid validate --fractions 0.5'"),
        (("validate", "--out", "x"), "use 'pushrecovery humanoid validate --out x'"),
        (("validate", "--workers", "1"), "use 'pushrecovery humanoid validate --workers 1'"),
        (("validate", "--rel-tolerance", "0.1"), "'pushrecovery humanoid validate --rel-tol"),
        (("campaign", "--backend", "mujoco", "--model", "biped3d", "--out", "x"),
         "--model biped3d is a 3-D humanoid: use 'pushrecovery humanoid campaign --model "
         "biped3d'"),
        (("campaign", "--model", "g1", "--out", "x"),
         "use 'pushrecovery humanoid campaign --model g1'"),
        (("campaign", "--azimuth", "30", "--out", "x"),
         "use 'pushrecovery humanoid campaign --azimuth 30'"),
        (("campaign", "--azimuths", "0:360:90", "--out", "x"),
         "use 'pushrecovery humanoid campaign --azimuths 0:360:90'"),
        (("campaign", "--fraction", "0.5", "2", "0.5", "--out", "x"),
         "use 'pushrecovery humanoid campaign --fraction 0.5 2 0.5'"),
        (("campaign", "--strategy", "hip", "--out", "x"),
         "use 'pushrecovery humanoid campaign --strategy hip'"),
        (("campaign", "--controller", "wbc-step", "--x0", "0", "0", "1", "--out", "x"),
         "use 'pushrecovery humanoid campaign --strategy step'"),
    ],
)  # fmt: skip
def test_a_planar_command_refuses_the_humanoids_in_one_line(capsys, args, words) -> None:
    code, _, err = run_cli(capsys, *args)
    assert code == 2 and err.count("\n") == 1 and words in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("simulate", "--model", "lipm"), "use 'pushrecovery simulate --model lipm'"),
        (("simulate", "--model", "foot"), "use 'pushrecovery simulate --model foot'"),
        (("simulate", "--xdot", "1"), "--xdot is an option of the planar models"),
        (("simulate", "--backend", "mujoco"), "--backend is an option of the planar models"),
        (("simulate", "--controller", "mpc"), "--controller is an option of the planar"),
        (("simulate", "--plot", "x.png"), "--plot is an option of the planar models"),
        (("critical-push", "--model", "torso"), "'pushrecovery critical-push --model torso'"),
        (("critical-push", "--direction", "backward"), "--direction is an option of the planar"),
        (("critical-push", "--kp", "100"), "--kp is an option of the planar models"),
        (("validate", "--model", "pendulum"), "use 'pushrecovery validate --strategy"),
        (("validate", "--x0", "0"), "--x0 is an option of the planar models"),
        (("validate", "--grid", "0"), "--grid is an option of the planar models"),
        (("simulate", "--model", "g1", "--mass", "30"), "--model g1 has the robot's own body"),
        (("simulate", "--view-azimuth", "10"), "apply to --render of the 3-D humanoids"),
        (("simulate", "--nope", "1"), "No such option"),
        (("campaign", "--model", "stepping", "--out", "x"),
         "use 'pushrecovery campaign --model stepping'"),
        (("campaign", "--backend", "mujoco", "--out", "x"), "--backend is an option of the planar"),
        (("campaign", "--controller", "wbc-hip", "--out", "x"), "--controller is an option of"),
        (("campaign", "--x0", "0", "0", "1", "--out", "x"), "--x0 is an option of the planar"),
        (("campaign", "--xdot", "0", "1", "0.5", "--out", "x"), "--xdot is an option of the"),
        (("campaign", "--out", "x"), "humanoid campaign needs one of --impulse, --fraction"),
        (("campaign", "--resume", "--model", "g1", "--out", "x"), "give its whole spec or none"),
    ],
)  # fmt: skip
def test_a_humanoid_command_refuses_planar_things_in_one_line(capsys, args, words) -> None:
    code, _, err = run_cli(capsys, "humanoid", *args)
    assert code == 2 and err.count("\n") == 1 and words in err and "Traceback" not in err


@pytest.mark.parametrize("command", ["simulate", "critical-push", "validate", "campaign"])
def test_each_help_lists_only_its_familys_models_and_options(capsys, command) -> None:
    code, planar, _ = run_cli(capsys, command, "--help")
    assert code == 0
    humanoid_only = ("--azimuth", "biped3d", "g1", "--stepping", "--view-", "--frame-times",
                     "--quick", "--fractions", "--no-critical", "--rel-tolerance",
                     "--fraction")  # fmt: skip
    if command == "campaign":  # the planar one has its own --workers; validate --strategy
        humanoid_only += ("--strategy", "wbc-", "3-D:", "at the torso")
    else:
        humanoid_only += ("--workers",)
    for word in humanoid_only:
        assert word not in planar, (command, word)
    assert "pushrecovery humanoid" in planar  # where the 3-D humanoids went
    code, humanoid, _ = run_cli(capsys, "humanoid", command, "--help")
    assert code == 0
    planar_only = ("--xdot", "--controller", "--backend", "--kp", "--option", "--direction",
                   "--x0", "--grid", "lipm", "pendulum", "stepping-plane",
                   "--control-period")  # fmt: skip
    if command != "campaign":  # the campaigns' --plot/--no-plot writes their figures
        planar_only += ("--plot",)
    for word in planar_only:
        assert word not in humanoid, (command, word)
    assert "[biped3d|g1]" in humanoid and "Example:" in humanoid
    example = humanoid.split("Example:")[1].split()
    assert example[:3] == ["pushrecovery", "humanoid", command]


@pytest.mark.parametrize("limit", ["0", "-0.01", "2", "nan"])
def test_humanoid_simulate_refuses_a_slip_limit_out_of_range(capsys, limit: str) -> None:
    code, _, err = run_cli(capsys, "humanoid", "simulate", "--push", "5", "--duration", "0.2",
                           "--slip-limit", limit)  # fmt: skip
    assert code == 2 and "slip_limit must be" in err and "[1e-06, 1]" in err
    assert len(err.strip().splitlines()) == 1
