"""Measured-trial analysis: filters, gaps, zero-point integration, margins, the CSV reader.

The truth comes from LIPM trajectories integrated here with scipy (independent of the
library's simulators), written out as measured data.
"""

import math
import re
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.signal import butter, sosfiltfilt

from pushrecovery.analysis.margins import direction_margins, time_to_leave
from pushrecovery.analysis.readers import read_csv_recording
from pushrecovery.analysis.recording import Foot, Recording, support_from_feet
from pushrecovery.analysis.signals import lowpass, repair_gaps, smooth_and_differentiate
from pushrecovery.analysis.trial import AnalysisSettings, analyze, body_for
from pushrecovery.analysis.zero_point import com_from_force
from pushrecovery.errors import InputFileError, InvalidParameterError
from pushrecovery.presets import load_params
from pushrecovery.surfaces.classify import STRATEGY_CODES, classify, classify_states

PARAMS = load_params()
OMEGA = PARAMS.omega


# --- signals -----------------------------------------------------------------------------
@pytest.mark.parametrize(("rate", "cutoff"), [(100.0, 6.0), (1000.0, 10.0), (100.0, 30.0)])
def test_lowpass_is_minus_3_db_at_the_cutoff(rate, cutoff):
    t = np.arange(0.0, 20.0, 1.0 / rate)
    middle = slice(len(t) // 4, 3 * len(t) // 4)

    def gain(frequency):
        wave = np.sin(2 * np.pi * frequency * t)
        return math.sqrt(2 * np.mean(lowpass(wave, rate, cutoff)[middle] ** 2))  # amplitude

    assert gain(cutoff) == pytest.approx(1 / math.sqrt(2), abs=0.01)
    assert gain(cutoff / 5) == pytest.approx(1.0, abs=0.01)
    assert gain(min(4 * cutoff, 0.45 * rate)) < 0.02


def test_lowpass_rejects_a_cutoff_above_nyquist():
    with pytest.raises(InvalidParameterError, match="cutoff"):
        lowpass(np.zeros(100), 100.0, 60.0)


def test_short_gap_filled_long_gap_and_ends_reported():
    t = np.arange(0.0, 5.0, 0.01)
    values = np.sin(t)
    values[100:105] = np.nan  # 0.05 s: filled
    values[200:260] = np.nan  # 0.6 s: left
    values[:3] = np.nan  # at the start: nothing to interpolate from
    repaired, gaps = repair_gaps(t, values, 0.1, "com")
    assert [(g.samples, g.filled) for g in gaps] == [(3, False), (5, True), (60, False)]
    assert np.abs(repaired[100:105] - np.sin(t[100:105])).max() < 1e-6
    assert np.isnan(repaired[200:260]).all() and np.isnan(repaired[:3]).all()
    assert gaps[1].start == pytest.approx(1.0) and gaps[1].end == pytest.approx(1.04)


def test_derivative_stops_at_gaps():
    t = np.arange(0.0, 4.0, 0.01)
    values = np.sin(2 * t)
    values[150:200] = np.nan
    _smooth, slope = smooth_and_differentiate(t, values, 0.0)
    ok = np.isfinite(slope)
    assert not ok[150:200].any() and ok[:150].all() and ok[200:].all()
    inner = np.r_[5:145, 205:395]
    assert np.abs(slope[inner] - 2 * np.cos(2 * t[inner])).max() < 1e-3


# --- zero-point-to-zero-point integration --------------------------------------------------
def _sway(duration=20.0, rate=1000.0, seed=0):
    """Quiet standing on the LIPM: the CoP follows a PD law on the CoM plus smooth noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, 1.0 / rate)
    # Smooth CoP noise of about 1 cm: horizontal forces of a few newtons, as in people.
    noise = sosfiltfilt(butter(2, 1.0, fs=rate, output="sos"), rng.normal(0, 0.3, len(t)))

    def cop(time, x, xdot):
        return x + 0.8 * x + 0.5 * xdot + np.interp(time, t, noise)

    sol = solve_ivp(
        lambda time, s: [s[1], OMEGA**2 * (s[0] - cop(time, s[0], s[1]))],
        (0, duration),
        [0.01, 0.0],
        t_eval=t,
        rtol=1e-10,
        atol=1e-12,
        max_step=1e-3,
    )
    x, xdot = sol.y
    p = cop(t, x, xdot)
    force = PARAMS.mass * OMEGA**2 * (x - p)
    return t, x, xdot, p, force


def test_zero_point_integration_recovers_the_com():
    t, x, xdot, p, force = _sway()
    com, velocity = com_from_force(t, force, p, PARAMS.mass)
    inside = np.isfinite(com)
    assert inside.mean() > 0.9
    # Sway of 3 cm; the pins are the samples nearest each zero (1 ms apart).
    assert np.abs(com[inside] - x[inside]).max() < 5e-4
    # A pin where |F| <= 0.02 % of the weight is within 0.2 mm of the CoM; over the shortest
    # interval (0.1 s) that is 2 mm/s of velocity, 0.6 mm of capture point.
    assert np.abs(velocity[inside] - xdot[inside]).max() < 3e-3


def test_zero_point_integration_removes_the_drift_of_a_force_bias():
    t, x, _, p, force = _sway()
    biased = force + 1.0  # a 1 N offset of the plate
    com, _ = com_from_force(t, biased, p, PARAMS.mass)
    inside = np.isfinite(com)
    plain = x[0] + np.cumsum(np.cumsum(biased / PARAMS.mass) / 1000.0) / 1000.0
    assert np.abs(plain - x).max() > 0.5  # double integration alone drifts by metres
    assert np.abs(com[inside] - x[inside]).max() < 5e-3


def test_zero_point_integration_needs_two_zero_points():
    t = np.linspace(0, 1, 100)
    with pytest.raises(InvalidParameterError, match="cross zero"):
        com_from_force(t, np.ones(100), np.zeros(100), 70.0)


# --- margins -----------------------------------------------------------------------------
@pytest.mark.parametrize(("xi", "p"), [(0.10, 0.05), (0.0, 0.02), (0.14, -0.04), (-0.04, 0.1)])
def test_time_to_leave_matches_the_lipm(xi, p):
    """ξ leaves the foot when the LIPM with the CoP held at p says so."""
    lower, upper = PARAMS.heel, PARAMS.toe
    predicted = float(time_to_leave(np.array(xi), np.array(p), lower, upper, OMEGA))

    def leave(_, s):
        capture = s[0] + s[1] / OMEGA
        return (capture - upper) * (capture - lower)

    leave.terminal = True
    sol = solve_ivp(
        lambda _, s: [s[1], OMEGA**2 * (s[0] - p)],
        (0, 20),
        [xi, 0.0],
        events=leave,
        rtol=1e-11,
        atol=1e-13,
    )
    assert sol.t_events[0][0] == pytest.approx(predicted, rel=1e-6)


def test_time_to_leave_edge_cases():
    lower, upper = np.array([-0.05] * 3), np.array([0.15] * 3)
    times = time_to_leave(
        np.array([0.2, 0.05, np.nan]), np.array([0.0, 0.05, 0.0]), lower, upper, 3
    )
    assert times[0] == 0.0 and times[1] == np.inf and np.isnan(times[2])


@settings(max_examples=60, deadline=None)
@given(
    x=st.floats(-0.3, 0.3),
    xdot=st.floats(-2.0, 2.0),
    ankle=st.floats(-1.0, 1.0),
)
def test_single_foot_margins_agree_with_the_classifier(x, xdot, ankle):
    """A fixed single foot in the lab: the per-frame analysis is the paper's classifier."""
    one = np.array([1.0])
    margins = direction_margins(
        (ankle + x) * one,
        xdot * one,
        (ankle + PARAMS.heel) * one,
        (ankle + PARAMS.toe) * one,
        ankle * one,
        PARAMS,
    )
    expected = classify(x, xdot, PARAMS)
    assert STRATEGY_CODES[margins.strategy[0]] == expected.strategy
    assert margins.cop[0] == pytest.approx(expected.margins["cop"], abs=1e-12)
    assert margins.cmp[0] == pytest.approx(expected.margins["cmp"], abs=1e-12)
    assert margins.capture_point[0] == pytest.approx(ankle + expected.capture_point, abs=1e-12)
    if expected.step is not None:
        assert margins.step_length[0] == pytest.approx(expected.step["step_length"], abs=1e-9)


# --- base of support ---------------------------------------------------------------------
def _foot(name, ap, ml, lift, n):
    z = np.full(n, 0.01) + lift
    heel = np.column_stack([np.full(n, ap - 0.05), np.full(n, ml), z])
    toe = np.column_stack([np.full(n, ap + 0.20), np.full(n, ml), z])
    ankle = np.column_stack([np.full(n, ap), np.full(n, ml), z + 0.07])
    return Foot(name, heel, toe, ankle)


def test_support_from_feet_follows_a_lifted_foot():
    n = 4
    lift = np.array([0.0, 0.0, 0.1, 0.0])
    left = _foot("left", 0.0, 0.1, np.zeros(n), n)
    right = _foot("right", 0.3, -0.1, lift, n)  # right foot ahead, lifted in frame 2
    support = support_from_feet((left, right), contact_height=0.02, foot_width=0.09)
    assert support.lower["ap"].tolist() == pytest.approx([-0.05] * 4)
    assert support.upper["ap"].tolist() == pytest.approx([0.5, 0.5, 0.2, 0.5])
    assert support.upper["ml"].tolist() == pytest.approx([0.145] * 4)
    assert support.lower["ml"].tolist() == pytest.approx([-0.145, -0.145, 0.055, -0.145])
    assert support.foot["ap"] == pytest.approx((-0.05, 0.2))
    ankle = support.stance_ankle("ap", np.array([0.4, 0.0, 0.4, 0.1]))
    assert ankle.tolist() == pytest.approx([0.3, 0.0, 0.0, 0.0])


def test_feet_facing_backward_are_refused():
    n = 3
    foot = _foot("left", 0.0, 0.1, np.zeros(n), n)
    backward = Foot("left", foot.toe, foot.heel, foot.ankle)
    with pytest.raises(InvalidParameterError, match="ap-axis"):
        support_from_feet((backward,), contact_height=0.02, foot_width=0.09)


# --- a whole trial from CSV --------------------------------------------------------------
PUSH_TIME, PUSH_DURATION = 1.0, 0.1


def _push_trial(push, duration=3.0, rate=100.0, x0=0.02):
    """Quiet standing, then a half-sine push of 0.1 s from t = 1 s giving a velocity ``push``;
    the CoP tracks a capture-point law, saturated on the foot."""

    def cop(s):
        capture = s[0] + s[1] / OMEGA
        return np.clip(capture + 1.0 * (capture - x0), PARAMS.heel, PARAMS.toe)

    def pushing(time):
        phase = (time - PUSH_TIME) / PUSH_DURATION
        inside = (phase > 0.0) & (phase < 1.0)
        return np.where(inside, push * np.pi / (2 * PUSH_DURATION) * np.sin(np.pi * phase), 0.0)

    def rhs(time, s):
        return [s[1], OMEGA**2 * (s[0] - cop(s)) + pushing(time)]

    def fallen(_, s):  # the recording ends as the body reaches the floor
        return abs(s[0]) - 0.6

    fallen.terminal = True
    t = np.arange(0.0, duration, 1.0 / rate)
    sol = solve_ivp(
        rhs,
        (0.0, duration),
        [x0, 0.0],
        t_eval=t,
        events=fallen,
        rtol=1e-10,
        atol=1e-12,
        max_step=0.005,
    )
    states = sol.y.T
    return t[: len(states)], states, np.array([cop(s) for s in states])


def _write_csv(path, t, states, cop, scale=1.0, gaps=()):
    com = states[:, 0].copy()
    for start, stop in gaps:
        com[start:stop] = np.nan
    lines = ["time,com_ap,com_ml,cop_ap,cop_ml"]
    for i in range(len(t)):
        cell = "" if np.isnan(com[i]) else f"{com[i] * scale:.6f}"
        lines.append(f"{t[i]:.4f},{cell},0,{cop[i] * scale:.6f},0")
    path.write_text("\n".join(lines) + "\n")


FIXED = AnalysisSettings(ankle_ap=0.0, ankle_ml=0.0)


@pytest.mark.parametrize("push", [0.25, 0.5, 0.9])
def test_trial_strategy_is_the_classifier_of_the_true_state(tmp_path, push):
    """Frame by frame (away from the push's filter transient and from the boundaries)."""
    t, states, cop = _push_trial(push)
    path = tmp_path / "trial.csv"
    _write_csv(path, t, states, cop)
    result = analyze(read_csv_recording(path), PARAMS, FIXED)
    truth = classify_states(states[:, 0], states[:, 1], PARAMS)
    true_capture = states[:, 0] + states[:, 1] / OMEGA
    cop_margin = np.minimum(true_capture - PARAMS.heel, PARAMS.toe - true_capture)
    # A zero-lag filter spreads the push over its own time scale: compare outside it.
    after = t > PUSH_TIME + PUSH_DURATION + 0.05
    settled = (np.abs(states[:, 0]) < 0.5) & ((t < PUSH_TIME - 0.05) | after)
    clear = settled & (np.abs(cop_margin) > 0.005) & (np.abs(cop_margin + 0.03) > 0.005)
    names = np.array([STRATEGY_CODES[c].value for c in truth])
    assert clear.sum() > 100
    assert (result.columns["ap_strategy"][clear] == names[clear]).mean() > 0.98
    error = np.abs(result.columns["ap_capture_point"] - true_capture)[settled]
    assert error.max() < 5e-3


def test_trial_summary_reports_what_a_biomechanist_needs(tmp_path):
    push = 0.25  # ankle only: ξ ≈ 0.02 + 0.25/3.13 = 0.10 < toe
    t, states, cop = _push_trial(push)
    path = tmp_path / "trial.csv"
    _write_csv(path, t, states, cop)
    summary = analyze(read_csv_recording(path), PARAMS, FIXED).summary
    assert summary.most_demanding == "ankle"
    assert summary.directions["ap"].time_in_strategy["ankle"] == pytest.approx(3.0)
    true_capture = states[:, 0] + states[:, 1] / OMEGA
    low = np.min(PARAMS.toe - true_capture)
    assert summary.directions["ap"].min_cop_margin.value == pytest.approx(low, abs=3e-3)
    assert summary.step_events == ()


def test_trial_needing_a_step_reports_the_step_event(tmp_path):
    t, states, cop = _push_trial(0.9)
    path = tmp_path / "trial.csv"
    _write_csv(path, t, states, cop)
    summary = analyze(read_csv_recording(path), PARAMS, FIXED).summary
    events = summary.step_events
    assert events and events[0].axis == "ap"
    assert PUSH_TIME < events[0].time < PUSH_TIME + PUSH_DURATION + 0.05
    # Once the push is over, the recommended step is the classifier's for the true state.
    result = analyze(read_csv_recording(path), PARAMS, FIXED)
    checked = 0
    for i in np.flatnonzero(t > PUSH_TIME + PUSH_DURATION + 0.05):
        expected = classify(states[i, 0], states[i, 1], PARAMS)
        if expected.step is None or result.columns["ap_strategy"][i] != "step":
            continue
        if result.columns["ap_steps"][i] != expected.steps:
            continue  # ξ estimated across the edge between N and N + 1 steps: another plan
        got = result.columns["ap_step_length"][i]
        # The plan's first step is l (ξ − c)/h of C_N (h ≈ 0.7 m for one step): the estimated
        # ξ's few millimetres of error move it about 1.5 times as much.
        assert got == pytest.approx(expected.step["step_length"], abs=0.02)
        checked += 1
    assert checked >= 3


def test_units_mm_give_the_same_analysis(tmp_path):
    t, states, cop = _push_trial(0.5)
    metres, millimetres = tmp_path / "m.csv", tmp_path / "mm.csv"
    _write_csv(metres, t, states, cop)
    _write_csv(millimetres, t, states, cop, scale=1000.0)
    a = analyze(read_csv_recording(metres), PARAMS, FIXED).columns
    b = analyze(read_csv_recording(millimetres, units="mm"), PARAMS, FIXED).columns
    assert np.allclose(a["ap_capture_point"], b["ap_capture_point"], atol=1e-5)  # 6 digits
    assert (a["strategy"] == b["strategy"]).all()


def test_millimetres_read_as_metres_are_refused(tmp_path):
    t, states, cop = _push_trial(0.25)
    path = tmp_path / "mm.csv"
    _write_csv(path, t, states, cop, scale=1000.0)
    with pytest.raises(InputFileError, match="units") as info:
        read_csv_recording(path, units="m")
    # Each quantity with its own unit (the message once said "at most 5 m, m/s").
    assert re.search(
        r"excursion of [\d.]+ m is not a standing body's \(at most \d m\)", str(info.value)
    )


def test_gaps_are_interpolated_or_excluded_and_reported(tmp_path):
    t, states, cop = _push_trial(0.25)
    path = tmp_path / "gaps.csv"
    _write_csv(path, t, states, cop, gaps=[(30, 35), (150, 200)])
    result = analyze(read_csv_recording(path), PARAMS, FIXED)
    gaps = result.summary.gaps
    assert [(g.signal, g.samples, g.filled) for g in gaps] == [
        ("com", 5, True),
        ("com", 50, False),
    ]
    assert result.columns["interpolated"][30:35].all()
    assert not result.columns["valid"][150:200].any()
    assert result.summary.excluded_frames == 50
    assert result.summary.excluded == {"no CoM": 50}


def _table(header, row=lambda i: f"{i / 100:.2f},0,0", n=12, change=None):
    """A CSV text of ``n`` rows made by ``row(i)``; ``change`` maps row index -> its text."""
    rows = [row(i) for i in range(n)]
    for i, text in (change or {}).items():
        rows[i] = text
    return "\n".join([header, *rows]) + "\n"


MALFORMED = {
    "no time": (_table("com_ap,com_ml", lambda i: "0,0"), "missing column 'time'"),
    "no com": (_table("time,foo,bar"), "no CoM"),
    "half a pair": (_table("time,com_ap", lambda i: f"{i / 100:.2f},0"), "com_ml"),
    "text": (_table("time,com_ap,com_ml", change={1: "0.01,abc,0"}), "row 3 is not a number"),
    "backwards": (_table("time,com_ap,com_ml", change={2: "0.005,0,0"}), "increase"),
    "uneven": (_table("time,com_ap,com_ml", change={11: "0.5,0,0"}), "evenly"),
    "ms": (_table("time,com_ap,com_ml", lambda i: f"{10 * i},0,0"), "seconds"),
    "one row": ("time,com_ap,com_ml\n0,0,0\n", "at least 10 rows"),
    "empty": ("", "empty"),
    "base": (_table("time,com_ap,com_ml,base_ap_min", lambda i: f"{i / 100},0,0,0"), "base_ap_max"),
    "ragged": (_table("time,com_ap,com_ml", change={3: "0.03,0"}), "malformed CSV"),
    "no values": (
        _table("time,com_ap,com_ml", lambda i: f"{i / 100},,0"),
        "'com_ap' has no values",
    ),
    "force on the plate": (
        _table(
            "time,com_ap,com_ml,cop_ap,cop_ml,force_ap,force_ml,force_v",
            lambda i: f"{i / 100},0,0,0,0,0,0,-700",
        ),
        "on the subject",
    ),
    "inverted base": (
        _table(
            "time,com_ap,com_ml,base_ap_min,base_ap_max,base_ml_min,base_ml_max",
            lambda i: f"{i / 100},0,0,0.2,-0.05,-0.1,0.1",
        ),
        "inverted",
    ),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_csv_is_one_clear_line(tmp_path, case):
    text, message = MALFORMED[case]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputFileError, match=message) as info:
        read_csv_recording(path)
    assert "\n" not in str(info.value)


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(InputFileError, match="not found"):
        read_csv_recording(tmp_path / "nothing.csv")
    with pytest.raises(InputFileError, match="directory"):
        read_csv_recording(tmp_path)


def test_body_from_flag_file_and_force_plates():
    t = np.linspace(0, 1, 11)
    force = np.column_stack([np.zeros(11), np.zeros(11), np.full(11, 700.0)])
    plates = Recording(time=t, force_time=t, force=force, cop=np.zeros((11, 2)))
    values, sources = body_for(plates, mass=None, com_height=None, gravity=10.0)
    assert values == {"mass": 70.0} and sources["mass"].startswith("force plates")
    assert sources["com_height"] == "preset"
    stored = Recording(time=t, mass=65.0, com_height=0.9)
    values, sources = body_for(stored, mass=80.0, com_height=None, gravity=9.81)
    assert values == {"mass": 80.0, "com_height": 0.9}
    assert sources == {"mass": "flag", "com_height": "file"}


def test_force_plate_only_csv_integrates_the_com(tmp_path):
    t, x, _xdot, p, force = _sway(duration=10.0, rate=500.0)
    path = tmp_path / "plates.csv"
    rows = ["time,cop_ap,cop_ml,force_ap,force_ml,force_v"]
    weight = PARAMS.mass * PARAMS.gravity
    rows += [
        f"{t[i]:.4f},{p[i]:.7f},{p[i]:.7f},{force[i]:.5f},{force[i]:.5f},{weight:.3f}"
        for i in range(len(t))
    ]
    path.write_text("\n".join(rows) + "\n")
    recording = read_csv_recording(path)
    values, _sources = body_for(recording, mass=None, com_height=None, gravity=PARAMS.gravity)
    assert values["mass"] == pytest.approx(PARAMS.mass, rel=1e-4)
    result = analyze(recording, PARAMS, AnalysisSettings(ankle_ap=-0.05, ankle_ml=0.0))
    assert result.summary.com_source.startswith("zero-point")
    com = result.columns["ap_com"]
    inside = np.isfinite(com)
    assert inside.mean() > 0.8
    assert np.abs(com[inside] - x[inside]).max() < 2e-3
    assert result.summary.most_demanding == "ankle"


def test_a_foot_without_markers_leaves_the_base_unknown():
    n = 4
    left = _foot("left", 0.0, 0.1, np.zeros(n), n)
    right = _foot("right", 0.0, -0.1, np.zeros(n), n)
    for part in (right.heel, right.toe, right.ankle):
        part[1:3] = np.nan  # the right foot's markers drop out in frames 1 and 2
    support = support_from_feet((left, right), contact_height=0.02, foot_width=0.09)
    assert np.isnan(support.lower["ml"][1:3]).all() and np.isnan(support.upper["ap"][1:3]).all()
    assert support.lower["ml"][[0, 3]].tolist() == pytest.approx([-0.145, -0.145])


def test_the_lateral_malleolus_marker_does_not_widen_the_base():
    n = 2
    foot = _foot("left", 0.0, 0.1, np.zeros(n), n)
    foot.ankle[:, 1] = 0.135  # Plug-in Gait's LANK, 3.5 cm lateral of the midline
    support = support_from_feet((foot,), contact_height=0.02, foot_width=0.09)
    assert support.upper["ml"].tolist() == pytest.approx([0.145, 0.145])
    assert support.stance_ankle("ml", np.array([0.1, 0.1])).tolist() == pytest.approx([0.1, 0.1])


def test_body_axes_follow_the_files_up_axis():
    from pushrecovery.analysis.readers import body_rotation

    assert body_rotation("x").tolist() == [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    y_up = np.array([0.0, 1.0, 0.0])
    rotation = body_rotation("z", y_up)
    assert rotation.tolist() == [[0, 0, 1], [1, 0, 0], [0, 1, 0]]  # ml = up x ap = +x
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    with pytest.raises(InvalidParameterError, match="horizontal"):
        body_rotation("y", y_up)


def test_a_header_that_is_not_utf8_is_one_clear_line(tmp_path):
    # Found by make fuzz: pyarrow decoded the names lazily and raised UnicodeDecodeError.
    path = tmp_path / "latin1.csv"
    path.write_bytes(b"time,com_\xe3p,com_ml\n" + b"".join(b"0.%02d,0,0\n" % i for i in range(12)))
    with pytest.raises(InputFileError, match="the header is not UTF-8 text") as info:
        read_csv_recording(path)
    assert "\n" not in str(info.value)


def test_time_to_leave_a_subnormal_away_from_the_anchor_is_infinite_without_a_warning():
    # Found by make fuzz: a CSV cell of 1e-320 overflowed edge / ahead with a RuntimeWarning.
    from pushrecovery.analysis.margins import time_to_leave

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        time = time_to_leave(np.array([1e-320]), np.array([0.0]), -0.05, 0.15, 3.13)
    assert time[0] == np.inf


def test_a_number_with_a_form_feed_is_read_as_python_reads_it(tmp_path):
    # Found by make fuzz (seed 0, case 7147): pyarrow typed the column as text, no cell failed
    # float(), and the search for the bad cell ended in a StopIteration traceback.
    path = tmp_path / "ff.csv"
    rows = [f"{i / 100:.2f},{0.001 * i:.6f},0" for i in range(12)]
    rows[5] = "0.05,0.005000\f,0"
    path.write_text("time,com_ap,com_ml\n" + "\n".join(rows) + "\n")
    recording = read_csv_recording(path)
    assert recording.com[5, 0] == pytest.approx(0.005)


def test_the_cop_margin_is_the_nearer_edge_and_mos_ap_the_edge_ahead(tmp_path):
    # docs/base_polygon.md, "Which margin is which": on the same base (fixed feet), per frame
    # the CoP margin is min(ξ − heel, toe − ξ) and mos_ap the margin toward the motion, so the
    # first is never larger, and the trial's min_cop_margin is the smaller.
    t, states, cop = _push_trial(0.5)
    path = tmp_path / "trial.csv"
    _write_csv(path, t, states, cop)
    result = analyze(read_csv_recording(path), PARAMS, FIXED)
    columns = result.columns
    both = np.isfinite(columns["ap_margin_cop"]) & np.isfinite(columns["mos_ap"])
    assert both.sum() > 100
    assert (columns["ap_margin_cop"][both] <= columns["mos_ap"][both] + 1e-9).all()
    moving = both & (columns["ap_com_velocity"] > 0.05)  # forward: mos_ap is to the toe
    xi = columns["ap_capture_point"][moving]
    np.testing.assert_allclose(columns["mos_ap"][moving], columns["ap_base_max"][moving] - xi)
    summary = result.summary
    assert summary.directions["ap"].min_cop_margin.value <= summary.plane.min_mos_ap.value


def test_the_xcom_takes_the_leg_length_when_asked(tmp_path):
    # Hof's XCoM with l = leg length: ξ = r + v/sqrt(g/l) in the 2-D margins, by hand from the
    # frames' own CoM and velocity; the per-axis margins of Eq. (4) keep the body's ω.
    import dataclasses

    from pushrecovery.analysis.trial import AnalysisSettings

    body = dataclasses.replace(PARAMS, leg_length=0.9 * PARAMS.com_height, max_step_length=None)
    t, states, cop = _push_trial(0.25)
    path = tmp_path / "trial.csv"
    _write_csv(path, t, states, cop)
    leg = AnalysisSettings(ankle_ap=0.0, ankle_ml=0.0, xcom_length="leg_length")
    default = analyze(read_csv_recording(path), body, FIXED)
    mine = analyze(read_csv_recording(path), body, leg)
    omega = math.sqrt(body.gravity / body.leg_length)
    columns = mine.columns
    xi = columns["ap_com"] + columns["ap_com_velocity"] / omega
    np.testing.assert_allclose(columns["xcom_ap"], xi, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(columns["ap_margin_cop"], default.columns["ap_margin_cop"])
    assert not np.allclose(columns["mos"], default.columns["mos"], equal_nan=True)
    plane = mine.summary.to_dict()["plane"]
    assert plane["xcom_length"] == "leg_length" and plane["omega"] == pytest.approx(omega)
    assert default.summary.to_dict()["plane"]["omega"] == pytest.approx(body.omega)
    with pytest.raises(InvalidParameterError, match="xcom_length must be one of"):
        AnalysisSettings(xcom_length="hip")
