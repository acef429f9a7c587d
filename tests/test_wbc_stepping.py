"""The stepping task of the whole-body controller (issue 19 item 3): steps in every direction."""

import math

import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Support
from pushrecovery.sim.mujoco.humanoid3d.biped3d import biped3d_model
from pushrecovery.sim.mujoco.humanoid3d.wbc import WholeBodyQP, foot_contact
from pushrecovery.sim.mujoco.humanoid3d.wbc_control import WholeBodyController
from pushrecovery.sim.mujoco.humanoid3d.wbc_push import bent_knee_qpos, push_biped3d
from pushrecovery.sim.mujoco.humanoid3d.wbc_step import Stepper, StepSettings, quintic
from pushrecovery.sim.mujoco.humanoid3d.wbc_step_plan import axis_inertia, leg_joints, lipm_com

#: The push, in CoP-region critical impulses (docs/plane.md): well outside the ankle region.
OUTSIDE = 1.5
#: DAQP's primal tolerance on rows in newtons, with room for rounding [N].
FORCE_TOL = 1e-5
#: How close the landed ankle must be to the last planned foothold [m].
PLACEMENT = 0.03
#: How much earlier or later than planned the foot may touch down [s].
TIMING = 0.05


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def model(params):
    return biped3d_model(params)


@pytest.fixture(scope="module")
def impulse(params):
    """OUTSIDE × m ω × the ray distance from the ankles' midpoint to P's left edge [N s]."""
    polygon = Support.from_params(params).polygon
    return OUTSIDE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, math.pi / 2)


@pytest.fixture(scope="module")
def runs(params, model, impulse):
    kwargs = {"duration": 2.5, "model": model, "step_settings": StepSettings(swing_time=0.2)}
    return {
        stepping: push_biped3d(params, impulse, math.pi / 2, stepping=stepping, **kwargs)
        for stepping in (False, True)
    }


def test_side_push_falls_without_stepping(runs):
    run = runs[False]
    assert run.controller.stepper is None
    assert run.com[-1, 2] < 0.6 or run.torso_tilt.max() > 1.0


def test_side_push_recovers_with_a_lateral_step(runs):
    run = runs[True]
    assert run.ok.all()
    assert run.com[-1, 2] > 0.9 and run.torso_tilt.max() < 0.5
    assert np.linalg.norm(run.com_velocity[-1, :2]) < 0.1
    steps = run.controller.stepper.steps
    assert len(steps) == 1
    step = steps[0]
    assert step.foot == "left_foot"
    assert step.landed[1] > 0.1 + 0.2  # the left ankle, at y = 0.1 before, moves left
    assert step.error < PLACEMENT
    assert abs(step.touchdown - step.planned_touchdown) < TIMING
    assert len(step.plans) > 1  # re-planned during the swing
    assert run.sole_lift[:, 0].max() > 0.02  # the left foot lifted; the right one stayed
    assert run.sole_lift[:, 1].max() < 0.01  # an edge of the stance sole rises a few mm


#: Forward and diagonal pushes: azimuth [deg] -> the foot that must step (the push's side).
DIRECTIONS = {0.0: None, 30.0: "left_foot"}


@pytest.fixture(scope="module")
def direction_runs(params, model):
    """OUTSIDE × the ankle's critical impulse along each azimuth, without and with stepping."""
    polygon = Support.from_params(params).polygon
    runs = {}
    for azimuth in DIRECTIONS:
        heading = math.radians(azimuth)
        impulse = OUTSIDE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, heading)
        for stepping in (False, True):
            runs[azimuth, stepping] = push_biped3d(
                params, impulse, heading, duration=2.0, model=model, stepping=stepping,
                step_settings=StepSettings(swing_time=0.2),
            )  # fmt: skip
    return runs


@pytest.mark.parametrize("azimuth", sorted(DIRECTIONS))
def test_forward_and_diagonal_pushes_fall_without_and_recover_with_a_step(direction_runs, azimuth):
    fell = direction_runs[azimuth, False]
    assert fell.com[-1, 2] < 0.6 or fell.torso_tilt.max() > 1.0
    run = direction_runs[azimuth, True]
    assert run.ok.all()
    assert run.com[-1, 2] > 0.85 and run.torso_tilt.max() < 0.5
    assert np.linalg.norm(run.com_velocity[-1, :2]) < 0.1
    steps = run.controller.stepper.steps
    assert steps and all(step.landed is not None for step in steps)
    heading = np.array([math.cos(math.radians(azimuth)), math.sin(math.radians(azimuth))])
    first = steps[0]
    assert (first.landed - first.origin) @ heading > 0.2  # a step along the push, > 20 cm
    if DIRECTIONS[azimuth] is not None:
        assert first.foot == DIRECTIONS[azimuth]
    # The CoM ends over the feet it stands on: ahead of where it started, along the push.
    assert (run.com[-1, :2] - run.com[0, :2]) @ heading > 0.1


@pytest.mark.parametrize("case", ["side", 0.0, 30.0])
def test_wrenches_satisfy_friction_and_cop_rows_at_every_tick(runs, direction_runs, case):
    run = runs[True] if case == "side" else direction_runs[case, True]
    for foot, rows in enumerate(f.constraint_rows() for f in run.controller.feet):
        assert np.all(run.wrenches[:, foot] @ rows.T <= FORCE_TOL)
    # A swinging foot carries nothing: from lift-off to touchdown its wrench is 0.
    names = [f.name for f in run.controller.feet]
    for step in run.controller.stepper.steps:
        end = math.inf if step.touchdown is None else step.touchdown
        swing = (run.time > step.liftoff + 1e-9) & (run.time < end - 1e-9)
        assert np.allclose(run.wrenches[swing, names.index(step.foot)], 0.0, atol=FORCE_TOL)


def test_leg_inertia_matches_the_joint_space_inertia(model):
    """I about the hip axes (a sum over bodies) against M's diagonal (MuJoCo's own route)."""
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)  # MuJoCo 4 (the project pins it)
    leg = leg_joints(model, model.body("left_foot").id)
    assert min(leg.hip_pitch, leg.hip_roll, leg.knee) >= 0
    for joint in (leg.hip_pitch, leg.hip_roll, leg.knee):
        dof = model.jnt_dofadr[joint]
        assert axis_inertia(model, data, joint) == pytest.approx(full[dof, dof], rel=1e-9)


def test_lipm_com_obeys_the_lipm():
    """c̈ = ω² (c − p) by central differences [m/s²], and c(0) = c, ċ(0) = v."""
    com, vel, cop, omega, h = np.array([0.1, -0.2]), np.array([0.5, 0.3]), np.zeros(2), 3.0, 1e-4
    assert np.allclose(lipm_com(com, vel, cop, omega, 0.0), com)
    assert np.allclose((lipm_com(com, vel, cop, omega, h) - com) / h, vel, atol=1e-3)
    at = [lipm_com(com, vel, cop, omega, 0.3 + k * h) for k in (-1, 0, 1)]
    accel = (at[0] - 2 * at[1] + at[2]) / h**2
    assert np.allclose(accel, omega**2 * (at[1] - cop), rtol=1e-4)


def test_quintic_meets_its_ends():
    p0, v0, a0, p1 = np.array([0.0, 1.0]), np.array([0.5, 0.0]), np.array([0.0, 2.0]), np.ones(2)
    coeffs = quintic(p0, v0, a0, p1, 0.4)
    powers = 0.4 ** np.arange(6)
    assert np.allclose(powers @ coeffs, p1)
    assert np.allclose((np.arange(1, 6) * powers[:-1]) @ coeffs[1:], 0.0)
    assert np.allclose(coeffs[0], p0) and np.allclose(coeffs[1], v0)
    with pytest.raises(InvalidParameterError, match="duration"):
        quintic(p0, v0, a0, p1, 0.0)


def test_swing_foot_contacts_in_the_qp(model):
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    qp = WholeBodyQP(model, [foot_contact(model, data, n) for n in ("left_foot", "right_foot")])
    qp.set_contacts([False, True])
    solution = qp.solve(data, [])
    assert solution.ok and np.allclose(solution.wrenches[0], 0.0)
    with pytest.raises(InvalidParameterError, match="contacts"):
        qp.set_contacts([True])
    with pytest.raises(InvalidParameterError, match="contacts"):
        qp.set_contacts([1, 0])


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"stepping": True}, "stepping"),
        ({"stepping": "yes"}, "stepping"),
        ({"stepping": True, "params": "body"}, "stepping"),
        ({"step_settings": 0.2}, "step_settings"),
    ],
)
def test_bad_controller_inputs(model, kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        WholeBodyController(model, **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"swing_time": 0.0}, "swing_time"),
        ({"lift": -0.1}, "lift"),
        ({"weight": 0.0}, "weight"),
        ({"replan_fraction": 2.0}, "replan_fraction"),
        ({"contact": math.nan}, "contact"),
        ({"torque_share": 0.0}, "torque_share"),
        ({"torque_share": 1.5}, "torque_share"),
        ({"max_swing_time": 3.0}, "max_swing_time"),
        ({"swing_time": 0.5, "max_swing_time": 0.4}, "swing_time"),
        ({"knee_min": -0.1}, "knee_min"),
        ({"knee_min": 1.5}, "knee_min"),
        ({"knee_weight": 0.0}, "knee_weight"),
        ({"lift_weight": 0.0}, "lift_weight"),
        ({"lift_weight": math.inf}, "lift_weight"),
    ],
)
def test_bad_step_settings(kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        StepSettings(**kwargs)


def test_plant_controller_with_stepping(params):
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, wbc_for

    plant = Biped3DPlant(params)
    assert wbc_for(plant, stepping=True).stepping
    assert not wbc_for(plant).stepping


def test_stepper_refuses_a_non_bool_hip(model, params):
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    feet = tuple(foot_contact(model, data, n) for n in ("left_foot", "right_foot"))
    with pytest.raises(InvalidParameterError, match="hip"):
        Stepper(model, params, feet, 0, 0.0, 1.0, hip="yes")
