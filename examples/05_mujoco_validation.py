"""MuJoCo against the decision surfaces: the tables and filmstrips of docs/validation.md.

Prints the critical-push table (every strategy, both directions, several start positions) and
the confusion matrix as Markdown, and renders one filmstrip (PNG + GIF) per strategy into
``--out`` (default ``out/validation``; the documentation's images are made with
``--out docs/img``). ``--quick`` runs a small subset (for tests).
"""

import argparse
from pathlib import Path

import numpy as np

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.sim.mujoco.render import render_run
from pushrecovery.sim.push import Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.sim.validation import LABELS, confusion_matrix, critical_table

#: Strategy -> (model, controller, push [N s], caption) for the filmstrips.
FILMSTRIPS = {
    "ankle": ("foot", "ankle-pd", 25.0, "ankle strategy: foot + ankle PD, 25 N s"),
    "hip": ("torso", "mpc", 40.0, "hip strategy: torso + MPC, 40 N s"),
    "step": ("biped", "recovery", 80.0, "stepping: biped + recovery controller, 80 N s"),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", type=Path, default=Path("out/validation"))
    args = parser.parse_args()
    params = load_params()
    strategies = ("ankle",) if args.quick else ("ankle", "hip", "step")
    x0s = (0.0,) if args.quick else (-0.03, 0.0, 0.05, 0.1)

    print(
        "| strategy | model + controller | direction | x0 [m] | predicted [m/s] | corrected [m/s] "
        "| MuJoCo [m/s] | vs predicted | vs corrected |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for row in critical_table(
        params, strategies=strategies, x0s=x0s, tolerance=5e-3 if args.quick else 1e-3
    ):
        corrected = "—" if np.isnan(row.corrected) else f"{row.corrected:.4f}"
        error = "—" if np.isnan(row.corrected) else f"{100 * row.corrected_error:+.1f} %"
        print(
            f"| {row.strategy} | {row.model} + {row.controller} | {row.direction} "
            f"| {row.x0:.2f} | {row.predicted:.4f} | {corrected} | {row.measured:.4f} "
            f"| {100 * row.relative_error:+.1f} % | {error} |"
        )

    velocities = np.arange(-1.5, 3.01, 0.25) if not args.quick else np.array([0.2, 0.6])
    matrix = confusion_matrix(
        params, (0.0,) if args.quick else (0.0, 0.05), velocities, strategies=strategies
    )
    print(
        f"\nConfusion matrix (rows: predicted; columns: needed in MuJoCo); "
        f"accuracy {matrix.accuracy:.3f} over {int(matrix.counts.sum())} pushes\n"
    )
    print("| predicted \\ needed | " + " | ".join(LABELS) + " |")
    print("|---" * (len(LABELS) + 1) + "|")
    for label, counts in zip(LABELS, matrix.counts, strict=True):
        print(f"| {label} | " + " | ".join(str(c) for c in counts) + " |")
    misses = [case for case in matrix.cases if case[2] != case[3]]
    if misses:
        print("\nDisagreements (x0, ẋ, predicted, needed):")
        for x0, v, predicted, needed in misses:
            print(f"- x0 = {x0:.2f} m, ẋ = {v:+.2f} m/s: predicted {predicted}, needed {needed}")

    args.out.mkdir(parents=True, exist_ok=True)
    for strategy in strategies:
        model, controller, impulse, caption = FILMSTRIPS[strategy]
        plant = make_plant(model, params, "mujoco")
        plant.record()
        plant.reset(0.0, 0.0)
        pushed = plant.apply_push(Push.from_impulse(impulse, params.mass))
        result = simulate(plant, make_controller(controller, params), pushed, duration=4.0)
        files = render_run(
            plant.model,
            plant.frames,
            args.out / f"{strategy}.png",
            title=f"{caption}: {result.outcome.value}",
        )
        print(f"\n{strategy}: {result.outcome.value}; wrote {', '.join(map(str, files))}")


if __name__ == "__main__":
    main()
