"""Are the fall probabilities calibrated? Pushes simulated, the pushed states estimated with noise.

A body that can take two steps (the paper preset with max_steps = 2) is pushed forward from
standing at velocities uniform over 2.6-3.9 m/s, around where two steps stop sufficing; the
planar stepping model (analytic) and the MuJoCo biped recover with the recovery controller or
fall. A monitor estimates each pushed state with errors of 1 cm and 0.1 m/s (standard
deviations) and predicts P(fall) (surfaces.probability); a third study makes the controller
react 50 ms late (the CoP held at the foot's middle meanwhile) and predicts with that latency.
The example prints each study's reliability table and Brier scores and draws
out/examples/calibration.png. With --quick: 300, 60 and 40 pushes (the docs': 2,000, 400, 500).
"""

import dataclasses
import sys
from pathlib import Path

from pushrecovery import load_params
from pushrecovery.experiments.calibration import calibration_study
from pushrecovery.plots.calibration import reliability_figure
from pushrecovery.plots.common import save_figure

quick = "--quick" in sys.argv
params = dataclasses.replace(load_params(), max_steps=2)
studies = []
for label, model, backend, pushes, latency in (
    ("planar stepping model (analytic)", "stepping", "analytic", 300 if quick else 2000, 0.0),
    ("MuJoCo biped", "biped", "mujoco", 60 if quick else 400, 0.0),
    ("stepping model, 50 ms latency", "stepping", "analytic", 40 if quick else 500, 0.05),
):
    study = calibration_study(model, "recovery", params, velocities=(2.6, 3.9), pushes=pushes,
                              noise=(0.01, 0.1), backend=backend, duration=6.0, seed=1,
                              latency=latency)  # fmt: skip
    studies.append((label, study))
    print(f"{label}: {int(study.kept.sum())} runs scored, {study.excluded} undecided")
    print("  P(fall) bin    runs  mean predicted  observed (SE)")
    for low, high, runs, mean, rate, se in study.bins:
        print(f"  {low:.1f}-{high:.1f}  {runs:6d}  {mean:14.3f}  {rate:.3f} ({se:.3f})")
    print(f"  Brier: probabilities {study.brier:.4f}, certain verdict {study.brier_certain:.4f},"
          f" base rate {study.brier_base_rate:.4f}")  # fmt: skip
(path,) = save_figure(reliability_figure(studies), Path("out/examples/calibration"), ["png"])
print(f"wrote {path}")
