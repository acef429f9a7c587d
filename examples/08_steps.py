"""Several steps: where to put the foot after a push, and how many steps it takes.

A body stands on its left foot and is pushed forward and to the right. For a touchdown of the
right foot after min_step_time (0.2 s for the paper preset) the example prints the footholds
that capture the push with one step and with two (the first of two), the recommended foothold
of each (the one farthest from the region's edges), the plan classify recommends (footholds,
touchdown times and CoPs) and, at each touchdown, the capture point without and with Sec. IV's
impact. It ends with the largest push from standing that N steps absorb, draws the regions
into out/examples/steps.png, and simulates a push on the planar stepping model with the
recovery-plane controller (out/examples/steps_run.png, seen from above).
"""

from pathlib import Path

from pushrecovery import load_params
from pushrecovery.control.recovery.plane import PlaneRecoveryController
from pushrecovery.ground import Support
from pushrecovery.plots.common import save_figure
from pushrecovery.plots.runs import plane_run_figure
from pushrecovery.plots.steps import capture_regions_figure
from pushrecovery.sim.plane_stepping import PlaneSteppingPlant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.bounds import bounds_data
from pushrecovery.surfaces.capture.region import capture_region
from pushrecovery.surfaces.classify import classify

params = load_params()
support = Support.from_params(params, "left")
state = (0.0, 0.1, 1.6, -0.6)  # CoM over the left ankle, just after the push [m, m, m/s, m/s]

for steps in (1, 2):
    region = capture_region(*state, params, support, steps=steps)
    where = (
        "none"
        if region.foothold is None
        else f"({region.foothold[0]:.3f}, {region.foothold[1]:.3f}) m"
    )
    print(
        f"{steps} step(s), {region.swing.value} foot down at {region.touchdown:.2f} s: "
        f"footholds over {region.area:.3f} m², recommended {where}"
    )

x, y, xdot, ydot = state
verdict = classify(x, xdot, params, y=y, ydot=ydot, support=support)
print(
    f"verdict: {verdict.strategy.value}, {verdict.steps} step(s), step margin "
    f"{verdict.margins['step']:+.3f} m"
)
if verdict.plan is not None:
    plan = verdict.plan
    for k, (foot, time) in enumerate(zip(plan.footholds, plan.touchdowns, strict=True)):
        print(
            f"  step {k + 1}: {verdict.plan.swings[k].value} ankle to ({foot[0]:.3f}, "
            f"{foot[1]:.3f}) m at {time:.2f} s"
        )
    for impact in verdict.impacts:
        print(
            f"  touchdown at {impact.time:.2f} s: margin {impact.margin:+.3f} m without the "
            f"impact, {impact.margin_impact:+.3f} m with it (speed kept {impact.speed_ratio:.2f})"
        )

limits = bounds_data(params)["thresholds"]["steps"]
print(
    "largest push from standing, forward [m/s]: "
    + ", ".join(f"{n} step(s) {v[1]:.2f}" for n, v in limits.items() if n in ("1", "2", "3", "inf"))
)

paths = save_figure(
    capture_regions_figure(params, support, [state]), Path("out/examples/steps"), ("png",)
)
print(f"figure: {paths[0]}")

# The same push on the planar stepping model (double support at the start), recovered by the
# recovery-plane controller: it follows the N-step plan and re-plans at every touchdown.
plant = PlaneSteppingPlant(params)
start = plant.reset(0.0, 2.6, 0.0, 1.0)  # CoM over the ankles' midpoint, pushed
run = simulate(plant, PlaneRecoveryController(params), start, duration=8.0)
predicted = classify(0.0, 2.6, params, y=0.0, ydot=1.0)
print(
    f"simulated: {run.outcome.value} after {len(run.footholds_xy) - 1} step(s); "
    f"predicted {predicted.strategy.value} with {predicted.steps} step(s)"
)
paths = save_figure(plane_run_figure(run, params), Path("out/examples/steps_run"), ("png",))
print(f"figure: {paths[0]}")
