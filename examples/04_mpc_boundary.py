"""The MPC's empirical stabilisation boundary against the corrected Eq. (15).

For several initial positions and both directions, finds the critical push of the paper's
receding-horizon controller (and of variants that isolate each cause of the gap) by bisection,
and prints the Markdown tables of docs/mpc.md. ``--quick`` runs a small subset (for tests).
"""

import argparse

import numpy as np

from pushrecovery import load_params
from pushrecovery.sim.critical import critical_push

VARIANTS = {
    "paper (dt 0.02, N 50, γ 0.9)": {},
    "γ = 1 (uniform weights)": {"gamma": 1.0},
    "N = 100 (2 s horizon)": {"horizon": 100},
    "Q_θ = 1 (flywheel angle cheap)": {"state_weights": (1e3, 1.0, 10.0, 10.0)},
    "dt = 0.01, N = 100": {"dt": 0.01, "horizon": 100},
}


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    params = load_params()
    positions = [0.0] if args.quick else list(np.linspace(-0.04, 0.14, 4))
    tolerance = 1e-3 if args.quick else 1e-5

    print("### Paper settings: critical push per start\n")
    print(
        "| direction | x0 [m] | MPC [m/s] | bang-bang [m/s] | corrected Eq. (15) [m/s] "
        "| MPC error |"
    )
    print("|---|---|---|---|---|---|")
    for direction in ("forward", "backward"):
        for x0 in positions:
            mpc = critical_push(params, "flywheel", "mpc", x0, direction, tolerance=tolerance)
            bang = critical_push(
                params, "flywheel", "bang-bang", x0, direction, tolerance=tolerance
            )
            print(
                f"| {direction} | {x0:+.3f} | {mpc.velocity:+.5f} | {bang.velocity:+.5f} | "
                f"{mpc.predicted_velocity:+.5f} | {mpc.relative_error():+.3%} |"
            )

    print("\n### Variants, from x0 = 0: what closes the gap\n")
    print("| MPC variant | forward error | backward error |")
    print("|---|---|---|")
    variants = list(VARIANTS.items())[: 2 if args.quick else None]
    for label, options in variants:
        errors = [
            critical_push(
                params, "flywheel", "mpc", 0.0, d, tolerance=tolerance, controller_options=options
            ).relative_error()
            for d in ("forward", "backward")
        ]
        print(f"| {label} | {errors[0]:+.3%} | {errors[1]:+.3%} |")


if __name__ == "__main__":
    main()
