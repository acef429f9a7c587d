"""The ground plane: a side push on one foot, watched by a BalanceMonitor at 1 kHz.

A body stands on its left foot (turned 0.2 rad outward) and is pushed diagonally, forward and to
the left. Nobody reacts: the CoP stays at the middle of the foot and the upper body is still,
so the capture point runs away (the 2-D model of models.flywheel.plane, advanced exactly every
millisecond). The monitor classifies every state as a 1 kHz balance loop would, and reports
when the strategy the body needs escalates, from hip to a step to a fall: how long a controller
has to decide. The step margin is the capture point's distance to the N-step capture regions
(docs/steps.md): it turns negative exactly when the verdict turns to fall.
"""

import time

import numpy as np

from pushrecovery import load_params
from pushrecovery.ground import FootPose, Support
from pushrecovery.models.flywheel.plane import plane_propagate
from pushrecovery.surfaces.monitor import BalanceMonitor

params = load_params()
support = Support.from_params(params, "left", left=FootPose(0.0, 0.1, 0.2))
monitor = BalanceMonitor(params, support)  # built once: the step regions, compiled tests

cx, cy = support.polygon.centroid  # the CoP held at the middle of the foot
state = np.array([cx, cy, 0.0, 0.0, 0.15, 0.25, 0.0, 0.0])  # just after the push [m, m/s]
cop = np.array([cx, cy, 0.0, 0.0])
dt = 0.001

print(f"support polygon (left foot, yaw 0.2 rad): {np.round(support.polygon.vertices, 3).tolist()}")
last = None
costs = []
for tick in range(1500):
    start = time.perf_counter()
    verdict = monitor.query(state[0], state[1], state[4], state[5])
    costs.append(time.perf_counter() - start)
    if verdict.strategy != last:
        print(
            f"t = {tick * dt:5.3f} s  needs {verdict.strategy.value:5s}  capture point "
            f"({verdict.capture_point_x:+.3f}, {verdict.capture_point_y:+.3f}) m  margins: cop "
            f"{verdict.cop_margin:+.3f}, cmp {verdict.cmp_margin:+.3f}, step "
            f"{verdict.step_margin:+.3f} m"
        )
        last = verdict.strategy
    state = plane_propagate(state, cop, params, dt)
print(
    f"monitor query: median {np.median(costs) * 1e6:.1f} µs, max {max(costs) * 1e6:.1f} µs "
    f"over {len(costs)} ticks of 1 ms"
)
