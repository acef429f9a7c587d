"""Plots of a push campaign: the outcome map over the swept plane, critical push vs a parameter.

The outcome map draws one marker per push at (x0, ẋ), coloured by the strategy the run used,
over the analytic boundaries: the capture-point lines x0 + ẋ/ω = edge of the CoP region (Eq. 4)
and of the CMP region (corrected Eq. 15), and the single-step limit of Sec. IV.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import FALL_COLOUR, HIP_COLOUR, RECOVER_COLOUR, save_figure
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from pushrecovery.campaign.spec import CampaignSpec

__all__ = [
    "STEP_COLOUR",
    "STRATEGY_COLOURS",
    "UNITS",
    "plot_critical_vs_parameter",
    "plot_outcome_map",
    "plot_strategy_map",
    "step_limit_curve",
]

STEP_COLOUR = "#1565c0"
#: Colour of each strategy (ankle, hip, step) and of falls, shared with the strategy map.
STRATEGY_COLOURS: Mapping[str, str] = {
    "ankle": RECOVER_COLOUR,
    "hip": HIP_COLOUR,
    "step": STEP_COLOUR,
    "fall": FALL_COLOUR,
}
#: SI unit of each body parameter, for axis labels.
UNITS: Mapping[str, str] = {
    "mass": "kg",
    "com_height": "m",
    "gravity": "m/s²",
    "heel": "m",
    "toe": "m",
    "flywheel_inertia": "kg m²",
    "torque_max": "N m",
    "flywheel_angle_max": "rad",
    "leg_length": "m",
    "max_step_length": "m",
}
#: At most this many panels (swept values) in an outcome map.
MAX_PANELS = 4
#: Points along x0 at which the single-step limit is evaluated (a bisection each).
STEP_LIMIT_POINTS = 15
_FELL_COLOUR = "0.45"
_FORMATS = {".png", ".svg", ".pdf"}


def _check_path(path: Path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in _FORMATS:
        raise InvalidParameterError(
            f"plot must end in one of {sorted(_FORMATS)}, got {path.name!r}"
        )
    return path


def step_limit_curve(
    params: BodyParams,
    x0s: Sequence[float] | np.ndarray,
    direction: str,
    *,
    resolution: float = 2e-3,
) -> np.ndarray:
    """Single-step limit (Sec. IV) at each start ``x0s`` [m], signed like ẋ [m/s].

    The largest push of a grid of step ``resolution`` [m/s] on [0, sqrt(g L)] that one step
    recovers (:func:`~pushrecovery.surfaces.step.plan_steps`, all starts at once): the value
    of :func:`~pushrecovery.sim.critical.predicted_critical_velocity` ``(params, "step", x0,
    direction)`` within ``resolution``, about a hundred times faster than its bisection per
    start. NaN where no step recovers.
    """
    from pushrecovery.surfaces.step import plan_steps

    if direction not in ("forward", "backward"):
        raise InvalidParameterError(f"direction must be forward or backward, got {direction!r}")
    sign = 1.0 if direction == "forward" else -1.0
    top = float(np.sqrt(params.gravity * params.leg_length))
    speeds = np.arange(resolution, top + resolution, resolution)
    starts = np.asarray(x0s, dtype=float).reshape(-1, 1)
    feasible = plan_steps(starts, sign * speeds[np.newaxis, :], params).feasible
    last = speeds.size - 1 - np.argmax(feasible[:, ::-1], axis=1)
    limits = np.where(feasible.any(axis=1), sign * speeds[last], np.nan)
    return np.asarray(limits, dtype=float)


def _draw_boundaries(
    ax: Axes, params: BodyParams, xlim: tuple[float, float], vmax: float, *, legend: bool
) -> None:
    """Capture-point lines of Eq. (4), corrected Eq. (15) and N steps; Sec. IV's step limit."""
    omega = params.omega
    xs = np.linspace(*xlim, 50)
    from pushrecovery.surfaces.step_regions import sagittal_step_interval

    for region, colour, label in (
        (cop_region(params), RECOVER_COLOUR, "CoP region edge, Eq. (4)"),
        (cmp_region(params), HIP_COLOUR, "CMP region edge, corrected Eq. (15)"),
        (
            sagittal_step_interval(params),
            STEP_COLOUR,
            f"edge of {params.max_steps} steps (docs/steps.md)",
        ),
    ):
        for k, edge in enumerate((region.lower, region.upper)):
            ax.plot(
                xs,
                omega * (edge - xs),
                color=colour,
                lw=1.2,
                ls="--",
                label=label if legend and k == 0 else None,
            )
    # The step limit is defined for starts on the foot only; drawn when it is in view.
    lo, hi = max(xlim[0], params.heel + 1e-6), min(xlim[1], params.toe - 1e-6)
    if hi > lo:
        x0s = np.linspace(lo, hi, STEP_LIMIT_POINTS)
        curves = [step_limit_curve(params, x0s, d) for d in ("forward", "backward")]
        visible = [c for c in curves if np.any(np.abs(c) <= vmax)]
        for k, curve in enumerate(visible):
            ax.plot(
                x0s,
                curve,
                color=STEP_COLOUR,
                lw=1.2,
                ls="-.",
                label="Sec. IV's single step (recovery controller)" if legend and k == 0 else None,
            )
    for edge in (params.heel, params.toe):
        ax.axvline(edge, color="0.6", lw=0.8, ls=":")


def _columns(table: Any) -> dict[str, np.ndarray]:
    return {name: table.column(name).to_numpy(zero_copy_only=False) for name in table.column_names}


def _panels(spec: CampaignSpec, columns: dict[str, np.ndarray]) -> list[tuple[str, Any, Any]]:
    """(title, row mask, body) per panel: one per swept value, at most ``MAX_PANELS``."""
    n = len(columns["x0"])
    if not spec.sweeps:
        return [("", np.ones(n, dtype=bool), spec.params)]
    names = list(spec.sweeps)
    swept = np.column_stack([columns[f"param_{name}"] for name in names]) if n else None
    if swept is None:
        return [("", np.ones(0, dtype=bool), spec.params)]
    if spec.samples is None:
        combos = np.unique(swept, axis=0)
        picked = combos[np.unique(np.linspace(0, len(combos) - 1, MAX_PANELS).round().astype(int))]
        panels = []
        for combo in picked:
            mask = np.all(swept == combo, axis=1)
            title = ", ".join(
                f"{name} = {v:g} {UNITS.get(name, '')}"
                for name, v in zip(names, combo, strict=True)
            )
            panels.append((title, mask, spec.body(tuple(float(v) for v in combo))))
        return panels
    # Random samples: bins of the first swept parameter, each drawn with its median body.
    first = swept[:, 0]
    edges = np.quantile(first, np.linspace(0.0, 1.0, MAX_PANELS + 1))
    panels = []
    for k in range(MAX_PANELS):
        upper = first <= edges[k + 1] if k == MAX_PANELS - 1 else first < edges[k + 1]
        mask = (first >= edges[k]) & upper
        if not mask.any():
            continue
        median = tuple(float(v) for v in np.median(swept[mask], axis=0))
        title = f"{names[0]} in [{edges[k]:.3g}, {edges[k + 1]:.3g}] {UNITS.get(names[0], '')}"
        panels.append((title, mask, spec.body(median)))
    return panels


def plot_outcome_map(table: Any, spec: CampaignSpec, path: Path) -> Path:
    """Draw the outcome of every push over the (x0, ẋ) plane with the analytic boundaries.

    One marker per push at (x0 [m], ẋ [m/s]), coloured by the strategy the run used (column
    ``used``: ankle green, hip orange, step blue); falls (and undecided runs) are grey crosses.
    A black ring marks a push where the surfaces' verdict (``predicted_recovers``) disagrees
    with the outcome. The dashed lines are the capture-point boundaries x0 + ẋ/ω = edge of
    the CoP region (Eq. 4) and of the CMP region (corrected Eq. 15); dash-dotted, the
    single-step limit (Sec. IV).
    With swept body parameters, one panel per swept value (at most four, evenly picked), each
    with the boundaries of its own body; a random campaign (``spec.samples``) is split into
    four quantile bins of its first swept parameter, each drawn with the bin's median body.

    Parameters
    ----------
    table : pyarrow.Table
        The campaign's pushes (:mod:`pushrecovery.campaign.pushes` columns).
    spec : CampaignSpec
        The campaign that produced ``table``.
    path : Path
        Output file; the format (PNG, SVG or PDF) from its extension.

    Returns
    -------
    Path
        The file written.
    """
    path = _check_path(path)
    columns = _columns(table)
    panels = _panels(spec, columns)
    from matplotlib.figure import Figure

    fig = Figure(
        figsize=(6.4 if len(panels) == 1 else 4.4 * len(panels), 4.8), layout="constrained"
    )
    axes = fig.subplots(
        1,
        len(panels),
        sharey=True,
        squeeze=False,
    )
    x0, xdot = columns["x0"], columns["xdot"]
    used, outcome = columns["used"], columns["outcome"]
    recovered = outcome == "recovered"
    disagree = columns["predicted_recovers"] != recovered if len(x0) else np.zeros(0, bool)
    vmax = max(float(np.abs(xdot).max()) if len(xdot) else 0.0, 0.5) * 1.1
    for k, (ax, (title, mask, body)) in enumerate(zip(axes[0], panels, strict=True)):
        xs = x0[mask] if len(x0) else x0
        # Smaller markers where a start holds many pushes (about 40 fit a column).
        per_start = len(xs) / max(len(np.unique(xs)), 1)
        size = float(np.clip(22.0 * 40.0 / max(per_start, 1.0), 4.0, 22.0))
        low = min(body.heel, float(xs.min()) if len(xs) else body.heel)
        high = max(body.toe, float(xs.max()) if len(xs) else body.toe)
        pad = 0.08 * (high - low)
        xlim = (low - pad, high + pad)
        _draw_boundaries(ax, body, xlim, vmax, legend=k == 0)
        for name in ("ankle", "hip", "step"):
            pick = mask & (used == name) & recovered
            if pick.any():
                ax.scatter(
                    x0[pick],
                    xdot[pick],
                    s=size,
                    color=STRATEGY_COLOURS[name],
                    label=f"used {name}" if k == 0 else None,
                    zorder=3,
                )
        pick = mask & ~recovered
        if pick.any():
            ax.scatter(
                x0[pick],
                xdot[pick],
                s=1.2 * size,
                marker="x",
                color=_FELL_COLOUR,
                label="fell or undecided" if k == 0 else None,
                zorder=3,
            )
        pick = mask & disagree
        if pick.any():
            ax.scatter(
                x0[pick],
                xdot[pick],
                s=3.6 * size,
                facecolors="none",
                edgecolors="black",
                lw=0.9,
                label="verdict ≠ outcome" if k == 0 else None,
                zorder=4,
            )
        ax.set_xlim(*xlim)
        ax.set_ylim(-vmax, vmax)
        ax.set_xlabel("CoM position before the push x0 [m]")
        if title:
            ax.set_title(title, fontsize=10)
    axes[0][0].set_ylabel("push ẋ = J/m [m/s]")
    fig.suptitle(f"{spec.backend}: {spec.model} + {spec.controller}, {len(x0)} pushes", fontsize=11)
    axes[0][0].legend(loc="upper right", fontsize=7, framealpha=0.85)
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".").lower()])[0]


def plot_strategy_map(params: BodyParams, path: Path, *, xdot_max: float | None = None) -> Path:
    """Colour the (x, ẋ) plane by the strategy the paper's surfaces give each CoM state.

    :func:`~pushrecovery.surfaces.classify.classify_states`: ankle where the capture point lies
    in the CoP region (Eq. 4), hip in the CMP region (corrected Eq. 15), step where at most
    ``max_steps`` steps capture it (docs/steps.md), fall elsewhere; the boundaries drawn as
    in :func:`plot_outcome_map`.

    Parameters
    ----------
    params : BodyParams
        The body.
    path : Path
        Output file; the format (PNG, SVG or PDF) from its extension.
    xdot_max : float, optional
        Half-height of the plane [m/s]; default 1.25 times the largest N-step limit.

    Returns
    -------
    Path
        The file written.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from pushrecovery.surfaces.classify import STRATEGY_CODES, classify_states
    from pushrecovery.surfaces.step_regions import sagittal_step_interval

    path = _check_path(path)
    if xdot_max is None:
        interval = sagittal_step_interval(params)
        xdot_max = 1.25 * params.omega * max(abs(interval.lower), abs(interval.upper))
    span = params.toe - params.heel
    xlim = (params.heel - 0.25 * span, params.toe + 0.25 * span)
    xs = np.linspace(*xlim, 400)
    vs = np.linspace(-xdot_max, xdot_max, 500)
    codes = classify_states(xs[np.newaxis, :], vs[:, np.newaxis], params)
    names = [str(code) for code in STRATEGY_CODES]
    cmap = ListedColormap([STRATEGY_COLOURS[name] for name in names])
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.2, 5.0), layout="constrained")
    ax = fig.add_subplot()
    ax.imshow(
        codes,
        origin="lower",
        extent=(xlim[0], xlim[1], -xdot_max, xdot_max),
        aspect="auto",
        cmap=cmap,
        vmin=-0.5,
        vmax=len(names) - 0.5,
        alpha=0.35,
        interpolation="nearest",
    )
    _draw_boundaries(ax, params, xlim, xdot_max, legend=True)
    handles, _ = ax.get_legend_handles_labels()
    patches = [Patch(color=STRATEGY_COLOURS[n], alpha=0.35, label=n) for n in names]
    ax.legend(handles=patches + handles, loc="upper right", fontsize=7, framealpha=0.85)
    ax.set_xlim(*xlim)
    ax.set_ylim(-xdot_max, xdot_max)
    ax.set_xlabel("CoM position x [m] (relative to the ankle)")
    ax.set_ylabel("CoM velocity ẋ [m/s]")
    ax.set_title("Strategy the surfaces give each CoM state", fontsize=10)
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".").lower()])[0]


def plot_critical_vs_parameter(summary: Mapping[str, Any], path: Path) -> Path:
    """Draw the empirical and analytic critical pushes against the one swept body parameter.

    For each direction (a panel each) and each start x0 (a colour each): the empirical critical
    push of the grid (``summary["boundary"]``: the midpoint of its bracket, drawn with the
    bracket as error bar; a triangle at the largest push tried when nothing in the grid fell)
    and the analytic one of the controller's surface (Eq. 4, corrected Eq. 15 or the
    single-step limit) as a line.

    Parameters
    ----------
    summary : mapping
        A campaign summary (:func:`pushrecovery.campaign.summarize`) of a grid campaign that
        sweeps exactly one body parameter.
    path : Path
        Output file; the format (PNG, SVG or PDF) from its extension.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    InvalidParameterError
        If the campaign does not sweep exactly one parameter or has no boundary rows.
    """
    import matplotlib

    path = _check_path(path)
    sweeps = [name for name, _ in summary["spec"]["sweeps"]]
    if len(sweeps) != 1:
        raise InvalidParameterError(
            f"the critical push vs a parameter needs a campaign sweeping one parameter, "
            f"got {len(sweeps)} ({', '.join(sweeps) or 'none'})"
        )
    name = sweeps[0]
    rows = summary["boundary"]
    if not rows:
        raise InvalidParameterError("the summary has no boundary rows (a random campaign?)")
    directions = [d for d in ("forward", "backward") if any(r["direction"] == d for r in rows)]
    x0s = sorted({float(r["x0"]) for r in rows})
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.2 * len(directions), 4.2), layout="constrained")
    axes = fig.subplots(1, len(directions), squeeze=False)
    cmap = matplotlib.colormaps["viridis"]
    strategy = rows[0].get("strategy", "")
    for ax, direction in zip(axes[0], directions, strict=True):
        for k, x0 in enumerate(x0s):
            colour = cmap(k / max(len(x0s) - 1, 1)) if len(x0s) > 1 else "black"
            mine = sorted(
                (r for r in rows if r["direction"] == direction and float(r["x0"]) == x0),
                key=lambda r: float(r[name]),
            )
            values = np.array([float(r[name]) for r in mine])
            analytic = np.array([np.nan if r["analytic"] is None else r["analytic"] for r in mine])
            suffix = f", x0 = {x0:g} m" if len(x0s) > 1 else ""
            ax.plot(values, analytic, color=colour, lw=1.2, ls="--", label=f"analytic{suffix}")
            found = [r for r in mine if r["empirical"] is not None]
            if found:
                emp = np.array([float(r["empirical"]) for r in found])
                half = np.array([abs(r["bracket"][1] - r["bracket"][0]) / 2 for r in found])
                ax.errorbar(
                    [float(r[name]) for r in found],
                    emp,
                    yerr=half,
                    fmt="o",
                    color=colour,
                    ms=4,
                    capsize=3,
                    label=f"simulated{suffix}",
                )
            open_ended = [r for r in mine if r["empirical"] is None and r["bracket"][0] is not None]
            if open_ended:
                ax.plot(
                    [float(r[name]) for r in open_ended],
                    [float(r["bracket"][0]) for r in open_ended],
                    "^" if direction == "forward" else "v",
                    color=colour,
                    ms=6,
                    label=f"recovered every push tried{suffix}",
                )
        ax.set_xlabel(f"{name} [{UNITS.get(name, '')}]")
        ax.set_ylabel(f"critical push ẋ, {direction} [m/s]")
        ax.set_title(f"{direction} ({strategy} surface)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=7)
    return save_figure(fig, path.with_suffix(""), [path.suffix.lstrip(".").lower()])[0]
