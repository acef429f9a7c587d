"""Files made to carry the faults real labs record (issue 34, item 1), each flagged as documented.

Every file is a C3D written by the project's own writer: Plug-in Gait feet (heel, toe and ankle
markers), a ``CentreOfMass`` marker swaying over the feet, and force plates where the fault
needs them. docs/analysis.md, "Data checks", has the thresholds these tests check.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.analysis.c3d.writer import write_c3d
from pushrecovery.analysis.readers import read_recording
from pushrecovery.analysis.trial import analyze
from pushrecovery.campaign.trials import find_trials, run_trials, trial_jobs
from pushrecovery.errors import InvalidParameterError

RATE = 100.0  # marker rate [Hz]
SECONDS = 4.0
P = load_params(overrides={"mass": 70.0, "com_height": 0.95})


def _feet(n: int, forward: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Both feet standing still, 20 cm apart, heel 5 cm behind and toe 15 cm ahead of the
    ankle (lab x forward, y to the subject's left, z up) [m]."""
    markers = {}
    for side, ml in (("L", 0.10), ("R", -0.10)):
        lateral = 0.03 if side == "L" else -0.03
        markers[f"{side}HEE"] = np.tile([-0.05, ml, 0.03], (n, 1))
        markers[f"{side}TOE"] = np.tile([0.15, ml, 0.03], (n, 1))
        markers[f"{side}ANK"] = np.tile([0.0, ml + lateral, 0.08], (n, 1))
    return markers


def _com(n: int) -> np.ndarray:
    """A CoM swaying 3 cm sideways at 0.5 Hz and 1 cm forward at 0.3 Hz [m]."""
    t = np.arange(n) / RATE
    return np.column_stack(
        [
            0.04 + 0.01 * np.sin(2 * np.pi * 0.3 * t),
            0.03 * np.sin(2 * np.pi * 0.5 * t),
            np.full(n, 0.95),
        ]
    )


def _write(path, markers, plates=(), analog_rate=RATE):
    write_c3d(
        path, point_rate=RATE, markers=markers, analog_rate=analog_rate, plates=plates, mass=70.0
    )
    return read_recording(path)


# --- (a) marker gaps ------------------------------------------------------------------------
HEEL_GAP = slice(200, 230)  # 300 ms of the left heel marker
TOE_GAP = slice(300, 310)  # 100 ms of the left toe marker


def _gapped(tmp_path):
    n = int(SECONDS * RATE)
    markers = {**_feet(n), "CentreOfMass": _com(n)}
    clean = _write(tmp_path / "clean.c3d", markers)
    markers["LHEE"] = markers["LHEE"].copy()
    markers["LTOE"] = markers["LTOE"].copy()
    markers["LHEE"][HEEL_GAP] = np.nan
    markers["LTOE"][TOE_GAP] = np.nan
    return clean, _write(tmp_path / "gapped.c3d", markers)


def test_missing_base_markers_exclude_their_frames_counted_per_marker(tmp_path):
    clean, gapped = _gapped(tmp_path)
    before, after = analyze(clean, P), analyze(gapped, P)
    gap = np.zeros(len(after.time), dtype=bool)
    gap[HEEL_GAP] = gap[TOE_GAP] = True
    checks = after.summary.checks
    assert checks.to_dict()["marker_gap_frames"] == {"left heel": 30, "left toe": 10}
    assert checks.to_dict()["excluded_frames_markers"] == 40
    assert after.summary.excluded["a heel or toe marker missing (base unknown)"] == 40
    assert "no supporting foot" not in after.summary.excluded
    # No verdict and no base in those frames: not the smaller base of the markers left.
    assert not after.columns["valid"][gap].any()
    assert np.isnan(after.columns["ml_base_min"][gap]).all()
    assert np.isnan(after.columns["mos"][gap]).all()
    assert after.columns["valid"][~gap].all()
    assert after.summary.excluded_frames == 40
    # Elsewhere everything is the un-gapped trial's, and the smallest margins are those of the
    # un-gapped recording restricted to the same frames (the hand value).
    for name in ("mos", "ap_margin_cop", "ml_margin_cop", "ml_base_min", "ml_base_max"):
        np.testing.assert_array_equal(after.columns[name][~gap], before.columns[name][~gap])
    hand = float(np.min(before.columns["mos"][~gap]))
    assert after.summary.plane.min_mos.value == hand
    assert before.summary.plane.min_mos.value < hand  # the gaps hid the smallest margin
    hand_ml = float(np.min(before.columns["ml_margin_cop"][~gap]))
    assert after.summary.directions["ml"].min_cop_margin.value == hand_ml


def test_a_trial_without_gaps_reports_none(tmp_path):
    clean, _ = _gapped(tmp_path)
    checks = analyze(clean, P).summary.checks.to_dict()
    assert checks["marker_gap_frames"] == {}
    assert checks["excluded_frames_markers"] == 0


@pytest.mark.parametrize("part", ["LHEE", "RTOE"])
def test_one_missing_sample_is_not_filled(tmp_path, part):
    n = int(SECONDS * RATE)
    markers = {**_feet(n), "CentreOfMass": _com(n)}
    markers[part] = markers[part].copy()
    markers[part][200] = np.nan
    result = analyze(_write(tmp_path / "one.c3d", markers), P)
    assert result.summary.checks.to_dict()["excluded_frames_markers"] == 1
    assert not result.columns["valid"][200]


# --- (b) a loaded plate under no foot -------------------------------------------------------
ANALOG = 1000.0
WEIGHT = 70.0 * 9.81


def _plate(n, vertical, cop_xy, corners):
    force = np.zeros((n, 3))
    force[:, 2] = vertical
    cop = np.column_stack([cop_xy, np.zeros(n)])
    cop[vertical <= 0.0] = np.nan
    return force, cop, np.zeros(n), np.asarray(corners, dtype=float)


def _rectangle(x0, x1, y0, y1):
    return [[x1, y1, 0.0], [x0, y1, 0.0], [x0, y0, 0.0], [x1, y0, 0.0]]


def _standing_plates(n_points, stray_load=None, stray_at=(0.05, 0.30)):
    """Each foot on its own plate, the load shifting with the CoM sideways (the combined CoP
    under the CoM) and 0.3 N of noise on each (a noise-free total would be constant: a flat
    top at its extreme); optionally a third plate left of the left foot loaded to ``stray_load``
    [N] for 80 ms from 2 s (a half sine)."""
    n = int(n_points * ANALOG / RATE)
    t = np.arange(n) / ANALOG
    com = _com(n_points)
    ml = np.interp(t, np.arange(n_points) / RATE, com[:, 1])
    ap = np.interp(t, np.arange(n_points) / RATE, com[:, 0])
    left = 0.5 * WEIGHT * (1.0 + ml / 0.10)
    noise = np.random.default_rng(34).normal(0.0, 0.3, (2, n))  # a real plate's, ~0.3 N
    plates = [
        _plate(n, left + noise[0], np.column_stack([ap, np.full(n, 0.10)]),
               _rectangle(-0.2, 0.3, 0.0, 0.25)),
        _plate(n, WEIGHT - left + noise[1], np.column_stack([ap, np.full(n, -0.10)]),
               _rectangle(-0.2, 0.3, -0.25, 0.0)),
    ]  # fmt: skip
    if stray_load is not None:
        pulse = np.sin(np.pi * (t - 2.0) / 0.08)
        load = np.where((t > 2.0) & (t < 2.08), stray_load * pulse, 0.0)
        where = np.tile(stray_at, (n, 1))
        plates.append(_plate(n, load, where, _rectangle(-0.2, 0.3, 0.26, 0.51)))
    return plates


def _plated(path, **options):
    n = int(SECONDS * RATE)
    markers = {**_feet(n), "CentreOfMass": _com(n)}
    plates = _standing_plates(n, **options)
    return _write(path, markers, plates, analog_rate=ANALOG)


def test_a_light_plate_under_no_foot_makes_no_foot_events_and_is_flagged(tmp_path):
    clean = analyze(_plated(tmp_path / "two.c3d"), P)
    stray = analyze(_plated(tmp_path / "three.c3d", stray_load=66.0), P)
    checks = stray.summary.checks.to_dict()
    assert checks["stray_plates"] == ["plate 3"]
    assert checks["plate_feet"] == {"plate 1": "left", "plate 2": "right"}
    # 20 cm from the left foot's markers, 15 cm from its sole (5 cm half width).
    assert checks["plate_foot_distance"]["plate 3"] == pytest.approx(0.15, abs=1e-6)
    assert stray.summary.events.foot_events == ()
    assert any("plate 3" in note for note in stray.summary.notes)
    # The combined CoP and vertical force are the two feet's: no 15 cm jump sideways.
    for name in ("ml_cop", "ap_cop", "ml_margin_cop", "mos"):
        np.testing.assert_allclose(stray.columns[name], clean.columns[name], atol=1e-9)
    assert clean.summary.checks.to_dict()["stray_plates"] == []


def test_a_plate_loaded_beyond_a_quarter_of_the_weight_is_a_foots_contact(tmp_path):
    heavy = analyze(_plated(tmp_path / "heavy.c3d", stray_load=0.3 * WEIGHT), P)
    checks = heavy.summary.checks.to_dict()
    assert checks["stray_plates"] == []
    assert len(checks["plate_feet"]) == 3
    assert {e.event.kind for e in heavy.summary.events.foot_events} >= {"foot-contact"}


# --- (c) saturation and zero offset ---------------------------------------------------------
def _push(n_points, peak=-195.0, clip=None):
    """A backward horizontal force of ``peak`` [N] on the left plate, a 200 ms half sine from
    1.5 s, clipped at ``clip`` [N] (the issue's -120 N of a -195 N peak)."""
    n = int(n_points * ANALOG / RATE)
    t = np.arange(n) / ANALOG
    push = np.where((t >= 1.5) & (t < 1.7), peak * np.sin(np.pi * (t - 1.5) / 0.2), 0.0)
    return push if clip is None else np.maximum(push, clip)


def _pushed(path, clip=None, offset=None):
    n = int(SECONDS * RATE)
    markers = {**_feet(n), "CentreOfMass": _com(n)}
    plates = _standing_plates(n)
    force = plates[0][0].copy()
    force[:, 0] = _push(n, clip=clip)
    plates[0] = (force, *plates[0][1:])
    if offset is not None:  # a third plate, never stepped on, reading ``offset`` [N]
        samples = len(force)
        plates.append(
            _plate(samples, np.full(samples, offset), np.tile([0.05, 0.40], (samples, 1)),
                   _rectangle(-0.2, 0.3, 0.26, 0.51))
        )  # fmt: skip
    return _write(path, markers, plates, analog_rate=ANALOG)


def test_a_clipped_channel_is_flagged_saturated(tmp_path):
    clipped = analyze(_pushed(tmp_path / "clipped.c3d", clip=-120.0), P)
    checks = clipped.summary.checks.to_dict()
    assert checks["saturated_channels"] == ["force ap"]
    flat = next(c for c in checks["channels"] if c["channel"] == "force ap")["flat_samples"]
    # -195 sin(pi t / 0.2 s) < -120 N for 0.2 (1 - 2 asin(120/195)/pi) s = 116 ms at 1 kHz.
    expected = 0.2 * (1 - 2 * np.arcsin(120 / 195) / np.pi) * ANALOG
    assert abs(flat - expected) <= 2
    assert any("saturated" in note and "force ap" in note for note in clipped.summary.notes)
    whole = analyze(_pushed(tmp_path / "whole.c3d"), P).summary.checks.to_dict()
    assert whole["saturated_channels"] == []
    assert all(c["flat_samples"] < 5 for c in whole["channels"])


def test_an_offset_plate_is_flagged(tmp_path):
    offset = analyze(_pushed(tmp_path / "offset.c3d", offset=12.0), P)
    checks = offset.summary.checks.to_dict()
    assert checks["zero_offset_channels"] == ["plate 3 vertical"]
    plate = next(c for c in checks["channels"] if c["channel"] == "plate 3 vertical")
    assert plate["offset"] == pytest.approx(12.0, abs=1e-3)
    assert checks["saturated_channels"] == []  # a constant 12 N is no clipped peak
    fine = analyze(_pushed(tmp_path / "fine.c3d", offset=2.0), P).summary.checks.to_dict()
    assert fine["zero_offset_channels"] == []


# --- (d) the forward axis against the feet --------------------------------------------------
def _turned(values):
    """Body (ap, ml, up) -> the lab of a lab whose forward is -y: (ml, -ap, up)."""
    values = np.asarray(values, dtype=float)
    return np.stack([values[..., 1], -values[..., 0], values[..., 2]], axis=-1)


def _minus_y_lab(path):
    n = int(SECONDS * RATE)
    markers = {name: _turned(v) for name, v in {**_feet(n), "CentreOfMass": _com(n)}.items()}
    plates = [
        (_turned(force), _turned(cop), moment, _turned(corners))
        for force, cop, moment, corners in _standing_plates(n)
    ]
    write_c3d(path, point_rate=RATE, markers=markers, analog_rate=ANALOG, plates=plates)
    return path


def test_a_lab_whose_forward_is_minus_y_is_refused_with_the_default_axis(tmp_path):
    path = _minus_y_lab(tmp_path / "minus_y.c3d")
    with pytest.raises(
        InvalidParameterError, match=r"feet point 90 degrees to the right.*--ap-axis"
    ):
        analyze(read_recording(path), P)
    right = analyze(read_recording(path, ap_axis="-y"), P)
    same = analyze(_plated(tmp_path / "x.c3d"), P)
    assert right.summary.checks.forward_angle == pytest.approx(0.0, abs=1e-9)
    assert same.summary.checks.to_dict()["forward_angle"] == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(right.columns["mos"], same.columns["mos"], atol=1e-9)


def test_feet_turned_out_pass(tmp_path):
    """Feet turned out 20 degrees each (toe-out): their mean points forward."""
    n = int(SECONDS * RATE)
    markers = {**_feet(n), "CentreOfMass": _com(n)}
    for side, sign in (("L", 1.0), ("R", -1.0)):
        turn = np.radians(20.0) * sign
        heel, toe = markers[f"{side}HEE"].copy(), markers[f"{side}TOE"].copy()
        length = toe[0, 0] - heel[0, 0]
        toe[:, 0] = heel[:, 0] + length * np.cos(turn)
        toe[:, 1] = heel[:, 1] + length * np.sin(turn)
        markers[f"{side}TOE"] = toe
    result = analyze(_write(tmp_path / "out.c3d", markers), P)
    assert result.summary.checks.forward_angle == pytest.approx(0.0, abs=1e-6)


# --- a batch: the faulty trials flagged or failed, the rest intact -----------------------------
def test_a_batch_with_faulty_trials_keeps_the_clean_ones(tmp_path):
    folder = tmp_path / "trials"
    folder.mkdir()
    _plated(folder / "a_clean.c3d")
    _minus_y_lab(folder / "b_minus_y.c3d")
    _pushed(folder / "c_clipped.c3d", clip=-120.0)
    trials, root = find_trials([folder])
    batch = run_trials(trial_jobs(trials, root), tmp_path / "out", workers=1)
    status = {row["trial"]: (row["status"], row["error"]) for row in batch.trials}
    assert status["a_clean.c3d"] == ("analysed", None)
    assert status["c_clipped.c3d"] == ("analysed", None)
    assert status["b_minus_y.c3d"][0] == "failed"
    assert "--ap-axis" in status["b_minus_y.c3d"][1] and "\n" not in status["b_minus_y.c3d"][1]
    alone = analyze(read_recording(folder / "a_clean.c3d"), P).summary
    rows = [r for r in batch.trials if r["trial"] == "a_clean.c3d"]
    for row in rows:
        assert row["excluded_frames"] == alone.excluded_frames == 0
    summaries = {
        name: json.loads((tmp_path / "out" / "trials" / name / "summary.json").read_text())
        for name in ("a_clean.c3d", "c_clipped.c3d")
    }
    assert summaries["a_clean.c3d"]["checks"]["saturated_channels"] == []
    assert summaries["c_clipped.c3d"]["checks"]["saturated_channels"] == ["force ap"]


# --- the data-quality table -------------------------------------------------------------------
def test_the_data_quality_table_names_every_check_and_what_it_flagged(tmp_path):
    import pyarrow.parquet as pq

    from pushrecovery.analysis.output import write_analysis

    _, gapped = _gapped(tmp_path)
    paths = write_analysis(analyze(gapped, P), tmp_path / "gapped")
    table = pq.read_table(paths["quality_parquet"]).to_pylist()
    flagged = {(row["check"], row["target"]): row for row in table if row["flagged"]}
    assert set(flagged) == {("marker_gap", "left heel"), ("marker_gap", "left toe")}
    assert flagged["marker_gap", "left heel"]["frames"] == 30
    assert flagged["marker_gap", "left toe"]["frames"] == 10
    checks = {row["check"] for row in table}
    assert checks == {"flight", "cop_outside_base", "base_rejected", "marker_gap", "forward_axis"}
    assert paths["quality_csv"].read_text().splitlines()[0] == (
        '"check","target","flagged","frames","value","threshold","unit"'
    )
    stray = analyze(_plated(tmp_path / "three.c3d", stray_load=66.0), P).summary.checks
    rows = {(r["check"], r["target"]): r for r in stray.quality_rows()}
    assert rows["plate_under_no_foot", "plate 3"]["flagged"]
    assert not rows["plate_under_no_foot", "plate 1"]["flagged"]
    assert not rows["saturation", "force up"]["flagged"]
    assert stray.row_flags() == {
        "excluded_frames_markers": 0,
        "marker_gap_frames": "",
        "stray_plates": "plate 3",
        "saturated_channels": "",
        "zero_offset_channels": "",
        "forward_angle": pytest.approx(0.0, abs=1e-9),
    }


def test_a_batch_has_the_checks_in_its_rows_and_a_quality_table(tmp_path):
    # The flags reach the trials table (one column each) and the study's quality table.
    import pyarrow.parquet as pq

    folder = tmp_path / "trials"
    folder.mkdir()
    _gapped(folder)
    _plated(folder / "stray.c3d", stray_load=66.0)
    trials, root = find_trials([folder])
    batch = run_trials(trial_jobs(trials, root), tmp_path / "out", workers=1)
    rows = {(r["trial"], r["axis"]): r for r in batch.trials}
    assert rows["gapped.c3d", "ap"]["marker_gap_frames"] == "left heel=30; left toe=10"
    assert rows["gapped.c3d", "ml"]["excluded_frames_markers"] == 40
    assert rows["stray.c3d", "ap"]["stray_plates"] == "plate 3"
    q = pq.read_table(tmp_path / "out" / "quality.parquet").to_pylist()
    assert {(r["trial"], r["check"], r["target"]) for r in q if r["flagged"]} == {
        ("gapped.c3d", "marker_gap", "left heel"),
        ("gapped.c3d", "marker_gap", "left toe"),
        ("stray.c3d", "plate_under_no_foot", "plate 3"),
    }
