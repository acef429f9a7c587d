"""Plot of one simulated run: CoM and CoP over time, and the phase-plane path."""

from __future__ import annotations

from pathlib import Path

from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import FALL_COLOUR, RECOVER_COLOUR, save_figure, shade_regions
from pushrecovery.sim.result import SimulationResult

__all__ = ["save_run"]

_FORMATS = {".png", ".svg", ".pdf"}


def save_run(result: SimulationResult, params: BodyParams, path: Path) -> Path:
    """Write a two-panel plot of ``result`` to ``path`` (format from the extension)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if path.suffix.lower() not in _FORMATS:
        raise InvalidParameterError(
            f"plot must end in one of {sorted(_FORMATS)}, got {path.name!r}"
        )
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
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
