"""Many trials in one command (issue 18, item 1).

Files, folders and globs, a subjects table, local processes and a Dask cluster with the same
tables, a bad file among good ones.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pyarrow.parquet as pq
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.campaign.subjects import read_subjects, subject_for
from pushrecovery.campaign.trials import find_trials, run_trials, trial_jobs
from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

P = load_params()
OMEGA = P.omega
RATE = 100.0


def lipm_trial(push: float, azimuth: float, seed: int = 0) -> str:
    """A 2-D LIPM trial pushed at 1 s (``pushrecovery.experiments.synthetic_trials``)."""
    return lipm_trial_csv(P, push, azimuth, seed=seed)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """Two subjects' folders of trials (pushes from eight directions) and a bad file."""
    root = tmp_path_factory.mktemp("study")
    for s, subject in enumerate(("s01", "s02")):
        folder = root / subject
        folder.mkdir()
        for k in range(8):
            push = 0.1 + 0.05 * k
            (folder / f"trial{k:02d}.csv").write_text(lipm_trial(push, k * math.pi / 4, seed=s))
    (root / "s02" / "broken.csv").write_text("time,com_ap\n0.0,abc\n")
    (root / "subjects.csv").write_text(  # in the study's folder: the CLI leaves it out
        "pattern,subject,mass,leg_length,com_height,foot_length,foot_width\n"
        "s01/*,S1,70,0.95,1.0,,\n"
        "s02/*,S2,80,,,0.26,0.1\n"
    )
    return root


def test_files_folders_and_globs(study):
    folder, root = find_trials([study / "s01"])
    assert len(folder) == 8 and root == study / "s01"
    pattern, root = find_trials([str(study / "s0*" / "trial0[0-3].csv")])
    assert len(pattern) == 8 and root == study
    both, _ = find_trials([study / "s01", study / "s01" / "trial00.csv"])  # each once
    assert len(both) == 8
    for bad, words in (
        ([], "at least one"),
        ([study / "nothing"], "not found"),
        ([study / "subjects.csv", study / "x.txt"], "not found"),
        ([str(study / "*.nope")], "no .csv or .c3d"),
    ):
        with pytest.raises(InvalidParameterError, match=words):
            find_trials(bad)


def test_a_batch_on_one_and_two_workers_gives_the_same_tables(study, tmp_path):
    trials, root = find_trials([study])
    trials.remove(study / "subjects.csv")  # a CSV file, but the subjects' table
    jobs = trial_jobs(trials, root, read_subjects(study / "subjects.csv"))
    from distributed import LocalCluster

    one = run_trials(jobs, tmp_path / "one", workers=1)
    two = run_trials(jobs, tmp_path / "two", workers=2)
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as cluster:
        dask = run_trials(jobs, tmp_path / "dask", scheduler=cluster.scheduler_address)
    for name in ("trials", "events"):
        table = pq.read_table(tmp_path / "one" / f"{name}.parquet")
        assert table.equals(pq.read_table(tmp_path / "two" / f"{name}.parquet"))
        assert table.equals(pq.read_table(tmp_path / "dask" / f"{name}.parquet"))
    assert one.summary == two.summary == dask.summary
    # 17 trials: 16 analysed, the broken one a failed row per axis, the batch went on.
    assert one.summary["trials"] == 17 and one.summary["failed"] == 1
    failed = [row for row in one.trials if row["status"] == "failed"]
    assert [row["axis"] for row in failed] == ["ap", "ml"]
    assert "broken.csv: needs at least 10 rows" in failed[0]["error"]
    # The subjects table: S1's mass and leg length, S2's foot length scaled from the preset's.
    s1 = next(r for r in one.trials if r["subject"] == "S1" and r["status"] == "analysed")
    assert (s1["mass"], s1["leg_length"]) == (70.0, 0.95)
    assert s1["mass_source"] == "subjects table"
    s2 = [r for r in one.trials if r["subject"] == "S2" and r["status"] == "analysed"]
    assert s2 and all(r["mass"] == 80.0 for r in s2)
    assert set(one.summary["subjects"]) == {"S1", "S2"}
    # Pushes grow with the trial number: the larger ones need more than the ankles.
    analysed = [r for r in one.trials if r["status"] == "analysed"]
    demanding = {r["most_demanding"] for r in analysed}
    assert "ankle" in demanding and demanding - {"ankle"}
    # The checks and events of every analysed trial are in its rows: the CoP stays on the
    # foot by construction, and the push at 1 s is the onset (zero-lag filter: up to 1/fc =
    # 0.17 s early with this little noise).
    assert all(r["cop_outside_base_frames"] == 0 and not r["base_rejected"] for r in analysed)
    assert all(1.0 - 1.0 / 6.0 <= r["onset"] <= 1.01 for r in analysed), [
        r["onset"] for r in analysed
    ]
    onsets = [e for e in one.events if e["kind"] == "onset"]
    assert len(onsets) == 2 * 16  # one per analysed trial and axis


def test_a_resumed_batch_keeps_finished_trials(study, tmp_path):
    trials, root = find_trials([study / "s01"])
    jobs = trial_jobs(trials, root)
    whole = run_trials(jobs[:3], tmp_path / "b", workers=1)
    assert whole.ran == 3
    resumed = run_trials(jobs, tmp_path / "b", workers=1, resume=True)
    assert resumed.ran == 5 and resumed.summary["trials"] == 8


def test_bad_subjects_tables(tmp_path):
    cases = {
        "pattern,mass\nx,70\n": "needs the columns pattern and subject",
        "pattern,subject,shoe_size\nx,a,1\n": "unknown columns shoe_size",
        "pattern,subject,mass\nx,a,heavy\n": "line 2: mass must be a number",
        "pattern,subject,mass\nx,a,-3\n": "line 2: mass must be in",
        "pattern,subject\n,a\n": "line 2: pattern and subject must not be empty",
        "pattern,subject\n": "has no rows",
        "pattern,subject\nx,a,3\n": "line 2: more cells than columns",
    }
    for text, words in cases.items():
        path = tmp_path / "subjects.csv"
        path.write_text(text)
        with pytest.raises(InvalidParameterError, match=words):
            read_subjects(path)
    with pytest.raises(InvalidParameterError, match="cannot read"):
        read_subjects(tmp_path / "missing.csv")
    table = read_subjects(_write(tmp_path / "ok.csv", "pattern,subject\nA/*,a\n*.c3d,b\n"))
    assert subject_for("A/t1.csv", table).subject == "a"
    assert subject_for("B/t1.c3d", table).subject == "b"
    assert subject_for("B/t1.csv", table) is None


def test_bad_batch_arguments(study, tmp_path):
    trials, root = find_trials([study / "s01"])
    jobs = trial_jobs(trials, root)
    for workers in (0, -1, 1.5, True):
        with pytest.raises(InvalidParameterError, match="workers"):
            run_trials(jobs, tmp_path / "x", workers=workers)
    with pytest.raises(InvalidParameterError, match="no trials"):
        run_trials([], tmp_path / "x")


def test_the_cli_analyses_a_folder_in_one_command(study, tmp_path, capsys):
    from pushrecovery.cli import main

    out = tmp_path / "cli"
    args = ["analyze", str(study), "--out", str(out), "--subjects", str(study / "subjects.csv")]
    with pytest.raises(SystemExit) as done:
        main([*args, "--no-plot", "--json", "--workers", "2"])
    assert done.value.code == 0
    data = json.loads(capsys.readouterr().out)
    assert (data["trials"], data["analysed"], data["failed"]) == (17, 16, 1)
    assert (out / "trials.csv").exists() and (out / "events.parquet").exists()
    assert (out / "trials" / "s01__trial00.csv" / "frames.parquet").exists()
    for bad, words in (
        ([str(tmp_path / "none")], "not found"),
        ([str(study), "--subjects", str(tmp_path / "none.csv")], "cannot read the subjects"),
        ([str(study), "--workers", "0"], "--workers"),
    ):
        with pytest.raises(SystemExit) as done:
            main(["analyze", *bad, "--out", str(out)])
        assert done.value.code == 2
        error = capsys.readouterr().err
        assert words in error and len(error.strip().splitlines()) == 1, error


def _write(path, text):
    path.write_text(text)
    return path


def test_the_batch_tables_are_typed_and_read_by_pandas(study, tmp_path):
    from pushrecovery.campaign.trials.rows import TrialRow

    trials, root = find_trials([study / "s01"])
    jobs = trial_jobs(trials, root, flags={"mass": P.mass})  # no silent preset mass (issue 34)
    result = run_trials(jobs, tmp_path / "t", workers=1)
    rows = result.trial_rows()
    assert all(isinstance(row, TrialRow) for row in rows) and len(rows) == 16
    frame = result.to_pandas("trials")
    assert len(frame) == 16 and frame["min_mos"].notna().all()
    assert (frame["min_mos_normalised"] * frame["leg_length"]).to_numpy() == pytest.approx(
        frame["min_mos"].to_numpy()
    )
    events = result.to_pandas("events")
    assert set(events["kind"]) >= {"onset"}
    with pytest.raises(InvalidParameterError, match="table must be"):
        result.to_pandas("frames")


def test_synthetic_trials_refuse_bad_arguments():
    bad = (("push", -1.0), ("azimuth", float("nan")), ("rate", 0.0), ("duration", 0.0),
           ("x0", 1.0), ("noise", -1e-3), ("seed", -1))  # fmt: skip
    for name, value in bad:
        kwargs = {"push": 0.3, "azimuth": 0.0, name: value}
        push, azimuth = kwargs.pop("push"), kwargs.pop("azimuth")
        with pytest.raises(InvalidParameterError, match=name):
            lipm_trial_csv(P, push, azimuth, **kwargs)
    # Known truth: no push, the CoM stays where it stood (the noise apart).
    rows = lipm_trial_csv(P, 0.0, 0.0, noise=0.0).splitlines()[1:]
    assert {row.split(",")[1] for row in rows} == {"0.020000"}


def test_a_subjects_table_that_is_no_file_is_refused_in_one_line(tmp_path, capsys):
    # The fuzz campaign's `--subjects /dev/zero` read forever (killed): a device, a folder or
    # a missing path is refused before reading.
    import os

    from pushrecovery.campaign.subjects import read_subjects
    from pushrecovery.errors import InvalidParameterError

    for path in ("/dev/zero", tmp_path, tmp_path / "none.csv"):
        if str(path) == "/dev/zero" and not os.path.exists(path):
            continue
        with pytest.raises(InvalidParameterError, match="not a CSV file of at most 50 MB"):
            read_subjects(path)


def test_the_subjects_figure_shows_each_trials_margins_by_subject(study, tmp_path, capsys):
    # Per subject, every analysed trial's two smallest margins (trials table values, plotted
    # as they are) and its mean: the figure's points are the table's values.
    pytest.importorskip("matplotlib")
    import pyarrow.parquet as pq

    from pushrecovery.cli import main
    from pushrecovery.plots.subjects import MEASURES, subjects_figure

    out = tmp_path / "cli"
    args = ["analyze", str(study), "--out", str(out), "--subjects", str(study / "subjects.csv")]
    with pytest.raises(SystemExit) as done:
        main([*args, "--figure-format", "svg", "--json", "--workers", "1"])
    assert done.value.code == 0
    files = json.loads(capsys.readouterr().out)["files"]
    assert files["subjects_figure"].endswith("subjects.svg")
    assert (out / "subjects.svg").read_bytes().startswith(b"<?xml")
    rows = pq.read_table(out / "trials.parquet").to_pylist()
    figure = subjects_figure(rows)
    ap = figure.axes[0]
    subjects = sorted({r["subject"] for r in rows if r["status"] == "analysed"})
    assert [t.get_text() for t in ap.get_xticklabels()] == subjects
    plotted = sorted(
        float(y) for line in ap.get_lines() if line.get_marker() in ("o", "^")
        for y in line.get_ydata()
    )  # fmt: skip
    expected = sorted(
        r[column] for r in rows for column, *_ in MEASURES
        if r["status"] == "analysed" and r["axis"] == "ap" and r[column] is not None
    )  # fmt: skip
    assert plotted == pytest.approx(expected)


@pytest.fixture(scope="module")
def conditions_study(tmp_path_factory):
    """Two subjects, each with a slip and a trip trial, and a baseline trial of the first."""
    root = tmp_path_factory.mktemp("conditions")
    for s, subject in enumerate(("s01", "s02")):
        (root / subject).mkdir()
        for k, condition in enumerate(("slip", "trip", "baseline")[: 3 - s]):
            text = lipm_trial(0.15 + 0.1 * k, k * math.pi / 2, seed=s)
            (root / subject / f"{condition}1.csv").write_text(text)
    (root / "subjects.csv").write_text(
        "pattern,subject,mass,condition\n"
        "s01/slip*,S1,70,slip\ns01/trip*,S1,70,trip\ns01/*,S1,70,baseline\n"
        "s02/slip*,S2,80,slip\ns02/*,S2,80,\n"
    )
    return root


def test_the_subjects_tables_condition_reaches_the_trials_table(conditions_study, tmp_path):
    table = read_subjects(conditions_study / "subjects.csv")
    assert [s.condition for s in table] == ["slip", "trip", "baseline", "slip", None]
    assert subject_for("s01/trip1.csv", table).condition == "trip"  # the first match applies
    trials, root = find_trials([conditions_study / "s01", conditions_study / "s02"])
    result = run_trials(trial_jobs(trials, root, table), tmp_path / "b", workers=1)
    condition = {row["trial"]: row["condition"] for row in result.trials}
    assert condition == {"s01__baseline1.csv": "baseline", "s01__slip1.csv": "slip",
                         "s01__trip1.csv": "trip", "s02__slip1.csv": "slip",
                         "s02__trip1.csv": None}  # fmt: skip
    assert pq.read_table(tmp_path / "b" / "trials.parquet").column_names[-1] == "condition"
    without = run_trials(trial_jobs(trials, root), tmp_path / "c", workers=1)
    assert {row["condition"] for row in without.trials} == {None}


def test_a_malformed_condition_is_refused_naming_the_column_and_line(tmp_path):
    for cell in ('"a\tb"', "x" * 65):
        path = _write(tmp_path / "s.csv", f"pattern,subject,condition\nx,a,slip\ny,b,{cell}\n")
        with pytest.raises(InvalidParameterError, match=r"s.csv line 3: condition must be"):
            read_subjects(path)


def test_the_study_figure_shows_each_trials_margins_by_condition(conditions_study, tmp_path,
                                                                 capsys):  # fmt: skip
    # The CLI writes study.<fmt> in each figure format; the figure's dots are the trials
    # table's values, the diamonds each subject's mean per condition (joined across them).
    pytest.importorskip("matplotlib")
    from pushrecovery.cli import main
    from pushrecovery.plots.study import ALL, MEASURES, NONE, study_figure

    out = tmp_path / "cli"
    args = ["analyze", str(conditions_study), "--out", str(out), "--json", "--subjects",
            str(conditions_study / "subjects.csv")]  # fmt: skip
    magic = {"png": b"\x89PNG", "svg": b"<?xml", "pdf": b"%PDF"}
    for k, fmt in enumerate(magic):  # the trials once, then only the batch's figures
        with pytest.raises(SystemExit) as done:
            main([*args, "--figure-format", fmt, *(["--resume"] if k else [])])
        assert done.value.code == 0
        files = json.loads(capsys.readouterr().out)["files"]
        assert files["study_figure"] == str(out / f"study.{fmt}")
        assert (out / f"study.{fmt}").read_bytes().startswith(magic[fmt])
    rows = pq.read_table(out / "trials.parquet").to_pylist()
    figure = study_figure(rows)
    names = ["baseline", "slip", "trip", NONE]
    assert sorted(names) == [t.get_text() for t in figure.axes[2].get_xticklabels()]
    for ax, (axis, (column, _)) in zip(
        figure.axes, [(a, m) for a in ("ap", "ml") for m in MEASURES], strict=True
    ):
        mine = [r for r in rows if r["axis"] == axis and r[column] is not None]
        dots = sorted(y for line in ax.get_lines() if line.get_marker() == "o"
                      for y in line.get_ydata())  # fmt: skip
        assert dots == sorted(r[column] for r in mine)  # exactly the table's values
        (s1, s2) = [line.get_ydata() for line in ax.get_lines() if line.get_marker() == "D"]
        by = {(r["subject"], r["condition"] or NONE): r[column] for r in mine}
        order = sorted(names)
        for subject, means in (("S1", s1), ("S2", s2)):  # one trial each: its own value
            np.testing.assert_array_equal(means, [by.get((subject, c), np.nan) for c in order])
    plain = study_figure([{**r, "condition": None} for r in rows])  # no conditions: one group
    assert [t.get_text() for t in plain.axes[2].get_xticklabels()] == [ALL]
