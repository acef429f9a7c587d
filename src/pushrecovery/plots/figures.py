"""Reproductions of the paper's figures (Sec. II: Fig. 3a and 3b)."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from pushrecovery.control.base import make_controller
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import (
    FALL_COLOUR,
    RECOVER_COLOUR,
    new_figure,
    save_figure,
    shade_cop_region,
)
from pushrecovery.sim.plants import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.cop import critical_velocity

__all__ = ["fig3a", "fig3b", "write_figures"]


def _limits(params: BodyParams) -> tuple[tuple[float, float], tuple[float, float]]:
    span = params.toe - params.heel
    xlim = (params.heel - 0.5 * span, params.toe + 0.5 * span)
    vmax = params.omega * span * 1.3
    return xlim, (-vmax, vmax)


def _draw_runs(
    ax: object,
    params: BodyParams,
    model: str,
    controller: str,
    starts: Iterable[tuple[float, float]],
) -> None:
    plant, ctrl = make_plant(model, params), make_controller(controller, params)
    for x0, v0 in starts:
        run = simulate(plant, ctrl, np.array([x0, v0]), duration=4.0)
        colour = RECOVER_COLOUR if run.recovered else FALL_COLOUR
        ax.plot(run.states[:, 0], run.states[:, 1], color=colour, lw=1.2)  # type: ignore[attr-defined]
        ax.plot(x0, v0, "o", color=colour, ms=3)  # type: ignore[attr-defined]


def fig3a(params: BodyParams, formats: Iterable[str], out: Path) -> list[Path]:
    """Fig. 3(a): open-loop saturated ankle torque on the LIPM from upright, pushed."""
    fig, ax = new_figure()
    xlim, ylim = _limits(params)
    shade_cop_region(ax, params, xlim, ylim)
    # Pushes from upright spanning both boundaries: ẋ0 from 1.4x the backward to 1.4x the
    # forward critical velocity of Eq. (4).
    v_back, v_fwd = params.omega * params.heel, params.omega * params.toe
    _draw_runs(
        ax,
        params,
        "lipm",
        "ankle-saturated",
        [(0.0, v) for v in np.linspace(1.4 * v_back, 1.4 * v_fwd, 13)],
    )
    ax.set_title("Fig. 3(a): saturated ankle torque, LIPM (green recovers, red falls)")
    return save_figure(fig, out / "fig3a", formats)


def fig3b(params: BodyParams, formats: Iterable[str], out: Path) -> list[Path]:
    """Fig. 3(b): saturated PD ankle control of the nonlinear pendulum from many states."""
    fig, ax = new_figure()
    xlim, ylim = _limits(params)
    shade_cop_region(ax, params, xlim, ylim)
    # From three positions: pushes 15 % inside and outside Eq. (4) in both directions.
    starts = [
        (float(x0), float(fraction * critical_velocity(x0, direction, params)))
        for x0 in np.linspace(params.heel, params.toe, 5)[1:-1]
        for direction in (1.0, -1.0)
        for fraction in (0.5, 0.85, 1.15)
    ]
    _draw_runs(ax, params, "pendulum", "ankle-pd", starts)
    ax.set_title(
        "Fig. 3(b): saturated PD ankle control, nonlinear pendulum\n"
        "(pushes 15 % inside / outside Eq. (4); falls drawn until certain)",
        fontsize=10,
    )
    return save_figure(fig, out / "fig3b", formats)


def write_figures(
    params: BodyParams, out: Path, formats: Iterable[str] = ("png", "svg")
) -> list[Path]:
    """Write every reproduced figure into ``out``; return the files written."""
    formats = tuple(formats)
    return [*fig3a(params, formats, out), *fig3b(params, formats, out)]
