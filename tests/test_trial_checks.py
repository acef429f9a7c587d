"""A trial's data checked before its verdicts (issue 18, item 5), on real and generated trials.

biomdp's force-plate files: the mass from quiet windows within 1 % of the standing weight on
the jumps, and no verdict in flight. Generated trials: a CoP beyond the base withholds the
verdicts of those frames, and rejects the base when it does so in most frames.
"""

from __future__ import annotations

import json
import pathlib

import biomdp
import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.analysis.readers import read_recording
from pushrecovery.analysis.trial import analyze, body_for
from pushrecovery.analysis.trial.checks import COP_TOLERANCE

DATA = pathlib.Path(biomdp.__file__).parent / "tests" / "datasets"
P = load_params()
JUMPS = ("kistler_CMJ_1plate.c3d", "kistler_DJ_2plates.c3d", "vicon_CMJ_kinem_kinet_emg.c3d")


@pytest.mark.parametrize("name", JUMPS)
def test_jumps_weigh_the_subject_standing_and_give_no_verdict_in_flight(name):
    recording = read_recording(DATA / name)
    found, sources = body_for(recording, mass=None, com_height=None, gravity=9.81)
    # The standing weight: the first second, before any countermovement (the subject stands).
    first = recording.force_time < recording.force_time[0] + 1.0
    standing = float(np.nanmean(recording.force[first, 2])) / 9.81
    assert found["mass"] == pytest.approx(standing, rel=0.01), sources["mass"]
    assert "quiet windows" in sources["mass"]
    params = load_params(overrides=found)
    result = analyze(recording, params)
    flights = result.summary["checks"]["flight_phases"]
    assert flights, "every jump has a flight"
    in_flight = result.columns["flight"]
    assert in_flight.any()
    assert not result.columns["valid"][in_flight].any()
    assert all(s is None for s in result.columns["strategy"][in_flight])
    for start_end in flights:
        frames = (result.time > start_end["start"] + 0.01) & (result.time < start_end["end"] - 0.01)
        assert in_flight[frames].all()
    assert result.summary["posturography"] is None  # a jump is no quiet standing


def _csv(path, shift_ml, frames_shifted):
    """Quiet standing at 100 Hz over a CSV base; the base moved ``shift_ml`` [m] sideways in
    the first ``frames_shifted`` frames (the CoP stays under the real feet)."""
    rng = np.random.default_rng(1)
    n = 600
    t = np.arange(n) / 100.0
    com = 0.02 + 0.003 * np.sin(2 * np.pi * 0.3 * t) + rng.normal(0, 2e-4, n)
    cop = com + 0.002 * np.sin(2 * np.pi * 0.7 * t)
    lines = ["time,com_ap,com_ml,cop_ap,cop_ml,force_ap,force_ml,force_v,"
             "base_ap_min,base_ap_max,base_ml_min,base_ml_max"]  # fmt: skip
    for k in range(n):
        shift = shift_ml if k < frames_shifted else 0.0
        lines.append(
            f"{t[k]:.3f},{com[k]:.6f},0,{cop[k]:.6f},0,0,0,{P.weight:.3f},"
            f"-0.05,0.15,{-0.15 + shift:.4f},{0.15 + shift:.4f}"
        )
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_cop_beyond_the_base_withholds_those_verdicts(tmp_path):
    shift = 0.15 + COP_TOLERANCE + 0.03  # the base's ml edge 3 cm beyond the tolerance
    result = analyze(read_recording(_csv(tmp_path / "a.csv", shift, 60)), P)
    checks = result.summary["checks"]
    assert checks["cop_outside_base_frames"]["ml"] == 60 and not checks["base_rejected"]
    assert not result.columns["valid"][:60].any()
    assert result.columns["valid"][60:].all()
    assert result.columns["cop_outside_base"][:60].all()
    reasons = result.summary["excluded"]
    assert reasons["CoP beyond the computed base by more than 2 cm"] == 60


def test_a_base_the_cop_contradicts_is_rejected_and_nothing_is_classified(tmp_path):
    result = analyze(read_recording(_csv(tmp_path / "b.csv", 0.2, 600)), P)
    assert result.summary["checks"]["base_rejected"]
    assert not result.columns["valid"].any()
    assert result.summary["strategy"]["most_demanding"] is None
    assert any("no verdict is given" in note for note in result.summary["notes"])
    # Within the tolerance nothing is withheld.
    inside = analyze(read_recording(_csv(tmp_path / "c.csv", 0.15 + 0.01, 600)), P)
    assert inside.columns["valid"].all() and not inside.summary["checks"]["base_rejected"]


def test_quiet_standing_gets_its_sway_measures(tmp_path):
    recording = read_recording(DATA / "kistler_COP.c3d")
    found, _ = body_for(recording, mass=None, com_height=None, gravity=9.81)
    result = analyze(recording, load_params(overrides=found))
    sway = result.summary["posturography"]
    assert sway is not None and sway["cop_cutoff"] == 10.0
    # The 95 % prediction ellipse holds the CoP (order of magnitude of a standing subject).
    assert 1e-5 < sway["ellipse_area"] < 1e-2
    json.dumps(sway, allow_nan=False)
