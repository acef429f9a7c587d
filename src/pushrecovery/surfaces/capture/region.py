r"""Capture regions of a step: the footholds that capture a state, and the recommended one.

The N-step capturable sets (S1) of :mod:`pushrecovery.surfaces.n_step`, solved for the first
foothold: for a landing at time t (T = e^{ωt}) followed by N − 1 further steps,

.. math:: Q_T = T\xi_0 \oplus T(-H) \oplus (T - 1)(-S) \oplus (-V_{N-1}), \qquad (S3)

intersected with the reach; for a touchdown at any time from t on, the union
Q_{T_0} ⊕ cone(A), A = ξ_0 ⊕ (−H) ⊕ (−S). docs/steps.md, "Footholds: the capture region of a
step (S3)", derives both and the recommended foothold (the region's Chebyshev centre).

Over 400 lines on purpose: the region, its recommended foothold and the step terms they are
built from are one construction (the Minkowski terms of a step), kept together.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_float, finite_vector, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.chebyshev import chebyshev_centre, chebyshev_centre_unchecked
from pushrecovery.ground.minkowski import (
    Shape,
    clip,
    clip_halfplanes,
    minkowski_sum_unchecked,
    stacked_shapes,
)
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import MAX_STEP_TIME, MAX_STEPS, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.n_step import (
    StepOption,
    hip_box,
    landing_viable,
    reach_polygon,
    step_options,
)

__all__ = [
    "CaptureRegion",
    "capture_region",
    "chebyshev_centre",
    "foothold_region",
]

FloatArray = NDArray[np.float64]

#: Largest abs(x), abs(y) [m] and abs(ẋ), abs(ẏ) [m/s] of the states :func:`capture_region`
#: takes, and so the largest abs(ξ) component (ω >= :data:`~pushrecovery.params.OMEGA_MIN`) [m].
MAX_POSITION = 1e3
MAX_SPEED = 1e2
MAX_CAPTURE_POINT = MAX_POSITION + MAX_SPEED / OMEGA_MIN


@dataclass(frozen=True, slots=True, eq=False)
class CaptureRegion:
    """Footholds of the first landing foot from which ``steps`` steps capture a state.

    Attributes
    ----------
    polygon : ConvexPolygon or None
        The region of ankle positions of the landing foot [m]; None when empty. Built when
        first read (a loop that needs the foothold alone does not pay for it).
    swing : Stance
        The landing foot.
    touchdown : float
        The (earliest) touchdown time [s] from now.
    timing : str
        ``"exact"``: the foot lands at ``touchdown``; ``"after"``: at any time from then on.
    steps : int
        Steps of the capture, this one included (1: captured on the landing foot).
    foothold : ndarray of shape (2,) or None
        The recommended foothold: the region's Chebyshev centre, the foothold farthest from
        its boundary (the largest margin for a misplaced foot) [m].
    """

    swing: Stance
    touchdown: float
    timing: str
    steps: int
    foothold: FloatArray | None = field(default=None)
    # The polygon, or its counter-clockwise vertices until first read.
    _polygon: ConvexPolygon | None = field(default=None, repr=False)
    _vertices: FloatArray | None = field(default=None, repr=False)

    @property
    def polygon(self) -> ConvexPolygon | None:
        """The region of ankle positions of the landing foot [m]; None when empty."""
        if self._polygon is None and self._vertices is not None:
            object.__setattr__(self, "_polygon", ConvexPolygon._from_ccw(self._vertices))
        return self._polygon

    @property
    def area(self) -> float:
        """Area of the region [m²] (0 when empty)."""
        polygon = self.polygon
        return 0.0 if polygon is None else polygon.area

    def margin(self, x: NDArray[np.float64] | float, y: NDArray[np.float64] | float) -> FloatArray:
        """Signed distance of footholds (x, y) to the region [m], + inside, −inf if empty."""
        polygon = self.polygon
        if polygon is None:
            return np.full(np.broadcast(np.asarray(x), np.asarray(y)).shape, -np.inf)
        return polygon.signed_distance(x, y)


def capture_region(
    x: float,
    y: float,
    xdot: float,
    ydot: float,
    params: BodyParams,
    support: Support,
    swing_time: float | None = None,
    *,
    steps: int = 1,
    timing: Literal["exact", "after"] = "exact",
    swing: Stance | str | None = None,
    hip: bool = True,
) -> CaptureRegion:
    """Footholds that capture a state with ``steps`` steps, the first landing after swing_time.

    (S3) of the module docstring, intersected with the reach about the stance ankle.

    Parameters
    ----------
    x, y, xdot, ydot : float
        CoM position [m] and velocity [m/s] now, world frame.
    params : BodyParams
        Body parameters.
    support : Support
        The support now; in single support the free foot lands, in double support ``swing``
        or, by default, the foot on the side of the capture point from the ankles' midpoint.
    swing_time : float, optional
        Remaining time to touchdown t >= 0 [s] (mid-swing included); default
        ``min_step_time``.
    steps : int
        1: captured on the landing foot; N: with N − 1 more steps every Δt_s after it.
    timing : {"exact", "after"}
        Touchdown exactly at ``swing_time``, or at any time from then on.
    swing : {"left", "right"}, optional
        The landing foot.
    hip : bool
        Let the upper body help (its box H).

    Returns
    -------
    CaptureRegion
    """
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
    t = params.min_step_time
    if swing_time is not None:
        t = bounded_float("swing_time", swing_time, 0.0, MAX_STEP_TIME, "s")
    hip = _checked_plan(steps, timing, hip)
    xi = _capture_point(x, y, xdot, ydot, params)
    if swing is None and support.stance is Stance.DOUBLE:
        centre = support.ankle
        lateral = -math.sin(support.yaw) * (xi[0] - centre[0]) + math.cos(support.yaw) * (
            xi[1] - centre[1]
        )
        swing = Stance.LEFT if lateral >= 0.0 else Stance.RIGHT
    if swing is not None and not isinstance(swing, str):  # refused by step_options, by name
        step_options(params, support, swing)
    option, ankle, key = _first_option(params, support, swing)
    if timing == "exact":  # the compiled pipeline: a balance loop asks at every tick
        region, foothold = _region_loop(xi, params, option, ankle, key, t, steps, hip)
        if isinstance(region, ConvexPolygon):  # pragma: no cover - the numpy path's polygon
            return CaptureRegion(option.swing, t, timing, steps, foothold, _polygon=region)
        return CaptureRegion(option.swing, t, timing, steps, foothold, _vertices=region)
    polygon = foothold_region(xi, params, option, t, steps, timing=timing, hip=hip)
    foothold = None if polygon is None else chebyshev_centre_unchecked(polygon)
    return CaptureRegion(option.swing, t, timing, steps, foothold, _polygon=polygon)


@functools.lru_cache(maxsize=64)
def _first_option(
    params: BodyParams, support: Support, swing: Stance | str | None
) -> tuple[StepOption, FloatArray, bytes]:
    """Return the step option, its stance ankle and its :func:`step_terms` key (kept)."""
    option = step_options(params, support, swing)[0]
    ankle = np.asarray(option.ankle, dtype=np.float64)
    ankle.flags.writeable = False
    return option, ankle, (option.stance.vertices - ankle).tobytes()


ORIGIN = np.zeros(2)
ORIGIN.flags.writeable = False


@dataclass(frozen=True, slots=True, eq=False)
class StepTerms:
    """One step of a plan relative to its stance ankle, stacked for the compiled kernels.

    The foothold region (S3) is scale·ξ_rel ⊕ (1 − scale) S ⊕ (−V_{N−1}) ⊕ (−scale H) cut by the
    reach R; the split of scale·ξ_rel − q over scale H ⊕ (scale − 1) S ⊕ V_{N−1} gives the hip's
    share, the CoP and the capture point at touchdown relative to the landed ankle.
    """

    scale: float
    has_box: bool
    foot_shapes: FloatArray
    foot_counts: NDArray[np.int64]
    foot_weights: FloatArray
    window_normals: FloatArray
    window_offsets: FloatArray
    split_shapes: FloatArray
    split_counts: NDArray[np.int64]
    split_weights: FloatArray
    split_total: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class _StepShapes:
    """The touchdown-free part of :class:`StepTerms`: the stacked shapes and the window."""

    has_box: bool
    foot_shapes: FloatArray
    foot_counts: NDArray[np.int64]
    window_normals: FloatArray
    window_offsets: FloatArray
    split_shapes: FloatArray
    split_counts: NDArray[np.int64]


@functools.lru_cache(maxsize=256)
def _step_shapes(
    params: BodyParams, swing: Stance, yaw: float, steps: int, hip: bool, stance_key: bytes
) -> _StepShapes:
    """Return the shapes of :func:`step_terms`, the same for every touchdown (kept)."""
    stance = np.frombuffer(stance_key, dtype=np.float64).reshape(-1, 2)
    landing = landing_viable(params, swing, yaw, steps - 1)
    box = hip_box(params, yaw) if hip else None
    foot: list[tuple[float, Shape]] = [(1.0, stance), (-1.0, landing)]
    if box is not None:
        foot.append((-1.0, box))
    split: list[tuple[float, Shape]] = [
        (1.0, box if box is not None else np.zeros((1, 2))),
        (1.0, stance),
        (1.0, landing),
    ]
    foot_shapes, foot_counts, _ = stacked_shapes(foot)
    split_shapes, split_counts, _ = stacked_shapes(split)
    window = reach_polygon(params, swing, yaw)
    return _StepShapes(
        box is not None,
        foot_shapes,
        foot_counts,
        window.normals,
        window.offsets,
        split_shapes,
        split_counts,
    )


@functools.lru_cache(maxsize=256)
def step_terms(
    params: BodyParams,
    swing: Stance,
    yaw: float,
    steps: int,
    touchdown: float,
    hip: bool,
    stance_key: bytes,
) -> StepTerms:
    """Return the terms of one step, the stance given by its vertices relative to its ankle.

    Kept (the plans and the regions ask for the same few again and again): ``stance_key`` is
    the float64 bytes of the stance's vertices minus its ankle. A new touchdown costs the
    weights and one compiled sum: the shapes are kept apart, for every touchdown.
    """
    from pushrecovery.kernels.polygons import minkowski_loop

    shapes = _step_shapes(params, swing, yaw, steps, hip, stance_key)
    scale = math.exp(params.omega * touchdown)
    foot = (1.0 - scale, -1.0, -scale) if shapes.has_box else (1.0 - scale, -1.0)
    foot_weights = np.array(foot, dtype=np.float64)
    split_weights = np.array((scale, scale - 1.0, 1.0), dtype=np.float64)
    if not math.isfinite(float(foot_weights.sum() + split_weights.sum())):
        raise InvalidParameterError(f"Minkowski weights must be finite, got {list(foot)}")
    return StepTerms(
        scale,
        shapes.has_box,
        shapes.foot_shapes,
        shapes.foot_counts,
        foot_weights,
        shapes.window_normals,
        shapes.window_offsets,
        shapes.split_shapes,
        shapes.split_counts,
        split_weights,
        minkowski_loop(shapes.split_shapes, shapes.split_counts, split_weights, ORIGIN),
    )


def _region_loop(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    ankle: FloatArray,
    key: bytes,
    t: float,
    steps: int,
    hip: bool,
) -> tuple[FloatArray | ConvexPolygon | None, FloatArray | None]:
    """(S3) exactly at t and its recommended foothold, in one compiled call [m].

    The region as its counter-clockwise vertices (the polygon left unbuilt), or as the
    polygon of :func:`foothold_region` and the foothold its :func:`chebyshev_centre` when the
    compiled simplex fails; (None, None) when no foothold captures.
    """
    from pushrecovery.kernels.polygons import foothold_kernel

    terms = step_terms(params, option.swing, option.yaw, steps, t, hip, key)
    vertices, qx, qy, ok = foothold_kernel(
        terms.foot_shapes,
        terms.foot_counts,
        terms.foot_weights,
        terms.scale * (xi - ankle),
        terms.window_normals,
        terms.window_offsets,
    )
    if not ok:  # pragma: no cover - the compiled simplex found no start: the numpy path
        region = foothold_region(xi, params, option, t, steps, hip=hip)
        return region, None if region is None else chebyshev_centre_unchecked(region)
    if len(vertices) < 3:
        return None, None
    return vertices + ankle, np.array([qx + ankle[0], qy + ankle[1]])


def foothold_region(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    touchdown: float,
    steps: int,
    *,
    timing: Literal["exact", "after"] = "exact",
    hip: bool = True,
) -> ConvexPolygon | None:
    """(S3) for the capture point ξ0: first footholds of ``option``'s landing foot [m].

    The core of :func:`capture_region`, given the capture point ξ0 [m] and the step option
    (:func:`~pushrecovery.surfaces.n_step.step_options`); ``touchdown`` t [s] after now, then
    ``steps`` − 1 steps every Δt_s. None when no foothold within reach captures.

    Raises
    ------
    ParameterTypeError
        If ``params``, ``option`` or ``hip`` has the wrong type.
    InvalidParameterError
        A ξ0 that is not a finite (x, y) within ±:data:`MAX_CAPTURE_POINT` (the capture
        points of the states :func:`capture_region` takes), ``touchdown`` outside [0, 5] s,
        ``steps`` not a whole number in [1, 50], or an unknown ``timing``.
    """
    xi = finite_vector("xi", xi, 2, MAX_CAPTURE_POINT, "m")
    require_type("params", params, BodyParams)
    require_type("option", option, StepOption)
    touchdown = bounded_float("touchdown", touchdown, 0.0, MAX_STEP_TIME, "s")
    hip = _checked_plan(steps, timing, hip)
    landing = landing_viable(params, option.swing, option.yaw, steps - 1)
    box = hip_box(params, option.yaw) if hip else None
    boxes: list[tuple[float, Shape]] = [] if box is None else [(1.0, box)]
    window = _window(params, option.swing, option.yaw, *(float(v) for v in option.ankle))
    scale = math.exp(params.omega * touchdown)
    at = minkowski_sum_unchecked(
        [(-scale * w, b) for w, b in boxes] + [(1.0 - scale, option.stance), (-1.0, landing)],
        scale * xi,
    )
    if timing == "exact":
        return clip(at, window)
    return _after(at, xi, boxes, option.stance, window)


def _checked_plan(steps: int, timing: str, hip: bool) -> bool:
    """Check the plan's ``steps``, ``timing`` and ``hip``; return ``hip`` as a bool."""
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
        raise InvalidParameterError(
            f"steps must be a whole number in [1, {MAX_STEPS}], got {steps!r}"
        )
    if not isinstance(timing, str) or timing not in ("exact", "after"):
        raise InvalidParameterError(f"timing must be 'exact' or 'after', got {timing!r}")
    require_type("hip", hip, (bool, np.bool_))
    return bool(hip)


@functools.lru_cache(maxsize=64)
def _window(
    params: BodyParams, side: Stance, yaw: float, ankle_x: float, ankle_y: float
) -> ConvexPolygon:
    """Return the reach polygon about the stance ankle (kept: a loop asks again and again)."""
    return reach_polygon(params, side, yaw).transformed(ankle_x, ankle_y, 0.0)


def _capture_point(x: float, y: float, xdot: float, ydot: float, params: BodyParams) -> FloatArray:
    values = [
        finite_float(n, v, u)
        for n, v, u in zip(
            ("x", "y", "xdot", "ydot"), (x, y, xdot, ydot), ("m", "m", "m/s", "m/s"), strict=True
        )
    ]
    bounds = (MAX_POSITION, MAX_POSITION, MAX_SPEED, MAX_SPEED)
    for name, value, bound in zip(("x", "y", "xdot", "ydot"), values, bounds, strict=True):
        if abs(value) > bound:
            raise InvalidParameterError(f"{name} must be in [-{bound:g}, {bound:g}], got {value:g}")
    return np.array([values[0] + values[2] / params.omega, values[1] + values[3] / params.omega])


def _after(
    at: ConvexPolygon,
    xi: FloatArray,
    boxes: list[tuple[float, Shape]],
    stance: ConvexPolygon,
    window: ConvexPolygon,
) -> ConvexPolygon | None:
    """(Q_{T0} ⊕ cone(A)) ∩ window, A = ξ0 ⊕ (−H) ⊕ (−S) (module docstring)."""
    growth = minkowski_sum_unchecked([(-w, b) for w, b in boxes] + [(-1.0, stance)], xi)
    if float(growth.signed_distance(0.0, 0.0)) > 0.0:
        return window  # already captured without a step: any later foothold
    # The cone's edges: the extreme directions of A's vertices seen from the origin.
    centre = growth.vertices.mean(axis=0)
    base = math.atan2(centre[1], centre[0])
    angles = np.arctan2(growth.vertices[:, 1], growth.vertices[:, 0]) - base
    angles = (angles + math.pi) % (2.0 * math.pi) - math.pi
    rays = growth.vertices[[int(np.argmin(angles)), int(np.argmax(angles))]]
    rays = rays / np.hypot(rays[:, 0], rays[:, 1])[:, None]
    tolerance = 1e-12
    keep = np.all(at.normals @ rays.T <= tolerance, axis=1)
    # Normals of the cone's own edges: perpendicular to a ray, pointing away from the other.
    sides = np.array([[rays[0, 1], -rays[0, 0]], [-rays[1, 1], rays[1, 0]]])
    sides = np.where((np.sum(sides * rays[::-1], axis=1) > 0.0)[:, None], -sides, sides)
    normals = np.vstack([at.normals[keep], sides])
    offsets = np.concatenate([at.offsets[keep], (at.vertices @ sides.T).max(axis=0)])
    return clip_halfplanes(window, normals, offsets)
