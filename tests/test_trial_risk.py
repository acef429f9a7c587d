"""The analysis' risk columns: P(the ankle does not suffice) from the CoM's noise, end to end.

A synthetic trial (``lipm_trial_csv``) stands still 12 mm behind the toe; analysed without
noise, its risk under a CoM noise σ is the probability that a noisy recording of it puts the
capture point past the toe. 200 recordings with that noise (seeded) are analysed like any
trial: the spread of their capture points is the predicted σ_ξ (the filter's noise gains) and
the share of their frames past the toe is the risk, within 4 standard errors.
"""

import math

import numpy as np
import pytest

from pushrecovery.analysis.readers import read_recording
from pushrecovery.analysis.signals import noise_gains, smooth_and_differentiate
from pushrecovery.analysis.trial import AnalysisSettings, analyze
from pushrecovery.errors import InvalidParameterError
from pushrecovery.experiments.synthetic_trials import lipm_trial_csv
from pushrecovery.presets import load_params

P = load_params()
NOISE = 0.004
EDGE = 20  # frames left out at each end: the filter's start and end


def _trial(tmp_path, noise, seed, com_noise=NOISE):
    path = tmp_path / f"t{seed}.csv"
    path.write_text(lipm_trial_csv(P, 0.0, 0.0, duration=1.5, push_time=0.0, x0=P.toe - 0.012,
                                   noise=noise, seed=seed))  # fmt: skip
    return analyze(read_recording(path), P, AnalysisSettings(com_noise=com_noise)).columns


def test_the_noise_gains_are_those_of_the_filter():
    rng = np.random.default_rng(0)
    n = 100_000
    smooth, slope = smooth_and_differentiate(np.arange(n) / 100.0, rng.normal(0, 1, n), 6.0)
    g0, g1 = noise_gains(100.0, 6.0)
    assert smooth[1000:-1000].std() == pytest.approx(g0, rel=0.02)
    assert slope[1000:-1000].std() == pytest.approx(g1, rel=0.02)
    # No filter: the central difference alone, (x[k+1] - x[k-1]) / (2 dt): sqrt(2) / (2 dt).
    assert noise_gains(100.0, 0.0) == pytest.approx((1.0, 100.0 / math.sqrt(2.0)))


def test_the_risk_is_the_share_of_noisy_recordings_past_the_toe(tmp_path):
    truth = _trial(tmp_path, 0.0, 0)
    risk = truth["ap_risk"][EDGE:-EDGE]
    assert np.ptp(risk) < 1e-12 and 0.1 < risk[0] < 0.2  # one state: one risk (0.15)
    shares, errors = [], []
    for seed in range(1, 201):
        columns = _trial(tmp_path, NOISE, seed)
        shares.append(np.mean(columns["ap_margin_cop"][EDGE:-EDGE] < 0.0))
        errors.append(
            columns["ap_capture_point"][EDGE:-EDGE] - truth["ap_capture_point"][EDGE:-EDGE]
        )
    g0, g1 = noise_gains(100.0, AnalysisSettings().cutoff)
    assert np.concatenate(errors).std() == pytest.approx(NOISE * math.hypot(g0, g1 / P.omega),
                                                         rel=0.02)  # fmt: skip
    mean, se = np.mean(shares), np.std(shares) / math.sqrt(len(shares))
    assert abs(mean - risk[0]) <= 4.0 * se, (mean, se, risk[0])


def test_without_com_noise_there_are_no_risk_columns(tmp_path):
    columns = _trial(tmp_path, 0.0, 0, com_noise=None)
    assert not any(name.endswith("_risk") for name in columns)
    exact = _trial(tmp_path, 0.0, 0, com_noise=0.0)  # known exactly: inside, so 0
    assert np.nanmax(exact["ap_risk"]) == 0.0


def test_bad_noise_is_refused(tmp_path, capsys):
    with pytest.raises(InvalidParameterError, match="com_noise"):
        AnalysisSettings(com_noise=-0.001)
    from pushrecovery.cli import main

    trial = tmp_path / "t.csv"
    trial.write_text(lipm_trial_csv(P, 0.2, 0.0, duration=1.5))
    with pytest.raises(SystemExit) as info:
        main(["analyze", str(trial), "--mass", "72", "--out", str(tmp_path / "o"),
              "--com-noise", "nan"])  # fmt: skip
    err = capsys.readouterr().err
    assert info.value.code == 2 and "com_noise" in err and err.count("\n") == 1


def test_a_com_height_spread_is_the_average_over_bodies(tmp_path):
    """The risk with com_height_sd equals the risks of bodies of those heights, averaged."""
    import dataclasses

    path = tmp_path / "push.csv"
    path.write_text(lipm_trial_csv(P, 0.39, 0.0, duration=2.0, push_time=0.5, noise=0.0))
    recording = read_recording(path)
    spread = 0.05
    together = analyze(recording, P, AnalysisSettings(com_noise=0.002, com_height_sd=spread))
    rng = np.random.default_rng(11)
    risks = np.array([
        analyze(recording, dataclasses.replace(P, com_height=P.com_height + spread * z),
                AnalysisSettings(com_noise=0.002)).columns["ap_risk"]
        for z in rng.normal(0.0, 1.0, 200)
    ])  # fmt: skip
    expected, se = risks.mean(axis=0), risks.std(axis=0) / math.sqrt(len(risks))
    found = together.columns["ap_risk"]
    moving = np.isfinite(found) & (se > 1e-4)  # the frames whose risk the height changes
    assert moving.sum() > 10
    assert np.all(np.abs(found[moving] - expected[moving]) <= 4.0 * se[moving] + 1e-6)
    with pytest.raises(InvalidParameterError, match="com_height_sd"):
        AnalysisSettings(com_height_sd=-0.01)
