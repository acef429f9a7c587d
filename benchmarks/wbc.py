"""The whole-body QP's cost (issue 19, item 3): the G1 + WBC at 500 Hz against MuJoCo alone.

One run: the Unitree G1 (33 kg, 29 torque motors, 1 ms steps; the ``robots`` extra), pushed
forward at 30 % of its CoP region's critical impulse at t = 0.1 s, 3 s, the
:class:`~pushrecovery.sim.mujoco.humanoid3d.wbc_control.WholeBodyController` every second step
(``mj_step1``, controller, ``mj_step2``, one ``mj_step``). MuJoCo alone: the same model from
the same state, the same push, the controls the WBC applied replayed tick by tick by a
Python loop of ``mj_step`` (no controller).
Both as real-time factors on one core (the best of ``REPEAT``, interleaved) and their ratio;
the DAQP solve times (median, p99) and the whole controller tick (task and constraint
assembly in NumPy, MuJoCo's M, Jacobians and J̇ q̇, the solve). Not wired into run.py.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any

import numpy as np

from pushrecovery.sim.mujoco.humanoid3d.measure import body_id
from pushrecovery.sim.mujoco.humanoid3d.robots import RobotDescription, describe_robot
from pushrecovery.sim.mujoco.humanoid3d.wbc_g1 import G1_TORSO, g1_ankle_impulse, g1_controller
from pushrecovery.sim.mujoco.humanoid3d.wbc_push import PUSH_DURATION

REPEAT = 5
DURATION = 3.0
PUSH_TIME = 0.1
FRACTION = 0.3
#: Physics steps per control tick (1 ms steps, 500 Hz control).
STEPS = 2


def _run(robot: RobotDescription, impulse: float, controls: np.ndarray | None) -> dict[str, Any]:
    """Simulate; with ``controls`` replay them (MuJoCo alone), else run the WBC and record."""
    import mujoco

    model = robot.model
    data = mujoco.MjData(model)
    data.qpos[:] = robot.qpos
    mujoco.mj_forward(model, data)
    torso = body_id(model, G1_TORSO)
    force = np.array([impulse / PUSH_DURATION, 0.0, 0.0])
    dt = float(model.opt.timestep)
    ticks = round(DURATION / (STEPS * dt))
    start, stop = round(PUSH_TIME / dt), round((PUSH_TIME + PUSH_DURATION) / dt)
    controller = None
    if controls is None:
        controller = g1_controller(robot)
        controller.reset(data)
    applied, solves, ticks_time = np.zeros((ticks, model.nu)), np.zeros(ticks), np.zeros(ticks)
    began = time.perf_counter()
    for tick in range(ticks):
        if controller is not None:
            mujoco.mj_step1(model, data)
            tick_start = time.perf_counter()
            data.ctrl[:] = controller.compute(data.time, data)
            ticks_time[tick] = time.perf_counter() - tick_start
            assert controller.last is not None
            solves[tick] = controller.last.solve_time
            applied[tick] = data.ctrl
        else:
            assert controls is not None
            data.ctrl[:] = controls[tick]
        for sub in range(STEPS):
            step = tick * STEPS + sub
            data.xfrc_applied[torso, :3] = force if start <= step < stop else 0.0
            if sub == 0 and controller is not None:
                mujoco.mj_step2(model, data)
            else:
                mujoco.mj_step(model, data)
    wall = time.perf_counter() - began
    return {
        "factor": DURATION / wall,
        "controls": applied,
        "solves": solves,
        "ticks": ticks_time,
        "com": np.array(data.subtree_com[0]),
    }


def main() -> int:
    """Print the WBC's real-time factor against MuJoCo alone and its solve times; return 0."""
    robot = describe_robot("g1")
    model = robot.model
    impulse = FRACTION * g1_ankle_impulse(robot)
    best_wbc, best_alone = 0.0, 0.0
    solves, ticks = [], []
    for _ in range(REPEAT):
        wbc = _run(robot, impulse, None)
        alone = _run(robot, impulse, wbc["controls"])
        best_wbc, best_alone = max(best_wbc, wbc["factor"]), max(best_alone, alone["factor"])
        solves.append(wbc["solves"])
        ticks.append(wbc["ticks"])
        drift = float(np.linalg.norm(wbc["com"] - alone["com"]))
    solve, tick = np.concatenate(solves) * 1e6, np.concatenate(ticks) * 1e6
    print(
        f"G1 + whole-body QP at 500 Hz, {DURATION:g} s, a {impulse:.1f} N s push: "
        f"{best_wbc:.2f}x real time; MuJoCo alone on the same controls {best_alone:.2f}x; "
        f"ratio {best_wbc / best_alone:.2f} (replayed CoM {1e3 * drift:.2g} mm from the WBC's)"
    )
    print(
        f"DAQP solve: median {np.median(solve):.1f} us, p99 {np.percentile(solve, 99):.1f} us; "
        f"controller tick: median {np.median(tick):.0f} us, p99 {np.percentile(tick, 99):.0f} us; "
        f"MuJoCo's {STEPS} steps per tick: "
        f"{1e6 * STEPS * float(model.opt.timestep) / best_alone:.0f} us"
    )
    if not math.isfinite(best_wbc):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
