"""`analyze` on a stepping trial: the steps table of a batch, the events written into a C3D copy.

The trial is the project's MuJoCo biped pushed into one step, recorded as a gait lab would
(`experiments.mocap.record_push`) and written as a C3D file (tests/test_roundtrip.py checks the
same step against the simulation through the API).
"""

import functools
import json

import pytest

from conftest import cli_error
from pushrecovery.analysis.c3d import read_events, write_c3d
from pushrecovery.cli import main
from pushrecovery.experiments.mocap import record_push
from pushrecovery.presets import load_params

P = load_params()


@functools.cache
def _recording():
    return record_push("biped", P, impulse=1.3 * P.mass, duration=2.5)


def _c3d(path):
    rec = _recording()
    write_c3d(path, point_rate=rec.point_rate, markers=rec.markers, analog_rate=rec.analog_rate,
              plates=rec.plates, mass=rec.mass)  # fmt: skip
    return path


def test_one_c3d_trial_writes_its_events_into_a_copy(tmp_path, capsys):
    trial = _c3d(tmp_path / "step.c3d")
    before = trial.read_bytes()
    out = tmp_path / "o"
    with pytest.raises(SystemExit) as info:
        main(["analyze", str(trial), "--out", str(out), "--no-plot", "--write-events", "--json"])
    assert info.value.code == 0
    files = json.loads(capsys.readouterr().out)["files"]
    assert files["events_c3d"] == str(out / "events.c3d")
    assert trial.read_bytes() == before  # the input is never modified
    summary = json.loads((out / "summary.json").read_text())
    written = read_events(out / "events.c3d")
    feet = summary["events"]["foot_events"]
    assert len(written) == 1 + len(feet)  # the onset and every foot event
    strike = [e for e in written if (e.context, e.label) == ("Right", "Foot Strike")]
    assert [e.time for e in strike] == pytest.approx(
        [e["time"] for e in feet if (e["foot"], e["kind"]) == ("right", "foot-contact")], abs=1e-6
    )


def test_write_events_needs_a_c3d_trial(tmp_path, capsys):
    from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

    csv = tmp_path / "t.csv"
    csv.write_text(lipm_trial_csv(P, 0.3, 0.0))
    err = cli_error(capsys, "analyze", str(csv), "--mass", "72", "--out", str(tmp_path / "o"),
                "--write-events")  # fmt: skip
    assert "--write-events" in err and "t.csv is no .c3d file" in err


def test_a_batch_writes_the_steps_table_and_each_c3d_trials_events(tmp_path, capsys):
    import pyarrow.parquet as pq

    from pushrecovery.campaign.trials.steps import STEP_FIELDS
    from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

    study = tmp_path / "study"
    study.mkdir()
    _c3d(study / "step.c3d")
    (study / "quiet.csv").write_text(lipm_trial_csv(P, 0.2, 0.0))  # no step, no EVENT group
    out = tmp_path / "o"
    with pytest.raises(SystemExit) as info:
        main(["analyze", str(study), "--out", str(out), "--mass", "72", "--no-plot",
              "--write-events", "--json"])  # fmt: skip
    assert info.value.code == 0
    files = json.loads(capsys.readouterr().out)["files"]
    assert files["steps"] == str(out / "steps.parquet") and (out / "steps.csv").exists()
    table = pq.read_table(out / "steps.parquet")
    assert table.column_names == [name for name, _ in STEP_FIELDS]
    assert table.schema.field("duration").metadata[b"unit"] == b"s"
    (row,) = table.to_pylist()  # the C3D trial's one step; the CSV trial took none
    assert row["trial"] == "step.c3d" and row["foot"] == "right" and row["step"] == 1
    truth = _recording().truth
    assert row["length"] == pytest.approx(truth["step_lengths"][0], abs=0.01)
    summary = json.loads((out / "trials" / "step.c3d" / "summary.json").read_text())
    assert row["foot_contact"] == summary["events"]["measured_steps"][0]["contact_time"]
    # events.c3d beside the C3D trial's outputs only.
    assert read_events(out / "trials" / "step.c3d" / "events.c3d")
    assert not (out / "trials" / "quiet.csv" / "events.c3d").exists()
