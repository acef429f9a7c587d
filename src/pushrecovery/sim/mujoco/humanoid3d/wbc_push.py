"""Push the 3-D biped and let the whole-body controller recover (docs/humanoid3d_wbc.md).

The biped stands with its knees bent by ``knee`` (a straight knee sits on its joint stop,
whose constraint force the QP does not model): hip pitch −knee/2, knee +knee, ankle pitch
−knee/2 keep each foot flat and under its hip; the root is lowered onto the floor. A push is
an impulse J [N s] at the torso's centre of mass, horizontal, at azimuth ψ (0 forward, π/2
left), applied as the constant force J/Δ over Δ = :data:`PUSH_DURATION` through
``xfrc_applied``: the whole body's CoM gains J/m of velocity. The controller runs at 500 Hz
(every fourth 0.5 ms step): ``mj_step1`` computes the state's dynamics, the controller sets
``ctrl``, ``mj_step2`` integrates; the steps between hold ``ctrl``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.bodies import body_id, sole_points
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.control.wbc.gains import WbcGains
from pushrecovery.control.wbc.observation import HumanoidObservation, mujoco_observation
from pushrecovery.control.wbc.stepper.settings import StepSettings
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.humanoid3d.biped3d import SIDES, biped3d_model
from pushrecovery.sim.mujoco.humanoid3d.measure import standing_qpos

FloatArray = NDArray[np.float64]

__all__ = [
    "KNEE_BEND",
    "PUSH_DURATION",
    "WbcRun",
    "bent_knee_qpos",
    "push_biped3d",
    "push_humanoid",
]

#: Knee flexion of the standing posture [rad].
KNEE_BEND = 0.3
#: Duration over which a push's impulse is applied [s].
PUSH_DURATION = 0.01
#: Physics steps per control tick (0.5 ms steps, 500 Hz control).
STEPS_PER_TICK = 4


@dataclass(frozen=True)
class WbcRun:
    """A run's record, one row per control tick.

    Attributes
    ----------
    time : float array, shape (n,)
        Time since the start [s].
    com, com_velocity : float arrays, shape (n, 3)
        Whole-body CoM [m] and its velocity [m/s] (world).
    pelvis : float array, shape (n, 3)
        The torso body's origin [m].
    torso_tilt : float array, shape (n,)
        Angle between the torso's z axis and the vertical [rad].
    sole_lift : float array, shape (n, 2)
        Each foot's highest sole point above the floor [m] (0 on the floor).
    wrenches : float array, shape (n, 2, 6)
        The QP's wrench per foot (F, T) in its sole frame [N, N m].
    desired_cop : float array, shape (n, 2)
        The DCM law's CoP [m] (world xy).
    cmp_offset : float array, shape (n, 2)
        The hip law's CMP offset δ from the CoP [m] (0 with the ankles only, :mod:`~.wbc.hip`).
    ok : bool array, shape (n,)
        Whether DAQP solved the tick.
    solve_time, control_time, physics_time : float arrays, shape (n,)
        Wall time of the DAQP solve, of the whole controller tick, and of the tick's physics
        steps [s] (diagnostics, not for tests).
    qpos, qvel, ctrl : float arrays, shapes (n, nq), (n, nv), (n, nu)
        MuJoCo's state and the tick's motor commands (to replay and render the run):
        ``qpos`` [m] for slide and free-joint positions, [-] for the free joint's unit
        quaternion, [rad] for hinges; ``qvel`` [m/s] and [rad/s] likewise; ``ctrl`` the
        motors' torques [N m] (gear 1).
    controller : WholeBodyController
        The controller after the run (its feet's constraints and support polygon).
    """

    time: FloatArray
    com: FloatArray
    com_velocity: FloatArray
    pelvis: FloatArray
    torso_tilt: FloatArray
    sole_lift: FloatArray
    wrenches: FloatArray
    desired_cop: FloatArray
    cmp_offset: FloatArray
    ok: NDArray[np.bool_]
    solve_time: FloatArray
    control_time: FloatArray
    physics_time: FloatArray
    qpos: FloatArray
    qvel: FloatArray
    ctrl: FloatArray
    controller: WholeBodyController


def bent_knee_qpos(model: Any, knee: float = KNEE_BEND) -> FloatArray:
    """Return the biped's standing posture with knees bent by ``knee`` [rad], soles on z = 0.

    Raises
    ------
    InvalidParameterError
        If ``knee`` is not in [0, 1] rad.
    """
    if not (isinstance(knee, int | float) and 0.0 <= knee <= 1.0):
        raise InvalidParameterError(f"knee must be in [0, 1] rad, got {knee!r}")
    qpos = np.array(model.key("stand").qpos, dtype=float)
    for side in SIDES:
        for joint, angle in (("hip_pitch", -0.5), ("knee", 1.0), ("ankle_pitch", -0.5)):
            qpos[model.jnt_qposadr[model.joint(f"{side}_{joint}").id]] = angle * knee
    feet = [body_id(model, f"{side}_foot") for side in SIDES]
    return standing_qpos(model, qpos, feet)


def _check_push(impulse: float, azimuth: float, duration: float, push_time: float) -> None:
    checks = (
        ("impulse", impulse, 0.0, 1e4, "N s"),
        ("azimuth", azimuth, -2.0 * math.pi, 2.0 * math.pi, "rad"),
        ("duration", duration, 0.0, 60.0, "s"),
        ("push_time", push_time, 0.0, 60.0, "s"),
    )
    for name, value, low, high, unit in checks:
        if not (isinstance(value, int | float) and math.isfinite(value) and low <= value <= high):
            raise InvalidParameterError(
                f"{name} must be in [{low:g}, {high:g}] {unit}, got {value!r}"
            )


def push_biped3d(
    params: BodyParams,
    impulse: float,
    azimuth: float = 0.0,
    *,
    duration: float = 3.0,
    push_time: float = 0.1,
    gains: WbcGains | None = None,
    model: Any = None,
    hip: bool = False,
    stepping: bool = False,
    step_settings: StepSettings | None = None,
) -> WbcRun:
    """Push the biped3d of ``params`` and run the whole-body controller (module docstring).

    Parameters
    ----------
    params : BodyParams
        The body (:func:`~.biped3d.biped3d_model`).
    impulse : float
        J in [0, 1e4] N s.
    azimuth : float
        ψ in [−2π, 2π] rad, 0 forward (+x), π/2 to the left (+y).
    duration : float
        Simulated time in [0, 60] s.
    push_time : float
        Start of the push in [0, 60] s.
    gains : WbcGains, optional
        The controller's gains.
    model : mujoco.MjModel, optional
        A compiled ``biped3d_model(params)`` to reuse.
    hip : bool
        Enable the hip (CMP) task with ``params``' flywheel limits (:mod:`~.wbc.hip`).
    stepping : bool
        Enable the stepping task, planned for ``params`` (:mod:`~.wbc.stepper`).
    step_settings : StepSettings, optional
        Its settings.
    """
    _check_push(impulse, azimuth, duration, push_time)
    model = biped3d_model(params) if model is None else model
    compiled = model

    def controller(observation: HumanoidObservation) -> WholeBodyController:
        return WholeBodyController(compiled, gains=gains, observation=observation,
                                   hip=params if hip else None, stepping=stepping,
                                   params=params, step_settings=step_settings)  # fmt: skip

    feet = tuple(f"{side}_foot" for side in SIDES)
    return push_humanoid(model, bent_knee_qpos(model), controller, feet, "torso", impulse,
                         azimuth, duration=duration, push_time=push_time)  # fmt: skip


def push_humanoid(
    model: Any,
    qpos: FloatArray,
    controller: Callable[[HumanoidObservation], WholeBodyController],
    feet: tuple[str, ...],
    torso: str,
    impulse: float,
    azimuth: float = 0.0,
    *,
    duration: float = 3.0,
    push_time: float = 0.1,
) -> WbcRun:
    """Stand ``model`` at ``qpos``, push body ``torso`` and run a controller (module docstring).

    ``controller`` builds it on the run's observation
    (:func:`~pushrecovery.control.wbc.observation.mujoco_observation`); it runs every
    round(:attr:`~.WholeBodyController.control_period` / timestep) physics steps (4 at
    0.5 ms, 2 at the robots' 1 ms). ``feet`` names the foot bodies whose sole lift is
    recorded. Arguments as :func:`push_biped3d`.
    """
    import mujoco

    _check_push(impulse, azimuth, duration, push_time)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    observation = mujoco_observation(model, data)
    built = controller(observation)
    com_state = np.concatenate([data.subtree_com[0], data.subtree_linvel[0]])
    built.reset(com_state)  # the WBC reads the observation
    body = body_id(model, torso)
    soles = [body_id(model, name) for name in feet]
    force = impulse / PUSH_DURATION * np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    dt = float(model.opt.timestep)
    per_tick = max(1, round(built.control_period / dt))
    ticks = round(duration / (per_tick * dt))
    start_step = round(push_time / dt)
    stop_step = start_step + round(PUSH_DURATION / dt)
    columns: dict[str, list[Any]] = {
        k: [] for k in WbcRun.__dataclass_fields__ if k != "controller"
    }
    for tick in range(ticks):
        mujoco.mj_step1(model, data)
        began = time.perf_counter()
        data.ctrl[:] = built.compute(data.time, com_state).motors
        control = time.perf_counter() - began
        solution = built.last
        assert solution is not None
        columns["time"].append(float(data.time))
        columns["com"].append(np.array(data.subtree_com[0]))
        columns["com_velocity"].append(np.array(data.subtree_linvel[0]))
        columns["pelvis"].append(np.array(data.xpos[body]))
        columns["torso_tilt"].append(math.acos(min(1.0, float(data.xmat[body][8]))))
        columns["sole_lift"].append([float(sole_points(model, data, f)[:, 2].max()) for f in soles])
        columns["wrenches"].append(solution.wrenches)
        columns["desired_cop"].append(built.desired_cop.copy())
        columns["cmp_offset"].append(built.cmp_offset.copy())
        columns["ok"].append(solution.ok)
        columns["solve_time"].append(solution.solve_time)
        columns["control_time"].append(control)
        for name in ("qpos", "qvel", "ctrl"):
            columns[name].append(np.array(getattr(data, name)))
        began = time.perf_counter()
        for sub in range(per_tick):
            step = tick * per_tick + sub
            data.xfrc_applied[body, :3] = force if start_step <= step < stop_step else 0.0
            if sub == 0:
                mujoco.mj_step2(model, data)
            else:
                mujoco.mj_step(model, data)
        columns["physics_time"].append(time.perf_counter() - began)
    arrays = {k: np.array(v) for k, v in columns.items()}
    return WbcRun(**arrays, controller=built)
