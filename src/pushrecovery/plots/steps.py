"""Figures of steps: capture regions over the support polygon, and the N-step strategy map.

Computing stays in :mod:`pushrecovery.surfaces.capture.region`, ``n_step`` and
:mod:`pushrecovery.surfaces.step.regions`; these functions draw on matplotlib ``Figure``
objects (no pyplot state) and return them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from pushrecovery.arguments import finite_vector, require_type, whole_number
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import MAX_STEPS, BodyParams
from pushrecovery.plots.common import FALL_COLOUR, HIP_COLOUR, RECOVER_COLOUR, frame_points
from pushrecovery.surfaces.cop import capture_point

__all__ = ["STEP_COLOURS", "capture_regions_figure", "n_step_map_figure"]

#: Colours of the one-, two- and more-step regions.
STEP_COLOURS = ("#1565c0", "#6a1b9a", "#00838f", "#5d4037")

State = tuple[float, float, float, float]


def _outline(
    ax: Axes, polygon: ConvexPolygon, colour: str, label: str | None, **kw: object
) -> None:
    ax.add_patch(Polygon(polygon.vertices, closed=True, fill=False, ec=colour, label=label, **kw))


def _fill(ax: Axes, polygon: ConvexPolygon, colour: str, label: str | None) -> None:
    ax.add_patch(
        Polygon(polygon.vertices, closed=True, fc=colour, ec=colour, alpha=0.25, label=label)
    )


def draw_capture_regions(
    ax: Axes,
    params: BodyParams,
    support: Support,
    state: State,
    *,
    swing_time: float | None = None,
    steps: int = 2,
) -> None:
    """Draw the support, the CMP region, ξ and the 1 ... ``steps``-step foothold regions.

    Each region is that of the first landing foot, touchdown exactly at ``swing_time``
    (default ``min_step_time``), with its recommended foothold (the Chebyshev centre, ×);
    the reach of the stance ankle is the dotted circle.
    """
    from pushrecovery.surfaces.capture.region import capture_region
    from pushrecovery.surfaces.plane import cmp_polygon

    x, y, xdot, ydot = state
    xi = (capture_point(x, xdot, params.omega), capture_point(y, ydot, params.omega))
    _fill(ax, support.polygon, RECOVER_COLOUR, "support polygon (ankle)")
    _outline(ax, cmp_polygon(support, params), HIP_COLOUR, "CMP region (hip)")
    corners = [support.polygon.vertices, np.array([xi])]
    swing = Stance.LEFT
    for n in range(steps, 0, -1):
        region = capture_region(x, y, xdot, ydot, params, support, swing_time, steps=n)
        colour = STEP_COLOURS[min(n, len(STEP_COLOURS)) - 1]
        label = f"footholds, {n} step" + ("s" if n > 1 else "")
        if region.polygon is None:
            ax.plot([], [], color=colour, label=f"{label}: none")
            continue
        _fill(ax, region.polygon, colour, label)
        corners.append(region.polygon.vertices)
        if region.foothold is not None:
            ax.plot(*region.foothold, "x", color=colour, ms=8, mew=2)
        swing = region.swing
    ankle = support.right if swing is Stance.LEFT else support.left  # the stance foot's
    ax.add_patch(
        Circle((ankle.x, ankle.y), params.max_step_length, fill=False, ec="0.6", ls=":", lw=0.8)
    )
    ax.plot(*xi, "o", color=FALL_COLOUR, ms=6, label="capture point ξ")
    ax.annotate(
        "",
        xy=xi,
        xytext=(x, y),
        arrowprops={"arrowstyle": "->", "color": "0.3", "lw": 1.0},
    )
    frame_points(ax, np.vstack(corners), 0.1)
    ax.set_xlabel("x [m] (forward)")
    ax.set_ylabel("y [m] (left)")
    speed = math.hypot(xdot, ydot)
    ax.set_title(f"push {speed:.2f} m/s, heading {math.degrees(math.atan2(ydot, xdot)):.0f}°")


def capture_regions_figure(
    params: BodyParams,
    support: Support | None = None,
    states: Sequence[State] | None = None,
    *,
    swing_time: float | None = None,
    steps: int = 2,
) -> Figure:
    """One panel per state (at most 4): :func:`draw_capture_regions`.

    By default four pushes from rest over the ankles' midpoint: forward 2.0 m/s, left
    1.2 m/s, backward-right 1.8 m/s and forward-left 2.8 m/s (two steps needed).
    """
    steps = whole_number("steps", steps, 1, MAX_STEPS)
    if states is not None and (isinstance(states, str) or not isinstance(states, list | tuple)):
        raise ParameterTypeError(
            f"states must be a list of CoM states, got {type(states).__name__}"
        )
    if states is not None:  # (x, y, xdot, ydot) [m, m/s] each, as classify takes them
        states = [tuple(finite_vector("each of states", s, 4, 1e3)) for s in states]
    require_type("params", params, BodyParams)
    if support is not None:
        require_type("support", support, Support)
    support = Support.from_params(params) if support is None else support
    if states is None:
        ax0, ay0 = support.ankle
        states = [
            (ax0, ay0, 2.0, 0.0),
            (ax0, ay0, 0.0, 1.2),
            (ax0, ay0, -1.8 * math.sqrt(0.5), -1.8 * math.sqrt(0.5)),
            (ax0, ay0, 2.8 * math.cos(0.4), 2.8 * math.sin(0.4)),
        ]
    if not 1 <= len(states) <= 4:
        raise InvalidParameterError(f"states must hold 1 to 4 states, got {len(states)}")
    columns = min(2, len(states))
    rows = math.ceil(len(states) / columns)
    fig = Figure(figsize=(5.2 * columns, 4.6 * rows), layout="constrained")
    axes = fig.subplots(rows, columns, squeeze=False).ravel()
    for ax, state in zip(axes, states, strict=False):
        draw_capture_regions(ax, params, support, state, swing_time=swing_time, steps=steps)
    for ax in axes[len(states) :]:
        ax.set_visible(False)
    axes[0].legend(loc="best", fontsize=7)
    timing = params.min_step_time if swing_time is None else swing_time
    fig.suptitle(
        f"Footholds that capture the push with 1 or {steps} steps (touchdown at {timing:g} s, "
        f"then every {params.min_step_time:g} s); × the recommended foothold"
    )
    return fig


def n_step_map_figure(
    params: BodyParams,
    xlim: tuple[float, float] = (-0.4, 0.6),
    ylim: tuple[float, float] | None = None,
    resolution: int = 301,
) -> Figure:
    """Draw the sagittal strategy map, with the number of steps a state needs.

    Colours: ankle, hip, then one shade per N = 1 ... 4 (5 and more share the last), and
    fall. The boundaries are lines of constant capture point ξ = x + ẋ/ω: every verdict
    escalates with push size, and no ``fall`` region lies below a ``step`` region.
    """
    from matplotlib.colors import ListedColormap

    from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy, classify_states
    from pushrecovery.surfaces.step.regions import line_steps

    require_type("params", params, BodyParams)
    xlim = tuple(finite_vector("xlim", xlim, 2, 1e3, "m"))
    resolution = whole_number("resolution", resolution, 2, 4001)  # 16 million states at most
    if ylim is not None:
        ylim = tuple(finite_vector("ylim", ylim, 2, 1e3, "m/s"))
    omega = params.omega
    top = ylim if ylim is not None else (-1.2 * omega * 1.2, 1.2 * omega * 1.4)
    xs = np.linspace(*xlim, resolution)
    vs = np.linspace(*top, resolution)
    x, v = np.meshgrid(xs, vs)
    codes = classify_states(x, v, params)
    steps = line_steps(capture_point(x, v, omega), params.heel, params.toe, 0.0, params).steps
    # 0 ankle, 1 hip, 2..5 steps 1..4+, 6 fall.
    shade = np.where(codes == STRATEGY_CODES.index(Strategy.STEP), 1 + np.minimum(steps, 4), 0)
    shade = np.where(codes == STRATEGY_CODES.index(Strategy.HIP), 1, shade)
    shade = np.where(codes == STRATEGY_CODES.index(Strategy.FALL), 6, shade)
    colours = [RECOVER_COLOUR, HIP_COLOUR, *STEP_COLOURS, FALL_COLOUR]
    fig = Figure(figsize=(7.0, 5.0), layout="constrained")
    ax = fig.subplots()
    ax.pcolormesh(xs, vs, shade, cmap=ListedColormap(colours), vmin=-0.5, vmax=6.5, alpha=0.6)
    names = ["ankle", "hip", "1 step", "2 steps", "3 steps", "4+ steps", "fall"]
    for colour, name in zip(colours, names, strict=True):
        ax.fill_between([], [], color=colour, alpha=0.6, label=name)
    ax.legend(loc="upper right", fontsize=8)
    for edge in (params.heel, params.toe):
        ax.axvline(edge, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("CoM position x [m] (relative to the ankle)")
    ax.set_ylabel("CoM velocity ẋ [m/s]")
    ax.set_title(
        f"Steps needed (Δt_s = {params.min_step_time:g} s, reach {params.max_step_length:g} m, "
        f"at most {params.max_steps})"
    )
    return fig
