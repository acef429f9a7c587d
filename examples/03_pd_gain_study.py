"""How closely Eq. (4) predicts the critical push of a PD-controlled pendulum, per gain set.

Prints the Markdown tables of docs/ankle_pd.md. ``--quick`` uses a coarse grid (for tests).
"""

import argparse
import math

import numpy as np

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.models.pendulum import ankle_torque_for_cop, lean_from_com
from pushrecovery.sim.critical import NotRecoverableError, critical_push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate


def gain_sets(params):
    mgl = params.weight * params.com_height
    inertia = params.mass * params.com_height**2
    for stiffness_ratio in (1.25, 2.0, 3.0, 5.0, 10.0):
        kp = stiffness_ratio * mgl
        for zeta in (0.7, 1.0, 2.0):
            kd = 2 * zeta * math.sqrt((kp - mgl) * inertia)
            yield f"{stiffness_ratio:g} mgL, ζ={zeta:g}", kp, kd
        yield f"{stiffness_ratio:g} mgL, k_d=k_p/ω", kp, kp / params.omega


def sweep(params, model, kp, kd, positions, tolerance):
    rows = []
    for direction in ("forward", "backward"):
        for x in positions:
            try:
                found = critical_push(
                    params,
                    model,
                    "ankle-pd",
                    float(x),
                    direction,
                    tolerance=tolerance,
                    controller_options={"stiffness": kp, "damping": kd},
                )
                rows.append(
                    (direction, x, found.velocity, found.predicted_velocity, found.relative_error())
                )
            except NotRecoverableError:
                rows.append((direction, x, 0.0, float("nan"), -1.0))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    params = load_params()
    fractions = [0.05, 0.5, 0.95] if args.quick else [0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95]
    positions = params.heel + (params.toe - params.heel) * np.array(fractions)
    tolerance = 1e-3 if args.quick else 1e-5

    kp_default = 3.0 * params.weight * params.com_height
    print("### Default gains, pendulum: critical push per position\n")
    print("| direction | x0 [m] | pendulum [m/s] | Eq. (4) [m/s] | error |")
    print("|---|---|---|---|---|")
    for direction, x, v, predicted, error in sweep(
        params, "pendulum", kp_default, kp_default / params.omega, positions, tolerance
    ):
        print(f"| {direction} | {x:+.3f} | {v:+.5f} | {predicted:+.5f} | {error:+.2%} |")

    print("\n### Applied over commanded torque on the pendulum (errata E7)\n")
    plant, controller = make_plant("pendulum", params), make_controller("ankle-pd", params)
    ratios = []
    for _, x, v, _, _ in sweep(
        params, "pendulum", kp_default, kp_default / params.omega, positions, 1e-3
    ):
        run = simulate(plant, controller, np.array([x, 0.999 * v]))
        for (cx, cv), cop in zip(run.states[:-1], run.cops, strict=True):
            if cop != 0.0:
                lean, rate = lean_from_com(cx, cv, params.com_height)
                torque = ankle_torque_for_cop(
                    lean, rate, cop, params.mass, params.com_height, params.gravity
                )
                ratios.append(torque / (cop * params.weight))
    print(f"F_z / (m g) at 99.9 % of each critical push: {min(ratios):.3f} … {max(ratios):.3f}")

    print("\n### Worst error over the foot and both directions, per gain set\n")
    print(
        "| gains | k_p [N m/rad] | k_d [N m s/rad] | LIPM worst | pendulum worst | pendulum best |"
    )
    print("|---|---|---|---|---|---|")
    sets = list(gain_sets(params))
    for label, kp, kd in sets[:2] if args.quick else sets:
        lipm = [r[4] for r in sweep(params, "lipm", kp, kd, positions, tolerance)]
        pend = [r[4] for r in sweep(params, "pendulum", kp, kd, positions, tolerance)]
        print(
            f"| {label} | {kp:.0f} | {kd:.0f} | {min(lipm):+.2%} | {min(pend):+.2%} "
            f"| {max(pend):+.2%} |"
        )


if __name__ == "__main__":
    main()
