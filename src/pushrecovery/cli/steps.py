"""The ``capture-region`` command: where to put the foot, for one state."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.options import (
    body_options,
    emit,
    needs_plots,
    params_from,
    support_from,
    support_options,
)
from pushrecovery.surfaces.cop import capture_point

__all__ = ["capture_region_command"]


@click.command(
    "capture-region",
    short_help="Footholds that capture a state with N steps.",
    epilog=example(
        "pushrecovery capture-region --x 0.0 --xdot 0.6 --ydot 0.2",
        "pushrecovery capture-region --x 0.0 --xdot 0.9 --steps 2 --plot out/regions.png --json",
    ),
)
@click.option("--x", "x", type=float, required=True, help="CoM position, forward [m].")
@click.option(
    "--y", "y", type=float, default=0.0, show_default=True, help="CoM position, left [m]."
)
@click.option("--xdot", type=float, required=True, help="CoM velocity, forward [m/s].")
@click.option(
    "--ydot", type=float, default=0.0, show_default=True, help="CoM velocity, left [m/s]."
)
@click.option(
    "--swing-time",
    type=float,
    default=None,
    help="Time left until touchdown [s], >= 0 (mid-swing too; default: min_step_time).",
)
@click.option(
    "--steps",
    type=click.IntRange(1, 50),
    default=1,
    show_default=True,
    help="Steps of the capture, this one included (N-step regions for N >= 2).",
)
@click.option(
    "--timing",
    type=click.Choice(("exact", "after")),
    default="exact",
    show_default=True,
    help="Touchdown exactly after --swing-time, or at any time from then on.",
)
@click.option(
    "--swing",
    type=click.Choice(("left", "right")),
    default=None,
    help="The landing foot (default: the free foot; from double support, the one on the "
    "capture point's side).",
)
@click.option("--no-hip", "no_hip", is_flag=True, help="Without the upper body's help.")
@click.option(
    "--plot",
    "plot",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    callback=needs_plots,
    help="Also draw the regions into this PNG, SVG or PDF file.",
)
@support_options
@body_options
def capture_region_command(
    x: float,
    y: float,
    xdot: float,
    ydot: float,
    swing_time: float | None,
    steps: int,
    timing: str,
    swing: str | None,
    no_hip: bool,
    plot: Path | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Footholds of the landing foot (its ankle, world frame [m]) that capture the state.

    The state is the CoM's position and velocity in the frame of the feet, x forward and y
    left (by default the ankles' midpoint is the origin). The LIPM with the support's feet,
    the reach (max_step_length about the stance ankle), touchdowns min_step_time apart and the
    hip's box (docs/steps.md). Prints the landing foot, the touchdown time [s], the region's
    vertices [m] and area [m^2], and the recommended foothold [m]: the region's Chebyshev
    centre, the one farthest from its edges, and whether it crosses over (lands across the
    stance foot's midline; min_step_width forbids it); then the capture point [m], the support
    and the state. An empty region has no vertices (null in JSON).
    """
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.surfaces.capture.region import capture_region

    file = kwargs["params_file"]
    params = params_from(kwargs)
    support = support_from(kwargs, params, file)
    if plot is not None and plot.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise InvalidParameterError(f"--plot must end in .png, .svg or .pdf, got {plot.name!r}")
    region = capture_region(
        x,
        y,
        xdot,
        ydot,
        params,
        support,
        swing_time,
        steps=steps,
        timing="after" if timing == "after" else "exact",
        swing=swing,
        hip=not no_hip,
    )
    data: dict[str, Any] = {
        "swing": region.swing.value,
        "touchdown": region.touchdown,
        "timing": region.timing,
        "steps": region.steps,
        "area": region.area,
        "vertices": None if region.polygon is None else region.polygon.to_list(),
        "foothold": None if region.foothold is None else [float(v) for v in region.foothold],
        "crossover": None if region.foothold is None else _crosses(region, support),
        "capture_point_xy": [
            capture_point(x, xdot, params.omega),
            capture_point(y, ydot, params.omega),
        ],
        "support": support.to_dict(),
        "state": {"x": x, "y": y, "xdot": xdot, "ydot": ydot},
    }
    if plot is not None:
        from pushrecovery.plots.common import save_figure
        from pushrecovery.plots.steps import capture_regions_figure

        figure = capture_regions_figure(
            params, support, [(x, y, xdot, ydot)], swing_time=swing_time, steps=max(steps, 2)
        )
        (path,) = save_figure(figure, plot.with_suffix(""), (plot.suffix[1:].lower(),))
        data["plot"] = str(path)
    emit(data, as_json)


def _crosses(region: Any, support: Any) -> bool:
    """Whether the recommended foothold lands across the stance foot's midline (docs/steps.md)."""
    import math

    from pushrecovery.ground.support import Stance
    from pushrecovery.surfaces.capture.plan import CROSSOVER_TOLERANCE

    stance = support.right if region.swing is Stance.LEFT else support.left
    dx, dy = float(region.foothold[0]) - stance.x, float(region.foothold[1]) - stance.y
    lateral = -math.sin(stance.yaw) * dx + math.cos(stance.yaw) * dy
    outward = lateral if region.swing is Stance.LEFT else -lateral
    return outward < -CROSSOVER_TOLERANCE
