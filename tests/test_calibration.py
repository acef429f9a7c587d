"""The calibration study: its reliability table by hand, its scores, its refusals."""

import dataclasses
import math

import numpy as np
import pytest

from pushrecovery.errors import InvalidParameterError
from pushrecovery.experiments.calibration import calibration_study
from pushrecovery.presets import load_params
from pushrecovery.surfaces.probability import brier_score, reliability

P = dataclasses.replace(load_params(), max_steps=2)


def test_the_reliability_table_by_hand():
    predicted = np.array([0.05, 0.07, 0.5, 0.55, 0.95, 1.0])
    failed = np.array([False, True, True, False, True, True])
    rows = reliability(predicted, failed, bins=2)
    assert rows[0][:3] == (0.0, 0.5, 2) and rows[1][:3] == (0.5, 1.0, 4)  # 1.0 in the last bin
    assert rows[0][3] == pytest.approx(0.06) and rows[0][4] == pytest.approx(0.5)
    assert rows[1][3] == pytest.approx(0.75) and rows[1][4] == pytest.approx(0.75)
    assert rows[1][5] == pytest.approx(math.sqrt(0.75 * 0.25 / 4))
    assert [r[2] for r in reliability(predicted, failed)] == [2, 2, 2]  # empty bins left out


def test_a_small_analytic_study_scores_its_probabilities():
    study = calibration_study("stepping", "recovery", P, velocities=(2.6, 3.9), pushes=300,
                              noise=(0.01, 0.1), duration=6.0, seed=3)  # fmt: skip
    assert study.kept.all() and study.excluded == 0
    hit = study.failed
    assert study.brier == pytest.approx(np.mean((study.predicted - hit) ** 2))
    base = hit.mean()
    assert study.brier_base_rate == pytest.approx(base * (1 - base))
    # The probabilities beat the certain verdict of the same estimates and the base rate.
    assert study.brier < study.brier_certain < study.brier_base_rate
    # Falls only among the faster pushes: above the 2-step region's 3.22 m/s, with the
    # controller recovering a little beyond it.
    assert not hit[study.velocity < 3.1].any() and hit[study.velocity > 3.5].all()
    assert sum(row[2] for row in study.bins) == 300


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"velocities": (3.0, 2.0)}, "low < high"),
        ({"pushes": 5}, "pushes"),
        ({"noise": (0.0, 0.1)}, r"noise\[0\]"),
        ({"noise": (0.01,)}, "noise must be"),
        ({"seed": -1}, "seed"),
    ],
)
def test_bad_arguments_are_refused(kwargs, match):
    options = {"velocities": (2.6, 3.9), "pushes": 20, "noise": (0.01, 0.1), **kwargs}
    with pytest.raises(InvalidParameterError, match=match):
        calibration_study("stepping", "recovery", P, **options)


def test_the_brier_score_by_hand_and_its_refusals():
    assert brier_score([0.2, 0.9, 0.5], np.array([False, True, True])) == pytest.approx(
        (0.04 + 0.01 + 0.25) / 3
    )
    assert math.isnan(brier_score([], np.array([], dtype=bool)))
    with pytest.raises(InvalidParameterError, match="booleans"):
        brier_score([0.2], np.array([1.0]))
    with pytest.raises(InvalidParameterError, match=r"probabilities in \[0, 1\]"):
        reliability([1.2], np.array([True]))
    with pytest.raises(InvalidParameterError, match="one length"):
        reliability([0.2, 0.3], np.array([True]))
