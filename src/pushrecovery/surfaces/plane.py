r"""The capture point and the CoP (ankle) and CMP (hip) regions on the ground plane.

The LIPM of Eq. (6) holds in each horizontal axis with the same ω = sqrt(g/L); the upper body
torques in pitch and roll move the CMP:

.. math:: \ddot{\mathbf r} = \omega^2 (\mathbf r - \mathbf p - \mathbf c), \qquad
          \boldsymbol\xi = \mathbf r + \dot{\mathbf r} / \omega, \qquad
          \dot{\boldsymbol\xi} = \omega (\boldsymbol\xi - \mathbf p - \mathbf c),

with the CoP p in the support polygon P and the CMP offset c = (τ_pitch, τ_roll)/(m g) in the
body's axes. The capturable set of the hip is the Minkowski sum

.. math:: \mathcal C_{hip} = P \oplus [-a_x, a_x] \times [-a_y, a_y],

a_i the corrected Eq. (15) offset of each axis (exact when the constraints on p and on each
axis are independent, an outer bound otherwise; docs/plane.md, "The CMP (hip) region:
derivation"). From a moving upper body each axis's interval is [−Δ⁻, Δ⁺] instead
(:func:`cmp_polygon_from`, errata E19). Margins are signed Euclidean distances of ξ to a
region, positive inside.

Over 400 lines on purpose: the closed forms of the ground plane share the capture point and
the CoP and CMP polygons, from the margins of a state to the one-step threshold of a direction.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    finite_vector,
    float_array,
    output_array,
    require_type,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon, convex_hull
from pushrecovery.ground.support import Stance, Support
from pushrecovery.kernels.step_scalar import step_line
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_from, cmp_offset_roll
from pushrecovery.surfaces.cop import _fusable, capture_point
from pushrecovery.surfaces.step import StepDecision, plan_step, step_feasible

__all__ = [
    "DIRECTIONS",
    "StepFrame",
    "capture_margin_xy",
    "capture_point_xy",
    "cmp_margin_xy",
    "cmp_polygon",
    "cmp_polygon_from",
    "cop_margin_xy",
    "direction_thresholds",
    "plan_step_xy",
    "step_threshold_xy",
]

FloatArray = NDArray[np.float64]

#: Named push directions on the ground plane: heading [rad], counter-clockwise from +x.
DIRECTIONS: dict[str, float] = {
    "forward": 0.0,
    "left": 0.5 * math.pi,
    "backward": math.pi,
    "right": -0.5 * math.pi,
}


def capture_point_xy(
    x: ArrayLike, y: ArrayLike, xdot: ArrayLike, ydot: ArrayLike, omega: float
) -> tuple[FloatArray, FloatArray]:
    """Capture point ξ = r + ṙ/ω in the plane [m] (Eq. 4's middle term, per axis).

    Parameters
    ----------
    x, y : array_like
        CoM position in the world frame [m] (x forward, y left).
    xdot, ydot : array_like
        CoM velocity [m/s].
    omega : float
        sqrt(g / L) [1/s].

    Returns
    -------
    (ndarray, ndarray)
        ξ_x and ξ_y [m].

    Raises
    ------
    InvalidParameterError
        If ``omega`` is outside [0.1, 100] 1/s, or a position and its velocity do not
        broadcast (named as :func:`~pushrecovery.surfaces.cop.capture_point` names them; the
        states are not checked: NaN in, NaN out).
    """
    return (
        np.asarray(capture_point(x, xdot, omega), dtype=np.float64),
        np.asarray(capture_point(y, ydot, omega), dtype=np.float64),
    )


def cmp_polygon(support: Support, params: BodyParams) -> ConvexPolygon:
    """Capture-point region of CMP balancing: P ⊕ box(a_pitch, a_roll) [m] (module docstring).

    The box is aligned with the stance's heading (the upper body's pitch and roll axes). The
    last regions built are kept, keyed by the polygon's vertices and the box.
    """
    require_type("support", support, Support)
    require_type("params", params, BodyParams)
    vertices = support.polygon.vertices
    return _grown(
        vertices.tobytes(), len(vertices), cmp_offset(params), cmp_offset_roll(params), support.yaw
    )


def cmp_polygon_from(
    support: Support,
    params: BodyParams,
    pitch: tuple[float, float] = (0.0, 0.0),
    roll: tuple[float, float] = (0.0, 0.0),
) -> ConvexPolygon:
    """:func:`cmp_polygon` from the upper body's current angles and rates [m] (errata E19).

    P ⊕ [−Δ⁻_p, Δ⁺_p] × [−Δ⁻_r, Δ⁺_r] in the stance's axes, with (Δ⁻, Δ⁺) of each axis from
    :func:`~pushrecovery.surfaces.cmp.cmp_offset_from`: the box of half-sizes (Δ⁻ + Δ⁺)/2
    (never negative) centred at ((Δ⁺_p − Δ⁻_p)/2, (Δ⁺_r − Δ⁻_r)/2) in those axes. Equals
    :func:`cmp_polygon` for an upright body at rest (up to rounding, 1e-16 m).

    Parameters
    ----------
    support : Support
        The stance's support (its polygon P and yaw).
    params : BodyParams
        Body parameters.
    pitch, roll : (float, float)
        Upper-body (angle [rad], rate [rad/s]) about the pitch axis (positive forward) and the
        roll axis (positive toward the body's left).

    Raises
    ------
    InvalidParameterError
        An angle outside its joint range, a rate from which the flywheel cannot stop inside it,
        or a non-finite value (the message names ``theta0`` or ``thetadot0``).
    """
    require_type("support", support, Support)
    for name, state in (("pitch", pitch), ("roll", roll)):
        if not (isinstance(state, tuple | list) and len(state) == 2):
            raise InvalidParameterError(
                f"{name} must be an (angle [rad], rate [rad/s]) pair, got {str(state)[:40]!r}"
            )
    minus_p, plus_p = cmp_offset_from(params, *pitch)
    minus_r, plus_r = cmp_offset_from(params, *roll, axis="roll")
    yaw = support.yaw
    c, s = math.cos(yaw), math.sin(yaw)
    shift_p, shift_r = 0.5 * (plus_p - minus_p), 0.5 * (plus_r - minus_r)
    box = support.polygon.grown(
        max(0.5 * (plus_p + minus_p), 0.0), max(0.5 * (plus_r + minus_r), 0.0), yaw
    )
    return box.transformed(c * shift_p - s * shift_r, s * shift_p + c * shift_r, 0.0)


@functools.lru_cache(maxsize=64)
def _grown(vertices: bytes, count: int, half_x: float, half_y: float, yaw: float) -> ConvexPolygon:
    """:meth:`ConvexPolygon.grown` of the polygon with these (float64, CCW) vertices."""
    polygon = convex_hull(np.frombuffer(vertices, dtype=np.float64).reshape(count, 2))
    return polygon.grown(half_x, half_y, yaw)


def capture_margin_xy(
    x: ArrayLike,
    y: ArrayLike,
    xdot: ArrayLike,
    ydot: ArrayLike,
    omega: float,
    polygon: ConvexPolygon,
    *,
    out: NDArray[np.float64] | None = None,
) -> FloatArray:
    """Signed distance of the capture points ξ = r + ṙ/ω to a convex region [m], + inside.

    Large same-shape C-contiguous arrays take one fused, multithreaded compiled pass (cached
    on disk); smaller ones a chunked numpy pass.

    Parameters
    ----------
    x, y, xdot, ydot : array_like
        CoM positions [m] and velocities [m/s], broadcast together.
    omega : float
        sqrt(g / L) [1/s].
    polygon : ConvexPolygon
        The region, e.g. ``support.polygon`` (ankle) or :func:`cmp_polygon` (hip).
    out : ndarray, optional
        Float64 array of the broadcast shape for the result.

    Returns
    -------
    ndarray
        Margins [m].

    Raises
    ------
    ParameterTypeError
        If ``polygon`` is not a :class:`~pushrecovery.ground.polygon.ConvexPolygon`.
    InvalidParameterError
        If a state is NaN or infinite, shapes do not broadcast, or ``omega`` is outside
        [0.1, 100] 1/s (:data:`~pushrecovery.params.OMEGA_MIN`,
        :data:`~pushrecovery.params.OMEGA_MAX`).
    """
    require_type("polygon", polygon, ConvexPolygon)
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    arrays = [
        float_array(name, value)
        for name, value in (("x", x), ("y", y), ("xdot", xdot), ("ydot", ydot))
    ]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError:
        shapes = ", ".join(str(a.shape) for a in arrays)
        raise InvalidParameterError(f"x, y, xdot and ydot must broadcast, got {shapes}") from None
    if out is not None:
        out = output_array("out", out, shape)
    if (
        all(a.shape == shape for a in arrays)
        and _fusable(arrays[0], arrays[2], out)
        and all(a.flags.c_contiguous for a in arrays)
    ):
        from pushrecovery.kernels.plane_codes import padded_edges, polygon_margin

        margin = np.empty(shape) if out is None else out
        xs, ys, xds, yds = (a.reshape(-1) for a in arrays)
        edges = padded_edges(polygon.edge_table)
        bad = polygon_margin(xs, ys, xds, yds, 1.0 / omega, edges, margin.reshape(-1))
    else:
        with np.errstate(over="ignore", invalid="ignore"):  # reported below, as one error
            px, py = capture_point_xy(arrays[0], arrays[1], arrays[2], arrays[3], omega)
            margin = polygon.signed_distance(px, py)
        if out is not None:
            out[...] = margin
            margin = out
        bad = 0 if margin.size == 0 or np.isfinite(margin).all() else 1
    if bad:
        for name, array in zip(("x", "y", "xdot", "ydot"), arrays, strict=True):
            finite_array(name, array)
        finite_array("capture point", margin)  # overflow of finite states
    return margin


def cop_margin_xy(
    x: ArrayLike,
    y: ArrayLike,
    xdot: ArrayLike,
    ydot: ArrayLike,
    support: Support,
    params: BodyParams,
    *,
    out: NDArray[np.float64] | None = None,
) -> FloatArray:
    """Signed distance of ξ to the support polygon (CoP balancing, Eq. 4 in the plane) [m]."""
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
    return capture_margin_xy(x, y, xdot, ydot, params.omega, support.polygon, out=out)


def cmp_margin_xy(
    x: ArrayLike,
    y: ArrayLike,
    xdot: ArrayLike,
    ydot: ArrayLike,
    support: Support,
    params: BodyParams,
    *,
    out: NDArray[np.float64] | None = None,
) -> FloatArray:
    """Signed distance of ξ to the CMP region :func:`cmp_polygon` (hip strategy) [m]."""
    polygon = cmp_polygon(support, params)
    return capture_margin_xy(x, y, xdot, ydot, params.omega, polygon, out=out)


def direction_thresholds(
    polygon: ConvexPolygon, origin: tuple[float, float], omega: float
) -> dict[str, float]:
    """Largest push speed a region absorbs from a CoM at rest at ``origin``, per direction.

    A push of speed v along heading ψ puts ξ at origin + (v/ω)(cos ψ, sin ψ): the critical
    speed is ω times the distance from the origin to the region's boundary along ψ [m/s]
    (unsigned; :data:`DIRECTIONS` names the headings).

    Raises
    ------
    ParameterTypeError
        If ``polygon`` is not a :class:`~pushrecovery.ground.polygon.ConvexPolygon`.
    InvalidParameterError
        If ``origin`` is not a finite (x, y) strictly inside the polygon, or ``omega`` is
        outside [0.1, 100] 1/s.
    """
    require_type("polygon", polygon, ConvexPolygon)
    start = finite_vector("origin", origin, 2, unit="m")
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    return {
        name: omega * polygon.ray_distance(float(start[0]), float(start[1]), heading)
        for name, heading in DIRECTIONS.items()
    }


@dataclass(frozen=True, slots=True)
class StepFrame:
    """What the step line of a support needs (:func:`step_scalar.step_line`), as floats.

    Attributes
    ----------
    ankle_x, ankle_y : float
        The stance's ankle (the ankles' midpoint in double support) [m].
    heading_x, heading_y : float
        Unit vector of the stance's heading [-].
    swing : float
        −1: the right foot lands (left stance), +1: the left (right stance), 0: the foot on
        the side of the step (double support).
    foot_x, foot_y : tuple of float
        The left foot's vertices in its own frame [m] (the right one is their mirror).
    """

    ankle_x: float
    ankle_y: float
    heading_x: float
    heading_y: float
    swing: float
    foot_x: tuple[float, ...]
    foot_y: tuple[float, ...]

    @classmethod
    def of(cls, support: Support) -> StepFrame:
        """Return the frame of ``support``."""
        swing = {Stance.LEFT: -1.0, Stance.RIGHT: 1.0, Stance.DOUBLE: 0.0}[support.stance]
        return cls(
            *support.ankle,
            math.cos(support.yaw),
            math.sin(support.yaw),
            swing,
            tuple(float(v) for v in support.foot.vertices[:, 0]),
            tuple(float(v) for v in support.foot.vertices[:, 1]),
        )

    def line(
        self, x: float, y: float, xdot: float, ydot: float, inv_omega: float
    ) -> tuple[float, float, float, float, float, float]:
        """(e_x, e_y, s, ṡ, heel, toe) of a state: :func:`step_scalar.step_line`."""
        return step_line(
            x,
            y,
            xdot,
            ydot,
            inv_omega,
            self.ankle_x,
            self.ankle_y,
            self.heading_x,
            self.heading_y,
            self.swing,
            self.foot_x,  # type: ignore[arg-type]
            self.foot_y,  # type: ignore[arg-type]
        )


def plan_step_xy(
    x: float, y: float, xdot: float, ydot: float, params: BodyParams, support: Support
) -> tuple[tuple[float, float], StepDecision | None]:
    """Sec. IV's single step on the line through the stance ankle and ξ (its excursion).

    The line's unit vector e points from the stance's ankle (the stance ankle, or the ankles'
    midpoint in double support) to ξ, turned to the stance's heading side (e · heading >= 0)
    so that the sagittal case keeps its signs. The state is projected on it, s = (r − ankle)
    · e, ṡ = ṙ · e, as the sagittal model measures x from the ankle, and the landing foot
    (the swing foot: the right one from left stance, the left from right stance, the one on
    the side of the step from double support) lands with the stance's yaw, its edges along e
    its support function (``kernels.step_scalar.step_line``, the one implementation of the
    line). The planner then steps forward or backward along e exactly as on the sagittal line
    (:func:`~pushrecovery.surfaces.step.plan_step`). With y = ẏ = 0 and feet at yaw 0 this is
    the sagittal plan.

    Parameters
    ----------
    x, y : float
        CoM position in the world frame [m].
    xdot, ydot : float
        CoM velocity [m/s].
    params : BodyParams
        Body parameters.
    support : Support
        Stance and feet.

    Returns
    -------
    (tuple of float, StepDecision or None)
        The line's unit vector e, and the plan (None when abs(s) >= leg_length: no step).
    """
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
    x, y = finite_float("x", x, "m"), finite_float("y", y, "m")
    xdot, ydot = finite_float("xdot", xdot, "m/s"), finite_float("ydot", ydot, "m/s")
    ex, ey, along, speed, heel, toe = StepFrame.of(support).line(
        x, y, xdot, ydot, 1.0 / params.omega
    )
    if abs(along) >= params.leg_length:
        return (ex, ey), None
    return (ex, ey), plan_step(along, speed, params, heel=heel, toe=toe)


def step_threshold_xy(
    params: BodyParams, support: Support, heading: float, *, tolerance: float = 1e-9
) -> float:
    """Largest push speed along ``heading`` [rad] that one step recovers, CoM at the ankle [m/s].

    The CoM starts at rest above ``support.ankle``; bisection on the feasibility of
    :func:`plan_step_xy` (monotone in the push along a fixed line, as on the sagittal line),
    tested without solving for the step angle (:func:`~pushrecovery.surfaces.step.step_feasible`).
    Along ±x on yaw-0 feet it is :func:`~pushrecovery.surfaces.step.step_thresholds`.

    Raises
    ------
    ParameterTypeError
        If ``params`` or ``support`` has the wrong type.
    InvalidParameterError
        If ``heading`` is not finite or ``tolerance`` is outside [1e-12, 0.1] m/s (a
        bisection of speeds up to sqrt(g L) <= 31.6 m/s ends at float resolution below).
    """
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
    heading = finite_float("heading", heading, "rad")
    tolerance = bounded_float("tolerance", tolerance, 1e-12, 0.1, "m/s")
    ux, uy = math.cos(heading), math.sin(heading)
    frame = StepFrame.of(support)
    inv = 1.0 / params.omega
    low, high = 0.0, math.sqrt(params.gravity * params.leg_length)
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        _, _, along, speed, heel, toe = frame.line(
            frame.ankle_x, frame.ankle_y, middle * ux, middle * uy, inv
        )
        if abs(along) < params.leg_length and step_feasible(along, speed, heel, toe, params):
            low = middle
        else:
            high = middle
    return low
