"""The polar plot of the 3-D validation: critical impulse against push azimuth, per strategy.

Radius: the critical impulse [N s]; angle: the push's azimuth ψ (0 forward +x, 90 left +y,
counter-clockwise, as seen from above). Per strategy (colour): the 2-D prediction m ω ρ_R
(solid line; for the step, the one-step capture region's), the prediction corrected for the
push's height (dashed), and the measured critical impulses (markers, with a bar to the lowest
impulse that fell). The lines close the circle only when the azimuths cover it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, cast

from pushrecovery.arguments import require_type
from pushrecovery.experiments.validation3d import CURVE_AZIMUTHS, Validation3D
from pushrecovery.experiments.validation3d.step import StepValidation
from pushrecovery.plots.common import HIP_COLOUR, RECOVER_COLOUR

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from matplotlib.projections.polar import PolarAxes

__all__ = ["STRATEGY_COLOURS", "validation3d_figure"]

#: One colour per strategy.
STRATEGY_COLOURS = {"ankle": RECOVER_COLOUR, "hip": HIP_COLOUR, "step": "#1565c0"}


def validation3d_figure(result: Validation3D | None, step: StepValidation | None = None) -> Figure:
    """Return the polar plot of ``result`` and the step column ``step`` as a Figure.

    Either may be None (not both); the step column is a model's
    (:func:`~pushrecovery.experiments.validation3d.step.run_step_validation`).
    """
    if result is not None:
        require_type("result", result, Validation3D)
    if step is not None:
        require_type("step", step, StepValidation)
    from matplotlib.figure import Figure

    from pushrecovery.errors import InvalidParameterError

    if result is None and step is None:
        raise InvalidParameterError("validation3d_figure needs a validation or a step column")
    fig = Figure(figsize=(6.4, 6.4))
    ax = cast("PolarAxes", fig.add_subplot(projection="polar"))
    columns: list[tuple[str, list[Any]]] = []
    if result is not None:
        columns += [(s, list(result.rows_for(s))) for s in result.strategies]
    if step is not None:
        columns.append(("step", list(step.rows)))
    # The predictions as dense curves (every 2°) where the result has them.
    curves = dict(result.curves) if result is not None else {}
    if step is not None and step.curve:
        curves["step"] = step.curve
    dense = [math.radians(a) for a in CURVE_AZIMUTHS]
    for strategy, unsorted in columns:
        rows = sorted(unsorted, key=lambda row: row.azimuth % 360.0)
        if not rows:
            continue
        colour = STRATEGY_COLOURS.get(strategy, "0.3")
        angles = [math.radians(row.azimuth) for row in rows]
        # The measured rows' own ratio corrected / predicted (1 / (1 + d/z0)).
        factor = rows[0].corrected / rows[0].predicted if rows[0].predicted else 1.0
        if strategy in curves:
            line_angles, predicted = dense, list(curves[strategy])
            corrected = [factor * value for value in predicted]
        else:  # a result without curves: straight lines between the measured azimuths
            closed = len(rows) > 2
            loop = (lambda values: [*values, values[0]]) if closed else (lambda values: values)
            line_angles = loop(angles)
            predicted = loop([row.predicted for row in rows])
            corrected = loop([row.corrected for row in rows])
        ax.plot(line_angles, predicted, "-", color=colour, label=f"{strategy}: 2-D prediction")
        ax.plot(line_angles, corrected, "--", color=colour,
                label=f"{strategy}: corrected (push height)")  # fmt: skip
        ax.errorbar(
            angles,
            [row.measured for row in rows],
            yerr=[[0.0] * len(rows), [row.bracket[1] - row.measured for row in rows]],
            fmt="o",
            color=colour,
            label=f"{strategy}: measured (WBC)",
        )
    ax.set_theta_zero_location("E")
    ax.set_theta_direction(1)
    ax.set_rlabel_position(112.5)
    model = result.model if result is not None else step.model if step is not None else ""
    ax.set_title(f"{model}: critical push [N s] by azimuth (0° forward, 90° left)", pad=18)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, -0.28), ncol=2, fontsize="small")
    fig.subplots_adjust(bottom=0.22)
    return fig
