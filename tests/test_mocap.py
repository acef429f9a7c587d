"""Pushes recorded as a gait lab measures them (markers, force plates) against the truth."""

import math

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.experiments.mocap import record_push
from pushrecovery.sim.mujoco.lab import MARKER_LABELS, PLATE_LENGTH, PLATE_WIDTH, MocapRecording
from pushrecovery.surfaces.step import plan_step

P = load_params()
FOOT = P.toe - P.heel


def plate_force_x(rec: MocapRecording) -> np.ndarray:
    """Horizontal force of the floor on the subject, both plates [N]."""
    return sum(plate[0][:, 0] for plate in rec.plates)


def on_plate(point: np.ndarray, corners: np.ndarray) -> bool:
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    return bool(lo[0] <= point[0] <= hi[0] and lo[1] <= point[1] <= hi[1])


@pytest.fixture(scope="module")
def standing() -> MocapRecording:
    return record_push("foot", P, duration=1.5)


@pytest.fixture(scope="module")
def ankle_push() -> MocapRecording:
    # 0.3 m/s from x0 = 0: well inside Eq. (4) (0.46 m/s in MuJoCo, docs/validation.md).
    return record_push("foot", P, impulse=0.3 * P.mass, duration=3.5)


@pytest.fixture(scope="module")
def step_push() -> MocapRecording:
    # 1.3 m/s from x0 = 0: one step of about 0.8 m (single-step limit 2.55 m/s).
    return record_push("biped", P, impulse=1.3 * P.mass, duration=2.5)


def test_recording_shapes_and_time_base(standing: MocapRecording) -> None:
    rec = standing
    assert (rec.point_rate, rec.analog_rate) == (100.0, 1000.0)
    assert list(rec.markers) == list(MARKER_LABELS)
    n = len(rec.point_time)
    assert n == 150 and rec.point_time[1] == pytest.approx(0.01)
    assert len(rec.analog_time) == 10 * n
    for force, cop, free, corners in rec.plates:
        assert force.shape == cop.shape == (10 * n, 3) and free.shape == (10 * n,)
        assert corners.shape == (4, 3) and np.all(corners[:, 2] == 0.0)
        size = corners.max(axis=0) - corners.min(axis=0)
        assert size[:2] == pytest.approx([PLATE_LENGTH, PLATE_WIDTH])
    assert rec.truth["push_time"] == pytest.approx(0.5)
    assert rec.mass == pytest.approx(P.mass + 0.201)  # + foot 0.2 kg and rod 1 g


def test_standing_still_loads_the_first_plate_with_the_weight(standing: MocapRecording) -> None:
    rec = standing
    (force, cop, free, corners), (force2, cop2, _, corners2) = rec.plates
    weight = rec.mass * P.gravity
    assert force[:, 2].mean() == pytest.approx(weight, rel=5e-3)
    assert np.abs(force[:, :2]).max() < 1.0
    assert np.abs(free).max() < 1e-6  # planar model
    # Plate 2 lies in front of plate 1 and carries nothing.
    assert corners2[:, 0].min() == pytest.approx(corners[:, 0].max())
    assert np.all(force2 == 0.0) and np.all(np.isnan(cop2))
    # At rest the CoP is under the CoM, between the feet.
    com = rec.markers["CentreOfMass"]
    assert np.abs(cop[::10, 0] - com[:, 0]).max() < 3e-3
    assert np.abs(cop[:, 1]).max() < 1e-6 and np.all(cop[:, 2] == 0.0)
    # The plates' CoP is the plant's own measured CoP at every sample.
    assert np.abs(cop[:, 0] - rec.truth["plant_cop"]).max() < 1e-3
    assert rec.truth["used"] == "ankle" and rec.truth["push"]["kind"] == "none"


def test_markers_follow_the_foot(standing: MocapRecording, step_push: MocapRecording) -> None:
    for rec in (standing, step_push):
        for label, marker in rec.markers.items():
            assert np.all(np.isfinite(marker)), label
        assert np.all(rec.markers["CentreOfMass"][:, 1] == 0.0)
    m = standing.markers
    for side, y in (("L", 0.1), ("R", -0.1)):
        heel, toe, ankle = m[side + "HEE"], m[side + "TOE"], m[side + "ANK"]
        # Flat foot: heel to toe is the foot length, both 1 cm above the sole.
        assert toe[:, 0] - heel[:, 0] == pytest.approx(FOOT, abs=1e-5)
        assert heel[:, 2] == pytest.approx(0.01, abs=2e-4)
        assert toe[:, 2] == pytest.approx(0.01, abs=2e-4)
        assert ankle[:, 0] - heel[:, 0] == pytest.approx(-P.heel, abs=1e-5)
        assert np.all(heel[:, 1] == y) and np.all(toe[:, 1] == y) and np.all(ankle[:, 1] == y)
    # The biped's feet stand flat side by side before the push.
    b = step_push.markers
    for side in "LR":
        assert b[side + "TOE"][:40, 0] - b[side + "HEE"][:40, 0] == pytest.approx(FOOT, abs=1e-4)
    assert b["LANK"][0, 0] == pytest.approx(b["RANK"][0, 0], abs=1e-4)


def test_ankle_push_obeys_newton_on_the_plates(ankle_push: MocapRecording) -> None:
    rec = ankle_push
    truth = rec.truth
    assert truth["outcome"] == "recovered" and truth["used"] == "ankle"
    assert truth["predicted"]["strategy"] == "ankle"
    assert truth["steps"] == 0 and truth["peak_hip_torque"] == 0.0
    impulse = 0.3 * P.mass
    dt = 1.0 / rec.analog_rate
    push = truth["push_force"]
    assert push.sum() * dt == pytest.approx(impulse)
    assert rec.analog_time[np.flatnonzero(push)[0]] == pytest.approx(truth["push_time"])
    after = truth["state_after_push"]
    assert after["xdot"] == pytest.approx(0.3, rel=0.08)
    # Momentum: m v(t) = J + ∫ F_x dt, v from the CoM marker (central differences).
    fx = plate_force_x(rec)
    momentum = np.cumsum(fx + push) * dt
    com = rec.markers["CentreOfMass"][:, 0]
    per_frame = round(rec.analog_rate / rec.point_rate)
    for t in (0.55, 0.7, 1.0, 1.5, 2.5):
        j = round(t * rec.point_rate)
        v = (com[j + 1] - com[j - 1]) * rec.point_rate / 2.0
        assert rec.mass * v == pytest.approx(momentum[j * per_frame - 1], abs=0.03 * impulse)
    # From rest to rest the plates take back the whole push.
    assert fx.sum() * dt == pytest.approx(-impulse, rel=0.01)
    # The CoP runs forward toward the toe to stop the body, and comes back under the CoM.
    force, cop, _, _ = rec.plates[0]
    assert np.nanmax(cop[:, 0]) > 0.1
    assert np.abs(cop[-200:, 0] - com[-1]).max() < 3e-3
    assert np.abs(cop[:, 0] - truth["plant_cop"]).max() < 1e-3
    assert force[:, 2].mean() == pytest.approx(rec.mass * P.gravity, rel=5e-3)


def test_velocity_jump_is_not_seen_by_the_plates() -> None:
    rec = record_push("foot", P, xdot=0.2, duration=1.0, analog_rate=500.0)
    assert rec.plates[0][0].shape == (5 * len(rec.point_time), 3)
    truth = rec.truth
    assert truth["push"]["kind"] == "velocity" and not np.any(truth["push_force"])
    assert truth["state_after_push"]["xdot"] == pytest.approx(0.2, rel=1e-3)
    com = rec.markers["CentreOfMass"][:, 0]
    # Standing still before, then the CoM moves at 0.2 m/s at once; only the plates slow it.
    assert abs(com[49] - com[40]) < 1e-5
    fx = plate_force_x(rec)
    momentum = rec.mass * 0.2 + np.cumsum(fx[250:]) / rec.analog_rate  # from the jump on
    j = 80
    v = (com[j + 1] - com[j - 1]) * rec.point_rate / 2.0
    assert rec.mass * v == pytest.approx(momentum[(j - 50) * 5 - 1], rel=0.03)


def test_torso_push_uses_the_hip() -> None:
    rec = record_push("torso", P, impulse=0.55 * P.mass, duration=1.5)
    truth = rec.truth
    assert truth["controller"] == "mpc" and truth["predicted"]["strategy"] == "hip"
    assert truth["used"] == "hip" and truth["peak_hip_torque"] == pytest.approx(P.torque_max)
    assert truth["outcome"] != "fell"


def test_biped_step_lands_on_the_second_plate(step_push: MocapRecording) -> None:
    rec = step_push
    truth = rec.truth
    assert truth["controller"] == "recovery" and truth["outcome"] == "recovered"
    assert truth["predicted"]["strategy"] == "step"
    assert truth["used"] == "step" and truth["steps"] == 1
    (length,) = truth["step_lengths"]
    footholds = truth["footholds"]
    assert length == pytest.approx(footholds[1] - footholds[0]) and length > 0.2
    # The controller starts on the pushed state, so it takes Sec. IV's step for it (Eq. 21
    # at the standing CoM height 0.985 m instead of L: 1 cm shorter). The verdict's own plan
    # (N steps, LIPM, min_step_time) is a different step, reported beside it.
    after = truth["state_after_push"]
    sec4 = plan_step(after["x"], after["xdot"], P)
    assert length == pytest.approx(sec4.step_length, abs=0.02)
    assert truth["predicted"]["steps"] >= 1 and "plan" in truth["predicted"]
    assert truth["off_plate_samples"] == 0
    (force1, _, _, corners1), (force2, cop2, _, corners2) = rec.plates
    # The right foot swings: from plate 1 to plate 2, where its ankle lands at the foothold.
    m = rec.markers
    for label in ("RHEE", "RTOE", "RANK"):
        assert on_plate(m[label][0], corners1) and on_plate(m[label][-1], corners2)
    # Plate 2 is loaded from the landing on, after the push; finally with the whole weight.
    landing = int(np.argmax(force2[:, 2] > 0.0))
    t_land = rec.analog_time[landing]
    frame = math.ceil(t_land * rec.point_rate) + 2
    assert m["RANK"][frame, 0] == pytest.approx(footholds[1], abs=1e-3)
    # Then the loaded foot creeps forward on the soft contact (measured 4.5 mm in 1.7 s).
    assert 0.0 <= m["RANK"][-1, 0] - m["RANK"][frame, 0] < 0.01
    assert truth["push_time"] < t_land < truth["push_time"] + 0.5
    assert np.all(force2[:landing] == 0.0)
    assert np.all(force2[landing:, 2] > 0.0)
    weight = rec.mass * P.gravity
    assert force2[-200:, 2].mean() == pytest.approx(weight, rel=5e-3)
    assert np.abs(force1[-200:]).max() < 1e-6  # the trailing left foot hangs in the air
    # Single support on the right foot (y = −0.1 m), CoP between its heel and toe.
    late = cop2[-200:]
    assert late[:, 1] == pytest.approx(-0.1, abs=1e-3)
    assert np.all((late[:, 0] > m["RHEE"][-1, 0]) & (late[:, 0] < m["RTOE"][-1, 0]))
    # Standing on both plates' feet before the push: the plates see the weight.
    assert force1[:400, 2].mean() == pytest.approx(weight, rel=5e-3)
    cop = rec.plates[0][1][:400, 0]
    assert np.abs(cop - truth["plant_cop"][:400]).max() < 1e-3


def test_reacting_during_the_push_plans_the_step_on_part_of_it(
    step_push: MocapRecording,
) -> None:
    rec = record_push("biped", P, impulse=1.3 * P.mass, duration=1.2, react_during_push=True)
    assert rec.truth["used"] == "step" and rec.truth["steps"] == 1
    (early,) = rec.truth["step_lengths"]
    assert early < step_push.truth["step_lengths"][0] - 0.03


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"xdot": 0.1, "impulse": 5.0}, "not both"),
        ({"analog_rate": 300.0}, "divided by a whole number"),
        ({"point_rate": 300.0}, "whole multiple"),
        ({"duration": 0.4}, "duration must exceed"),
        ({"controller": "nope"}, "controller must be one of"),
        ({"xdot": math.nan}, "finite"),
    ],
)
def test_bad_input_raises(kwargs: dict, match: str) -> None:
    with pytest.raises(InvalidParameterError, match=match):
        record_push("foot", P, **kwargs)


def test_unknown_model_or_wrong_controller_raises() -> None:
    with pytest.raises(InvalidParameterError, match="model must be one of"):
        record_push("stepping", P)
    with pytest.raises(InvalidParameterError, match="stepping model"):
        record_push("foot", P, controller="recovery")
