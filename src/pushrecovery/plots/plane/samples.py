"""What the capture-point plane shows, computed: pushes from rest, limits, thresholds."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import finite_array, require_type, whole_number
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams

__all__ = [
    "HEADINGS",
    "LIMIT_HEADINGS",
    "MAX_HEADINGS",
    "SPEEDS",
    "PlaneSamples",
    "plane_samples",
    "recovery_limits",
    "threshold_lines",
]

#: Most headings, or push speeds, of a sampling (a polar grid of their product).
MAX_HEADINGS = 1000


#: Default number of push headings (evenly spaced, the first straight forward).
HEADINGS = 32


#: Default number of push speeds per heading (evenly spaced up to the largest).
SPEEDS = 36


#: The largest default push is this many times the largest single-step threshold.
_SPEED_REACH = 1.15


#: Headings at which the single-step limit curve is evaluated (one vectorised bisection).
LIMIT_HEADINGS = 72


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
    if isinstance(headings, int | np.integer) and not isinstance(headings, bool):
        count = whole_number("headings", headings, 1, MAX_HEADINGS)
        return np.linspace(0.0, 2.0 * math.pi, count, endpoint=False)
    values = np.atleast_1d(finite_array("headings", headings, 100.0, "rad"))
    if values.ndim != 1 or not 0 < values.size <= MAX_HEADINGS:
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
    from pushrecovery.surfaces.step.regions import StepRegions

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
    values = np.atleast_1d(finite_array("speeds", speeds, 1e3, "m/s"))
    if values.ndim != 1 or not 0 < values.size <= MAX_HEADINGS or (values < 0).any():
        raise InvalidParameterError(
            f"speeds must be 1 to {MAX_HEADINGS} push speeds in [0, 1000] m/s"
        )
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
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
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
