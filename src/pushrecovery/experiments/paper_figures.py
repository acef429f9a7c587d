"""The runs behind the paper's figures, and the whole set written to a folder.

The drawing is :mod:`pushrecovery.plots.figures`; here the pushes are chosen (relative to the
body's own thresholds, so the figures show the same story for any body) and simulated:
``write_figures(params, paper_runs(params), out)`` writes them all.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.control.base import make_controller
from pushrecovery.models.flywheel import max_spin_up_time
from pushrecovery.params import BodyParams
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.result import SimulationResult
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import critical_velocity

__all__ = [
    "HIP_FRACTIONS",
    "PaperRuns",
    "ankle_runs",
    "fig3a_starts",
    "fig3b_starts",
    "hip_runs",
    "paper_runs",
]

#: Fractions of the hip's critical push in Figs. 5(a) and 6.
HIP_FRACTIONS = (0.3, 0.6, 0.85, 0.99, 1.05)


def fig3a_starts(params: BodyParams) -> list[tuple[float, float]]:
    """Pushes from upright from 1.4× the backward to 1.4× the forward Eq. (4) limit [m, m/s]."""
    require_type("params", params, BodyParams)
    v_back, v_fwd = params.omega * params.heel, params.omega * params.toe
    return [(0.0, float(v)) for v in np.linspace(1.4 * v_back, 1.4 * v_fwd, 13)]


def fig3b_starts(params: BodyParams) -> list[tuple[float, float]]:
    """From three positions, pushes at 0.5, 0.85 and 1.15 of Eq. (4) both ways [m, m/s]."""
    require_type("params", params, BodyParams)
    return [
        (float(x0), float(fraction * critical_velocity(x0, direction, params)))
        for x0 in np.linspace(params.heel, params.toe, 5)[1:-1]
        for direction in (1.0, -1.0)
        for fraction in (0.5, 0.85, 1.15)
    ]


def ankle_runs(
    params: BodyParams, model: str, controller: str, starts: Iterable[tuple[float, float]]
) -> list[SimulationResult]:
    """Simulate ``controller`` on an ankle ``model`` from each (x0, ẋ0) for 4 s."""
    plant, ctrl = make_plant(model, params), make_controller(controller, params)
    return [simulate(plant, ctrl, plant.reset(x0, v0), duration=4.0) for x0, v0 in starts]


def hip_runs(
    params: BodyParams, controller: str, fractions: Iterable[float], **options: float
) -> list[SimulationResult]:
    """Pushes from upright at fractions of the hip strategy's forward critical velocity."""
    plant = make_plant("flywheel", params)
    ctrl = make_controller(controller, params, **options)
    limit = float(critical_velocity(0.0, 1.0, params, region=cmp_region(params)))
    return [simulate(plant, ctrl, plant.reset(0.0, f * limit), duration=4.0) for f in fractions]


@dataclass(frozen=True, slots=True)
class PaperRuns:
    """The simulated runs the paper's figures show.

    Attributes
    ----------
    fig3a, fig3b : list of SimulationResult
        Saturated ankle on the LIPM (:func:`fig3a_starts`), ankle PD on the pendulum
        (:func:`fig3b_starts`).
    fig5, fig5_worst : list of SimulationResult
        Bang-bang at :data:`HIP_FRACTIONS` of the hip's critical push; at 0.99 switching at
        T_max.
    fig6 : list of SimulationResult
        The MPC at :data:`HIP_FRACTIONS`.
    """

    fig3a: list[SimulationResult]
    fig3b: list[SimulationResult]
    fig5: list[SimulationResult]
    fig5_worst: list[SimulationResult]
    fig6: list[SimulationResult]


def paper_runs(params: BodyParams) -> PaperRuns:
    """Simulate every run of Figs. 3, 5 and 6 for ``params``."""
    require_type("params", params, BodyParams)
    return PaperRuns(
        fig3a=ankle_runs(params, "lipm", "ankle-saturated", fig3a_starts(params)),
        fig3b=ankle_runs(params, "pendulum", "ankle-pd", fig3b_starts(params)),
        fig5=hip_runs(params, "bang-bang", HIP_FRACTIONS),
        fig5_worst=hip_runs(params, "bang-bang", (0.99,), switch_time=max_spin_up_time(params)),
        fig6=hip_runs(params, "mpc", HIP_FRACTIONS),
    )
