"""MPC benchmarks (issue 17): the tick at several horizons, against a baseline in the same run.

For N = 50, 100 and 200 (dt = 0.02 s, the paper's weights), every tick of a closed-loop run
of ``flywheel`` + ``mpc`` after a 0.6 m/s push (torque, CoP and joint limits active) is timed
one by one, the DAQP workspace warm-started between ticks as in a real loop. Baseline: one
``numpy.dot`` of a 100 x 100 matrix and a 100-vector, timed in the same loop. Targets: the tick
median at N = 50 <= 15x that baseline; p99 <= 20x the median; the median at N = 200 <= 5x the
median at N = 50. Also printed: the time to build the controller (its QP and workspace), once
per body and horizon.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from pushrecovery import load_params
from pushrecovery.control.mpc import MPCController
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

HORIZONS = (50, 100, 200)


def _matvec_us(calls: int = 2000) -> float:
    matrix, vector = np.random.default_rng(0).normal(size=(100, 100)), np.ones(100)
    clock, times = time.perf_counter_ns, []
    for _ in range(calls):
        start = clock()
        np.dot(matrix, vector)
        times.append(clock() - start)
    return statistics.median(times) / 1e3


def _ticks_us(horizon: int) -> tuple[np.ndarray, float]:
    """Every tick [µs] of a closed-loop run at this horizon, and the build time [ms]."""
    params = load_params()
    start = time.perf_counter()
    controller = MPCController(params, horizon=horizon)
    build = (time.perf_counter() - start) * 1e3
    plant = make_plant("flywheel", params)
    run = simulate(plant, MPCController(params, horizon=horizon), plant.reset(0.0, 0.6))
    states = run.states[:-1]
    clock, times = time.perf_counter_ns, []
    for _ in range(3):  # three passes over the run: the first loads the caches
        controller.reset(states[0])
        for k, state in enumerate(states):
            begin = clock()
            controller.compute(0.02 * k, state)
            times.append(clock() - begin)
    return np.array(times[len(states) :]) / 1e3, build


def main() -> int:
    medians, failed = {}, False
    for horizon in HORIZONS:
        ticks, build = _ticks_us(horizon)
        baseline = _matvec_us()
        median, p99 = float(np.median(ticks)), float(np.percentile(ticks, 99))
        medians[horizon] = median
        print(
            f"MPC tick, N = {horizon}: median {median:.0f} µs ({median / baseline:.0f}x a 100x100 "
            f"mat-vec of {baseline:.2f} µs), p99 {p99:.0f} µs ({p99 / median:.1f}x the median), "
            f"largest {ticks.max():.0f} µs; build {build:.1f} ms"
        )
        if horizon == 50:
            failed |= median > 15.0 * baseline
        failed |= p99 > 20.0 * median
    growth = medians[200] / medians[50]
    failed |= growth > 5.0
    print(f"MPC tick growth N = 200 / N = 50: {growth:.1f}x (target <= 5x)")
    print("MPC targets met" if not failed else "MPC TARGET MISSED")
    return int(failed)


if __name__ == "__main__":
    sys.exit(main())
