"""The capture-point plane: feet, support polygon, CMP region and pushes coloured by verdict.

One panel shows the ground plane of a stance (x forward, y left, world frame [m], equal
aspect): the feet (the lifted one dashed in single support), the support polygon (the ankle
strategy's capture region, Eq. 4 in the plane), the CMP region (the polygon grown by the pitch
and roll flywheels' offsets, corrected Eq. 15: hip) and sample states: pushes of many headings
and speeds from a CoM at rest above the stance's reference point (``support.ankle``), each
drawn at its capture point ξ = r + ṙ/ω and coloured by
:func:`~pushrecovery.surfaces.classify.classify_states` (ankle, hip, step, fall). The dashed
blue curve is the largest push some strategy recovers along each heading: the single-step
limit (Sec. IV applied along the capture point's excursion), found by bisection on the same
classifier (it matches :func:`~pushrecovery.surfaces.plane.step_threshold_xy`).

:func:`capture_plane_figure` draws one stance, whole and close to the feet;
:func:`capture_plane_panels` draws double, left and right support side by side on one scale.
Figures are built outside pyplot (``matplotlib.figure.Figure``): nothing to close.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.plots.campaign import STEP_COLOUR, STRATEGY_COLOURS
from pushrecovery.plots.common import HIP_COLOUR, RECOVER_COLOUR

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "PlaneSamples",
    "capture_plane_figure",
    "capture_plane_panels",
    "draw_capture_plane",
    "plane_samples",
    "recovery_limits",
    "threshold_lines",
]

#: Default number of push headings (evenly spaced, the first straight forward).
HEADINGS = 32
#: Default number of push speeds per heading (evenly spaced up to the largest).
SPEEDS = 36
#: The largest default push is this many times the largest single-step threshold.
_SPEED_REACH = 1.15
#: Headings at which the single-step limit curve is evaluated (one vectorised bisection).
LIMIT_HEADINGS = 72
_FOOT_COLOUR = "0.25"


@dataclass(frozen=True, slots=True)
class PlaneSamples:
    """Pushes from a CoM at rest above ``support.ankle`` and their verdicts.

    Attributes
    ----------
    x, y : ndarray
        CoM position [m] (the reference point, for every sample).
    xdot, ydot : ndarray
        CoM velocity right after the push [m/s].
    xi_x, xi_y : ndarray
        Capture point ξ = r + ṙ/ω [m].
    codes : ndarray of int8
        Verdicts, indices into :data:`~pushrecovery.surfaces.classify.STRATEGY_CODES`.
    """

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    xdot: NDArray[np.float64]
    ydot: NDArray[np.float64]
    xi_x: NDArray[np.float64]
    xi_y: NDArray[np.float64]
    codes: NDArray[np.int8]


def _headings(headings: int | ArrayLike) -> NDArray[np.float64]:
    if isinstance(headings, int | np.integer):
        if headings < 1:
            raise InvalidParameterError(f"headings must be >= 1, got {headings}")
        return np.linspace(0.0, 2.0 * math.pi, int(headings), endpoint=False)
    values = np.atleast_1d(np.asarray(headings, dtype=np.float64))
    if values.ndim != 1 or values.size == 0 or not np.isfinite(values).all():
        raise InvalidParameterError("headings must be finite angles in rad (or a count)")
    return values


def _recovery_limits(
    params: BodyParams, support: Support, angles: NDArray[np.float64], tolerance: float = 1e-4
) -> NDArray[np.float64]:
    """Largest push along each heading that some strategy recovers, from rest [m/s].

    One vectorised bisection on :func:`~pushrecovery.surfaces.classify.classify_states` (not
    ``fall``) over all headings, from 0 to ω times the farthest vertex of the regions: beyond
    the hip region this is the limit of ``max_steps`` steps, drawn by the same classifier as
    the samples.
    """
    from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy, classify_states
    from pushrecovery.surfaces.plane import cmp_polygon
    from pushrecovery.surfaces.step_regions import StepRegions

    fall = STRATEGY_CODES.index(Strategy.FALL)
    low = np.zeros(angles.shape)
    corners = np.vstack(
        [cmp_polygon(support, params).vertices]
        + [p.vertices for p in StepRegions.of(params, support).polygons]
    )
    farthest = float(np.max(np.hypot(*(corners - np.array(support.ankle)).T)))
    high = np.full(angles.shape, params.omega * farthest * (1.0 + 1e-9))
    ux, uy = np.cos(angles), np.sin(angles)
    x, y = np.full(angles.shape, support.ankle[0]), np.full(angles.shape, support.ankle[1])
    while float(np.max(high - low)) > tolerance:
        middle = 0.5 * (low + high)
        codes = classify_states(x, middle * ux, params, y=y, ydot=middle * uy, support=support)
        recovered = codes != fall
        low = np.where(recovered, middle, low)
        high = np.where(recovered, high, middle)
    return low


def _limit_angles() -> NDArray[np.float64]:
    return np.linspace(0.0, 2.0 * math.pi, LIMIT_HEADINGS, endpoint=False)


def recovery_limits(params: BodyParams, support: Support) -> NDArray[np.float64]:
    """Largest push some strategy recovers from rest above ``support.ankle`` [m/s].

    Along :data:`LIMIT_HEADINGS` evenly spaced headings, the first along +x (to 1e-4 m/s):
    the limit of the ``step`` verdict (``max_steps`` steps).
    """
    return _recovery_limits(params, support, _limit_angles())


def _speeds(
    params: BodyParams,
    support: Support,
    speeds: ArrayLike | None,
    limits: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Return the push speeds [m/s]; by default up to 1.15 times the largest recoverable push."""
    if speeds is None:
        if limits is None:
            limits = _recovery_limits(params, support, _limit_angles())
        reach = float(np.max(limits))
        top = _SPEED_REACH * reach if reach > 0.0 else 1.0
        return np.linspace(top / SPEEDS, top, SPEEDS)
    values = np.atleast_1d(np.asarray(speeds, dtype=np.float64))
    if values.ndim != 1 or values.size == 0 or not np.isfinite(values).all() or (values < 0).any():
        raise InvalidParameterError("speeds must be finite push speeds >= 0 in m/s")
    return values


def plane_samples(
    params: BodyParams,
    support: Support,
    *,
    speeds: ArrayLike | None = None,
    headings: int | ArrayLike = HEADINGS,
) -> PlaneSamples:
    """Pushes of every speed along every heading from rest above ``support.ankle``, classified.

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support
        Stance and feet.
    speeds : array_like, optional
        Push speeds [m/s]; default :data:`SPEEDS` evenly spaced up to 1.15 times the largest
        push some strategy recovers along any heading (the single-step limit).
    headings : int or array_like
        A count of evenly spaced headings (the first along +x), or the headings [rad],
        counter-clockwise from +x.

    Returns
    -------
    PlaneSamples
        Speed-major order: heading k of speed j is sample j * len(headings) + k.
    """
    return _samples(params, support, _speeds(params, support, speeds), _headings(headings))


def _samples(
    params: BodyParams, support: Support, speed: NDArray[np.float64], angle: NDArray[np.float64]
) -> PlaneSamples:
    from pushrecovery.surfaces.classify import classify_states
    from pushrecovery.surfaces.plane import capture_point_xy

    xdot = np.ravel(speed[:, None] * np.cos(angle)[None, :])
    ydot = np.ravel(speed[:, None] * np.sin(angle)[None, :])
    x = np.full(xdot.shape, support.ankle[0])
    y = np.full(xdot.shape, support.ankle[1])
    codes = classify_states(x, xdot, params, y=y, ydot=ydot, support=support)
    xi_x, xi_y = capture_point_xy(x, y, xdot, ydot, params.omega)
    return PlaneSamples(x, y, xdot, ydot, xi_x, xi_y, codes)


def _step_limit(
    params: BodyParams, support: Support, limits: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Return the capture points of the largest recoverable push per heading, closed [m]."""
    angles = _limit_angles()
    speed = limits / params.omega
    ax, ay = support.ankle
    curve = np.column_stack([ax + speed * np.cos(angles), ay + speed * np.sin(angles)])
    return np.vstack([curve, curve[:1]])


def _feet(support: Support) -> list[tuple[NDArray[np.float64], bool]]:
    """Outline of each foot in the world frame and whether it carries weight."""
    left = support.foot.transformed(support.left.x, support.left.y, support.left.yaw)
    right = support.foot.mirrored().transformed(support.right.x, support.right.y, support.right.yaw)
    return [
        (left.vertices, support.stance is not Stance.RIGHT),
        (right.vertices, support.stance is not Stance.LEFT),
    ]


def threshold_lines(params: BodyParams, support: Support) -> list[str]:
    """Format the per-direction push limits of each strategy as fixed-width lines [m/s].

    The numbers of :func:`~pushrecovery.surfaces.bounds.plane_bounds` ``["thresholds"]``.
    """
    from pushrecovery.surfaces.bounds import plane_bounds

    thresholds = plane_bounds(params, support)["thresholds"]
    lines = ["largest push [m/s]  ankle   hip  step"]
    for name in ("forward", "backward", "left", "right"):
        values = " ".join(f"{thresholds[s][name]:5.2f}" for s in ("ankle", "hip", "step"))
        lines.append(f"{name:<18s} {values}")
    return lines


def _title(support: Support) -> str:
    title = f"{support.stance.value} support"
    if support.stance is not Stance.DOUBLE and support.yaw != 0.0:
        title += f", foot yawed {math.degrees(support.yaw):.0f}°"
    elif support.stance is Stance.DOUBLE and (support.left.yaw or support.right.yaw):
        title += (
            f", feet yawed {math.degrees(support.left.yaw):.0f}° (left) / "
            f"{math.degrees(support.right.yaw):.0f}° (right)"
        )
    return title


Extent = tuple[float, float, float, float]


def draw_capture_plane(
    ax: Axes,
    params: BodyParams,
    support: Support,
    *,
    speeds: ArrayLike | None = None,
    headings: int | ArrayLike = HEADINGS,
    samples: PlaneSamples | None = None,
    limits: ArrayLike | None = None,
    zoom: bool = False,
) -> tuple[Extent, Extent]:
    """Draw one stance's capture-point plane on ``ax`` (module docstring); no limits set.

    Each verdict is one scatter collection labelled with the strategy's name (``ankle``,
    ``hip``, ``step``, ``fall``) whose offsets are the samples' capture points [m].

    Parameters
    ----------
    ax : Axes
        Where to draw.
    params : BodyParams
        The body.
    support : Support
        Stance and feet.
    speeds, headings
        The pushes (:func:`plane_samples`).
    samples : PlaneSamples, optional
        Precomputed samples (else :func:`plane_samples`).
    limits : array_like, optional
        Precomputed largest recoverable push [m/s] along each of :data:`LIMIT_HEADINGS`
        evenly spaced headings (:func:`recovery_limits`).
    zoom : bool
        Larger markers, for a close-up of the feet.

    Returns
    -------
    (extent, close_up)
        (xmin, xmax, ymin, ymax) [m] of everything drawn, and of a close-up around the CMP
        region and the feet.
    """
    from matplotlib.patches import Polygon

    from pushrecovery.surfaces.classify import STRATEGY_CODES
    from pushrecovery.surfaces.plane import cmp_polygon

    limit_speeds = (
        recovery_limits(params, support) if limits is None else np.asarray(limits, dtype=np.float64)
    )
    if samples is None:
        samples = _samples(
            params, support, _speeds(params, support, speeds, limit_speeds), _headings(headings)
        )
    hip = cmp_polygon(support, params)
    ax.add_patch(Polygon(hip.vertices, facecolor=HIP_COLOUR, alpha=0.18, lw=0, zorder=1))
    ax.add_patch(
        Polygon(
            hip.vertices,
            fill=False,
            edgecolor=HIP_COLOUR,
            lw=1.5,
            zorder=4,
            label="CMP region: hip (corrected Eq. 15)",
        )
    )
    ax.add_patch(
        Polygon(
            support.polygon.vertices,
            facecolor=RECOVER_COLOUR,
            edgecolor=RECOVER_COLOUR,
            alpha=0.28,
            lw=1.5,
            zorder=2,
            label="support polygon: ankle (Eq. 4)",
        )
    )
    for code, strategy in enumerate(STRATEGY_CODES):
        chosen = samples.codes == code
        ax.scatter(
            samples.xi_x[chosen],
            samples.xi_y[chosen],
            s=16 if zoom else 6,
            color=STRATEGY_COLOURS[strategy.value],
            edgecolors="white" if zoom else "none",
            linewidths=0.4,
            zorder=3,
            label=strategy.value,
        )
    limit = _step_limit(params, support, limit_speeds)
    ax.plot(
        limit[:, 0],
        limit[:, 1],
        color=STEP_COLOUR,
        ls="--",
        lw=1.0,
        zorder=3,
        label="largest push one step recovers (Sec. IV)",
    )
    feet = _feet(support)
    for outline, carries in feet:
        closed = np.vstack([outline, outline[:1]])
        ax.plot(
            closed[:, 0],
            closed[:, 1],
            color=_FOOT_COLOUR,
            lw=1.3 if carries else 1.1,
            ls="-" if carries else (0, (3, 2)),
            zorder=5,
        )
    for pose in (support.left, support.right):
        ax.plot(pose.x, pose.y, "+", color=_FOOT_COLOUR, ms=6 if zoom else 4, mew=0.8, zorder=5)
    ax.plot(*support.ankle, "kx", ms=7 if zoom else 5, mew=1.5, zorder=6)
    # Equal scales by widening the data limits: the axes keep their layout box (constrained
    # layout leaves room for the labels of that box, not of a box shrunk to the aspect).
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x, forward [m]")
    ax.set_ylabel("y, left [m]")
    ax.grid(True, color="0.9", lw=0.6)
    ax.set_axisbelow(True)
    drawn = np.vstack(
        [np.column_stack([samples.xi_x, samples.xi_y]), limit, hip.vertices]
        + [outline for outline, _ in feet]
    )
    near = np.vstack([hip.vertices] + [outline for outline, _ in feet])
    return _box(drawn), _box(near)


def _box(points: NDArray[np.float64]) -> Extent:
    return (
        float(points[:, 0].min()),
        float(points[:, 0].max()),
        float(points[:, 1].min()),
        float(points[:, 1].max()),
    )


def _union(extents: Sequence[Extent]) -> Extent:
    box = np.array(extents)
    return (box[:, 0].min(), box[:, 1].max(), box[:, 2].min(), box[:, 3].max())


def _set_limits(ax: Axes, extent: Extent, pad: float) -> None:
    """Show ``extent`` grown by ``pad`` times its larger side, at equal scales.

    The equal aspect widens one range to the axes' shape (``adjustable="datalim"``); fixed
    limits would be overridden with a warning, so the axes autoscale to exactly this box.
    """
    xmin, xmax, ymin, ymax = extent
    pad *= max(xmax - xmin, ymax - ymin)
    ax.dataLim.set_points(np.array([[xmin - pad, ymin - pad], [xmax + pad, ymax + pad]]))
    ax.ignore_existing_data_limits = False
    ax.margins(0.0)
    ax.autoscale(enable=True)
    ax.autoscale_view()


def _mark_close_up(ax: Axes, extent: Extent, pad: float) -> None:
    from matplotlib.patches import Rectangle

    xmin, xmax, ymin, ymax = extent
    pad *= max(xmax - xmin, ymax - ymin)
    xmin, xmax, ymin, ymax = xmin - pad, xmax + pad, ymin - pad, ymax + pad
    ax.add_patch(
        Rectangle(
            (xmin, ymin),
            xmax - xmin,
            ymax - ymin,
            fill=False,
            ec="0.15",
            lw=1.0,
            ls=(0, (1.5, 1.5)),
            zorder=6,
        )
    )


def _legend_handles(ax: Axes) -> list[Artist]:
    from matplotlib.lines import Line2D

    handles, _ = ax.get_legend_handles_labels()
    return [
        *handles,
        Line2D([], [], color=_FOOT_COLOUR, lw=1.3, label="stance foot (+ ankle)"),
        Line2D([], [], color=_FOOT_COLOUR, lw=1.1, ls=(0, (3, 2)), label="lifted foot"),
        Line2D([], [], color="k", marker="x", ls="none", ms=7, mew=1.5, label="CoM before push"),
    ]


def _thresholds_box(ax: Axes, lines: list[str], x: float, y: float, va: str) -> None:
    ax.text(
        x,
        y,
        "\n".join(lines),
        transform=ax.transAxes,
        fontsize=7.5,
        family="monospace",
        va=va,
        ha="center",
        bbox={"facecolor": "white", "edgecolor": "0.75", "pad": 3.0},
    )


def _new_figure(width: float, height: float) -> Figure:
    """Create a figure outside pyplot's registry (nothing to close), drawn by Agg when saved."""
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


_SUPTITLE = (
    "Pushes from a CoM at rest above the reference point (×), drawn at their capture point "
    "ξ = r + ṙ/ω and coloured by the strategy they need"
)


@dataclass(frozen=True, slots=True)
class _Prepared:
    support: Support
    limits: NDArray[np.float64]
    samples: PlaneSamples


def _prepare(
    params: BodyParams,
    supports: Sequence[Support],
    speeds: ArrayLike | None,
    headings: int | ArrayLike,
) -> list[_Prepared]:
    """Limits and samples of each support; default speeds shared (the largest reach)."""
    limits = [recovery_limits(params, support) for support in supports]
    if speeds is None:
        speed = _speeds(params, supports[0], None, np.concatenate(limits))
    else:
        speed = _speeds(params, supports[0], speeds)
    angle = _headings(headings)
    return [
        _Prepared(support, limit, _samples(params, support, speed, angle))
        for support, limit in zip(supports, limits, strict=True)
    ]


def capture_plane_figure(
    params: BodyParams,
    support: Support | None = None,
    *,
    speeds: ArrayLike | None = None,
    headings: int | ArrayLike = HEADINGS,
    thresholds: bool = True,
    title: str | None = None,
) -> Figure:
    """Draw the capture-point plane of one stance (module docstring), whole and close up.

    Left: every push; middle: a close-up of the feet, the support polygon and the CMP region
    (dotted frame on the left); right: the legend and the per-direction push limits.

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support, optional
        Stance and feet; default double support on the default feet.
    speeds : array_like, optional
        Push speeds [m/s] (:func:`plane_samples`).
    headings : int or array_like
        Number of push headings, or the headings [rad] counter-clockwise from +x.
    thresholds : bool
        Print the per-direction push limits [m/s] of each strategy.
    title : str, optional
        Figure title.

    Returns
    -------
    Figure
        Save it with :func:`~pushrecovery.plots.common.save_figure` or ``fig.savefig``.
    """
    support = Support.from_params(params) if support is None else support
    (prepared,) = _prepare(params, [support], speeds, headings)
    fig = _new_figure(12.5, 5.4)
    whole, close, side = fig.subplots(1, 3, width_ratios=(1.0, 1.0, 0.62))
    extent, near = draw_capture_plane(
        whole, params, support, samples=prepared.samples, limits=prepared.limits
    )
    draw_capture_plane(
        close, params, support, samples=prepared.samples, limits=prepared.limits, zoom=True
    )
    _set_limits(whole, extent, 0.04)
    _set_limits(close, near, 0.3)
    _mark_close_up(whole, near, 0.3)
    whole.set_title("every push", fontsize=9)
    close.set_title("close to the feet (dotted frame on the left)", fontsize=9)
    side.axis("off")
    side.legend(handles=_legend_handles(close), loc="upper center", fontsize=8, frameon=False)
    if thresholds:
        _thresholds_box(side, threshold_lines(params, support), 0.5, 0.02, "bottom")
    fig.suptitle(title or f"{_title(support)}\n{_SUPTITLE}", fontsize=10)
    return fig


def capture_plane_panels(
    params: BodyParams,
    supports: Sequence[Support] | None = None,
    *,
    speeds: ArrayLike | None = None,
    headings: int | ArrayLike = HEADINGS,
    thresholds: bool = True,
) -> Figure:
    """Draw stances side by side on one scale: by default double, left and right support.

    Each column: every push (top) with the per-direction push limits, and a close-up of the
    feet (bottom, the dotted frame above); one legend below.

    Parameters
    ----------
    params : BodyParams
        The body.
    supports : sequence of Support, optional
        One column each; default the three stances on the default feet.
    speeds, headings, thresholds
        As :func:`capture_plane_figure`; the default speeds are the same for every column.

    Returns
    -------
    Figure
        The panels, sharing axes row by row.
    """
    if supports is None:
        supports = [Support.from_params(params, stance) for stance in Stance]
    if not supports:
        raise InvalidParameterError("capture_plane_panels needs at least one support")
    count = len(supports)
    fig = _new_figure(4.6 * count, 9.8)
    axes = fig.subplots(2, count, squeeze=False)
    extents, nears = [], []
    for index, prepared in enumerate(_prepare(params, supports, speeds, headings)):
        support, whole, close = prepared.support, axes[0, index], axes[1, index]
        extent, near = draw_capture_plane(
            whole, params, support, samples=prepared.samples, limits=prepared.limits
        )
        draw_capture_plane(
            close, params, support, samples=prepared.samples, limits=prepared.limits, zoom=True
        )
        extents.append(extent)
        nears.append(near)
        whole.set_title(_title(support), fontsize=10)
        close.set_title(f"{_title(support)}, close to the feet", fontsize=9)
        if index:
            for ax in (whole, close):
                ax.set_ylabel("")
                ax.tick_params(labelleft=False)
        if thresholds:
            _thresholds_box(whole, threshold_lines(params, support), 0.5, -0.13, "top")
    # The same limits row by row (not shared axes: equal aspect adjusts each one's limits).
    whole_box, near_box = _union(extents), _union(nears)
    for whole, close in zip(axes[0], axes[1], strict=True):
        _set_limits(whole, whole_box, 0.04)
        _set_limits(close, near_box, 0.3)
        _mark_close_up(whole, near_box, 0.3)
    fig.legend(handles=_legend_handles(axes[1, 0]), loc="outside lower center", ncol=5, fontsize=8)
    fig.suptitle(_SUPTITLE, fontsize=10)
    return fig
