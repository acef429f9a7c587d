r"""Per-frame 2-D balance measures against the base-of-support polygon (issue 18, item 2).

Body axes x = ap (forward +), y = ml (left +) [m]; the base per frame from
:mod:`pushrecovery.analysis.base_polygon`. Definitions (``docs/base_polygon.md``):

- **XCoM** (Hof, Gazendam & Sinke 2005, J Biomech 38:1-8): ξ = r + v/ω0, ω0 = sqrt(g/l) [m];
  the capture point of the LIPM.
- **Margin of stability** b: the signed Euclidean distance from ξ to the polygon's boundary,
  positive inside (Hof 2005's b, in the plane): inside the distance to the nearest edge line,
  outside minus the distance to the nearest edge segment (as
  :meth:`pushrecovery.ground.ConvexPolygon.signed_distance`).
- **Components** (Hof 2005's b_ap, b_ml): the distances from ξ to the polygon's anterior,
  posterior, left and right extremes, b_ant = max x − ξ_x, b_post = ξ_x − min x, b_left =
  max y − ξ_y, b_right = ξ_y − min y (the toe and heel markers and the feet's lateral edges,
  as these margins are usually reported); ``mos_ap`` and ``mos_ml`` pick the side the CoM is
  moving toward (sign of v; at v = 0 the nearer side). They equal the 1-D margins of
  :mod:`pushrecovery.analysis.margins` with the base's extents as the interval.
- **Time to boundary of the CoP** (Slobounov et al. 1997; van Wegen, van Emmerik & Riccio
  2002, Hum Mov Sci 21:61-84; first-order form): with the CoP p moving at its velocity ṗ,
  TtB = D(p, ṗ/‖ṗ‖)/‖ṗ‖ [s], D the distance from p along ṗ to the boundary; 0 with p outside,
  +inf with ṗ = 0.
- **Time to boundary of the XCoM** (LIPM, the CoP held): ξ̇ = ω0 (ξ − p) gives
  ξ(t) = p + (ξ − p) e^{ω0 t}, so TtB = ln(D(p, ξ − p)/‖ξ − p‖)/ω0 [s]; 0 with ξ outside,
  +inf with ξ = p (the 2-D :func:`pushrecovery.analysis.margins.time_to_leave`).
- **Verdicts**: :func:`pushrecovery.surfaces.classify.many.classify_states` against the
  library's :class:`~pushrecovery.ground.Support` of each stance phase (the CoP region, the
  CMP region P ⊕ box, the N-step regions), and the signed distance of ξ to the CMP region.

Over 400 lines on purpose: the measures share one geometry of the base's edges, computed once
per run of equal polygons (a batch's hot path, issue 34); split, it would cross modules.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.analysis.base_polygon import BasePolygons, edges
from pushrecovery.arguments import bounded_float, require_type, sample_array
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.classify.many import classify_states
from pushrecovery.surfaces.plane import cmp_margin_xy

__all__ = [
    "Margins2D",
    "margins_2d",
    "phase_supports",
    "signed_distance",
    "time_to_boundary_cop",
    "time_to_boundary_xcom",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Margins2D:
    """2-D measures of n frames (module docstring); NaN (codes −1) where unknown.

    Attributes
    ----------
    xcom : ndarray, shape (n, 2)
        ξ (ap, ml) [m].
    mos : ndarray
        Signed distance of ξ to the base's boundary, + inside [m].
    mos_ap, mos_ml : ndarray
        Component margins toward the side the CoM moves [m].
    mos_anterior, mos_posterior, mos_left, mos_right : ndarray
        Component margins to each extreme of the base [m].
    mos_cmp : ndarray
        Signed distance of ξ to the CMP region of the phase's Support [m].
    ttb_cop, ttb_xcom : ndarray
        Times to boundary of the CoP and of the XCoM [s].
    base_area : ndarray
        Area of the base [m²].
    strategy : ndarray of int8
        Codes into :data:`~pushrecovery.surfaces.strategy.STRATEGY_CODES`, −1 unknown.
    """

    xcom: FloatArray
    mos: FloatArray
    mos_ap: FloatArray
    mos_ml: FloatArray
    mos_anterior: FloatArray
    mos_posterior: FloatArray
    mos_left: FloatArray
    mos_right: FloatArray
    mos_cmp: FloatArray
    ttb_cop: FloatArray
    ttb_xcom: FloatArray
    base_area: FloatArray
    strategy: NDArray[np.int8]

    def to_columns(self) -> dict[str, NDArray[np.float64] | NDArray[np.int8]]:
        """Per-frame table columns (``docs/base_polygon.md``): metres, seconds, m², codes."""
        columns: dict[str, NDArray[np.float64] | NDArray[np.int8]] = {
            "xcom_ap": self.xcom[:, 0],
            "xcom_ml": self.xcom[:, 1],
        }
        for field in dataclasses.fields(self)[1:]:
            name = "strategy_2d" if field.name == "strategy" else field.name
            columns[name] = getattr(self, field.name)
        return columns


def signed_distance(base: BasePolygons, points: ArrayLike) -> FloatArray:
    """Signed distance of one point per frame to that frame's polygon, + inside [m].

    Inside min_i (b_i − n_i · p) (nearest edge line), outside −min_i dist(p, edge segment_i), as
    :meth:`pushrecovery.ground.ConvexPolygon.signed_distance`, over every frame at once.

    Raises
    ------
    PushRecoveryError
        If ``base`` is not a BasePolygons or ``points`` is not (n, 2) for its n frames (NaN:
        missing, NaN out; infinities refused).
    """
    require_type("base", base, BasePolygons)
    p = _frames("points", points, len(base))
    return _signed(_geometry(base), p)


def _frames(name: str, value: ArrayLike, n: int) -> FloatArray:
    """Return an (n, 2) float array (NaN missing) or raise naming ``name``."""
    array = sample_array(name, value, (2,), values="nan")
    if array.shape != (n, 2):
        raise InvalidParameterError(f"{name} must have shape ({n}, 2), got {array.shape}")
    return array


class _Geometry(NamedTuple):
    """Edge starts, vectors, unit outward normals (n, m, 2), lengths (n, m) (NaN unused), known.

    Computed once per run of frames with the same polygon (fixed feet: one for the whole
    trial) and spread to the frames as read-only views: the same numbers as frame by frame.
    """

    start: FloatArray
    vector: FloatArray
    normal: FloatArray
    length: FloatArray
    known: NDArray[np.bool_]


def _geometry(base: BasePolygons) -> _Geometry:
    """Return the edges of every frame's polygon (:class:`_Geometry`)."""
    n = len(base)
    bits = base.vertices.reshape(n, -1).view(np.int64)  # bit patterns: NaN pads, signed zeros
    same = (bits[1:] == bits[:-1]).all(axis=1) & (base.counts[1:] == base.counts[:-1])
    first = np.flatnonzero(np.concatenate([[True], ~same])) if n else np.zeros(0, np.int64)
    unique = dataclasses.replace(base, vertices=base.vertices[first], counts=base.counts[first])
    start, end, valid = edges(unique)
    vector = np.where(valid[..., None], end - start, np.nan)
    length = np.hypot(vector[..., 0], vector[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        normal = np.stack([vector[..., 1], -vector[..., 0]], axis=-1) / length[..., None]
    arrays = [start, vector, normal, length]
    if len(first) == 1:
        arrays = [np.broadcast_to(a, (n, *a.shape[1:])) for a in arrays]
    elif len(first) < n:
        arrays = [a[np.cumsum(np.concatenate([[False], ~same]))] for a in arrays]
    return _Geometry(arrays[0], arrays[1], arrays[2], arrays[3], base.known)


def _fold(ufunc: np.ufunc, values: FloatArray) -> FloatArray:
    """``ufunc.reduce(values, axis=1)`` of an (n, m) array, column by column (faster, small m)."""
    out = values[:, 0].copy()
    for k in range(1, values.shape[1]):
        ufunc(out, values[:, k], out=out)
    return out


def _signed(geometry: _Geometry, p: FloatArray) -> FloatArray:
    start, vector, normal, length, known = geometry
    rel = p[:, None, :] - start
    with np.errstate(invalid="ignore", divide="ignore"):
        excess = _fold(np.fmax, np.einsum("fmk,fmk->fm", normal, rel))
        along = np.clip(np.einsum("fmk,fmk->fm", rel, vector) / length**2, 0.0, 1.0)
        gap = _fold(np.fmin, np.hypot(*np.moveaxis(rel - along[..., None] * vector, -1, 0)))
    out = np.where(excess <= 0.0, -excess, -gap)
    return np.where(known & np.isfinite(p).all(axis=1), out, np.nan)


def _ray(geometry: _Geometry, origin: FloatArray, direction: FloatArray) -> FloatArray:
    """Distance from a point of each polygon along a unit direction to its boundary [m]."""
    start, _, normal, _, _ = geometry
    rate = np.einsum("fmk,fk->fm", normal, direction)
    gap = -np.einsum("fmk,fmk->fm", normal, origin[:, None, :] - start)
    # A ray all but parallel to an edge (a subnormal rate) reaches it at infinity: no warning.
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ahead = np.where(rate > 0.0, np.maximum(gap, 0.0) / rate, np.inf)
    return _fold(np.minimum, ahead)


def _nearest(geometry: _Geometry, p: FloatArray, signed: FloatArray) -> FloatArray:
    """Return the polygon's point nearest each p (p itself inside; ``signed``: p's) [m]."""
    start, vector, _, length, _ = geometry
    rel = p[:, None, :] - start
    with np.errstate(invalid="ignore", divide="ignore"):
        along = np.clip(np.einsum("fmk,fmk->fm", rel, vector) / length**2, 0.0, 1.0)
    foot = start + along[..., None] * vector
    gap = np.where(np.isfinite(length), np.hypot(*np.moveaxis(p[:, None] - foot, -1, 0)), np.inf)
    best = np.take_along_axis(foot, np.argmin(gap, axis=1)[:, None, None], axis=1)[:, 0]
    return np.where((signed > 0.0)[:, None], p, best)


def time_to_boundary_cop(base: BasePolygons, cop: ArrayLike, cop_velocity: ArrayLike) -> FloatArray:
    """CoP time to boundary at constant velocity (module docstring) [s].

    Raises
    ------
    PushRecoveryError
        If ``base`` is not a BasePolygons or ``cop`` [m], ``cop_velocity`` [m/s] are not (n, 2)
        for its n frames (NaN: missing; infinities refused).
    """
    require_type("base", base, BasePolygons)
    p = _frames("cop", cop, len(base))
    return _ttb_cop(_geometry(base), p, _frames("cop_velocity", cop_velocity, len(base)))


def _ttb_cop(
    geometry: _Geometry, p: FloatArray, velocity: FloatArray, signed: FloatArray | None = None
) -> FloatArray:
    """:func:`time_to_boundary_cop` of checked arrays (``signed``: the CoP's, if known)."""
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        reach = _ray(geometry, p, velocity / speed[:, None])
        time = np.where(speed > 0.0, reach / speed, np.inf)
    time = np.where((_signed(geometry, p) if signed is None else signed) > 0.0, time, 0.0)
    return np.where(np.isfinite(speed) & geometry.known & np.isfinite(p).all(axis=1), time, np.nan)


def time_to_boundary_xcom(
    base: BasePolygons, xcom: ArrayLike, cop: ArrayLike, omega: float
) -> FloatArray:
    """XCoM time to boundary with the CoP held, LIPM (module docstring) [s].

    A CoP beyond the base is taken at the base's nearest point (a measured CoP a hair outside
    the computed base lies on it).

    Raises
    ------
    PushRecoveryError
        If ``base`` is not a BasePolygons, ``xcom`` or ``cop`` [m] is not (n, 2) (NaN: missing;
        infinities refused), or ``omega`` is outside [0.1, 100] 1/s.
    """
    require_type("base", base, BasePolygons)
    xi = _frames("xcom", xcom, len(base))
    p = _frames("cop", cop, len(base))
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    geometry = _geometry(base)
    return _ttb_xcom(geometry, xi, p, omega, _signed(geometry, xi), _signed(geometry, p))


def _ttb_xcom(
    geometry: _Geometry, xi: FloatArray, p: FloatArray, omega: float, *signed: FloatArray
) -> FloatArray:
    """:func:`time_to_boundary_xcom` of checked arrays and their ``signed`` distances."""
    anchor = _nearest(geometry, p, signed[1])
    delta = xi - anchor
    size = np.hypot(delta[:, 0], delta[:, 1])
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        reach = _ray(geometry, anchor, delta / size[:, None])
        time = np.where(size > 0.0, np.log(np.maximum(reach / size, 1.0)) / omega, np.inf)
    time = np.where(signed[0] > 0.0, time, 0.0)
    return np.where(np.isfinite(size) & geometry.known, time, np.nan)


def phase_supports(
    base: BasePolygons, params: BodyParams
) -> tuple[tuple[Support | None, ...], NDArray[np.int64], BodyParams | None]:
    """Return the Support of each stance phase, the phase of each frame, and the body.

    Stated feet: their Support in every frame. Foot markers (two feet named left and right):
    one Support per run of frames with the same supporting feet, the feet at the run's median
    ankle and circular-mean yaw, the sole the base's median sole (``params`` with ``heel``,
    ``toe``, ``foot_width``, ``foot_polygon`` replaced); None for a phase the library refuses
    (overlapping feet, ankles two legs apart). CSV vertices: none (phase −1).

    Raises
    ------
    ParameterTypeError
        If ``base`` is not a BasePolygons or ``params`` not a BodyParams.
    """
    require_type("base", base, BasePolygons)
    require_type("params", params, BodyParams)
    n = len(base)
    phase = np.full(n, -1, dtype=np.int64)
    if base.support is not None:
        return (base.support,), np.where(base.known, 0, -1), params
    names = [name.lower() for name in base.names]
    if base.poses is None or base.supporting is None or sorted(names) != ["left", "right"]:
        return (), phase, None
    body = _body(params, base.sole)
    if body is None:
        return (), phase, None
    left, right = names.index("left"), names.index("right")
    code = base.supporting[:, left] * 1 + base.supporting[:, right] * 2
    code = np.where(base.known, code, 0)
    starts = np.flatnonzero(np.diff(code, prepend=-1) != 0)
    ends = np.append(starts[1:], n)
    supports: list[Support | None] = []
    stances = {1: Stance.LEFT, 2: Stance.RIGHT, 3: Stance.DOUBLE}
    for start, end in zip(starts.tolist(), ends.tolist(), strict=True):
        if code[start] == 0:
            continue
        stance = stances[int(code[start])]
        feet = [_median_pose(base.poses[start:end, i]) for i in (left, right)]
        mine = feet[0] if stance is Stance.LEFT else feet[1]
        try:
            support: Support | None = Support.from_params(
                body, stance, left=feet[0] or mine, right=feet[1] or mine
            )
        except PushRecoveryError:
            support = None
        phase[start:end] = len(supports)
        supports.append(support)
    return tuple(supports), phase, body


def _body(params: BodyParams, sole: tuple[float, float, float, float] | None) -> BodyParams | None:
    """Return the body with the measured sole (left-foot frame), None if refused."""
    if sole is None:
        return None
    heel, toe, outer, inner = sole
    polygon = (
        None if outer == inner else ((heel, -inner), (toe, -inner), (toe, outer), (heel, outer))
    )
    try:
        return dataclasses.replace(
            params, heel=heel, toe=toe, foot_width=outer + inner, foot_polygon=polygon
        )
    except PushRecoveryError:
        return None


def _median_pose(poses: FloatArray) -> FootPose | None:
    """Median ankle and circular-mean yaw of a run of (x, y, yaw); None if all missing."""
    rows = poses[np.isfinite(poses).all(axis=1)]
    if not len(rows):
        return None
    yaw = math.atan2(float(np.sin(rows[:, 2]).mean()), float(np.cos(rows[:, 2]).mean()))
    return FootPose(float(np.median(rows[:, 0])), float(np.median(rows[:, 1])), yaw)


def margins_2d(
    base: BasePolygons,
    com: ArrayLike,
    velocity: ArrayLike,
    params: BodyParams,
    *,
    omega: float | None = None,
    cop: ArrayLike | None = None,
    cop_velocity: ArrayLike | None = None,
    verdicts: bool = True,
) -> Margins2D:
    """Per-frame 2-D margins, times to boundary and verdicts (module docstring).

    Parameters
    ----------
    base : BasePolygons
        The base per frame.
    com, velocity : array_like, shape (n, 2)
        CoM (ap, ml) [m] and its velocity [m/s]; NaN: missing frame.
    params : BodyParams
        The body (ω, the hip and step limits of the verdicts).
    omega : float, optional
        ω0 = sqrt(g/l) of the XCoM [1/s], in [0.1, 100]; default ``params.omega``. The verdicts
        always use the body's ω.
    cop, cop_velocity : array_like, shape (n, 2), optional
        CoP [m] and its velocity [m/s] for the times to boundary (NaN without).
    verdicts : bool
        Compute ``strategy`` and ``mos_cmp`` (one classifier call per stance phase).

    Raises
    ------
    PushRecoveryError
        A wrong type, an array not (n, 2) for the base's n frames, an infinity, or ``omega``
        out of range.
    """
    require_type("base", base, BasePolygons)
    require_type("params", params, BodyParams)
    require_type("verdicts", verdicts, bool)
    n = len(base)
    r, v = _frames("com", com, n), _frames("velocity", velocity, n)
    omega = params.omega if omega is None else omega
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    with np.errstate(over="ignore", invalid="ignore"):
        xi = r + v / omega
    known = (np.isfinite(r) & np.isfinite(v)).all(axis=1)
    if not np.isfinite(xi[known]).all():
        raise InvalidParameterError("states are too large: the XCoM overflows")
    xi[~known] = np.nan  # a frame is known or missing
    geometry = _geometry(base)
    mos = _signed(geometry, xi)
    xmin, xmax, ymin, ymax = base.extents()
    sides = (xmax - xi[:, 0], xi[:, 0] - xmin, ymax - xi[:, 1], xi[:, 1] - ymin)
    toward = [
        np.where(v[:, k] > 0.0, sides[2 * k], np.where(v[:, k] < 0.0, sides[2 * k + 1], near))
        for k, near in enumerate((np.fmin(sides[0], sides[1]), np.fmin(sides[2], sides[3])))
    ]
    nan = np.full(n, np.nan)
    ttb_cop = ttb_xcom = nan
    cop_rate = None if cop_velocity is None else _frames("cop_velocity", cop_velocity, n)
    if cop_rate is not None and cop is None:
        raise InvalidParameterError("cop_velocity needs cop (the time to boundary of the CoP)")
    if cop is not None:
        p = _frames("cop", cop, n)
        signed_p = _signed(geometry, p)
        ttb_xcom = _ttb_xcom(geometry, xi, p, omega, mos, signed_p)
        if cop_rate is not None:
            ttb_cop = _ttb_cop(geometry, p, cop_rate, signed_p)
    codes = np.full(n, -1, dtype=np.int8)
    mos_cmp = nan.copy()
    if verdicts:
        _verdicts(base, r, v, params, codes, mos_cmp)
    return Margins2D(
        xi, mos, toward[0], toward[1], sides[0], sides[1], sides[2], sides[3], mos_cmp,
        ttb_cop, ttb_xcom, base.area, codes,
    )  # fmt: skip


def _verdicts(
    base: BasePolygons,
    r: FloatArray,
    v: FloatArray,
    params: BodyParams,
    codes: NDArray[np.int8],
    mos_cmp: FloatArray,
) -> None:
    """Fill the codes and CMP margins of the frames of each phase with a Support."""
    supports, phase, body = phase_supports(base, params)
    if body is None:
        return
    state = np.isfinite(r).all(axis=1) & np.isfinite(v).all(axis=1)
    for index, support in enumerate(supports):
        rows = np.flatnonzero((phase == index) & state)
        if support is None or not rows.size:
            continue
        x, y, xd, yd = r[rows, 0], r[rows, 1], v[rows, 0], v[rows, 1]
        codes[rows] = classify_states(x, xd, body, y=y, ydot=yd, support=support)
        mos_cmp[rows] = cmp_margin_xy(x, y, xd, yd, support, body)
