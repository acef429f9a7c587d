"""A 1 kHz balance loop: the planner commands, the monitor watches, contacts change in µs.

A body stands on feet placed as a robot would measure them (turned, not at the default poses)
and is pushed forward and to the left. Every millisecond the loop thread asks the plane
recovery controller for a command, advances the plant (the exact planar model with stepping
feet) and, when a foot lifts or lands, tells the monitor the new support; a second thread
reads the monitor's verdict at 100 Hz, with the upper body's current pitch and roll, as a
logger or a safety supervisor would, while the loop changes the support under it
(docs/realtime.md gives the thread rules). Everything that builds regions or loads compiled
code happens before the loop; the loop prints what each kind of call cost against the 1 ms
period.
"""

import threading
import time

import numpy as np

from pushrecovery import load_params
from pushrecovery.control.recovery.plane import PlaneRecoveryController
from pushrecovery.ground import FootPose, Support
from pushrecovery.sim.plane_stepping import PlaneSteppingPlant
from pushrecovery.surfaces.monitor import BalanceMonitor

params = load_params()
feet = Support.from_params(
    params, "double", left=FootPose(0.02, 0.11, 0.12), right=FootPose(-0.01, -0.1, -0.05)
)

# Start-up, before the loop: regions, plans' terms and compiled kernels (from numba's disk
# cache after the first run on this machine).
start = time.perf_counter()
controller = PlaneRecoveryController(params)
monitor = BalanceMonitor(params, feet)
plant = PlaneSteppingPlant(params)
print(f"start-up: {(time.perf_counter() - start) * 1e3:.0f} ms (controller, monitor, plant)")

state = plant.reset(0.0, 0.9, 0.0, 0.7, support=feet)  # pushed: 0.9 m/s forward, 0.7 left
controller.reset(state)
controller.support = feet  # the measured feet

latest = [state]  # the loop's newest state: one list item, replaced whole
seen: dict[str, int] = {}
done = threading.Event()


def supervise() -> None:
    """Read the monitor at 100 Hz while the loop runs (queries are safe beside set_support).

    The verdict takes the upper body's current pitch and roll (angle, rate) too: the hip
    strategy has less room on the side the upper body already leans or turns toward.
    """
    while not done.is_set():
        x, y, pitch, roll, xdot, ydot, pitch_rate, roll_rate = latest[0].tolist()
        verdict = monitor.query(x, y, xdot, ydot, pitch=(pitch, pitch_rate), roll=(roll, roll_rate))
        seen[verdict.strategy.value] = seen.get(verdict.strategy.value, 0) + 1
        time.sleep(0.01)


supervisor = threading.Thread(target=supervise)
supervisor.start()
dt, ticks, changes = 1e-3, [], []
clock = time.perf_counter_ns
for tick in range(1500):
    t = tick * dt
    begin = clock()
    command = controller.compute(t, state)
    ticks.append(clock() - begin)
    state = plant.step(command, dt).state
    latest[0] = state
    if plant.support is not monitor.support:  # a foot lifted or landed
        begin = clock()
        monitor.set_support(plant.support)
        changes.append(clock() - begin)
        x, y, _, _, xdot, ydot, _, _ = state
        verdict = monitor.query(float(x), float(y), float(xdot), float(ydot))
        print(
            f"t = {t + dt:5.3f} s  now on {plant.support.stance.value:6s} the monitor says "
            f"{verdict.strategy.value} (step margin {verdict.step_margin:+.3f} m)"
        )
done.set()
supervisor.join()

tick_us, change_us = np.array(ticks) / 1e3, np.array(changes) / 1e3
print(f"footholds: {np.round(plant.footholds_xy, 3).tolist()}")
print(
    f"controller.compute: median {np.median(tick_us):.0f} µs, p99 "
    f"{np.percentile(tick_us, 99):.0f} µs, largest {tick_us.max():.0f} µs over {len(ticks)} "
    f"ticks of 1000 µs"
)
print(
    f"monitor.set_support at {len(changes)} contact changes: median "
    f"{np.median(change_us):.0f} µs, largest {change_us.max():.0f} µs"
)
print(f"the supervisor's verdicts: {seen}")
