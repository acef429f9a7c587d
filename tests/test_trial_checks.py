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
    flights = result.summary.checks.flights
    assert flights, "every jump has a flight"
    in_flight = result.columns["flight"]
    assert in_flight.any()
    assert not result.columns["valid"][in_flight].any()
    assert all(s is None for s in result.columns["strategy"][in_flight])
    for start, end in flights:
        frames = (result.time > start + 0.01) & (result.time < end - 0.01)
        assert in_flight[frames].all()
    assert result.summary.sway is None  # a jump is no quiet standing


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
    checks = result.summary.checks
    assert checks.cop_outside["ml"].sum() == 60 and not checks.base_rejected
    assert not result.columns["valid"][:60].any()
    assert result.columns["valid"][60:].all()
    assert result.columns["cop_outside_base"][:60].all()
    reasons = result.summary.excluded
    assert reasons["CoP beyond the computed base by more than 2 cm"] == 60


def test_a_base_the_cop_contradicts_is_rejected_and_nothing_is_classified(tmp_path):
    result = analyze(read_recording(_csv(tmp_path / "b.csv", 0.2, 600)), P)
    assert result.summary.checks.base_rejected
    assert not result.columns["valid"].any()
    assert result.summary.most_demanding is None
    assert any("no verdict is given" in note for note in result.summary.notes)
    # Within the tolerance nothing is withheld.
    inside = analyze(read_recording(_csv(tmp_path / "c.csv", 0.15 + 0.01, 600)), P)
    assert inside.columns["valid"].all() and not inside.summary.checks.base_rejected


def test_quiet_standing_gets_its_sway_measures(tmp_path):
    recording = read_recording(DATA / "kistler_COP.c3d")
    found, _ = body_for(recording, mass=None, com_height=None, gravity=9.81)
    result = analyze(recording, load_params(overrides=found))
    sway = result.summary.to_dict()["posturography"]
    assert result.summary.sway is not None and sway["cop_cutoff"] == 10.0
    # The 95 % prediction ellipse holds the CoP (order of magnitude of a standing subject).
    assert 1e-5 < result.summary.sway.ellipse.area < 1e-2
    json.dumps(sway, allow_nan=False)


def _stepping_recording(step=(0.30, -0.02)):
    """A subject standing on two feet (markers at 100 Hz), pushed forward at 1.0 s (the CoM
    from the exact LIPM with the CoP at the toe), who lifts the right foot at 1.5 s and puts
    it down 0.30 m ahead and 0.02 m outward at 1.9 s."""
    import math

    from pushrecovery.analysis.recording import Foot, Recording

    n, rate = 300, 100.0
    t = np.arange(n) / rate
    omega = P.omega
    x = np.full(n, 0.02)
    v = np.zeros(n)
    for k in range(101, n):  # standing still (CoP under the CoM) until the push
        push = 0.5 if k == 101 else 0.0
        offset, speed = x[k - 1] - P.toe, v[k - 1] + push
        ch, sh = math.cosh(omega / rate), math.sinh(omega / rate)
        x[k] = P.toe + offset * ch + speed / omega * sh
        v[k] = omega * offset * sh + speed * ch
    noise = np.random.default_rng(3).normal(0.0, 5e-4, (n, 2))  # markers' noise [m]
    com = np.column_stack([x + noise[:, 0], noise[:, 1], np.full(n, 1.0)])

    def foot(name, ml, moves):
        heel = np.zeros((n, 3))
        heel[:, 0], heel[:, 1], heel[:, 2] = -0.05, ml, 0.02
        if moves:
            swing = (t >= 1.5) & (t < 1.9)
            phase = np.clip((t - 1.5) / 0.4, 0.0, 1.0)
            heel[:, 0] += step[0] * phase
            heel[:, 1] += step[1] * phase
            heel[swing, 2] += 0.08 * np.sin(np.pi * phase[swing])
        toe = heel + np.array([0.20, 0.0, 0.0])
        ankle = heel + np.array([0.05, 0.0, 0.06])
        return Foot(name, heel, toe, ankle)

    feet = (foot("left", 0.1, False), foot("right", -0.1, True))
    return Recording(time=t, com=com, feet=feet, source="generated")


def test_a_step_is_detected_measured_and_given_its_margins():
    import math

    result = analyze(_stepping_recording(), P)
    events = result.summary.events
    onset = events.onset.time
    # The push, from the CoM acceleration, low-passed at 6 Hz forward and backward: the zero-lag
    # filter spreads the push over about +-1/fc, and with little noise the threshold is crossed
    # early in that spread: up to 1/fc = 0.17 s before the push, never after it.
    assert 1.0 - 1.0 / 6.0 <= onset <= 1.0 + 0.01
    kinds = [(e.event.foot, e.event.kind) for e in events.foot_events]
    assert kinds == [("right", "foot-off"), ("right", "foot-contact")]
    off, contact = (e.event.time for e in events.foot_events)
    # The markers method (docs/events.md): off once the foot is 3 cm up (0.08 sin(pi s / 0.4 s)
    # reaches 3 cm 49 ms after the lift), down when within 3 cm and slower than 0.1 m/s.
    lifted = 1.5 + 0.4 * math.asin(0.03 / 0.08) / math.pi
    assert off == pytest.approx(lifted, abs=0.011) and 1.85 <= contact <= 1.95
    (taken,) = events.measured_steps
    step = taken.step
    assert step.length == pytest.approx(0.30, abs=1e-3)
    assert step.width == pytest.approx(-0.02, abs=1e-3)
    assert step.latency == pytest.approx(off - onset)
    # The margins at foot-off are the frame's own.
    frame = int(np.argmin(np.abs(result.time - off)))
    at_off = taken.at_foot_off.axes["ap"]
    assert at_off.capture_point == pytest.approx(result.columns["ap_capture_point"][frame])
    assert at_off.strategy == result.columns["ap_strategy"][frame]
    compared = taken.against_recommended["ap"]
    assert compared.taken == step.length
    recommended = result.columns["ap_step_length"][frame]
    if np.isfinite(recommended):
        assert compared.recommended == pytest.approx(recommended)
        assert isinstance(compared.within, bool)
    else:
        assert compared.within is None


def test_the_plane_margin_is_the_xcom_distance_to_the_base_polygon(tmp_path):
    # Standing still at (0.02, 0.03) over a base [-0.05, 0.15] x [-0.15, 0.15] (CSV columns):
    # the XCoM is the CoM, 0.07 m from the rear edge and 0.12 m from the left edge.
    n = 300
    lines = ["time,com_ap,com_ml,base_ap_min,base_ap_max,base_ml_min,base_ml_max"]
    lines += [f"{k / 100:.2f},0.02,0.03,-0.05,0.15,-0.15,0.15" for k in range(n)]
    path = tmp_path / "still.csv"
    path.write_text("\n".join(lines) + "\n")
    result = analyze(read_recording(path), P)
    mos = result.columns["mos"]
    assert mos == pytest.approx(np.full(n, 0.07), abs=1e-9)
    plane = result.summary.plane
    assert plane.min_mos.value == pytest.approx(0.07, abs=1e-9)
    assert plane.base_source == "base columns"
    # The 2-D verdicts classify against feet (a Support): a base given as columns has none.
    assert plane.most_demanding is None
    assert result.columns["base_area"] == pytest.approx(np.full(n, 0.2 * 0.3))


def test_a_base_polygon_from_vertex_columns(tmp_path):
    # A triangle base (vertices in mm): the 2-D margin of a still CoM is its distance to the
    # nearest edge; a vertex given without its partner column is refused.
    n = 300
    head = "time,com_ap,com_ml,base_ap1,base_ml1,base_ap2,base_ml2,base_ap3,base_ml3"
    rows = [f"{k / 100:.2f},0,0,-50,-100,150,0,-50,100" for k in range(n)]
    path = tmp_path / "triangle.csv"
    path.write_text("\n".join([head, *rows]) + "\n")
    recording = read_recording(path, units="mm")
    assert recording.base_vertices.shape == (n, 3, 2)
    result = analyze(recording, P)
    # Distance from (0, 0) to the edge from (0.15, 0) to (-0.05, 0.1): |0.1*0 + 0.2*0 - 0.015|
    # / hypot(0.1, 0.2) (the line 0.1 x + 0.2 y = 0.015), and to the rear edge x = -0.05.
    expected = min(0.015 / np.hypot(0.1, 0.2), 0.05)
    assert result.columns["mos"] == pytest.approx(np.full(n, expected), abs=1e-9)
    assert result.summary.support_source == "base polygon columns"
    assert result.columns["ap_base_min"] == pytest.approx(np.full(n, -0.05))
    path.write_text(
        "\n".join([head.replace(",base_ml3", ""), *(r.rsplit(",", 1)[0] for r in rows)])
    )
    from pushrecovery.errors import InputFileError

    with pytest.raises(InputFileError, match="base_ml3 is missing"):
        read_recording(path, units="mm")


def test_normalised_columns_and_typed_tables(tmp_path):
    # Hof's dimensionless margins: the still CoM of the rectangle base above, 0.07 m inside,
    # for a leg of 0.875 m: 0.08; velocities over sqrt(g l).
    import dataclasses

    from pushrecovery.analysis.trial import AnalysisSettings

    n = 300
    lines = ["time,com_ap,com_ml,base_ap_min,base_ap_max,base_ml_min,base_ml_max"]
    lines += [f"{k / 100:.2f},0.02,0.03,-0.05,0.15,-0.15,0.15" for k in range(n)]
    path = tmp_path / "still.csv"
    path.write_text("\n".join(lines) + "\n")
    body = dataclasses.replace(P, leg_length=0.875)
    plain = analyze(read_recording(path), body)
    assert "mos_norm" not in plain.columns
    result = analyze(read_recording(path), body, AnalysisSettings(normalise=True))
    assert result.columns["mos_norm"] == pytest.approx(np.full(n, 0.08), abs=1e-9)
    assert result.columns["ap_margin_cop_norm"] == pytest.approx(
        result.columns["ap_margin_cop"] / 0.875
    )
    # Typed tables: arrow and pandas, the same frames as frames.parquet.
    table = result.to_arrow()
    assert table.num_rows == n and table.column("mos_norm").null_count == 0
    frames = result.to_pandas()
    assert list(frames.columns) == list(result.columns)
    assert frames["mos"].to_numpy() == pytest.approx(result.columns["mos"])


def test_foot_events_from_each_plate_of_a_drop_jump():
    # biomdp's drop jump on two Kistler plates: off the box's plate (2) into the first flight,
    # down on plate 1, off it into the jump's flight and back on it. Each plate's events are
    # the flights' ends (within 20 ms: the plates' own threshold and merging, docs/events.md).
    recording = read_recording(DATA / "kistler_DJ_2plates.c3d")
    assert len(recording.plates) == 2
    found, _ = body_for(recording, mass=None, com_height=None, gravity=9.81)
    result = analyze(recording, load_params(overrides=found))
    events = [(e.event.foot, e.event.kind, e.event.time) for e in result.summary.events.foot_events]
    assert [(foot, kind) for foot, kind, _ in events] == [
        ("plate 2", "foot-off"),
        ("plate 1", "foot-contact"),
        ("plate 1", "foot-off"),
        ("plate 1", "foot-contact"),
    ]
    flights = result.summary.checks.flights
    edges = [*flights[0], *flights[1]]
    for (_, _, time), edge in zip(events, edges, strict=True):
        assert time == pytest.approx(edge, abs=0.02)


def test_a_step_is_judged_against_the_capture_region_at_its_foot_off():
    # The landing 0.30 m ahead misses the one-step capture region of the state at foot-off
    # (the push was large); landing at the foothold the region recommends is inside it.
    first = analyze(_stepping_recording(), P).summary.events.measured_steps[0]
    region = first.capture_region
    assert region.landing_ankle == pytest.approx((0.30, -0.12), abs=1e-9)
    assert region.within is False and region.margin < 0.0
    foothold = region.recommended_foothold
    step = (foothold[0] - 0.0, foothold[1] - (-0.1))  # from the right ankle at (0, -0.1)
    again = analyze(_stepping_recording(step), P).summary.events.measured_steps[0]
    assert again.capture_region.within is True
    assert again.capture_region.margin > 0.01
