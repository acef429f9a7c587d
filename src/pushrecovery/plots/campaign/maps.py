"""A campaign's outcome map and a body's strategy map in the (x0, push) plane."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.errors import ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import check_plot_path, save_figure

if TYPE_CHECKING:
    from pushrecovery.campaign.spec import CampaignSpec
from pushrecovery.plots.campaign.style import (
    _FELL_COLOUR,
    MAX_PANELS,
    STRATEGY_COLOURS,
    UNITS,
    _columns,
    _draw_boundaries,
)

__all__ = [
    "plot_outcome_map",
    "plot_strategy_map",
]


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
    from pushrecovery.campaign.spec import CampaignSpec

    require_type("spec", spec, CampaignSpec)
    if not hasattr(table, "column_names"):
        raise ParameterTypeError(
            f"table must be a campaign's pyarrow table, got {type(table).__name__}"
        )
    path = check_plot_path(path)
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
        layers: list[tuple[Any, str, dict[str, Any]]] = [
            (mask & (used == name) & recovered, f"used {name}",
             {"s": size, "color": STRATEGY_COLOURS[name], "zorder": 3})
            for name in ("ankle", "hip", "step")
        ]  # fmt: skip
        layers += [
            (mask & ~recovered, "fell or undecided",
             {"s": 1.2 * size, "marker": "x", "color": _FELL_COLOUR, "zorder": 3}),
            (mask & disagree, "verdict ≠ outcome",
             {"s": 3.6 * size, "facecolors": "none", "edgecolors": "black", "lw": 0.9,
              "zorder": 4}),
        ]  # fmt: skip
        for pick, label, style in layers:
            if pick.any():
                ax.scatter(x0[pick], xdot[pick], label=label if k == 0 else None, **style)
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
    require_type("params", params, BodyParams)
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from pushrecovery.surfaces.classify import STRATEGY_CODES, classify_states
    from pushrecovery.surfaces.step.regions import sagittal_step_interval

    path = check_plot_path(path)
    if xdot_max is not None:
        xdot_max = bounded_float("xdot_max", xdot_max, 1e-3, 100.0, "m/s")
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
