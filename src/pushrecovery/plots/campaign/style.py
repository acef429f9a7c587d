"""What every campaign figure shares: strategy colours, units, the decision boundaries."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import UNITS as PARAMS_UNITS
from pushrecovery.params import BodyParams
from pushrecovery.plots.common import FALL_COLOUR, HIP_COLOUR, RECOVER_COLOUR
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region

if TYPE_CHECKING:
    from matplotlib.axes import Axes


__all__ = [
    "MAX_PANELS",
    "STEP_COLOUR",
    "STEP_LIMIT_POINTS",
    "STRATEGY_COLOURS",
    "UNITS",
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
UNITS: Mapping[str, str] = {name: unit.replace("^2", "²") for name, unit in PARAMS_UNITS.items()}


#: At most this many panels (swept values) in an outcome map.
MAX_PANELS = 4


#: Points along x0 at which the single-step limit is evaluated (a bisection each).
STEP_LIMIT_POINTS = 15


_FELL_COLOUR = "0.45"


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

    if not isinstance(direction, str) or direction not in ("forward", "backward"):
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
    from pushrecovery.surfaces.step.regions import sagittal_step_interval

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
