"""MuJoCo at its own speed (issue 17, item 3): the controller's overhead against MuJoCo alone.

1. ``torso`` + MPC at 50 Hz, 3 s after a 40 N s push, through the one loop
   (:func:`~pushrecovery.sim.simulate.simulate`), against MuJoCo alone on the same model and
   the same trajectory: the controls the loop applied, replayed by ``mujoco.rollout`` on one
   thread from the same state (no Python per step). Both as real-time factors and their ratio,
   measured in the same run, interleaved (the best of ``REPEAT`` each). Target: the loop at
   >= 0.7x the speed of MuJoCo alone. The MPC's own ticks (replayed on the loop's states) are
   printed beside it: the part of the gap that is the controller's, not the loop's.
2. ``foot`` + ankle PD on a grid of pushes: :func:`~pushrecovery.sim.mujoco.rollout.
   ankle_pd_rollout` (the pushes in lockstep, MuJoCo's threads) against the one loop on the
   same pushes, in pushes per second.

``main()`` returns 1 when the 0.7x target is missed (``benchmarks/run.py`` calls it).
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any

import numpy as np

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.sim.critical import pushed_state
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import RestCriterion, simulate

#: Target: the loop's real-time factor over MuJoCo alone's, same model, same run.
TARGET = 0.7
REPEAT = 15
DURATION = 3.0
IMPULSE = 40.0


class _Recorder:
    """Stands in for the ``mujoco`` module inside a plant: records what every step applied."""

    def __init__(self, mujoco: Any) -> None:
        self._mujoco = mujoco
        self.controls: list[tuple[np.ndarray, int]] = []

    def __getattr__(self, name: str) -> Any:
        return getattr(self._mujoco, name)

    def mj_step(self, model: Any, data: Any, nstep: int = 1) -> None:
        self.controls.append((data.ctrl.copy(), nstep))
        self._mujoco.mj_step(model, data, nstep=nstep)


def realtime() -> tuple[float, float, float, float]:
    """Return the real-time factors of the loop, of MuJoCo alone, their ratio, the MPC's share."""
    import mujoco
    from mujoco import rollout

    params = load_params()
    plant, ctrl = make_plant("torso", params, "mujoco"), make_controller("mpc", params)
    never = RestCriterion(duration=1e3)  # run the whole 3 s

    def start() -> np.ndarray:
        plant.reset(0.0, 0.0)
        return plant.apply_push(Push.from_impulse(IMPULSE, params.mass))

    # The trajectory once, recorded: the state after the push and every step's controls.
    state = start()
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    initial = np.empty(mujoco.mj_stateSize(plant.model, full))
    mujoco.mj_getState(plant.model, plant.data, initial, full)
    warmstart = plant.data.qacc_warmstart.copy()
    recorder = _Recorder(plant._mj)
    plant._mj = recorder
    run = simulate(plant, ctrl, state, duration=DURATION, rest=never)
    plant._mj = recorder._mujoco
    controls = np.concatenate([np.repeat(c[None], n, axis=0) for c, n in recorder.controls])
    steps = controls.shape[0]
    data = mujoco.MjData(plant.model)
    states = run.states[:-1]

    def loop() -> float:
        first = start()
        begin = time.perf_counter()
        simulate(plant, ctrl, first, duration=DURATION, rest=never)
        return time.perf_counter() - begin

    def alone() -> float:
        begin = time.perf_counter()
        rollout.rollout(
            plant.model, data, initial[None], controls[None], initial_warmstart=warmstart[None]
        )
        return time.perf_counter() - begin

    def ticks() -> float:
        ctrl.reset(states[0])
        begin = time.perf_counter()
        for k, s in enumerate(states):
            ctrl.compute(0.02 * k, s)
        return time.perf_counter() - begin

    best = {"loop": np.inf, "alone": np.inf, "ticks": np.inf}
    for _ in range(REPEAT):  # interleaved: a busy moment of the machine hits both
        best["loop"] = min(best["loop"], loop())
        best["alone"] = min(best["alone"], alone())
        best["ticks"] = min(best["ticks"], ticks())
    simulated = steps * plant.model.opt.timestep
    loop_factor, alone_factor = simulated / best["loop"], simulated / best["alone"]
    return loop_factor, alone_factor, loop_factor / alone_factor, best["ticks"] / best["loop"]


def pushes_per_second() -> tuple[float, float, int, int]:
    """Return the rollout's and the loop's pushes/s on the same pushes, their count, threads."""
    from pushrecovery.sim.mujoco.rollout import ankle_pd_rollout

    params = load_params()
    speeds = np.linspace(-0.3, 0.5, 24)
    x0 = np.zeros_like(speeds)
    threads = os.cpu_count() or 1
    plant, ctrl = make_plant("foot", params, "mujoco"), make_controller("ankle-pd", params)
    begin = time.perf_counter()
    for v in speeds:
        simulate(plant, ctrl, pushed_state(plant, 0.0, float(v), force=True), duration=6.0)
    looped = time.perf_counter() - begin
    ankle_pd_rollout(params, x0[:2], speeds[:2], duration=0.1, threads=threads)  # warm up
    begin = time.perf_counter()
    ankle_pd_rollout(params, x0, speeds, duration=6.0, threads=threads)
    rolled = time.perf_counter() - begin
    return speeds.size / rolled, speeds.size / looped, speeds.size, threads


def main() -> int:
    """Print the benchmark; return 1 if the loop runs below 0.7x MuJoCo alone."""
    loop_factor, alone_factor, ratio, mpc_share = realtime()
    met = ratio >= TARGET
    print(
        f"MuJoCo torso + MPC at 50 Hz, {DURATION:g} s after a push: {loop_factor:.0f}x real time; "
        f"MuJoCo alone on the same trajectory {alone_factor:.0f}x; ratio {ratio:.2f} "
        f"(target >= {TARGET:g}: {'met' if met else 'MISSED'}); the MPC's ticks are "
        f"{100 * mpc_share:.0f}% of the loop's time"
    )
    rolled, looped, count, threads = pushes_per_second()
    print(
        f"foot + ankle-pd, {count} pushes: lockstep rollout ({threads} threads) {rolled:.1f} "
        f"pushes/s; the one loop {looped:.1f} pushes/s; ratio {rolled / looped:.1f}"
    )
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
