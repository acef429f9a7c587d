"""Contact changes in a 1 kHz loop (issue 32), every call timed, against a 100 x 100 mat-vec.

1. ``BalanceMonitor.set_support`` on a new support each call: single support (either foot)
   and double support, every pose and yaw new (uniform in ±1 m and [−π, π]); the supports are
   built beforehand (``Support.from_params``, reported apart). Targets: median <= 50 µs,
   p99 <= 200 µs.
2. The plane recovery controller's re-plan: the tick (``compute``) in which it plans from a
   support it has not seen (new poses and yaw, single and double support; a push of 1.2 m/s in
   a random direction, beyond the CMP region): the CMP region and the regions placed for the
   support, the plan made and the stance lifted. Targets as 1.; the plan alone
   (``StepRegions.plan``: ``capture_plan`` in the stance foot's frame) is printed beside it.
   Then the support change's share of that tick: each tick minus the same tick run again right
   after on the same support and state (its regions and CMP region kept), against the same
   targets (a line of its own: the whole tick's line decides the target).
3. ``BalanceMonitor.query`` of a new state each call on a turned support (single and double),
   the upper body upright and at rest and with its current pitch and roll (angle and rate
   uniform over the states the flywheel can stop within its range; the CMP region P ⊕ the
   box of errata E19). Target: median <= 20 µs, p99 <= 200 µs.
4. Building a ``BalanceMonitor`` and a ``PlaneRecoveryController`` in this process (the
   compiled kernels loaded) and in a fresh one, against ``python -c "import numpy"``.
   Target: <= 50 ms in this process.

Every call is kept: median, p99 and largest over all of them, wall clock and the thread's CPU
time (which leaves out the time other processes took the core: on a shared machine the wall
clock's tail is theirs). The mat-vec is ``numpy.dot`` of a 100 x 100 matrix and a 100-vector,
timed the same way in the same run.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
import timeit

import numpy as np

from pushrecovery import load_params
from pushrecovery.control.recovery.plane import PlaneRecoveryController
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.surfaces.monitor import BalanceMonitor

CALLS = 2000
REPLANS = 1000
TARGET_MEDIAN_US, TARGET_P99_US, TARGET_BUILD_MS = 50.0, 200.0, 50.0
TARGET_QUERY_US = 20.0


def _matvec_us(calls: int = 2000) -> float:
    matrix, vector = np.random.default_rng(0).normal(size=(100, 100)), np.ones(100)
    clock, times = time.perf_counter_ns, []
    for _ in range(calls):
        start = clock()
        np.dot(matrix, vector)
        times.append(clock() - start)
    return float(np.median(times)) / 1e3


def _supports(params, stance: Stance, count: int, seed: int) -> list[Support]:
    """Supports on new poses and yaws: the feet 0.2 m apart, the right one turned a little."""
    rng = np.random.default_rng(seed)
    supports = []
    for i in range(count):
        yaw = rng.uniform(-math.pi, math.pi)
        x, y = rng.uniform(-1.0, 1.0, 2)
        turn = min(math.pi, max(-math.pi, yaw + rng.uniform(-0.2, 0.2)))
        left = FootPose(x - 0.1 * math.sin(yaw), y + 0.1 * math.cos(yaw), yaw)
        right = FootPose(x + 0.1 * math.sin(yaw), y - 0.1 * math.cos(yaw), turn)
        side = stance if stance is Stance.DOUBLE else (Stance.LEFT, Stance.RIGHT)[i % 2]
        supports.append(Support.from_params(params, side, left=left, right=right))
    return supports


def _timed(calls) -> tuple[np.ndarray, np.ndarray]:
    """Wall and thread CPU time of each call [µs]."""
    wall, cpu = np.empty(len(calls)), np.empty(len(calls))
    clock, thread = time.perf_counter_ns, time.thread_time_ns
    for i, call in enumerate(calls):
        start, start_cpu = clock(), thread()
        call()
        end_cpu, end = thread(), clock()
        wall[i], cpu[i] = (end - start) / 1e3, (end_cpu - start_cpu) / 1e3
    return wall, cpu


def _report(
    label: str,
    wall: np.ndarray,
    cpu: np.ndarray,
    baseline: float,
    target_median: float = TARGET_MEDIAN_US,
) -> bool:
    median, p99, largest = np.median(wall), np.percentile(wall, 99), wall.max()
    met = median <= target_median and p99 <= TARGET_P99_US
    print(
        f"{label}, {wall.size} calls: median {median:.1f} µs ({median / baseline:.1f}x a "
        f"100x100 mat-vec of {baseline:.2f} µs), p99 {p99:.0f} µs ({p99 / baseline:.0f}x), "
        f"largest {largest:.0f} µs ({largest / baseline:.0f}x); CPU time median "
        f"{np.median(cpu):.1f} µs, p99 {np.percentile(cpu, 99):.0f} µs, largest "
        f"{cpu.max():.0f} µs (targets median <= {target_median:.0f} µs, p99 <= "
        f"{TARGET_P99_US:.0f} µs{'' if met else ': MISSED'})"
    )
    return met


def set_support() -> bool:
    params = load_params()
    monitor = BalanceMonitor(params)
    met = True
    for stance, name in ((Stance.LEFT, "single"), (Stance.DOUBLE, "double")):
        supports = _supports(params, stance, CALLS, seed=len(name))
        build = [
            (lambda s=s: Support.from_params(params, s.stance, left=s.left, right=s.right))
            for s in _supports(params, stance, CALLS, seed=len(name) + 100)
        ]
        baseline = _matvec_us()
        wall, cpu = _timed([lambda s=s: monitor.set_support(s) for s in supports])
        met &= _report(f"BalanceMonitor.set_support, {name} support, new pose and yaw", wall, cpu,
                       baseline)  # fmt: skip
        made, _ = _timed(build)
        print(
            f"  (Support.from_params of a new {name} support, before it: median "
            f"{np.median(made):.1f} µs, p99 {np.percentile(made, 99):.0f} µs)"
        )
    return met


def replan() -> bool:
    from pushrecovery.surfaces.step.regions import StepRegions

    params = load_params()
    controller = PlaneRecoveryController(params)
    rng = np.random.default_rng(5)
    met = True
    for stance, name in ((Stance.LEFT, "single"), (Stance.DOUBLE, "double")):
        supports = _supports(params, stance, REPLANS, seed=7 + len(name))
        states = []
        for support in supports:
            heading = rng.uniform(-math.pi, math.pi)
            ax, ay = support.ankle
            states.append(
                np.array([ax, ay, 0.0, 0.0, 1.2 * math.cos(heading), 1.2 * math.sin(heading),
                          0.0, 0.0])
            )  # fmt: skip
        wall, cpu = np.empty(REPLANS), np.empty(REPLANS)
        plans, seen, seen_cpu = np.empty(REPLANS), np.empty(REPLANS), np.empty(REPLANS)
        clock, thread = time.perf_counter_ns, time.thread_time_ns
        omega = params.omega
        for i, (support, state) in enumerate(zip(supports, states, strict=True)):
            for times, times_cpu in ((wall, cpu), (seen, seen_cpu)):  # new, then seen
                controller.reset(state)
                controller.support = support
                start, start_cpu = clock(), thread()
                command = controller.compute(0.0, state)
                end_cpu, end = thread(), clock()
                times[i], times_cpu[i] = (end - start) / 1e3, (end_cpu - start_cpu) / 1e3
            if command.foothold is None:
                raise RuntimeError(f"no step planned ({controller.mode})")
            # The plan alone (StepRegions.plan: capture_plan in the stance foot's frame).
            regions = StepRegions.of(params, support)
            xi = state[0:2] + state[4:6] / omega
            steps, _ = regions.locate(float(xi[0]), float(xi[1]))
            start = clock()
            regions.plan(float(xi[0]), float(xi[1]), steps or params.max_steps)
            plans[i] = (clock() - start) / 1e3
        baseline = _matvec_us()
        met &= _report(f"PlaneRecoveryController re-plan tick, {name} support, new pose and "
                       "yaw", wall, cpu, baseline)  # fmt: skip
        print(
            f"  (of which the plan, StepRegions.plan on the same supports and states: median "
            f"{np.median(plans):.1f} µs, p99 {np.percentile(plans, 99):.0f} µs; the same tick "
            f"again on the support just seen: median {np.median(seen):.1f} µs)"
        )
        _report(f"  the support change in that tick (the tick minus the same tick on the support "
                f"just seen), {name} support", wall - seen, cpu - seen_cpu, baseline)  # fmt: skip
    return met


def _torso(params, rng) -> dict[str, tuple[float, float]]:
    """A pitch and a roll state, uniform over the angles and the rates the flywheel can stop."""
    torso = {}
    for name, torque, inertia, angle_max in (
        ("pitch", params.torque_max, params.flywheel_inertia, params.flywheel_angle_max),
        ("roll", params.torque_max_roll, params.flywheel_inertia_roll,
         params.flywheel_angle_max_roll),
    ):  # fmt: skip
        angle = rng.uniform(-angle_max, angle_max)
        accel = torque / inertia
        low = -math.sqrt(2.0 * accel * (angle_max + angle))
        rate = rng.uniform(low, math.sqrt(2.0 * accel * (angle_max - angle)))
        torso[name] = (float(angle), float(rate))
    return torso


def query() -> bool:
    params = load_params()
    monitor = BalanceMonitor(params)
    rng = np.random.default_rng(9)
    met = True
    for stance, name in ((Stance.LEFT, "single"), (Stance.DOUBLE, "double")):
        support = _supports(params, stance, 1, seed=11 + len(name))[0]
        monitor.set_support(support)
        states = [  # Python floats, as a loop passes them (numpy scalars are converted)
            tuple(float(v) for v in (*(np.add(support.ankle, rng.uniform(-0.1, 0.1, 2))),
                                     *rng.uniform(-1.0, 1.0, 2)))
            for _ in range(CALLS)
        ]  # fmt: skip
        torsos = [_torso(params, rng) for _ in range(CALLS)]
        for label, calls in (
            ("upright, at rest", [lambda s=s: monitor.query(*s) for s in states]),
            (
                "with the upper body's pitch and roll",
                [
                    lambda s=s, t=t: monitor.query(*s, **t)
                    for s, t in zip(states, torsos, strict=True)
                ],
            ),
        ):
            baseline = _matvec_us()
            wall, cpu = _timed(calls)
            met &= _report(
                f"BalanceMonitor.query, {name} support, {label}",
                wall,
                cpu,
                baseline,
                TARGET_QUERY_US,
            )
    return met


def build() -> bool:
    params = load_params()
    BalanceMonitor(params)
    PlaneRecoveryController(params)  # the compiled kernels loaded: what a loop pays next
    monitor = min(timeit.repeat(lambda: BalanceMonitor(params), number=1, repeat=7)) * 1e3
    controller = (
        min(timeit.repeat(lambda: PlaneRecoveryController(params), number=1, repeat=7)) * 1e3
    )
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}

    def fresh(code: str) -> float:
        return min(
            timeit.repeat(
                lambda: subprocess.run([sys.executable, "-c", code], check=True, env=env),
                number=1,
                repeat=3,
            )
        )

    numpy_import = fresh("import numpy")
    head = "from pushrecovery import load_params; P = load_params(); "
    fresh_monitor = fresh(head + "from pushrecovery.surfaces.monitor import BalanceMonitor; "
                          "BalanceMonitor(P)")  # fmt: skip
    fresh_controller = fresh(
        head + "from pushrecovery.control.recovery.plane import PlaneRecoveryController; "
        "PlaneRecoveryController(P)"
    )
    numba_import = fresh("import numba") - numpy_import
    met = monitor <= TARGET_BUILD_MS and controller <= TARGET_BUILD_MS
    print(
        f"build in this process: BalanceMonitor {monitor:.1f} ms, PlaneRecoveryController "
        f"{controller:.1f} ms (target <= {TARGET_BUILD_MS:.0f} ms{'' if met else ': MISSED'}); "
        f"in a fresh process, imports included: {fresh_monitor * 1e3:.0f} ms and "
        f"{fresh_controller * 1e3:.0f} ms, against python -c 'import numpy' "
        f"{numpy_import * 1e3:.0f} ms (ratios {fresh_monitor / numpy_import:.1f} and "
        f"{fresh_controller / numpy_import:.1f}; importing numba alone adds "
        f"{numba_import * 1e3:.0f} ms)"
    )
    return met


def main() -> int:
    met = set_support()
    met &= replan()
    met &= query()
    met &= build()
    print("realtime targets met" if met else "REALTIME TARGET MISSED")
    return int(not met)


if __name__ == "__main__":
    sys.exit(main())
