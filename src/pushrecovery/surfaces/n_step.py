r"""N-step capturability: the LIPM with feet, a reach and a step time, and the hip.

The model is that of :mod:`pushrecovery.surfaces.plane` (ξ̇ = ω (ξ − p − c)) with steps: at
touchdown times t_1 < t_2 < ... the landing foot F_k, its ankle at q_k, becomes the support,
the foothold within the reach polygon R_k about the stance ankle and touchdowns at least Δt_s
(``min_step_time``) apart. With a_k = e^{−ω t_k} and a_{N+1} = 0, the capture points captured
by N steps at these times are

.. math:: C_N = H \oplus (1 - a_1) S \oplus \{a_1 q_0\}
          \oplus \bigoplus_{k=1}^N (a_k - a_{k+1}) F_k \oplus \bigoplus_{j=1}^N a_j R_j,
          \qquad (S1)

a convex polygon (:mod:`pushrecovery.ground.minkowski`) with support function
h(d) = h_H + (1 − a_1) h_S + a_1 d·q_0 + Σ (a_k − a_{k+1}) h_{F_k} + Σ a_j h_{R_j} (S2), H the
hip's box. Along one direction with point feet it is Koolen et al. (2012)'s d_N. docs/steps.md
("The N-step capturable set (S1)") derives it and states when it is exact.

Over 400 lines on purpose: the model, its derivation and the exact N-step sets are one
concept; the LP that checks them is :mod:`pushrecovery.surfaces.capture.lp.steps`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_float,
    float_array,
    non_negative_float,
    require_type,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import (
    Shape,
    clip_halfplanes,
    minkowski_sum_unchecked,
    regular_polygon,
)
from pushrecovery.ground.polygon import ConvexPolygon, following
from pushrecovery.ground.support import Stance, Support, foot_shape
from pushrecovery.params import (
    LIMITS,
    MAX_STEP_TIME,
    OMEGA_MAX,
    OMEGA_MIN,
    BodyParams,
    default_max_steps,
)
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll

__all__ = [
    "REACH_SIDES",
    "StepOption",
    "capturability_distance",
    "default_max_steps",
    "hip_box",
    "landing_foot",
    "landing_viable",
    "reach_polygon",
    "step_options",
    "viable_region",
]

FloatArray = NDArray[np.float64]

#: Sides of the regular polygon inscribed in the reach disc: its edges come within
#: max_step_length (1 − cos(π/64)) = 0.12 % of the circle (1.2 mm for a 1 m reach).
REACH_SIDES = 64


def capturability_distance(
    steps: float,
    omega: float,
    step_time: float,
    reach: float,
    foot_radius: float = 0.0,
    hip: float = 0.0,
) -> float:
    """d_N: the farthest capture point from the stance ankle that N steps capture [m].

    (S2) along one direction for a point (``foot_radius`` 0) or disc foot, a reach ``reach``
    [m] along that direction, touchdowns every ``step_time`` Δt_s [s] from Δt_s on and a hip
    offset ``hip`` [m]: d_N = hip + r + l β (1 − β^N)/(1 − β), β = e^{−ωΔt_s} (Koolen et al.
    2012, with the hip added); ``steps`` may be ``math.inf``. Δt_s = 0 gives hip + r + N l.

    Parameters
    ----------
    steps : int or math.inf
        N, a whole number in [0, 2^53] (those a float holds exactly), or ``math.inf`` (the
        limit, which needs Δt_s > 0).
    omega : float
        sqrt(g/L) [1/s], in [0.1, 100] (:data:`~pushrecovery.params.OMEGA_MIN`,
        :data:`~pushrecovery.params.OMEGA_MAX`).
    step_time : float
        Δt_s [s], in [0, 5] (``min_step_time``'s range).
    reach : float
        l [m], in [0, 20] (``max_step_length`` < 2 ``leg_length`` <= 20 m).
    foot_radius, hip : float
        r and the hip offset [m], finite, >= 0.

    Raises
    ------
    InvalidParameterError
        If an argument is outside its range, or ``steps`` is ``math.inf`` with Δt_s = 0 (an
        unbounded distance).
    """
    if isinstance(steps, float) and steps == math.inf:
        count: float = math.inf
    else:
        count = whole_number("steps", steps, 0, 2**53)
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    step_time = bounded_float("step_time", step_time, 0.0, MAX_STEP_TIME, "s")
    reach = bounded_float("reach", reach, 0.0, 2.0 * LIMITS["leg_length"][1], "m")
    foot_radius = non_negative_float("foot_radius", foot_radius, "m")
    hip = non_negative_float("hip", hip, "m")
    if count == math.inf and step_time == 0.0:
        raise InvalidParameterError(
            "steps=inf needs step_time > 0 s: infinitely many instantaneous steps reach "
            "infinitely far"
        )
    return _capturability_distance(count, omega, step_time, reach, foot_radius, hip)


def _capturability_distance(
    steps: float,
    omega: float,
    step_time: float,
    reach: float,
    foot_radius: float = 0.0,
    hip: float = 0.0,
) -> float:
    """:func:`capturability_distance` of checked arguments (the library's own loops)."""
    beta = math.exp(-omega * step_time)
    if steps == 0:
        return hip + foot_radius
    if beta >= 1.0:
        return hip + foot_radius + steps * reach
    geometric = beta / (1.0 - beta) if math.isinf(steps) else beta * (1 - beta**steps) / (1 - beta)
    return hip + foot_radius + reach * geometric


def hip_box(params: BodyParams, yaw: float) -> FloatArray | None:
    """Return the hip's box H: ±(pitch, roll) corrected Eq. 15 offsets, heading-aligned [m].

    Counter-clockwise corners (a segment when one axis has no torque), or None when neither;
    read-only (the answers are kept). ``yaw`` [rad] in [−2π, 2π].

    Raises
    ------
    InvalidParameterError
        A ``yaw`` that is not a finite number in [−2π, 2π] (radians, not degrees).
    """
    return _hip_box(_body(params), _yaw(yaw))


def _body(params: object) -> BodyParams:
    require_type("params", params, BodyParams)
    return params  # type: ignore[return-value]


def _yaw(yaw: object) -> float:
    """Return a yaw [rad] as a float in [−2π, 2π] (beyond, its sine and cosine lose precision)."""
    return bounded_float("yaw", yaw, -2.0 * math.pi, 2.0 * math.pi, "rad, not degrees")


@functools.lru_cache(maxsize=64)
def _hip_box(params: BodyParams, yaw: float) -> FloatArray | None:
    half_x, half_y = cmp_offset(params), cmp_offset_roll(params)
    if half_x == 0.0 and half_y == 0.0:
        return None
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([[-half_x, -half_y], [half_x, -half_y], [half_x, half_y], [-half_x, half_y]])
    if half_x == 0.0 or half_y == 0.0:
        local = np.array([[-half_x, -half_y], [half_x, half_y]])
    box = np.asarray(local @ np.array([[c, s], [-s, c]]), dtype=np.float64)
    box.flags.writeable = False  # kept and shared between callers
    return box


@functools.lru_cache(maxsize=64)
def landing_foot(params: BodyParams, side: Stance, yaw: float) -> ConvexPolygon:
    """Return the ``side`` foot (LEFT or RIGHT), its ankle at the origin, turned by yaw [m]."""
    foot = foot_shape(params)
    return (foot if side is Stance.LEFT else foot.mirrored()).transformed(0.0, 0.0, yaw)


def reach_polygon(params: BodyParams, side: Stance, yaw: float) -> ConvexPolygon:
    """Footholds of the ``side`` foot relative to the stance ankle: R [m] (:func:`_reach`).

    ``side`` LEFT or RIGHT, ``yaw`` [rad] in [−2π, 2π].

    Raises
    ------
    InvalidParameterError
        An unknown side, or a ``yaw`` that is not a finite number in [−2π, 2π].
    """
    return _reach(_body(params), _foot_side("side", side), _yaw(yaw))


def _foot_side(name: str, value: str | Stance) -> Stance:
    """Return ``value`` as a foot, LEFT or RIGHT, or raise naming ``name``."""
    try:
        side = Stance(value)
    except ValueError:
        raise InvalidParameterError(
            f"{name} must be 'left' or 'right', got {value!r:.40}"
        ) from None
    if side is Stance.DOUBLE:
        raise InvalidParameterError(f"{name} must be 'left' or 'right', got 'double'")
    return side


@functools.lru_cache(maxsize=32)
def _reach(params: BodyParams, side: Stance, yaw: float) -> ConvexPolygon:
    """Footholds of the ``side`` foot relative to the stance ankle: R [m].

    The regular polygon of :data:`REACH_SIDES` sides inscribed in the disc of radius
    ``max_step_length`` (so no foothold beyond the reach is ever proposed), cut, when
    ``min_step_width`` is set, to the half-plane at least that far out on the landing foot's
    side of the stance ankle (a left foot lands on the left of a right stance foot), in the
    frame turned by the stance's yaw.
    """
    disc = regular_polygon(params.max_step_length, REACH_SIDES, phase=yaw)
    if params.min_step_width is None:
        return disc
    outward = 1.0 if side is Stance.LEFT else -1.0
    normal = -outward * np.array([[-math.sin(yaw), math.cos(yaw)]])  # −(lateral, outward)
    cut = clip_halfplanes(disc, normal, np.array([-params.min_step_width]))
    if cut is None:  # pragma: no cover - min_step_width < max_step_length is validated
        raise InvalidParameterError("min_step_width leaves no foothold within the reach")
    return cut


def _other(side: Stance) -> Stance:
    return Stance.RIGHT if side is Stance.LEFT else Stance.LEFT


@dataclass(frozen=True, slots=True, eq=False)
class StepOption:
    """One way to start stepping from a support: which foot lands first, on what it stands.

    Attributes
    ----------
    swing : Stance
        The foot that lands first (LEFT or RIGHT).
    stance : ConvexPolygon
        The support while it swings: the other foot [m].
    ankle : ndarray, shape (2,)
        The stance ankle q_0 [m].
    yaw : float
        The stance foot's yaw [rad], kept by every landing foot unless a plan chooses a
        landing yaw (:func:`~pushrecovery.surfaces.capture.plan.capture_plan`).
    """

    swing: Stance
    stance: ConvexPolygon
    ankle: FloatArray
    yaw: float


def step_options(
    params: BodyParams, support: Support, swing: Stance | str | None = None
) -> list[StepOption]:
    """List the ways to step from ``support``: the free foot, or either one from double.

    ``swing`` picks one foot from double support (it must be the free foot otherwise).
    """
    require_type("params", params, BodyParams)
    require_type("support", support, Support)
    if swing is not None:
        swing = _foot_side("swing", swing)
        if support.stance is not Stance.DOUBLE and swing is support.stance:
            raise InvalidParameterError(
                f"swing must be the free foot: the {support.stance.value} foot carries the body"
            )
    if support.stance is Stance.DOUBLE:
        sides = [Stance.LEFT, Stance.RIGHT] if swing is None else [swing]
    else:
        sides = [_other(support.stance)]
    options = []
    for side in sides:
        stance = _other(side)
        pose = support.left if stance is Stance.LEFT else support.right
        single = Support.from_params(params, stance, left=support.left, right=support.right)
        options.append(StepOption(side, single.polygon, np.array([pose.x, pose.y]), pose.yaw))
    return options


def _sum_terms(
    params: BodyParams,
    option: StepOption,
    touchdowns: tuple[float, ...],
    hip: bool,
    landing_yaw: float | None = None,
) -> tuple[list[tuple[float, Shape]], FloatArray, list[Stance]]:
    """Return the weighted shapes and the offset of (S1), and the landing sides.

    Terms in order: the hip's box, the stance, the landing feet, the reach polygons. The
    landing feet and the reach about each landed foot turn with ``landing_yaw`` (default: the
    stance's yaw); the first reach and the hip's box keep the stance's yaw.
    """
    landing = option.yaw if landing_yaw is None else landing_yaw
    omega = params.omega
    a = [math.exp(-omega * t) for t in touchdowns] + [0.0]
    terms: list[tuple[float, Shape]] = []
    box = hip_box(params, option.yaw) if hip else None
    terms.append((1.0 if box is not None else 0.0, box if box is not None else np.zeros((1, 2))))
    terms.append((1.0 - a[0], option.stance))
    sides = []
    side = option.swing
    for k in range(len(touchdowns)):
        sides.append(side)
        terms.append((a[k] - a[k + 1], landing_foot(params, side, landing)))
        side = _other(side)
    for k in range(len(touchdowns)):
        terms.append((a[k], reach_polygon(params, sides[k], option.yaw if k == 0 else landing)))
    return terms, a[0] * option.ankle, sides


def _check_touchdowns(params: BodyParams, touchdowns: tuple[float, ...]) -> None:
    """Refuse touchdown times that are not finite or come sooner than min_step_time apart."""
    previous = 0.0
    for k, t in enumerate(touchdowns):
        finite_float("touchdown", t, "s")
        gap = params.min_step_time if k else 0.0
        if t < previous + gap - 1e-12:
            raise InvalidParameterError(
                f"touchdown {k + 1} at {t:g} s comes sooner than min_step_time "
                f"{params.min_step_time:g} s after the previous one"
            )
        previous = t


def viable_region(
    params: BodyParams,
    option: StepOption,
    touchdowns: tuple[float, ...],
    *,
    hip: bool = True,
    landing_yaw: float | None = None,
) -> ConvexPolygon:
    """C_N of (S1): the capture points that N steps at these touchdown times capture [m].

    Parameters
    ----------
    params : BodyParams
        Body parameters (ω, feet, reach, hip).
    option : StepOption
        Which foot lands first and the stance it leaves (:func:`step_options`).
    touchdowns : tuple of float
        t_1 < ... < t_N [s] from now, at least ``min_step_time`` apart; () gives S ⊕ H.
    hip : bool
        Include the upper body's box H.
    landing_yaw : float, optional
        Yaw of every landing foot [rad], in [−π, π] (default: the stance's, ``option.yaw``).
        The landing feet F_k and the reach about each landed foot turn with it; the first
        reach and H keep the stance's frame. The feet are not rotationally symmetric, so C_N
        depends on it.

    Raises
    ------
    ParameterTypeError
        If ``params``, ``option`` or ``hip`` has the wrong type.
    InvalidParameterError
        Touchdown times that are not a one-dimensional sequence of finite numbers at least
        ``min_step_time`` apart (the first >= 0), or a ``landing_yaw`` outside [−π, π] rad.
    """
    require_type("params", params, BodyParams)
    require_type("option", option, StepOption)
    require_type("hip", hip, (bool, np.bool_))
    times = float_array("touchdowns", touchdowns)
    if times.ndim != 1:
        raise InvalidParameterError(
            f"touchdowns must be a sequence of times (shape (N,)) [s], got shape {times.shape}"
        )
    touchdowns = tuple(float(t) for t in times)
    _check_touchdowns(params, touchdowns)
    if landing_yaw is not None:
        landing_yaw = bounded_float("landing_yaw", landing_yaw, -math.pi, math.pi, "rad")
    terms, offset, _ = _sum_terms(params, option, touchdowns, bool(hip), landing_yaw)
    return minkowski_sum_unchecked(terms, offset)


def _ray_distances(
    params: BodyParams,
    option: StepOption,
    touchdowns: tuple[float, ...],
    origin: tuple[float, float],
    headings: FloatArray,
    *,
    hip: bool = True,
) -> FloatArray:
    """Distances from ``origin`` to the edge of C_N along each heading [m], from (S2) alone.

    C_N = {p : n · p <= h(n)} over the edge normals n of its terms (a superset of its own
    edge normals gives the same polygon), so the exit of the ray origin + s u is
    min over n · u > 0 of (h(n) − n · origin) / (n · u), with h of (S2): no polygon is built
    (``bounds`` needs only these distances). 0 when the origin is not inside C_N.
    """
    _check_touchdowns(params, touchdowns)
    terms, offset, _ = _sum_terms(params, option, tuple(touchdowns), hip)
    shapes: dict[int, tuple[FloatArray, list[float]]] = {}  # the reach repeats: one entry
    for weight, shape in terms:
        if weight != 0.0:
            shapes.setdefault(id(shape), (_vertices_of(shape), []))[1].append(weight)
    normals = np.vstack([_edge_normals(vertices) for vertices, _ in shapes.values()])
    support = normals @ offset
    for vertices, weights in shapes.values():
        support = support + sum(weights) * (vertices @ normals.T).max(axis=0)
    room = support - normals @ np.asarray(origin, dtype=np.float64)
    headings = np.atleast_1d(np.asarray(headings, dtype=np.float64))
    if np.any(room <= 0.0):
        return np.zeros(headings.shape)
    rate = normals @ np.vstack([np.cos(headings), np.sin(headings)])
    ratio = np.where(rate > 1e-15, room[:, None] / np.where(rate > 1e-15, rate, 1.0), np.inf)
    return np.asarray(ratio.min(axis=0), dtype=np.float64)


def _vertices_of(shape: Shape) -> FloatArray:
    return shape.vertices if isinstance(shape, ConvexPolygon) else np.asarray(shape)


def _edge_normals(vertices: FloatArray) -> FloatArray:
    """Return the outward unit normals of a counter-clockwise loop.

    Both sides of a segment; none for a point.
    """
    if len(vertices) < 2:
        return np.zeros((0, 2))
    edges = following(vertices) - vertices
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    keep = lengths > 0.0
    return np.column_stack([edges[keep, 1], -edges[keep, 0]]) / lengths[keep, None]


@functools.lru_cache(maxsize=256)
def landing_viable(params: BodyParams, side: Stance, yaw: float, more: int) -> ConvexPolygon:
    """Return V_more: what the landed ``side`` foot and ``more`` steps capture [m].

    Capture points relative to the landing ankle, touchdowns every Δt_s, without the hip.
    """
    foot = landing_foot(params, side, yaw)
    if more == 0:
        return foot
    option = StepOption(_other(side), foot, np.zeros(2), yaw)
    times = tuple(params.min_step_time * (k + 1) for k in range(more))
    return viable_region(params, option, times, hip=False)
