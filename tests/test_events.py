"""Events of measured trials on synthetic truth, on biomdp's jump files, and on bad input.

Synthetic trials set the onset, the flights, the steps' times and positions, with Gaussian noise
of a stated level from a seeded generator; each detection must come within a stated tolerance.
"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from pushrecovery.analysis.events import (
    flight_phases,
    mass_from_quiet,
    perturbation_onset,
    quiet_windows,
)
from pushrecovery.analysis.recording import Foot
from pushrecovery.analysis.signals import smooth_and_differentiate
from pushrecovery.analysis.steps_measured import (
    FootEvent,
    foot_events_from_force,
    foot_events_from_markers,
    measured_steps,
)
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError

G = 9.80665
MASS = 70.0


# --- perturbation onset ---------------------------------------------------------------------


def test_onset_of_a_force_step_within_two_samples():
    # Lean-release: F_ap / m jumps by 1.5 m/s² at the release; noise 0.05 m/s² SD at 1 kHz.
    rng = np.random.default_rng(1)
    time = np.arange(0.0, 3.0, 0.001)
    for onset in (1.0, 1.2345, 2.1):
        signal = np.where(time >= onset, 1.5, 0.0) + rng.normal(0.0, 0.05, len(time))
        found = perturbation_onset(time, signal, baseline=0.8, k=3.0, min_duration=0.02)
        assert found is not None and abs(found - onset) <= 0.002


def test_onset_of_a_ramped_push_lags_by_the_time_to_reach_k_sd():
    # A half-sine push of 2 m/s² over 0.2 s: the signal reaches k·σ = 0.15 m/s² after
    # asin(0.075) · 0.2 / π = 4.8 ms; the detection is there within 2 samples.
    rng = np.random.default_rng(2)
    time = np.arange(0.0, 2.0, 0.001)
    onset = 0.9
    phase = np.clip((time - onset) / 0.2, 0.0, 1.0)
    signal = 2.0 * np.sin(np.pi * phase) + rng.normal(0.0, 0.05, len(time))
    found = perturbation_onset(time, signal, baseline=(0.1, 0.8))
    expected = onset + np.arcsin(0.15 / 2.0) * 0.2 / np.pi
    assert found is not None and abs(found - expected) <= 0.002


def test_onset_from_kinematic_com_acceleration():
    # A CoM marker at 100 Hz (noise 0.1 mm SD) pushed by 1.5 m/s² for 0.2 s from t = 1.5 s;
    # the acceleration from two filtered differentiations (10 Hz) finds the onset within 30 ms:
    # the zero-lag filter spreads the step over about 1 / (2 · 10 Hz) either way.
    rng = np.random.default_rng(3)
    time = np.arange(0.0, 3.0, 0.01)
    onset = 1.5
    tau = np.clip(time - onset, 0.0, 0.2)
    position = 0.75 * tau**2 + 0.3 * np.clip(time - onset - 0.2, 0.0, None)
    marker = position + rng.normal(0.0, 1e-4, len(time))
    _, velocity = smooth_and_differentiate(time, marker, 10.0)
    _, acceleration = smooth_and_differentiate(time, velocity, 10.0)
    found = perturbation_onset(time, acceleration, baseline=1.0, k=3.0, min_duration=0.03)
    assert found is not None and abs(found - onset) <= 0.03


def test_no_onset_in_quiet_standing():
    rng = np.random.default_rng(4)
    time = np.arange(0.0, 5.0, 0.001)
    signal = rng.normal(0.0, 0.05, len(time))
    assert perturbation_onset(time, signal, baseline=1.0, k=5.0, min_duration=0.02) is None


# --- flight, quiet windows, mass ------------------------------------------------------------


def synthetic_jump(noise: float, seed: int = 5):
    """A countermovement jump at 1 kHz: quiet, unweighting, push-off, flight, landing, quiet.

    Flight from 2.6 s to 3.0 s (the force is exactly zero plus noise); the rest is the weight
    plus sin² bumps (impulse: height × duration / 2) sized so that the push-off gives the
    take-off speed of a 0.4 s flight (g · 0.2 s) and the landing stops it: the trial starts and
    ends at rest, as a real jump file.
    """
    rng = np.random.default_rng(seed)
    time = np.arange(0.0, 6.0, 0.001)
    weight = MASS * G
    force = np.full(len(time), weight)

    def bump(start, duration, height):
        phase = np.clip((time - start) / duration, 0.0, 1.0)
        return height * np.sin(np.pi * phase) ** 2

    force = force - bump(2.0, 0.3, 0.6 * weight) + bump(2.3, 0.3, (0.2 + 0.09) / 0.15 * weight)
    flight = (time >= 2.6) & (time < 3.0)
    force[flight] = 0.0
    force = force + bump(3.0, 0.4, (0.2 + 0.06) / 0.2 * weight) - bump(3.4, 0.3, 0.4 * weight)
    return time, force + rng.normal(0.0, noise, len(time)), (2.6, 3.0)


@pytest.mark.parametrize("noise", [2.0, 10.0])
def test_flight_found_within_a_sample_and_mass_from_quiet_within_1_percent(noise):
    # 10 N SD is the noise of the two-plate Vicon file's unloaded plate (±30 N peaks).
    time, force, (start, end) = synthetic_jump(noise)
    flights = flight_phases(time, force)
    assert len(flights.intervals) == 1
    found_start, found_end = flights.intervals[0]
    assert abs(found_start - start) <= 0.002 and abs(found_end - end) <= 0.002
    assert flights.mask.sum() == pytest.approx((found_end - found_start) / 0.001, abs=1)
    windows = quiet_windows(time, force)
    assert windows and all(b <= 2.0 or a >= 3.7 for a, b in windows)
    mass = mass_from_quiet(time, force, G, windows)
    assert mass.mass == pytest.approx(MASS, rel=0.01)
    assert mass.spread is not None and mass.spread < 0.01 * MASS
    # The loaded samples' mean is biased by T / (T - T_flight); the whole-trial mean is not.
    assert force.mean() / G == pytest.approx(MASS, rel=0.01)
    loaded = force[~flights.mask].mean() / G
    assert loaded == pytest.approx(MASS * 6.0 / 5.6, rel=0.01)


def test_flight_phases_merge_noise_and_drop_short_runs():
    time = np.arange(0.0, 1.0, 0.001)
    force = np.full(len(time), 700.0)
    force[300:600] = 0.0
    force[450] = 50.0  # one noisy sample above the threshold inside the flight
    force[800:805] = 0.0  # 5 ms below: noise, not a flight
    flights = flight_phases(time, force, min_duration=0.02)
    assert flights.intervals == ((0.3, 0.6),)
    assert flight_phases(time, force, min_duration=0.0).intervals[-1] == (0.8, 0.805)
    assert flights.to_dict()["total_duration"] == pytest.approx(0.3)


def test_foot_events_from_a_plate():
    rng = np.random.default_rng(6)
    time = np.arange(0.0, 2.0, 0.001)
    force = np.where((time >= 0.7) & (time < 1.05), 0.0, 350.0) + rng.normal(0.0, 3.0, len(time))
    events = foot_events_from_force(time, force, "right")
    assert [(e.kind, e.time) for e in events] == [
        ("foot-off", pytest.approx(0.7)),
        ("foot-contact", pytest.approx(1.05)),
    ]
    assert events[0].to_dict() == {
        "foot": "right",
        "kind": "foot-off",
        "time": pytest.approx(0.7),
        "source": "plate",
    }


# --- markers and steps ----------------------------------------------------------------------


def stepping_feet(noise: float, seed: int = 7):
    """Two feet at 100 Hz; the right one steps 0.30 m forward, 0.05 m left at 1.2 to 1.6 s.

    The swing lifts the foot with a sine height profile (clearance 8 cm); markers sit 3 cm
    (heel) and 2 cm (toe) above the floor on the foot's midline, heel 0.05 m behind and toe
    0.15 m ahead of the ankle.
    """
    rng = np.random.default_rng(seed)
    time = np.arange(0.0, 3.0, 0.01)
    off, contact = 1.2, 1.6
    phase = np.clip((time - off) / (contact - off), 0.0, 1.0)
    swing = (time > off) & (time < contact)
    lift = np.where(swing, 0.08 * np.sin(np.pi * phase), 0.0)
    shift = 0.5 * (1.0 - np.cos(np.pi * phase))  # 0 before, 1 after
    feet = []
    for name, ml, moves in (("left", 0.1, False), ("right", -0.1, True)):
        ap = 0.30 * shift if moves else np.zeros(len(time))
        lat = ml + (0.05 * shift if moves else 0.0)
        up = lift if moves else np.zeros(len(time))

        def marker(dx, height, ap=ap, lat=lat, up=up):
            clean = np.column_stack([ap + dx, np.broadcast_to(lat, ap.shape), up + height])
            return clean + rng.normal(0.0, noise, clean.shape)

        feet.append(Foot(name, marker(-0.05, 0.03), marker(0.15, 0.02), marker(0.0, 0.07)))
    return time, tuple(feet), (off, contact)


def test_marker_events_and_measured_step():
    time, feet, (off, contact) = stepping_feet(noise=3e-4)
    events = foot_events_from_markers(time, feet[1])
    assert [e.kind for e in events] == ["foot-off", "foot-contact"]
    # Foot-off: the first frame the lower marker is 3 cm up: 0.08 sin(π s) = 0.03 + 0.0;
    # contact: the marker is still (10 Hz filter) within 3 frames of touching down.
    rise = np.arcsin(0.03 / 0.08) / np.pi * (contact - off)
    assert abs(events[0].time - (off + rise)) <= 0.011
    assert 0.0 <= events[1].time - contact <= 0.03
    assert foot_events_from_markers(time, feet[0]) == []
    steps = measured_steps(time, feet, events, onset=1.0)
    assert len(steps) == 1
    step = steps[0]
    assert step.foot == "right"
    assert abs(step.length - 0.30) < 1e-3 and abs(step.width - 0.05) < 1e-3
    assert step.latency == pytest.approx(events[0].time - 1.0)
    assert step.duration == pytest.approx(events[1].time - events[0].time)
    assert abs(step.start_ap - 0.05) < 1e-3 and abs(step.end_ml + 0.05) < 1e-3
    row = step.to_dict()
    assert row["length"] == step.length and set(row) >= {"off_time", "contact_time", "latency"}


def test_measured_step_from_plate_events_and_at_events():
    time, feet, (off, contact) = stepping_feet(noise=3e-4)
    events = [
        FootEvent("right", "foot-contact", contact, "plate"),
        FootEvent("right", "foot-off", off, "plate"),
    ]
    (step,) = measured_steps(time, feet, events)
    assert step.latency is None and step.duration == pytest.approx(0.4)
    assert abs(step.length - 0.30) < 1e-3
    (at_events,) = measured_steps(time, feet, events, position="event")
    assert abs(at_events.length - 0.30) < 2e-3
    # A foot-off with no contact after it makes no step.
    assert measured_steps(time, feet, events[1:]) == []


# --- biomdp's real force-plate files ---------------------------------------------------------


def _biomdp_file(name: str) -> pathlib.Path:
    biomdp = pytest.importorskip("biomdp")
    path = pathlib.Path(biomdp.__file__).parent / "tests" / "datasets" / name
    if not path.exists():
        pytest.skip(f"biomdp has no {name}")
    return path


@pytest.mark.parametrize(
    ("name", "flights"),
    [
        # One countermovement jump on one plate; a drop from a box on plate 2 onto plate 1
        # (0.25 s) followed by a jump (0.50 s); a jump on two plates at 2 kHz whose unloaded
        # plate is noisy (SD 7 N, peaks above 30 N).
        ("kistler_CMJ_1plate.c3d", [(3.422, 3.976)]),
        ("kistler_DJ_2plates.c3d", [(3.197, 3.451), (3.854, 4.358)]),
        ("vicon_CMJ_kinem_kinet_emg.c3d", [(4.2525, 4.9195)]),
    ],
)
def test_biomdp_jumps_flights_and_quiet_mass(name, flights):
    from pushrecovery.analysis.c3d import read_c3d

    content = read_c3d(_biomdp_file(name))
    time = content.analog_time
    vertical = np.sum([plate.force[:, 2] for plate in content.plates], axis=0)
    found = flight_phases(time, vertical).intervals
    assert len(found) == len(flights)
    for (a, b), (start, end) in zip(found, flights, strict=True):
        assert abs(a - start) <= 0.002 and abs(b - end) <= 0.002
    # The weighing phase: the first second of quiet standing (1 s as Owen et al. 2014).
    standing = vertical[time < 1.0].mean() / G
    mass = mass_from_quiet(time, vertical, G, quiet_windows(time, vertical))
    assert mass.mass == pytest.approx(standing, rel=0.01)
    # Without the flights the mean is 7 to 10 % too high.
    assert vertical[~flight_phases(time, vertical).mask].mean() / G > 1.06 * standing


def test_biomdp_quiet_standing_mass_against_the_vendor_weight():
    from pushrecovery.analysis.c3d import read_c3d

    content = read_c3d(_biomdp_file("kistler_COP.c3d"))
    time, vertical = content.analog_time, content.plates[0].force[:, 2]
    assert flight_phases(time, vertical).intervals == ()
    mass = mass_from_quiet(time, vertical, G, quiet_windows(time, vertical))
    assert mass.mass * G == pytest.approx(667.6, rel=0.01)  # BioWare's normalised force


def test_biomdp_marker_events_against_the_plate():
    # Right heel (TalonInf) and metatarsal-head marker at 200 Hz against plate 1 at 2 kHz:
    # foot-off within 10 ms, contact 40 to 50 ms late (the metatarsal marker, on the dorsum,
    # keeps descending 2 cm after the forefoot lands at 3 m/s).
    from pushrecovery.analysis.c3d import read_c3d

    content = read_c3d(_biomdp_file("vicon_CMJ_kinem_kinet_emg.c3d"))
    markers = content.markers
    foot = Foot("right", markers["Right_TalonInf"], markers["Right_Meta"], markers["RAJC"])
    plate = foot_events_from_force(content.analog_time, content.plates[0].force[:, 2], "right")
    marker = foot_events_from_markers(content.point_time, foot)
    assert [e.kind for e in marker] == [e.kind for e in plate] == ["foot-off", "foot-contact"]
    assert abs(marker[0].time - plate[0].time) <= 0.01
    assert 0.03 <= marker[1].time - plate[1].time <= 0.05


# --- bad input ------------------------------------------------------------------------------

TIME = np.arange(0.0, 2.0, 0.01)
FORCE = np.full(len(TIME), 700.0)
FEET = stepping_feet(0.0)[1]
GOOD = {
    perturbation_onset: {"time": TIME, "signal": np.zeros(len(TIME))},
    flight_phases: {"time": TIME, "vertical_force": FORCE},
    quiet_windows: {"time": TIME, "vertical_force": FORCE},
    mass_from_quiet: {"time": TIME, "vertical_force": FORCE, "gravity": G, "windows": [(0, 1)]},
    foot_events_from_force: {"time": TIME, "vertical_force": FORCE, "foot": "left"},
    foot_events_from_markers: {"time": np.arange(0.0, 3.0, 0.01), "foot": FEET[0]},
    measured_steps: {"time": np.arange(0.0, 3.0, 0.01), "feet": FEET, "events": []},
}
BAD = [
    (perturbation_onset, "time", np.ones(len(TIME)), "strictly"),
    (perturbation_onset, "signal", np.zeros(3), "one sample per time"),
    (perturbation_onset, "signal", np.full(len(TIME), np.inf), "signal must be finite or NaN"),
    (perturbation_onset, "baseline", 0.0, "baseline must be > 0"),
    (perturbation_onset, "baseline", (1.0, 0.5), "t0 < t1"),
    (perturbation_onset, "baseline", (5.0, 6.0), "at least 2 finite samples"),
    (perturbation_onset, "baseline", "x", "baseline must be a"),
    (perturbation_onset, "k", -1.0, "k must be > 0"),
    (perturbation_onset, "min_duration", -0.1, "min_duration must be >= 0"),
    (flight_phases, "vertical_force", np.zeros((len(TIME), 2)), "vertical_force must be an"),
    (flight_phases, "threshold", np.nan, "threshold must be a finite"),
    (flight_phases, "min_duration", np.inf, "min_duration must be a finite"),
    (quiet_windows, "window", 0.02, "window must hold at least 3 samples"),
    (quiet_windows, "window", -1.0, "window must be > 0"),
    (quiet_windows, "max_acceleration", 0.0, "max_acceleration must be in [1e-06, 100]"),
    (quiet_windows, "gravity", -9.81, "gravity must be in [0.1, 100]"),
    (quiet_windows, "threshold", "x", "threshold must be a finite"),
    (mass_from_quiet, "gravity", 0.0, "gravity must be in [0.1, 100]"),
    (mass_from_quiet, "windows", [], "windows must be"),
    (mass_from_quiet, "windows", [(0.0, 1.0, 2.0)], "windows must be at least one"),
    (mass_from_quiet, "windows", [(1.0, 0.5)], "start < end"),
    (mass_from_quiet, "windows", [(5.0, 6.0)], "at least 2 finite samples"),
    (mass_from_quiet, "windows", None, "windows must be a"),
    (foot_events_from_force, "foot", 3, "foot must be a str"),
    (foot_events_from_force, "threshold", np.inf, "threshold must be a finite"),
    (foot_events_from_markers, "foot", "left", "each of feet must be a Foot"),
    (foot_events_from_markers, "time", np.arange(0.0, 1.0, 0.01), "one frame per time"),
    (foot_events_from_markers, "contact_height", 0.0, "contact_height must be > 0"),
    (foot_events_from_markers, "max_speed", np.nan, "max_speed must be a finite"),
    (foot_events_from_markers, "cutoff", 60.0, "cutoff must be in (0, 50)"),
    (foot_events_from_markers, "cutoff", -1.0, "cutoff must be >= 0"),
    (foot_events_from_markers, "min_duration", -1.0, "min_duration must be >= 0"),
    (measured_steps, "feet", (), "feet must name at least one foot"),
    (measured_steps, "time", TIME, "one frame per time"),
    (measured_steps, "events", [("right", "foot-off")], "each of events must be a FootEvent"),
    (measured_steps, "events", "x", "events must be a list or tuple"),
    (measured_steps, "onset", np.nan, "onset must be a finite"),
    (measured_steps, "position", "middle", "position must be 'stance' or 'event'"),
]


@pytest.mark.parametrize(("function", "argument", "value", "message"), BAD)
def test_bad_arguments_are_named(function, argument, value, message):
    function(**GOOD[function])  # the good call works
    with pytest.raises((InvalidParameterError, ParameterTypeError)) as caught:
        function(**{**GOOD[function], argument: value})
    assert message in str(caught.value)
    assert isinstance(caught.value, PushRecoveryError)
