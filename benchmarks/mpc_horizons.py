"""MPC benchmarks (issue 17): the tick at several horizons, against a baseline in the same run.

For N = 50, 100 and 200 (dt = 0.02 s, the paper's weights), every tick of closed-loop runs
of ``flywheel`` + ``mpc`` after pushes of 0.55, -0.4, 0.3 and 0.65 m/s (torque and CoP limits
active) is timed one by one, the solver warm-started between ticks as in a real loop, after a
warm-up run on another push (0.6 m/s: compilation, DAQP's workspace); each run is replayed
``REPLAYS`` times and each tick counts with its best time (the largest tick, against the
period, is the first run through's). Also printed: the share
of ticks verified by the Riccati passes (from the warm start, or from the interior point's
active set) and the share that needed the interior point, and the largest tick of
the recovery controller on the stepping model over 7 pushes (hip and step) after a warm-up
push (target 2 ms). Baseline: one
``numpy.dot`` of a 100 x 100 matrix and a 100-vector, timed in the same loop. Targets: the tick
median at N = 50 <= 15x that baseline and its p99 <= 20x its median (the issue's targets, at
N = 50); the median at N = 200 <= 5x the median at N = 50; at every horizon no tick over the
20 ms period. N = 100 and 200's p99 are printed: a third of their ticks need the interior
point, whose iterations grow with N (medians 11, 20 and 46 at N = 50, 100, 200), and their p99
is 70-110x the warm passes' median (docs/performance.md, "Per tick: a controller's or a
monitor's call"; the route in docs/mpc.md). Also
printed: the time to build the controller (its QP and workspace), once per body and horizon.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from pushrecovery import load_params
from pushrecovery.control.base import make_controller
from pushrecovery.control.mpc import FlywheelFeasibility, MPCController, MPCSettings, Status
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate

HORIZONS = (50, 100, 200)
#: The control period [µs]: a tick longer than it is not real time.
PERIOD_US = 20_000.0


def _matvec_us(calls: int = 2000) -> float:
    matrix, vector = np.random.default_rng(0).normal(size=(100, 100)), np.ones(100)
    clock, times = time.perf_counter_ns, []
    for _ in range(calls):
        start = clock()
        np.dot(matrix, vector)
        times.append(clock() - start)
    return statistics.median(times) / 1e3


#: Each measured run is replayed this many times from the same states (the controller reset:
#: the same warm starts, the same routes) and each tick's time is its best: the median and
#: p99 then measure the controller, not the machine's interruptions (one of them, 50-100 µs,
#: moved a single run's p99 at N = 50 from 16x to 21x the median). The largest tick, against
#: the period, is the first run through's, as a real loop meets it.
REPLAYS = 5
#: Pushes [m/s] of the measured runs; the warm-up run (compilation, first DAQP solves) uses
#: another one, so no measured tick was seen before.
WARM_UP_PUSH, MEASURED_PUSHES = 0.6, (0.55, -0.4, 0.3, 0.65)


def _ticks_us(
    horizon: int,
) -> tuple[np.ndarray, float, float, tuple[float, float], tuple[int, int]]:
    """Every measured tick [µs] (the best of its replays), the largest single tick of the first
    run through [µs], the build time [ms], the shares verified and interior-point.

    And the fallback ticks: (exactly infeasible, exactly feasible but failed by DAQP), by the
    gauge of the flywheel's viable set (``FlywheelFeasibility``).
    """
    params = load_params()
    start = time.perf_counter()
    controller = MPCController(params, horizon=horizon)
    build = (time.perf_counter() - start) * 1e3
    plant = make_plant("flywheel", params)
    runs = [
        simulate(plant, MPCController(params, horizon=horizon), plant.reset(0.0, v)).states[:-1]
        for v in (WARM_UP_PUSH, *MEASURED_PUSHES)
    ]
    clock, verified, interior = time.perf_counter_ns, 0, 0
    exact, infeasible, failed = FlywheelFeasibility(params, MPCSettings(horizon=horizon)), 0, 0
    replays: list[list[int]] = []
    for replay in range(REPLAYS):
        times = []
        for run, states in enumerate(runs if replay == 0 else runs[1:]):
            controller.reset(states[0])
            for k, state in enumerate(states):
                if controller.interior is not None:
                    controller.interior.iterations = 0
                begin = clock()
                controller.compute(0.02 * k, state)
                if run or replay:
                    times.append(clock() - begin)
                if replay or not run:
                    continue
                plan = controller.last_plan
                verified += plan is not None and plan.status is Status.VERIFIED
                interior += controller.interior is not None and controller.interior.iterations != 0
                if plan is not None and not plan.feasible:
                    outside = exact.gauge(state) > 1.0
                    infeasible, failed = infeasible + outside, failed + (not outside)
        replays.append(times)
    ticks = np.array(replays) / 1e3
    shares = (verified / ticks.shape[1], interior / ticks.shape[1])
    return ticks.min(axis=0), ticks[0].max(), build, shares, (infeasible, failed)


def _recovery_ticks_ms() -> tuple[float, int, int]:
    """Recovery controller on the stepping model: largest tick [ms] after warm-up runs.

    The first two runs (a hip push and a step push) load the caches and are not counted.
    """
    params = load_params()
    plant = make_plant("stepping", params)
    largest, over, count = 0.0, 0, 0
    for run, push in enumerate((0.5, 1.3, 0.45, -0.35, 0.8, 2.6, -1.0, -2.6, 1.7)):
        controller = make_controller("recovery", params)
        compute, ticks = controller.compute, []

        def timed(t: float, state: np.ndarray, compute=compute, ticks=ticks):
            begin = time.perf_counter_ns()
            command = compute(t, state)
            ticks.append(time.perf_counter_ns() - begin)
            return command

        controller.compute = timed  # type: ignore[method-assign]
        simulate(plant, controller, plant.reset(0.0, push))
        if run > 1:
            largest = max(largest, max(ticks) / 1e6)
            over += sum(t > 2e6 for t in ticks)
            count += len(ticks)
    return largest, over, count


def main() -> int:
    medians, failed = {}, False
    for horizon in HORIZONS:
        ticks, largest, build, (verified, interior), (infeasible, daqp_failed) = _ticks_us(horizon)
        baseline = _matvec_us()
        median, p99 = float(np.median(ticks)), float(np.percentile(ticks, 99))
        medians[horizon] = median
        print(
            f"MPC tick, N = {horizon}: median {median:.0f} µs ({median / baseline:.0f}x a 100x100 "
            f"mat-vec of {baseline:.2f} µs), p99 {p99:.0f} µs ({p99 / median:.1f}x the median), "
            f"largest {largest:.0f} µs; build {build:.1f} ms; {verified:.0%} of "
            f"{ticks.size} ticks verified by the Riccati passes, {interior:.0%} through the "
            f"interior point (the rest: DAQP); fallbacks: "
            f"{infeasible} infeasible QPs, {daqp_failed} feasible QPs DAQP failed"
            + ("" if horizon == 50 else "; (information: the p99 target is at N = 50)")
        )
        # The targets at N = 50: median <= 15x the mat-vec, p99 <= 20x the median. At
        # every horizon: real time, no tick over the 20 ms period.
        if horizon == 50:
            failed |= median > 15.0 * baseline or p99 > 20.0 * median
        failed |= largest > PERIOD_US
    growth = medians[200] / medians[50]
    failed |= growth > 5.0
    print(f"MPC tick growth N = 200 / N = 50: {growth:.1f}x (target <= 5x)")
    largest, over, count = _recovery_ticks_ms()
    failed |= largest > 2.0
    print(
        f"Recovery controller tick after warm-up: largest {largest:.2f} ms (target <= 2 ms), "
        f"{over} of {count} ticks over 2 ms"
    )
    print("MPC targets met" if not failed else "MPC TARGET MISSED")
    return int(failed)


if __name__ == "__main__":
    sys.exit(main())
