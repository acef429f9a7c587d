"""Plot of one simulated run: CoM and CoP over time, and the phase-plane path.

A run on the ground plane (``stepping-plane``) is drawn from above instead
(:func:`plane_run_figure`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from pushrecovery.arguments import require_type
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import (
    FALL_COLOUR,
    RECOVER_COLOUR,
    check_plot_path,
    frame_points,
    save_figure,
    shade_regions,
)
from pushrecovery.sim.result import SimulationResult
from pushrecovery.surfaces.cop import capture_point

__all__ = ["plane_run_figure", "save_run"]


def save_run(result: SimulationResult, params: BodyParams, path: Path) -> Path:
    """Write a two-panel plot of ``result`` to ``path`` (format from the extension)."""
    require_type("result", result, SimulationResult)
    require_type("params", params, BodyParams)
    path = check_plot_path(path)
    if result.states.shape[1] == 8:
        figure = plane_run_figure(result, params)
        return save_figure(figure, path.with_suffix(""), [path.suffix.lstrip(".")])[0]
    fig = Figure(figsize=(11, 4.2), layout="constrained")
    left, right = fig.subplots(1, 2)
    colour = RECOVER_COLOUR if result.recovered else FALL_COLOUR
    x, xdot = result.states[:, 0], result.states[:, result.states.shape[1] // 2]
    left.plot(result.time, x, color=colour, label="CoM x")
    left.step(result.time[:-1], result.cops, where="post", color="m", lw=1, label="CoP δ")
    for edge in (params.heel, params.toe):
        left.axhline(edge, color="0.5", lw=0.8, ls=":")
    left.set_xlabel("time [s]")
    left.set_ylabel("position relative to the ankle [m]")
    left.legend(loc="best")
    left.set_title(f"{result.model} + {result.controller}: {result.outcome.value}")
    span = max(abs(params.heel), params.toe)
    xlim = (min(x.min(), params.heel) - 0.5 * span, max(x.max(), params.toe) + 0.5 * span)
    vmax = max(abs(xdot).max(), params.omega * span) * 1.2
    shade_regions(right, params, xlim, (-vmax, vmax))
    right.plot(x, xdot, color=colour)
    right.plot(x[0], xdot[0], "o", color=colour)
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".")])[0]


def plane_run_figure(result: SimulationResult, params: BodyParams) -> Figure:
    """Top view of a run on the ground plane: feet, CoM, capture point and CoP paths [m].

    The feet are the two of the start (ankles at y = ±stance_width/2) and one at every
    landed foothold (``result.footholds_xy``), numbered in order; x forward, y left.
    """
    require_type("result", result, SimulationResult)
    require_type("params", params, BodyParams)
    from pushrecovery.ground.support import foot_shape

    states = result.states
    omega = params.omega
    figure = Figure(figsize=(7.5, 6.0), layout="constrained")
    ax = figure.add_subplot()
    foot = foot_shape(params)
    half = 0.5 * params.stance_width
    starts = [(0.0, half, foot), (0.0, -half, foot.mirrored())]
    landed = [(x, y, foot) for x, y in result.footholds_xy[1:]]
    for i, (x, y, shape) in enumerate(starts + landed):
        placed = shape.transformed(x, y, 0.0)
        first = i >= len(starts)
        ax.add_patch(
            Polygon(
                placed.vertices,
                closed=True,
                fc="0.85" if not first else "#bbdefb",
                ec="0.3",
                lw=0.8,
                label=("feet at the start" if i == 0 else "landed feet" if i == 2 else None),
            )
        )
        if first:
            ax.annotate(str(i - 1), (x, y), ha="center", va="center", fontsize=8)
    colour = RECOVER_COLOUR if result.recovered else FALL_COLOUR
    xi = capture_point(states[:, 0:2], states[:, 4:6], omega)
    ax.plot(states[:, 0], states[:, 1], color=colour, label="CoM")
    ax.plot(xi[:, 0], xi[:, 1], color=colour, ls="--", lw=1, label="capture point")
    # Points, not a line: the CoP jumps from foot to foot.
    ax.plot(result.inputs[:, 0], result.inputs[:, 1], "m.", ms=3, label="CoP")
    ax.plot(states[0, 0], states[0, 1], "o", color=colour)
    frame_points(ax, np.vstack([states[:, 0:2], np.array(result.footholds_xy)]), 0.2)
    ax.set_xlabel("x, forward [m]")
    ax.set_ylabel("y, left [m]")
    steps = len(result.footholds_xy) - 1
    ax.set_title(
        f"{result.model} + {result.controller}: {result.outcome.value} after {steps} "
        f"step{'s' if steps != 1 else ''}"
    )
    ax.legend(loc="best", fontsize=8)
    return figure
