"""The critical push against a swept body parameter, simulated and analytic."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.plots.campaign.style import UNITS
from pushrecovery.plots.common import check_plot_path, save_figure

__all__ = [
    "plot_critical_vs_parameter",
]


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
    if not isinstance(summary, Mapping):
        raise ParameterTypeError(
            f"summary must be a campaign summary (a mapping), got {type(summary).__name__}"
        )
    import matplotlib

    path = check_plot_path(path)
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
