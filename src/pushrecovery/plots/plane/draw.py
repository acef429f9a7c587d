"""The capture-point plane drawn on matplotlib Figure objects: feet, polygons, pushes."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import flag, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.plots.campaign import STEP_COLOUR, STRATEGY_COLOURS
from pushrecovery.plots.common import HIP_COLOUR, RECOVER_COLOUR, check_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
from pushrecovery.plots.plane.layout import (
    _FOOT_COLOUR,
    Extent,
    _box,
    _feet,
    _legend_handles,
    _mark_close_up,
    _new_figure,
    _set_limits,
    _thresholds_box,
    _title,
    _union,
)
from pushrecovery.plots.plane.samples import (
    HEADINGS,
    PlaneSamples,
    _headings,
    _samples,
    _speeds,
    _step_limit,
    recovery_limits,
    threshold_lines,
)

__all__ = [
    "capture_plane_figure",
    "capture_plane_panels",
    "draw_capture_plane",
]


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
    speeds : array_like, optional
        Push speeds [m/s] (:func:`plane_samples`).
    headings : int or array_like
        Number of push headings, or the headings [rad] counter-clockwise from +x.
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
    check_axes("ax", ax)
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
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
        label=f"largest push {params.max_steps} steps recover (N-step regions)",
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
    require_type("title", title, (str, type(None)))
    thresholds = flag("thresholds", thresholds)
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
    speeds : array_like, optional
        Push speeds [m/s], as :func:`capture_plane_figure`; the default speeds are the same for
        every column.
    headings : int or array_like
        Number of push headings, or the headings [rad] counter-clockwise from +x.
    thresholds : bool
        Print the per-direction push limits [m/s] of each strategy.

    Returns
    -------
    Figure
        The panels, sharing axes row by row.
    """
    require_type("params", params, BodyParams)
    thresholds = flag("thresholds", thresholds)
    if supports is not None and (not isinstance(supports, list | tuple) or not supports):
        raise InvalidParameterError("supports must be a list of at least one Support")
    for support in supports or ():
        require_type("each of supports", support, Support)
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
