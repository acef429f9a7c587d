"""A subjects table's height and sex scale each trial's body (issue 34 item 2, batch)."""

from __future__ import annotations

import pytest

from pushrecovery import InvalidParameterError
from pushrecovery.anthropometry import person_params
from pushrecovery.campaign.subjects import read_subjects
from pushrecovery.campaign.trials import find_trials, run_trials, trial_jobs
from test_analyze_batch import lipm_trial


def test_subjects_height_and_sex_scale_the_body(tmp_path):
    root = tmp_path / "study"
    for subject in ("s01", "s02"):
        (root / subject).mkdir(parents=True)
        (root / subject / "t.csv").write_text(lipm_trial(0.2, 0.0))
    table = tmp_path / "subjects.csv"
    table.write_text("pattern,subject,mass,height,sex\ns01/*,A,14.5,1.0,female\ns02/*,B,80,,\n")
    trials, root = find_trials([root])
    result = run_trials(trial_jobs(trials, root, read_subjects(table)), tmp_path / "o")
    rows = {row["subject"]: row for row in result.trials if row["axis"] == "ap"}
    child = person_params(14.5, 1.0, "female").params
    assert rows["A"]["status"] == "analysed", rows["A"]["error"]
    assert rows["A"]["mass"] == 14.5 and rows["A"]["com_height"] == child.com_height
    assert rows["A"]["leg_length"] == child.leg_length
    assert rows["A"]["body_source"].startswith("de Leva 1996 Table 4, female")
    assert rows["A"]["leg_length_source"].startswith("Winter 2009")
    assert rows["B"]["body_source"].startswith("preset")
    assert rows["B"]["mass"] == 80.0


def test_no_mass_in_a_batch_is_a_failed_row(tmp_path):
    (tmp_path / "t.csv").write_text(lipm_trial(0.2, 0.0))
    trials, root = find_trials([tmp_path / "t.csv"])
    result = run_trials(trial_jobs(trials, root), tmp_path / "o")
    assert {row["status"] for row in result.trials} == {"failed"}
    assert "no body mass for t.csv" in result.trials[0]["error"]


@pytest.mark.parametrize(
    ("cells", "words"),
    [
        ("1.7,", "height and sex go together"),
        (",male", "height and sex go together"),
        ("3,male", "height must be in"),
        ("1.7,x", "sex must be female or male"),
    ],
)
def test_bad_height_and_sex_columns_name_the_line(tmp_path, cells, words):
    table = tmp_path / "subjects.csv"
    table.write_text(f"pattern,subject,mass,height,sex\n*,A,70,{cells}\n")
    with pytest.raises(InvalidParameterError, match=words):
        read_subjects(table)
