"""The stepping task of the whole-body controller (issue 19 item 3): steps in every direction."""

import math

import mujoco
import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.control.wbc.foot_contact import foot_contact
from pushrecovery.control.wbc.observation import mujoco_observation
from pushrecovery.control.wbc.qp import WholeBodyQP
from pushrecovery.control.wbc.stepper.leg import axis_inertia, leg_joints
from pushrecovery.control.wbc.stepper.plan import lipm_com, quintic
from pushrecovery.control.wbc.stepper.settings import StepSettings
from pushrecovery.control.wbc.stepper.stepper import Stepper
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Support
from pushrecovery.sim.mujoco.humanoid3d.biped3d import bent_knee_qpos, biped3d_model
from pushrecovery.sim.mujoco.humanoid3d.plant3d import CONTROL_PERIOD, Biped3DPlant
from pushrecovery.sim.mujoco.humanoid3d.runs3d import WbcTrace, run_push3d
from pushrecovery.sim.push import Push3D
from pushrecovery.sim.result import Outcome


def wbc(model, data, **options):
    """The whole-body controller on ``data``'s observation (the plants hand theirs)."""
    return WholeBodyController(model, observation=mujoco_observation(model, data), **options)


#: The CoM state the loop passes the WBC (unused: its laws read the observation).
STILL = np.zeros(6)

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
def plant(params):
    return Biped3DPlant(params)


def push(plant, impulse, azimuth, *, duration, hip=False, stepping=True, swing_time=0.2):
    """Push ``plant`` by ``impulse`` [N s] at ``azimuth`` [rad] at 0.1 s, its WBC reacting
    through the 10 ms push (scheduled), and run it ``duration`` [s] after the push starts.
    Returns the result and the :class:`WbcTrace` of its ticks."""
    controller = WholeBodyController(
        plant.model, plant.feet, plant.upright, observation=plant.observation,
        hip=plant.params if hip else None, stepping=stepping, params=plant.params,
        step_settings=StepSettings(swing_time=swing_time),
    )  # fmt: skip
    trace = WbcTrace(plant, controller)
    kick = Push3D(impulse, math.degrees(azimuth), scheduled=True)
    result = run_push3d(plant, controller, kick, duration=duration, observers=(trace,))
    return result, trace


def swinging(trace, step):
    """The ticks of ``trace`` that began after ``step``'s lift-off and before its touchdown."""
    end = math.inf if step.touchdown is None else step.touchdown
    began = trace.time - CONTROL_PERIOD  # a tick's row is the body at its end
    return (began > step.liftoff + 1e-9) & (began < end - 1e-9)


@pytest.fixture(scope="module")
def impulse(params):
    """OUTSIDE × m ω × the ray distance from the ankles' midpoint to P's left edge [N s]."""
    polygon = Support.from_params(params).polygon
    return OUTSIDE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, math.pi / 2)


@pytest.fixture(scope="module")
def runs(plant, impulse):
    return {
        stepping: push(plant, impulse, math.pi / 2, duration=2.4, stepping=stepping)
        for stepping in (False, True)
    }


def test_side_push_falls_without_stepping(runs):
    result, run = runs[False]
    assert run.controller.stepper is None
    assert result.outcome is Outcome.FELL  # ξ beyond what the hips could bring back


def test_side_push_recovers_with_a_lateral_step(runs):
    result, run = runs[True]
    assert run.ok.all()
    assert result.states[-1, 2] > 0.9 and run.torso_tilt.max() < 0.5
    assert np.linalg.norm(result.states[-1, 3:5]) < 0.1
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
def direction_runs(params, plant):
    """OUTSIDE × the ankle's critical impulse along each azimuth, without and with stepping."""
    polygon = Support.from_params(params).polygon
    runs = {}
    for azimuth in DIRECTIONS:
        heading = math.radians(azimuth)
        impulse = OUTSIDE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, heading)
        for stepping in (False, True):
            runs[azimuth, stepping] = push(plant, impulse, heading, duration=2.2,
                                           stepping=stepping)  # fmt: skip
    return runs


@pytest.mark.parametrize("azimuth", sorted(DIRECTIONS))
def test_forward_and_diagonal_pushes_fall_without_and_recover_with_a_step(direction_runs, azimuth):
    assert direction_runs[azimuth, False][0].outcome is Outcome.FELL
    result, run = direction_runs[azimuth, True]
    com = result.states[:, :3]
    assert result.outcome is not Outcome.FELL
    assert run.ok.all()
    assert com[-1, 2] > 0.85 and run.torso_tilt.max() < 0.5
    assert np.linalg.norm(result.states[-1, 3:5]) < 0.1
    steps = run.controller.stepper.steps
    assert steps and all(step.landed is not None for step in steps)
    heading = np.array([math.cos(math.radians(azimuth)), math.sin(math.radians(azimuth))])
    first = steps[0]
    assert (first.landed - first.origin) @ heading > 0.2  # a step along the push, > 20 cm
    if DIRECTIONS[azimuth] is not None:
        assert first.foot == DIRECTIONS[azimuth]
    # The CoM ends over the feet it stands on: ahead of where it started, along the push.
    assert (com[-1, :2] - com[0, :2]) @ heading > 0.1


@pytest.mark.parametrize("case", ["side", 0.0, 30.0])
def test_wrenches_satisfy_friction_and_cop_rows_at_every_tick(runs, direction_runs, case):
    run = runs[True][1] if case == "side" else direction_runs[case, True][1]
    for foot, rows in enumerate(f.constraint_rows() for f in run.controller.feet):
        assert np.all(run.wrenches[:, foot] @ rows.T <= FORCE_TOL)
    # A swinging foot carries nothing: from lift-off to touchdown its wrench is 0.
    names = [f.name for f in run.controller.feet]
    for step in run.controller.stepper.steps:
        swing = swinging(run, step)
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
    solution = qp.solve(mujoco_observation(model, data), [])
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
        ({"stepping": True, "params": "body"}, "params must be a BodyParams"),
        ({"step_settings": 0.2}, "step_settings"),
    ],
)
def test_bad_controller_inputs(model, kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        wbc(model, mujoco.MjData(model), **kwargs)


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


# --- Follow-up steps: the trailing foot, no crossing, the pelvis lowered (issue 19 item 3) ---

#: A forward push of 2 × the ankle's critical impulse: one step does not capture it.
TWICE = 2.0


@pytest.fixture(scope="module")
def forward_twice(params, plant):
    polygon = Support.from_params(params).polygon
    impulse = TWICE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, 0.0)
    return push(plant, impulse, 0.0, duration=2.9)


def test_forward_push_of_twice_recovers_with_the_other_foot_second(forward_twice):
    result, run = forward_twice
    com = result.states[:, :3]
    height = com[0, 2]
    assert com[:, 2].min() > 0.8 * height and run.torso_tilt.max() < 1.0
    assert np.linalg.norm(result.states[-1, 3:5]) < 0.1  # at rest at 3 s
    steps = run.controller.stepper.steps
    assert len(steps) >= 2 and all(step.landed is not None for step in steps)
    assert steps[1].foot != steps[0].foot  # the trailing foot, not the one that just landed
    assert steps[1].liftoff >= steps[0].touchdown
    # The second step passes the first: its foot lands ahead of the first landing.
    assert steps[1].landed[0] > steps[0].landed[0] + 0.1


def test_forward_push_of_twice_wrenches_at_every_tick(forward_twice):
    run = forward_twice[1]
    for foot, rows in enumerate(f.constraint_rows() for f in run.controller.feet):
        assert np.all(run.wrenches[:, foot] @ rows.T <= FORCE_TOL)
    names = [f.name for f in run.controller.feet]
    for step in run.controller.stepper.steps:
        swing = swinging(run, step)
        assert swing.any()
        assert np.allclose(run.wrenches[swing, names.index(step.foot)], 0.0, atol=FORCE_TOL)


def test_the_trailing_foot_steps_after_a_forward_step(params):
    """Left foot landed 0.4 m ahead, ξ further ahead on the midline: the right foot swings."""
    from pushrecovery.control.wbc.stepper.plan import choose_step
    from pushrecovery.ground.support import FootPose, Stance

    poses = (FootPose(0.4, 0.1), FootPose(0.0, -0.1))
    state = (0.3, 0.0, 1.0, 0.0)  # ξ = (0.3 + 1/ω, 0): ahead of both feet, between them
    first, _, _ = choose_step(params, state, poses, 0.2, hip=False)
    assert first is Stance.LEFT  # no landing yet: the library's rule (ξ on the left, y >= 0)
    swing, foothold, count = choose_step(params, state, poses, 0.2, hip=False,
                                         landed=Stance.LEFT)  # fmt: skip
    assert swing is Stance.RIGHT and count in (1, 2)
    assert foothold[0] > 0.4  # ahead of the landed foot


def test_no_crossing_foothold(params):
    """ξ beyond the left foot's outer side: the right foot lands at least w + 2 cm right of it
    (the library's region, cut to that half-plane, when the uncut one would cross)."""
    from pushrecovery.control.wbc.stepper.plan import plan_foothold, planning_params
    from pushrecovery.ground.support import FootPose, Stance

    cut = planning_params(params, 0.02)
    assert cut.min_step_width == pytest.approx(params.foot_width + 0.02)
    assert planning_params(params, None) is params
    left, right = FootPose(0.0, 0.4), FootPose(0.0, -0.1)
    for vy in (0.5, 1.0, 2.0):  # ξ from 0.16 to 0.64 m left of the left ankle
        state = (0.0, 0.4, 0.0, vy)
        crossing, _ = plan_foothold(params, state, (Stance.LEFT, left), right, 0.2, hip=False)
        assert crossing[1] > left.y - cut.min_step_width  # uncut: across the stance foot
        foothold, _ = plan_foothold(params, state, (Stance.LEFT, left), right, 0.2, hip=False,
                                    cut=cut)  # fmt: skip
        assert foothold[1] <= left.y - cut.min_step_width + 1e-6


def test_swing_path_collision_with_the_stance_sole(params):
    """Soles of length L = toe − heel and width w overlap when the ankles are closer than
    (L, w) in x and y: paths through, beside and behind the stance foot."""
    from pushrecovery.control.wbc.stepper.plan import collides
    from pushrecovery.ground.support import FootPose

    stance = FootPose(1.0, 2.0)
    length = params.toe - params.heel
    through = collides(params, stance, np.array([1.0, 1.7]), np.array([1.0, 2.3]), 0.0)
    beside = collides(params, stance, np.array([0.5, 1.85]), np.array([1.5, 1.85]), 0.0)
    behind = collides(params, stance, np.array([1.0 - length - 0.01, 1.7]),
                      np.array([1.0 - length - 0.01, 2.3]), 0.0)  # fmt: skip
    near = collides(params, stance, np.array([0.5, 1.89]), np.array([1.5, 1.89]), 0.02)
    assert through and not beside and not behind and near
    turned = FootPose(1.0, 2.0, math.pi / 2)  # the box turns with the stance foot
    assert not collides(params, turned, np.array([0.85, 1.5]), np.array([0.85, 2.5]), 0.0)


def test_leg_span_and_pelvis_limit_match_the_standing_posture(model):
    """ℓ(κ) by the law of cosines against MuJoCo's hip-ankle distance; standing, the limit for
    the stance's own knee bend (feet under the hips) is the pelvis' height."""
    import mujoco

    from pushrecovery.control.wbc.stepper.height import leg_span, pelvis_limit, segment_lengths
    from pushrecovery.sim.mujoco.humanoid3d.biped3d import KNEE_BEND

    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    legs = tuple(leg_joints(model, model.body(n).id) for n in ("left_foot", "right_foot"))
    thigh, shank = segment_lengths(data, legs[0])
    for leg in legs:
        hip, ankle = data.xanchor[leg.hip_pitch], data.xpos[leg.foot]
        distance = float(np.linalg.norm(hip - ankle))
        assert leg_span(thigh, shank, KNEE_BEND) == pytest.approx(distance, abs=1e-9)
    pelvis = int(model.body_parentid[model.jnt_bodyid[legs[0].hip_pitch]])
    spans = (leg_span(thigh, shank, KNEE_BEND),) * 2
    limit = pelvis_limit(data, legs, spans, pelvis)
    assert limit == pytest.approx(float(data.xpos[pelvis][2]), abs=1e-6)
    # A foothold 0.4 m ahead of the left hip: the hip must be lower, by the right triangle.
    foothold = data.xanchor[legs[0].hip_pitch][:2] + np.array([0.4, 0.0])
    lower = pelvis_limit(data, legs, spans, pelvis, swing=0, foothold=foothold)
    drop = float(data.xanchor[legs[0].hip_pitch][2] - data.xpos[legs[1].foot][2])
    assert limit - lower == pytest.approx(drop - math.sqrt(spans[0] ** 2 - 0.4**2), abs=1e-6)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"clearance": -0.01}, "clearance"),
        ({"clearance": 0.6}, "clearance"),
        ({"clearance": math.nan}, "clearance"),
        ({"follow_time": -0.1}, "follow_time"),
        ({"follow_time": 11.0}, "follow_time"),
        ({"knee_reach": -0.1}, "knee_reach"),
        ({"knee_reach": 2.0}, "knee_reach"),
        ({"max_drop": 0.6}, "max_drop"),
        ({"max_drop": -0.1}, "max_drop"),
    ],
)
def test_bad_follow_up_settings(kwargs, name):
    with pytest.raises(InvalidParameterError, match=name):
        StepSettings(**kwargs)


def test_segment_lengths_need_a_hip_pitch_and_a_knee(model):
    import mujoco

    from pushrecovery.control.wbc.stepper.height import segment_lengths
    from pushrecovery.control.wbc.stepper.leg import Leg

    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with pytest.raises(InvalidParameterError, match="hip_pitch and a knee"):
        segment_lengths(data, Leg(model.body("left_foot").id))


def test_hip_and_stepping_hand_over_at_lift_off(params, plant):
    """A push of 1.5 × the ankle's limit at 30° with the hip and stepping tasks both on.

    The hip acts first (ξ leaves P before the CMP region); once a foot swings the step owns the
    recovery. With the hip law running through the swing this push fell after 9 steps.
    """
    polygon = Support.from_params(params).polygon
    azimuth = math.radians(30.0)
    impulse = OUTSIDE * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, azimuth)
    result, run = push(plant, impulse, azimuth, duration=3.9, hip=True,
                       swing_time=StepSettings().swing_time)  # fmt: skip
    com = result.states[:, :3]
    assert np.abs(run.cmp_offset).max() > 0.01  # the hip acted
    assert com[:, 2].min() > 0.7 * com[0, 2] and run.torso_tilt.max() < 1.0
    xi = com[-1, :2] + result.states[-1, 3:5] / run.controller.omega
    assert run.controller.support.point_signed_distance(*map(float, xi)) > -0.05
    assert 1 <= len(run.controller.stepper.steps) <= 2
