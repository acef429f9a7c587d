"""Step benchmarks (issue 14): medians per call, each beside a baseline measured in the same run.

1. ``capture_region`` (one step, with the hip, the recommended foothold included) of a 48 kg,
   0.78 m robot on 4-, 8- and 16-vertex soles, standing on its left foot yawed 10°, over 3000
   random states in a loop whose remaining swing time falls by 1 ms a call (a new touchdown
   at every call, as mid-swing in a 1 kHz loop): median, p99 and max over every call, beside
   a 100x100 mat-vec timed in the same loop (issue 32). Targets: median <= 50 µs, p99 <= 200
   µs.
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

import math
import statistics
import sys
import time

import numpy as np

from pushrecovery import load_params
from pushrecovery.ground import FootPose, Support
from pushrecovery.surfaces.capture.plan import capture_plan
from pushrecovery.surfaces.capture.region import capture_region
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


def _sole(vertices: int) -> list[tuple[float, float]]:
    """A convex sole of that many vertices inscribed in the ellipse over [-0.06, 0.18] x ±0.05 m."""
    angles = 2.0 * np.pi * (np.arange(vertices) + 0.5) / vertices
    return [(0.06 + 0.12 * math.cos(a), 0.05 * math.sin(a)) for a in angles]


def capture_regions() -> bool:
    """capture_region on 4-, 8- and 16-vertex soles, every call timed (item 1)."""
    rng = np.random.default_rng(11)
    n = 3000
    states = np.column_stack(
        [
            rng.normal(0.03, 0.05, n),
            rng.normal(0.0, 0.05, n),
            rng.normal(0.3, 0.9, n),
            rng.normal(0.0, 0.6, n),
        ]
    ).tolist()
    swing = [0.35 - 1e-3 * (k % 300) for k in range(n)]
    matrix, vector = rng.normal(size=(100, 100)), rng.normal(size=100)
    clock = time.perf_counter_ns
    failed = False
    for vertices in (4, 8, 16):
        robot = {"mass": 48.0, "com_height": 0.78}
        if vertices != 4:  # the rectangle: the preset's own foot
            robot |= {"foot_polygon": _sole(vertices), "heel": None, "toe": None}
            robot["foot_width"] = None
        params = load_params("paper", overrides=robot)
        left = FootPose(0.0, 0.1, math.radians(10.0))
        support = Support.from_params(params, "left", left=left)
        for state in states[:50]:  # the support's terms and the compiled paths, once
            capture_region(*state, params, support)
        own, base = np.empty(n), np.empty(n)
        for k, state in enumerate(states):
            start = clock()
            capture_region(*state, params, support, swing[k])
            middle = clock()
            matrix @ vector
            end = clock()
            own[k], base[k] = middle - start, end - middle
        own, base = own / 1e3, base / 1e3
        median, p99, worst = np.median(own), np.percentile(own, 99), own.max()
        base_median = np.median(base)
        failed |= median > 50.0 or p99 > 200.0
        print(
            f"capture_region, {vertices}-vertex sole, {n} calls: median {median:.1f} µs, p99 "
            f"{p99:.1f} µs, max {worst:.0f} µs (targets 50 / 200); 100x100 mat-vec "
            f"{base_median:.2f} µs; ratios {median / base_median:.1f} / "
            f"{p99 / base_median:.1f} / {worst / base_median:.0f}"
        )
    return failed


def controller_ticks_us(params) -> np.ndarray:
    """Every compute() time [µs] of closed-loop runs of recovery-plane on stepping-plane."""
    from pushrecovery.control.recovery.plane import PlaneRecoveryController
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
    failed = capture_regions()
    cases = {
        "3-step threshold d_N": (
            lambda: capturability_distance(3, params.omega, 0.2, 1.0, 0.05, 0.056),
            5.0,
        ),
        "3-step plan": (lambda: capture_plan(xi, params, option, 3), 200.0),
    }
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
