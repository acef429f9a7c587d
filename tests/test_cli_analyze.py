"""``pushrecovery analyze``: files written, the JSON contract, one-line errors with exit 2."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from conftest import cli_error
from pushrecovery.analysis.readers import AP_AXES, LENGTH_UNITS
from pushrecovery.cli.analyze import _AP_AXES, _UNITS
from pushrecovery.cli.app import cli

#: Keys of the summary other tools read (add keys, never rename or drop).
SUMMARY_KEYS = {
    "source",
    "frames",
    "valid_frames",
    "excluded_frames",
    "excluded",
    "rate",
    "duration",
    "body",
    "params",
    "com_source",
    "support_source",
    "filter",
    "gaps",
    "interpolated_frames",
    "strategy",
    "directions",
    "step_events",
    "notes",
}
DIRECTION_KEYS = {
    "most_demanding",
    "time_in_strategy",
    "min_margin",
    "min_time_to_leave",
    "capture_point_range",
    "foot",
}


def _trial(path, push=0.3):
    """A LIPM push in mm, the CoP on a capture-point law (Euler at 1 ms, sampled at 100 Hz)."""
    omega, heel, toe = 9.81**0.5, -0.05, 0.15
    x, v, rows = 0.02, 0.0, ["time,com_ap,com_ml,cop_ap,cop_ml"]
    for k in range(2500):
        if abs(x) > 0.6:  # on the floor: the recording ends
            break
        if k == 1000:
            v += push
        capture = x + v / omega
        cop = min(toe, max(heel, 2 * capture - 0.02))
        if k % 10 == 0:
            rows.append(f"{k / 1000:.3f},{x * 1000:.4f},3.0,{cop * 1000:.4f},2.0")
        x, v = x + v * 1e-3, v + omega**2 * (x - cop) * 1e-3
    path.write_text("\n".join(rows) + "\n")
    return path


def test_choices_match_the_readers():
    assert set(_UNITS) == set(LENGTH_UNITS)
    assert set(_AP_AXES) == set(AP_AXES)


def test_analyze_csv_writes_frames_summary_and_plots(tmp_path):
    trial = _trial(tmp_path / "trial.csv")
    out = tmp_path / "out"
    args = ["analyze", str(trial), "--units", "mm", "--mass", "72", "--out", str(out), "--json"]
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert set(data) >= SUMMARY_KEYS | {"files"}
    for axis in ("ap", "ml"):
        assert set(data["directions"][axis]) >= DIRECTION_KEYS
    assert data["strategy"]["most_demanding"] == "ankle"
    assert data["body"]["mass_source"] == "flag"
    for name in ("frames.parquet", "frames.csv", "summary.json", "time_series.png"):
        assert (out / name).stat().st_size > 0
    assert json.loads((out / "summary.json").read_text())["frames"] == 250
    import pyarrow.parquet as pq

    frames = pq.read_table(out / "frames.parquet").to_pydict()
    assert len(frames["time"]) == 250
    assert set(frames) >= {
        "time",
        "strategy",
        "valid",
        "ap_capture_point",
        "ap_margin_cop",
        "ap_margin_cmp",
        "ap_time_to_leave_cop",
        "ml_margin_cop",
        "ap_step_length",
    }
    # ml: the CoM 3 mm, the CoP 2 mm left of the assumed feet's centre.
    assert np.nanmax(np.abs(np.array(frames["ml_com"]) - 0.003)) < 1e-9


def test_gaps_reach_the_json_and_the_files(tmp_path):
    trial = _trial(tmp_path / "trial.csv")
    lines = trial.read_text().splitlines()
    for i in (*range(51, 54), *range(121, 171)):  # 3 and 50 frames without a CoM
        cells = lines[i].split(",")
        cells[1] = ""
        lines[i] = ",".join(cells)
    trial.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    args = ["analyze", str(trial), "--units", "mm", "--mass", "72", "--out", str(out), "--json"]
    args.append("--no-plot")
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output

    def no_constant(text):
        raise AssertionError(f"non-JSON constant {text}")

    data = json.loads(result.output, parse_constant=no_constant)
    assert [(g["samples"], g["filled"]) for g in data["gaps"]] == [(3, True), (50, False)]
    assert data["excluded_frames"] == 50
    assert json.loads((out / "summary.json").read_text(), parse_constant=no_constant) == {
        k: v for k, v in data.items() if k != "files"
    }


def test_analyze_table_output(tmp_path):
    trial = _trial(tmp_path / "trial.csv", push=0.8)
    args = ["analyze", str(trial), "--units", "mm", "--mass", "72", "--out", str(tmp_path / "o")]
    args.append("--no-plot")
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert "needs" in result.output and "step_events" in result.output
    assert not (tmp_path / "o" / "time_series.png").exists()


def test_bad_inputs_are_one_line(tmp_path, capsys):
    trial = _trial(tmp_path / "trial.csv")
    out = str(tmp_path / "o")
    assert "not found" in cli_error(capsys, "analyze", str(tmp_path / "none.csv"), "--out", out)
    empty = tmp_path / "empty"
    empty.mkdir()  # a folder is a batch of trials (issue 18), but this one has none
    assert "no .csv or .c3d trial" in cli_error(capsys, "analyze", str(empty), "--out", out)
    assert "'furlongs'" in cli_error(
        capsys, "analyze", str(trial), "--units", "furlongs", "--out", out
    )
    assert "units" in cli_error(capsys, "analyze", str(trial), "--out", out)  # mm read as m
    text = tmp_path / "trial.txt"
    text.write_text("hello")
    assert "expected .csv or .c3d" in cli_error(capsys, "analyze", str(text), "--out", out)
    mm = ("--units", "mm", "--mass", "72")
    err = cli_error(capsys, "analyze", str(trial), *mm, "--cutoff", "-1", "--out", out)
    assert "cutoff" in err
    err = cli_error(capsys, "analyze", str(trial), *mm, "--cutoff", "80", "--out", out)
    assert "cutoff must be in (0, 50)" in err
    err = cli_error(capsys, "analyze", str(trial), "--units", "mm", "--mass", "-3", "--out", out)
    assert "mass" in err
    assert "--out" in cli_error(capsys, "analyze", str(trial))
    fake = tmp_path / "fake.c3d"
    fake.write_text("time,com_ap\n0,0\n")
    cli_error(capsys, "analyze", str(fake), "--out", out)
    kistler = _kistler()
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(kistler.read_bytes()[:30_000])
    cli_error(capsys, "analyze", str(cut), "--out", out)
    err = cli_error(capsys, "analyze", str(kistler), "--com-marker", "C7", "--out", out)
    assert "'C7'" in err
    err = cli_error(capsys, "analyze", str(kistler), "--foot", "left=LHEE", "--out", out)
    assert "NAME=HEEL,TOE,ANKLE" in err
    err = cli_error(capsys, "analyze", str(trial), *mm, "--xcom-length", "hip", "--out", out)
    assert "'hip'" in err and "com_height" in err
    err = cli_error(capsys, "analyze", str(trial), *mm, "--figure-format", "gif", "--out", out)
    assert "'gif'" in err and "svg" in err


def test_no_mass_is_refused_not_guessed(tmp_path, capsys):
    """A CSV without a mass, plates or --mass: refused in one line, no silent 72 kg preset."""
    trial = _trial(tmp_path / "trial.csv")
    err = cli_error(capsys, "analyze", str(trial), "--units", "mm", "--out", str(tmp_path / "o"))
    assert "no body mass for trial.csv" in err and "--mass" in err


def test_height_and_sex_scale_the_body_to_the_person(tmp_path):
    """A 14.5 kg, 1.0 m child: de Leva's geometry, not the 72 kg, 1 m-CoM preset."""
    from pushrecovery.anthropometry import person_params

    trial = _trial(tmp_path / "trial.csv")
    out = tmp_path / "out"
    args = ["analyze", str(trial), "--units", "mm", "--mass", "14.5", "--height", "1.0"]
    args += ["--sex", "female", "--out", str(out), "--json", "--no-plot"]
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    child = person_params(14.5, 1.0, "female").params
    assert data["body"]["mass"] == 14.5 and data["body"]["mass_source"] == "flag"
    assert data["body"]["com_height"] == child.com_height
    assert data["body"]["com_height_source"].startswith("de Leva 1996 Table 4")
    for name in ("leg_length", "heel", "toe", "foot_width", "flywheel_inertia"):
        assert data["params"][name] == getattr(child, name), name
    # a flag wins over the table
    args += ["--foot-width", "0.07"]
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert json.loads(result.output)["params"]["foot_width"] == 0.07
    # the table's line in the brief output
    brief = ["analyze", str(trial), "--units", "mm", "--mass", "14.5", "--height", "1.0"]
    brief += ["--sex", "female", "--out", str(out), "--no-plot"]
    result = CliRunner().invoke(cli, brief, catch_exceptions=False)
    assert "EXTRAPOLATED" in result.output


def test_bad_height_and_sex_are_one_line(tmp_path, capsys):
    trial = str(_trial(tmp_path / "trial.csv"))
    base = ("analyze", trial, "--units", "mm", "--mass", "60", "--out", str(tmp_path / "o"))
    assert "height" in cli_error(capsys, *base, "--height", "3", "--sex", "male")
    assert "height" in cli_error(capsys, *base, "--height", "0.4", "--sex", "male")
    assert "'other'" in cli_error(capsys, *base, "--height", "1.7", "--sex", "other")
    assert "height and sex go together" in cli_error(capsys, *base, "--height", "1.7")
    assert "height and sex go together" in cli_error(capsys, *base, "--sex", "male")
    folder = tmp_path / "many"
    folder.mkdir()
    _trial(folder / "a.csv")
    err = cli_error(
        capsys, "analyze", str(folder), "--height", "1.7", "--sex", "male", "--out", "o"
    )
    assert "--height and --sex apply to one trial" in err


def _kistler():
    import pathlib

    import biomdp

    return pathlib.Path(biomdp.__file__).parent / "tests" / "datasets" / "kistler_COP.c3d"


def test_the_xcom_length_flag_reaches_the_summary(tmp_path):
    trial = _trial(tmp_path / "trial.csv")
    result = CliRunner().invoke(
        cli,
        ["analyze", str(trial), "--units", "mm", "--mass", "72", "--leg-length", "0.9",
         "--com-height", "1.0", "--xcom-length", "leg_length", "--no-plot", "--out",
         str(tmp_path / "o"), "--json"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    plane = json.loads(result.output)["plane"]
    assert plane["xcom_length"] == "leg_length"
    assert plane["omega"] == pytest.approx((9.81 / 0.9) ** 0.5)


def _cop_only(path, jump=0.0, gap=False, scale=1.0):
    """A posturography export: time, cop_ap, cop_ml [m] at 100 Hz for 30 s, slow sway (and a
    ``jump`` [m] over 50 ms at 15 s: a step's CoP)."""
    t = np.arange(0.0, 30.0, 0.01)
    ap = 0.005 * np.sin(2 * np.pi * 0.3 * t) + jump * np.clip((t - 15.0) / 0.05, 0.0, 1.0)
    ml = 0.003 * np.sin(2 * np.pi * 0.5 * t + 1.0)
    rows = ["time,cop_ap,cop_ml"]
    for k in range(len(t)):
        cell = "" if gap and 1000 <= k < 1010 else f"{ap[k] * scale:.7f}"
        rows.append(f"{t[k]:.2f},{cell},{ml[k] * scale:.7f}")
    path.write_text("\n".join(rows) + "\n")
    return path, np.column_stack([ap, ml])


def test_a_cop_only_file_gives_its_sway_measures(tmp_path, capsys):
    # No CoM, no force, no mass: not refused, the sway measures (docs/posturography.md); the
    # path length and RMS distance by hand from the written trace (0.3 and 0.5 Hz sway: the
    # 10 Hz low-pass leaves them).
    path, cop = _cop_only(tmp_path / "quiet.csv")
    out = tmp_path / "o"
    result = CliRunner().invoke(cli, ["analyze", str(path), "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["status"] == "posturography only" and data["rate"] == pytest.approx(100.0)
    sway = data["posturography"]
    hand = np.sum(np.hypot(*np.diff(cop, axis=0).T))
    assert sway["path_length"] == pytest.approx(hand, rel=5e-3)
    centred = cop - cop.mean(axis=0)
    rms = np.sqrt(np.mean(np.sum(centred**2, axis=1)))
    assert sway["rms_distance"] == pytest.approx(rms, rel=5e-3)
    assert json.loads((out / "summary.json").read_text())["posturography"] == sway
    table = CliRunner().invoke(cli, ["analyze", str(path), "--out", str(tmp_path / "t")])
    assert table.exit_code == 0 and "CoP only" in table.output
    # A gap, or a trace that is no quiet standing: one line, exit 2.
    gap, _ = _cop_only(tmp_path / "gap.csv", gap=True)
    assert "misses 10 frame(s)" in cli_error(capsys, "analyze", str(gap), "--out", str(out))
    step, _ = _cop_only(tmp_path / "step.csv", jump=0.1)
    assert "no quiet standing" in cli_error(capsys, "analyze", str(step), "--out", str(out))


def test_a_batch_keeps_its_cop_only_trials_as_posturography_rows(tmp_path):
    study = tmp_path / "study"
    study.mkdir()
    _cop_only(study / "quiet.csv", scale=1000.0)  # in mm, as the other trial
    _trial(study / "pushed.csv")
    out = tmp_path / "o"
    result = CliRunner().invoke(
        cli, ["analyze", str(study), "--units", "mm", "--mass", "72", "--no-plot", "--workers",
              "1", "--out", str(out), "--json"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    import pyarrow.parquet as pq

    rows = {(r["trial"], r["axis"]): r for r in pq.read_table(out / "trials.parquet").to_pylist()}
    quiet = rows[("quiet.csv", "ap")]
    assert quiet["status"] == "posturography only" and quiet["error"] is None
    assert quiet["sway_path_length"] > 0.0 and quiet["rate"] == pytest.approx(100.0)
    assert quiet["mass"] is None and quiet["min_cop_margin"] is None
    assert rows[("pushed.csv", "ap")]["status"] == "analysed"
    # The same sway as the file alone (in metres).
    alone, _ = _cop_only(tmp_path / "alone.csv")
    single = CliRunner().invoke(
        cli, ["analyze", str(alone), "--out", str(tmp_path / "a"), "--json"]
    )
    path_ap = json.loads(single.output)["posturography"]["path_length_ap"]
    assert quiet["sway_path_length"] == pytest.approx(path_ap, rel=1e-4)  # 7 decimals of m, mm


@pytest.mark.parametrize(("fmt", "magic"), [("svg", b"<?xml"), ("pdf", b"%PDF")])
def test_figures_in_a_vector_format(tmp_path, fmt, magic):
    pytest.importorskip("matplotlib")
    trial = _trial(tmp_path / "trial.csv")
    out = tmp_path / "o"
    result = CliRunner().invoke(
        cli, ["analyze", str(trial), "--units", "mm", "--mass", "72", "--figure-format", fmt,
              "--out", str(out), "--json"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    files = json.loads(result.output)["files"]
    for name in ("time_series", "phase_portrait", "plane"):
        assert files[name].endswith(f".{fmt}")
        assert (out / f"{name}.{fmt}").read_bytes().startswith(magic)
    study = tmp_path / "study"
    study.mkdir()
    _trial(study / "a.csv")
    batch = CliRunner().invoke(
        cli, ["analyze", str(study), "--units", "mm", "--mass", "72", "--figure-format", fmt,
              "--workers", "1", "--out", str(tmp_path / "b")],
    )  # fmt: skip
    assert batch.exit_code == 0, batch.output
    assert (tmp_path / "b" / "trials" / "a.csv" / f"plane.{fmt}").read_bytes().startswith(magic)
