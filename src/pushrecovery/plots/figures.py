"""Drawings of the paper's figures: Fig. 3 (Sec. II), 5 and 6 (Sec. III), 9 and 10 (Sec. IV).

The runs they show are simulated by :mod:`pushrecovery.experiments.paper_figures`, which also
writes them all; these functions only draw. Besides the paper's, ``plane``: the capture-point
plane of the ground-plane model (:mod:`pushrecovery.plots.plane`), and ``steps``.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.errors import ParameterTypeError
from pushrecovery.experiments.paper_figures import PaperRuns
from pushrecovery.models.flywheel import max_spin_up_time
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import (
    FALL_COLOUR,
    HIP_COLOUR,
    RECOVER_COLOUR,
    figure_outputs,
    new_figure,
    save_figure,
    shade_regions,
)
from pushrecovery.sim.result import SimulationResult
from pushrecovery.surfaces.cmp import cmp_region

__all__ = [
    "PAPER_FIGURES",
    "fig3a",
    "fig3b",
    "fig5",
    "fig6",
    "fig9",
    "fig10",
    "plane",
    "steps",
    "write_figures",
]

#: File stems of the paper's figures (``write_figures`` adds ``plane``).
PAPER_FIGURES = ("fig3a", "fig3b", "fig5a", "fig5b", "fig6a", "fig6b", "fig9", "fig10")


def fig3a(
    params: BodyParams, runs: Iterable[SimulationResult], formats: Iterable[str], out: Path
) -> list[Path]:
    """Fig. 3(a): open-loop saturated ankle torque on the LIPM from upright, pushed."""
    formats, out, runs = figure_outputs(params, formats, out, runs)
    title = "Fig. 3(a): saturated ankle torque, LIPM (green recovers, red falls)"
    return _phase(params, runs, title, out / "fig3a", formats, hip=False)


def fig3b(
    params: BodyParams, runs: Iterable[SimulationResult], formats: Iterable[str], out: Path
) -> list[Path]:
    """Fig. 3(b): saturated PD ankle control of the nonlinear pendulum from many states."""
    formats, out, runs = figure_outputs(params, formats, out, runs)
    title = (
        "Fig. 3(b): saturated PD ankle control, nonlinear pendulum\n"
        "(pushes 15 % inside / outside Eq. (4); falls drawn until certain)"
    )
    return _phase(params, runs, title, out / "fig3b", formats, hip=False, fontsize=10)


def write_figures(
    params: BodyParams,
    runs: PaperRuns,
    out: Path,
    formats: Iterable[str] = ("png", "svg"),
    *,
    ground_plane: bool = True,
    progress: Callable[[int], None] | None = None,
) -> list[Path]:
    """Draw every reproduced figure into ``out`` from ``runs``; return the files written.

    The paper's figures (:data:`PAPER_FIGURES`), the runs from
    :func:`~pushrecovery.experiments.paper_figures.paper_runs`, and, with ``ground_plane``,
    ``plane`` and the step figures. ``progress`` is called with 1 after each of them
    (:data:`FIGURE_COUNT` in all, a progress bar's ``update``).
    """
    formats, out, _ = figure_outputs(params, formats, out)
    require_type("runs", runs, PaperRuns)
    if progress is not None and not callable(progress):
        raise ParameterTypeError(f"progress must be callable, got {type(progress).__name__}")
    drawers: list[Callable[[], list[Path]]] = [
        lambda: fig3a(params, runs.fig3a, formats, out),
        lambda: fig3b(params, runs.fig3b, formats, out),
        lambda: fig5(params, runs.fig5, runs.fig5_worst, formats, out),
        lambda: fig6(params, runs.fig6, formats, out),
        lambda: fig9(params, formats, out),
        lambda: fig10(params, formats, out),
    ]
    if ground_plane:
        drawers += [lambda: plane(params, formats, out), lambda: steps(params, formats, out)]
    files: list[Path] = []
    for draw in drawers:
        files += draw()
        if progress is not None:
            progress(1)
    return files


#: Figures :func:`write_figures` draws with the ground plane (its progress steps).
FIGURE_COUNT = 8


def steps(params: BodyParams, formats: Iterable[str], out: Path) -> list[Path]:
    """Draw the capture regions of a few pushes and the N-step strategy map (``steps-*``).

    :func:`~pushrecovery.plots.steps.capture_regions_figure` and
    :func:`~pushrecovery.plots.steps.n_step_map_figure`.
    """
    formats, out, _ = figure_outputs(params, formats, out)
    from pushrecovery.plots.steps import capture_regions_figure, n_step_map_figure

    formats = tuple(formats)
    return [
        *save_figure(capture_regions_figure(params), out / "steps-regions", formats),
        *save_figure(n_step_map_figure(params), out / "steps-map", formats),
    ]


def plane(params: BodyParams, formats: Iterable[str], out: Path) -> list[Path]:
    """Draw the capture-point plane in double, left and right support (``plane``).

    Per stance: the feet, the support polygon (ankle), the CMP region (hip) and pushes from a
    CoM at rest above the stance's reference point, at their capture point and coloured by the
    strategy they need (:func:`~pushrecovery.plots.plane.capture_plane_panels`).
    """
    formats, out, _ = figure_outputs(params, formats, out)
    from pushrecovery.plots.plane import capture_plane_panels

    return save_figure(capture_plane_panels(params), out / "plane", formats)


def _phase(
    params: BodyParams,
    runs: Iterable[SimulationResult],
    title: str,
    stem: Path,
    formats: Iterable[str],
    *,
    hip: bool = True,
    **title_style: Any,
) -> list[Path]:
    """Phase paths (x, ẋ) of runs, green recovered, red fell, over the shaded regions.

    ``hip``: the flywheel model's runs (ẋ its state's third entry) over the CMP region, with
    a legend; else the ankle models' (ẋ the second) over the CoP region.
    """
    fig, ax = new_figure()
    span = params.toe - params.heel
    if hip:
        xlim = (params.heel - span, params.toe + span)
        vmax = params.omega * (cmp_region(params).upper - params.heel) * 1.1
        ylim = (-0.5 * vmax, vmax)
    else:
        xlim = (params.heel - 0.5 * span, params.toe + 0.5 * span)
        vmax = params.omega * span * 1.3
        ylim = (-vmax, vmax)
    shade_regions(ax, params, xlim, ylim, hip=hip)
    speed = 2 if hip else 1
    for run in runs:
        colour = RECOVER_COLOUR if run.recovered else FALL_COLOUR
        ax.plot(run.states[:, 0], run.states[:, speed], color=colour, lw=1.2)
        ax.plot(run.states[0, 0], run.states[0, speed], "o", color=colour, ms=3)
    if hip:
        ax.legend(loc="lower left", fontsize=8)
    ax.set_title(title, **title_style)
    return save_figure(fig, stem, formats)


def _time_panels(
    params: BodyParams,
    runs: list[SimulationResult],
    title: str,
    stem: Path,
    formats: tuple[str, ...],
    mark: float | None = None,
) -> list[Path]:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 7.5), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    labels = (
        "flywheel angle θ [rad]",
        "flywheel rate θ̇ [rad/s]",
        "hip torque τ [N m]",
        "CoM x [m]",
    )
    for run, colour in zip(runs, (RECOVER_COLOUR, HIP_COLOUR, FALL_COLOUR), strict=False):
        t = run.time
        axes[0].plot(t, run.states[:, 1], color=colour)
        axes[1].plot(t, run.states[:, 3], color=colour)
        axes[2].step(t[:-1], run.torques, where="post", color=colour)
        axes[3].plot(
            t,
            run.states[:, 0],
            color=colour,
            label=f"push {run.states[0, 2]:.2f} m/s: {run.outcome.value}",
        )
    for ax, label in zip(axes, labels, strict=True):
        ax.set_ylabel(label, fontsize=8)
        if mark is not None:
            ax.axvline(mark, color="0.3", ls="--", lw=0.8)
    for limit in (params.flywheel_angle_max, -params.flywheel_angle_max):
        axes[0].axhline(limit, color="0.5", ls=":", lw=0.8)
    axes[3].legend(fontsize=8)
    axes[3].set_xlabel("time [s]")
    axes[0].set_title(title, fontsize=10)
    return save_figure(fig, stem, formats)


def fig5(
    params: BodyParams,
    runs: list[SimulationResult],
    worst: list[SimulationResult],
    formats: Iterable[str],
    out: Path,
) -> list[Path]:
    """Fig. 5: bang-bang flywheel control: (a) ``runs`` in the phase plane, (b) ``worst`` in time.

    ``worst`` switches at T = T_max.
    """
    formats, out, runs = figure_outputs(params, formats, out, runs)
    _, _, worst = figure_outputs(params, formats, out, worst)
    formats = tuple(formats)
    files = _phase(
        params,
        runs,
        "Fig. 5(a): bang-bang hip torque + saturated ankle\n(orange band: corrected Eq. (15))",
        out / "fig5a",
        formats,
        fontsize=10,
    )
    spin_up = max_spin_up_time(params)
    files += _time_panels(
        params,
        worst,
        f"Fig. 5(b): bang-bang with T = T_max = {spin_up:.3f} s (dashed)",
        out / "fig5b",
        formats,
        mark=spin_up,
    )
    return files


def fig6(
    params: BodyParams, runs: list[SimulationResult], formats: Iterable[str], out: Path
) -> list[Path]:
    """Fig. 6: receding-horizon control (Eqs. 16-17). (a) phase plot; (b) time plots.

    ``runs``: pushes at 0.3, 0.6, 0.85, 0.99 and 1.05 of the hip's critical push.
    """
    formats, out, runs = figure_outputs(params, formats, out, runs)
    formats = tuple(formats)
    files = _phase(
        params,
        runs,
        "Fig. 6(a): receding-horizon control, paper's weights\n(orange band: corrected Eq. (15))",
        out / "fig6a",
        formats,
        fontsize=10,
    )
    small_large = [runs[0], runs[3], runs[4]]
    files += _time_panels(
        params,
        small_large,
        "Fig. 6(b): MPC, 1 s horizon; small, large and too-large push",
        out / "fig6b",
        formats,
    )
    return files


def fig9(params: BodyParams, formats: Iterable[str], out: Path) -> list[Path]:
    """Fig. 9: the stance pendulum, the coordinate jump to the new foot, and the impact.

    Velocities are divided by ω(z) = sqrt(g / z) of the current CoM height (the paper scales
    by √z), so every height shares the capture-point line ẋ/ω = −x of Eq. (21).
    """
    formats, out, _ = figure_outputs(params, formats, out)
    from pushrecovery.models.stepping import step_solution

    length, gravity = params.leg_length, params.gravity
    speeds = np.array([0.6, 0.9, 1.2, 1.5, 1.8])
    sol = step_solution(speeds, length, gravity, params.heel, params.toe)
    fig, ax = new_figure()
    xs = np.linspace(-0.6, 0.6, 200)
    ax.fill_between(
        xs,
        params.heel - xs,
        params.toe - xs,
        color=RECOVER_COLOUR,
        alpha=0.15,
        lw=0,
        label="new foot's CoP region, Eq. (4)",
    )
    ax.plot(xs, -xs, "k--", lw=1.0, label="Eq. (21): capture point on the new ankle")
    for i, v0 in enumerate(speeds):
        theta = np.linspace(0.0, sol.theta[i], 100)
        rate = np.sqrt((v0 / length) ** 2 + 2 * gravity / length * (1 - np.cos(theta)))
        z = length * np.cos(theta)
        scaled = length * np.cos(theta) * rate / np.sqrt(gravity / z)
        ax.plot(length * np.sin(theta), scaled, color=HIP_COLOUR, lw=1.2)
        x_hit = length * np.sin(sol.theta[i])
        before, after = scaled[-1], sol.velocity_after[i] / np.sqrt(gravity / z[-1])
        ax.plot([x_hit, -x_hit], [before, before], ":", color="0.4", lw=1.0)
        ax.plot([-x_hit, -x_hit], [before, after], color=FALL_COLOUR, lw=1.2)
        ax.plot(-x_hit, after, "o", color=RECOVER_COLOUR, ms=4)
    ax.set_xlim(-0.6, 0.6)
    ax.set_ylim(-0.2, 0.8)
    ax.set_xlabel("CoM x relative to the stance ankle [m] (new ankle after the step)")
    ax.set_ylabel("ẋ / ω(z) [m]  (ω(z) = sqrt(g / z))")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(
        "Fig. 9: falling (orange), re-referencing to the new foot (dotted),\n"
        "impact (red) onto Eq. (21)",
        fontsize=10,
    )
    return save_figure(fig, out / "fig9", formats)


def fig10(params: BodyParams, formats: Iterable[str], out: Path) -> list[Path]:
    """Fig. 10: optimal step length vs initial CoM velocity, with the admissible range."""
    formats, out, _ = figure_outputs(params, formats, out)
    from pushrecovery.models.stepping import step_solution
    from pushrecovery.surfaces.step import step_thresholds

    sol = step_solution(
        np.linspace(0.1, 3.0, 30), params.leg_length, params.gravity, params.heel, params.toe
    )
    fig, ax = new_figure()
    omega = params.omega
    edges = [0.0, omega * params.toe, omega * cmp_region(params).upper, step_thresholds(params)[1]]
    names = ("ankle", "hip", "step")
    for (start, stop), colour, name in zip(
        itertools.pairwise(edges),
        (RECOVER_COLOUR, HIP_COLOUR, "#1565c0"),
        names,
        strict=True,
    ):
        ax.axvspan(start, stop, color=colour, alpha=0.12, lw=0, label=name)
    ax.axvspan(edges[-1], 3.1, color=FALL_COLOUR, alpha=0.12, lw=0, label="fall")
    low = sol.step_length_of(sol.theta_low)
    high = sol.step_length_of(sol.theta_high)
    ok = sol.stance_leg_in_compression
    ax.errorbar(
        sol.v0,
        sol.step_length,
        yerr=[sol.step_length - low, high - sol.step_length],
        fmt="none",
        ecolor="0.3",
        capsize=2,
        lw=0.8,
    )
    ax.plot(sol.v0[ok], sol.step_length[ok], "o", color="k", ms=4, label="Eq. (21) step")
    ax.plot(
        sol.v0[~ok],
        sol.step_length[~ok],
        "o",
        mfc="none",
        color="k",
        ms=4,
        label="stance leg would pull",
    )
    ax.axhline(params.max_step_length, color="0.3", ls="--", lw=0.8, label="max step length")
    ax.set_xlim(0.0, 3.1)
    ax.set_xlabel("initial CoM velocity v0 [m/s] (CoM above the stance ankle)")
    ax.set_ylabel("step length, foot to foot [m]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("Fig. 10: optimal step vs push; bars: steps that land inside Eq. (4)", fontsize=10)
    return save_figure(fig, out / "fig10", formats)
