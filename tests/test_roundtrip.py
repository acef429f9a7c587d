"""Known truth: MuJoCo pushes written as C3D files (markers + force plates), analysed back.

The analysis sees only the C3D file; the truth is what the simulation did: the strategy it used
(ankle torque, hip torque, a step) and the step it took.
"""

import functools

import numpy as np
import pytest

from pushrecovery.analysis.c3d import write_c3d
from pushrecovery.analysis.readers import read_c3d_recording
from pushrecovery.analysis.trial import AnalysisSettings, analyze, body_for
from pushrecovery.experiments.mocap import record_push
from pushrecovery.presets import load_params

PARAMS = load_params()
SETTINGS = AnalysisSettings()

#: name -> (model, push velocity [m/s], duration [s]) chosen well inside each strategy's band.
CASES = {
    "ankle": ("foot", 0.30, 4.0),
    "hip": ("torso", 0.55, 4.0),
    "step": ("biped", 1.30, 2.5),
}


@functools.cache
def _recorded(case):
    model, velocity, duration = CASES[case]
    return record_push(model, PARAMS, impulse=velocity * PARAMS.mass, duration=duration)


def _c3d(tmp_path, recording, *, com=True):
    markers = dict(recording.markers)
    if not com:
        del markers["CentreOfMass"]
    path = tmp_path / "trial.c3d"
    write_c3d(
        path,
        point_rate=recording.point_rate,
        markers=markers,
        analog_rate=recording.analog_rate,
        plates=recording.plates,
        mass=recording.mass,
    )
    return path


def _analyse(path):
    trial = read_c3d_recording(path)
    found, sources = body_for(trial, mass=None, com_height=None, gravity=PARAMS.gravity)
    params = load_params(overrides=found)
    return trial, params, analyze(trial, params, SETTINGS, sources=sources)


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_analysis_needs_what_the_simulation_used(tmp_path, case):
    recording = _recorded(case)
    truth = recording.truth
    assert truth["used"] == case and truth["outcome"] == "recovered"
    assert truth["predicted"]["strategy"] == case
    _, params, result = _analyse(_c3d(tmp_path, recording))
    summary = result.summary
    assert summary.mass_source == "file"
    assert summary.params.mass == pytest.approx(recording.mass, rel=1e-6)
    assert summary.com_height_source == "file"
    # The ankle marker sits at the hinge: the standing CoM above it is the model's L (the
    # biped's 1.6 kg legs put its whole-body CoM 1.5 cm lower).
    assert params.com_height == pytest.approx(PARAMS.com_height, abs=0.02)
    assert summary.support_source == "foot markers"
    assert summary.directions["ap"].most_demanding == case
    if case != "step":
        assert summary.directions["ml"].most_demanding == "ankle"
    # else: the planar biped's feet are drawn 0.1 m either side of its CoM and its joints hold
    # it in the sagittal plane; in single support the markers rightly say that a free body
    # would need more than its ankle medio-laterally (the CoM 5.5 cm beyond the stance foot).
    assert summary.excluded_frames == 0
    # Before the push: quiet standing, ankle.
    time, strategy = result.columns["time"], result.columns["ap_strategy"]
    assert (strategy[time < truth["push_time"] - 0.1] == "ankle").all()


def test_the_predicted_step_is_the_step_taken(tmp_path):
    recording = _recorded("step")
    truth = recording.truth
    assert truth["steps"] == 1
    taken = truth["step_lengths"][0]
    _, _, result = _analyse(_c3d(tmp_path, recording))
    events = result.summary.step_events
    assert events and events[0].axis == "ap"
    assert abs(events[0].time - truth["push_time"]) < 0.05
    # From the end of the filter's transient to the landing the stance leg falls as a
    # pendulum, whose recommended step stays the one the controller took.
    time = result.columns["time"]
    landing = recording.analog_time[np.argmax(recording.plates[1][0][:, 2] > 20.0)]
    window = (time > truth["push_time"] + 0.1) & (time < landing - 0.02)
    lengths = result.columns["ap_step_length"][window]
    assert np.isfinite(lengths).mean() > 0.9
    # The controller takes Sec. IV's step; the analysis recommends the N-step plan's first
    # step (LIPM, min_step_time) and the range of first steps that still capture: the step
    # taken lies in that range, and the recommendation within 10 % of it.
    shortest = result.columns["ap_step_length_min"][window]
    longest = result.columns["ap_step_length_max"][window]
    # A frame's range assumes a touchdown min_step_time later, while the biped's swing is
    # shorter: the range of the first frame after the filter's transient (decided soonest)
    # holds the step taken (later frames ask for longer first steps, or for two steps).
    assert shortest[0] <= taken <= longest[0]
    assert np.nanmedian(lengths) == pytest.approx(taken, rel=0.1)
    assert events[0].step_length == pytest.approx(taken, rel=0.1)


def test_force_plates_alone_give_the_same_strategy(tmp_path):
    """No CoM marker: the CoM comes from the plates by zero-point integration.

    A push is an external force that is no ground reaction: the plates cannot see it, so the
    interval between the zero points around the push misses its impulse. Everywhere else the
    integrated CoM is the marker's.
    """
    recording = _recorded("ankle")
    _, _, result = _analyse(_c3d(tmp_path, recording, com=False))
    summary = result.summary
    assert summary.com_source.startswith("zero-point")
    assert summary.directions["ap"].most_demanding == "ankle"
    time = result.columns["time"]
    marker_com = np.interp(time, recording.point_time, recording.markers["CentreOfMass"][:, 0])
    error = np.abs(result.columns["ap_com"] - marker_com)
    assert np.isfinite(error).mean() > 0.9
    push = recording.truth["push_time"]
    away = (time < push - 0.3) | (time > push + 1.0)
    assert np.nanmax(error[away]) < 0.002
    assert np.nanmax(error) > 0.01  # the push itself is invisible to the plates


def test_the_cmp_from_the_plates_is_the_cop_moved_by_the_hip_torque(tmp_path):
    """CMP = CoM − L F_x/F_z (the LIPM's x − ẍ/ω²) against Eq. (6)'s δ + τ/(m g).

    The torso's hip torque switches bang-bang; the plates' 10 Hz filter rounds the switches,
    so the check is on the median and the shape, not on the instants of the switches.
    """
    recording = _recorded("hip")
    _, _, result = _analyse(_c3d(tmp_path, recording))
    time = result.columns["time"]
    torque = np.interp(time, recording.analog_time, recording.truth["hip_torque"])
    expected = torque / (recording.mass * PARAMS.gravity)
    measured = result.columns["ap_cmp"] - result.columns["ap_cop"]
    push = recording.truth["push_time"]
    response = (time > push + 0.1) & (time < push + 1.5)
    assert np.abs(expected[response]).max() > 0.1  # the hip did work: CMP 10+ cm off the CoP
    assert np.median(np.abs(measured - expected)[response]) < 0.005
    assert np.corrcoef(measured[response], expected[response])[0, 1] > 0.95
    assert np.abs(measured[time < push - 0.05]).max() < 0.003  # no torque, CMP on the CoP


def test_the_steps_table_is_the_step_the_simulation_took(tmp_path):
    """Issue 34: one row per step, its landing and touchdown those of the simulation.

    The right leg lifts off plate 1, which both feet stood on (so the plate cannot see that
    foot leave: its markers do), and lands on plate 2.
    """
    from pushrecovery.campaign.trials import TrialJob
    from pushrecovery.campaign.trials.steps import step_schema, trial_steps

    recording = _recorded("step")
    truth = recording.truth
    _, params, result = _analyse(_c3d(tmp_path, recording))
    job = TrialJob(tmp_path / "trial.c3d", "trial.c3d", None)
    (row,) = trial_steps(job, result.summary)
    true = {(e["foot"], e["kind"]): e["time"] for e in reversed(truth["foot_events"])}
    assert row.foot == "right" and row.step == 1
    # Touchdown: the first sample the floor carries the right foot again, to 10 ms.
    landing = max(e["time"] for e in truth["foot_events"] if e["kind"] == "foot-contact"
                  and e["foot"] == "right")  # fmt: skip
    assert abs(row.foot_contact - landing) <= 0.010
    # Foot-off from the heel and toe markers (3 cm up): later than the contact force's end.
    lift = true[("right", "foot-off")]
    assert 0.0 <= row.foot_off - lift <= 0.1
    # The landing: the foot point (heel-toe midpoint) is the ankle + (heel + toe) / 2; the
    # simulation's foothold is the landed ankle (and the foot creeps 4.5 mm after, see
    # test_mocap): to 1 cm.
    offset = 0.5 * (PARAMS.heel + PARAMS.toe)
    assert row.end_ap - offset == pytest.approx(truth["footholds"][1], abs=0.01)
    assert row.length == pytest.approx(truth["step_lengths"][0], abs=0.01)
    assert row.width == pytest.approx(0.0, abs=1e-9) and row.end_ml == pytest.approx(-0.1)
    assert row.duration == pytest.approx(row.foot_contact - row.foot_off)
    assert row.onset == pytest.approx(truth["push_time"], abs=0.01)
    assert row.latency == pytest.approx(row.foot_off - row.onset)
    # The verdict before the step needed it; the step taken lies in the capture range.
    assert row.strategy_ap == "step" and row.steps_needed_ap >= 1
    assert row.step_min_ap <= row.length <= row.step_max_ap
    assert row.step_margin_ap == pytest.approx(
        min(row.length - row.step_min_ap, row.step_max_ap - row.length)
    )
    assert row.in_capture_region is True and row.capture_region_margin > 0.0
    # MoS at the contact: Hof's b toward the motion, from the frames' own column.
    frame = int(np.argmin(np.abs(result.columns["time"] - row.foot_contact)))
    assert row.mos_ap_contact == result.columns["mos_ap"][frame]
    assert row.mos_ml_contact == result.columns["mos_ml"][frame]
    # Hand computation of b_ant at that frame: the base's front edge minus the XCoM.
    xcom = result.columns["ap_com"][frame] + result.columns["ap_com_velocity"][frame] / (
        (PARAMS.gravity / params.com_height) ** 0.5
    )
    front = result.columns["ap_base_max"][frame]
    assert row.mos_ap_contact == pytest.approx(front - xcom, abs=1e-9)
    schema = step_schema()
    assert schema.field("mos_ap_contact").metadata[b"unit"] == b"m"
    assert schema.names[:4] == ["trial", "subject", "step", "foot"]


def test_the_trials_events_go_into_a_copy_of_its_c3d(tmp_path):
    from pushrecovery.analysis.c3d import read_events, write_events
    from pushrecovery.analysis.trial.events import c3d_events

    path = _c3d(tmp_path, _recorded("step"))
    _, _, result = _analyse(path)
    events = result.summary.events
    written = write_events(path, tmp_path / "events.c3d", c3d_events(events))
    back = read_events(written)
    assert back[0].context == "General" and "onset" in back[0].description
    assert back[0].time == pytest.approx(events.onset.time, abs=1e-6)
    feet = [(e.context, e.label) for e in back[1:]]
    assert feet == [
        ("Right" if f.event.foot == "right" else "Left",
         "Foot Strike" if f.event.kind == "foot-contact" else "Foot Off")
        for f in events.foot_events
    ]  # fmt: skip
    assert ("Right", "Foot Off") in feet and ("Right", "Foot Strike") in feet
    times = [f.event.time for f in events.foot_events]
    assert [e.time for e in back[1:]] == pytest.approx(times, abs=1e-6)
    # The copy is still the trial: analysed again, the same frames.
    _, _, again = _analyse(written)
    assert np.array_equal(again.columns["mos_ap"], result.columns["mos_ap"], equal_nan=True)
