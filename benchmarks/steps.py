"""Step benchmarks (issue 14): medians per call, each beside a baseline measured in the same run.

1. ``capture_region`` (one step, left stance, touchdown after min_step_time, with the hip, the
   recommended foothold included). Target: median <= 50 µs.
2. ``capturability_distance`` (Koolen's d_N, 3 steps, disc foot, with the hip). Target: <= 5 µs.
3. ``capture_plan`` (a 3-step plan: footholds, touchdowns, CoPs). Target: <= 200 µs.
4. The ``recovery-plane`` controller's tick over closed-loop runs on ``stepping-plane`` (pushes
   needing 1-3 steps): median, p99 (target: under the 1 ms period) and the largest tick (a
   step decision or a touchdown's re-plan; information: one tick of a 2-core machine shared
   with the OS can always be late), with the same baseline.

Baseline: one ``numpy.dot`` of two 3-vectors, called in the same loop (a few hundred ns); the
ratio to it is printed beside each median.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from pushrecovery import load_params
from pushrecovery.ground import Support
from pushrecovery.surfaces.capture_plan import capture_plan
from pushrecovery.surfaces.capture_region import capture_region
from pushrecovery.surfaces.n_step import capturability_distance, step_options

CALLS = 2000


def median_us(func, calls=CALLS) -> float:
    clock = time.perf_counter_ns
    times = []
    for _ in range(calls):
        start = clock()
        func()
        times.append(clock() - start)
    return statistics.median(times) / 1e3


def controller_ticks_us(params) -> np.ndarray:
    """Every compute() time [µs] of closed-loop runs of recovery-plane on stepping-plane."""
    from pushrecovery.control.recovery_plane import PlaneRecoveryController
    from pushrecovery.sim.plane_stepping import PlaneSteppingPlant

    clock = time.perf_counter_ns
    controller = PlaneRecoveryController(params)  # builds its regions, loads the kernels
    times = []
    for xdot, ydot in ((1.2, 0.4), (2.6, -0.9), (-2.2, 0.5), (0.8, 2.9), (3.4, 1.0)):
        plant = PlaneSteppingPlant(params)
        state = plant.reset(0.0, xdot, 0.0, ydot)
        controller.reset(state)
        for k in range(3000):
            start = clock()
            command = controller.compute(k * 1e-3, state)
            times.append(clock() - start)
            step = plant.step(command, 1e-3)
            state = step.state
            controller.observe(step.info)
    return np.array(times) / 1e3


def main() -> int:
    params = load_params()
    support = Support.from_params(params, "left")
    option = step_options(params, support)[0]
    a, b = np.ones(3), np.arange(3.0)
    xi = np.array([0.9, 0.2])
    capture_region(0.0, 0.0, 1.5, 0.3, params, support)  # loads the compiled centre, caches
    cases = {
        "one-step capture region": (
            lambda: capture_region(0.0, 0.0, 1.5, 0.3, params, support),
            50.0,
        ),
        "3-step threshold d_N": (
            lambda: capturability_distance(3, params.omega, 0.2, 1.0, 0.05, 0.056),
            5.0,
        ),
        "3-step plan": (lambda: capture_plan(xi, params, option, 3), 200.0),
    }
    failed = False
    for name, (func, target) in cases.items():
        baseline = median_us(lambda: np.dot(a, b))
        median = median_us(func, 500 if target > 10 else CALLS)
        failed |= median > target
        print(
            f"{name}: median {median:.1f} µs (target <= {target:g}); numpy.dot of 3-vectors "
            f"{baseline:.2f} µs, ratio {median / baseline:.0f}"
        )
    ticks = controller_ticks_us(params)
    baseline = median_us(lambda: np.dot(a, b))
    p99 = float(np.percentile(ticks, 99))
    failed |= p99 > 1000.0
    print(
        f"recovery-plane tick: median {np.median(ticks):.1f} µs, p99 {p99:.1f} µs (target < "
        f"1000, the period), largest {ticks.max():.0f} µs; numpy.dot {baseline:.2f} µs, "
        f"median ratio {np.median(ticks) / baseline:.0f}"
    )
    print("step targets met" if not failed else "STEP TARGET MISSED")
    return int(failed)


if __name__ == "__main__":
    sys.exit(main())
