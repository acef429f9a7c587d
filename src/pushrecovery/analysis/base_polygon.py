r"""The base of support of a measured trial as a polygon per frame (issue 18, item 2).

Ground plane in body axes: x = ap (forward +), y = ml (left +) [m]; polygons counter-clockwise.
Three sources, one output, :class:`BasePolygons` (``docs/base_polygon.md``):

1. foot markers (:func:`base_from_feet`): each foot's sole from its heel and toe (and ankle)
   markers by a :class:`FootModel`; a foot supports by the contact rule of
   :func:`pushrecovery.analysis.recording.support_from_feet` (lower marker within
   ``contact_height`` of its lowest); the base is the convex hull of the supporting soles;
2. CSV vertex columns ``base_ap1, base_ml1, ..., base_apK, base_mlK`` (:func:`base_from_vertices`,
   an (n, K, 2) array): the hull of each frame's finite vertices;
3. a stated assumption (:func:`base_from_params`): the feet of
   :meth:`pushrecovery.ground.Support.from_params`, in every frame.

A frame's base is unknown (count 0) with no supporting foot, a missing heel or toe marker, or
fewer than three vertices. Foot-marker bases also keep each foot's pose (ankle, yaw) and the
median sole about the ankle: :mod:`pushrecovery.analysis.margins.plane` builds the library's
:class:`~pushrecovery.ground.Support` of each stance phase from them for the 2-D verdicts.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.analysis.recording import MAX_FRAMES, Foot, support_from_feet
from pushrecovery.arguments import bounded_float, require_type, sample_array, whole_number
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import MIN_EDGE, ConvexPolygon, convex_hull
from pushrecovery.ground.support import FootPose, Support
from pushrecovery.kernels.hull import hull_kernel
from pushrecovery.params import BodyParams

__all__ = [
    "MAX_VERTICES",
    "BasePolygons",
    "FootModel",
    "base_from_feet",
    "base_from_params",
    "base_from_vertices",
    "foot_soles",
]

FloatArray = NDArray[np.float64]
#: Most vertices per frame of :func:`base_from_vertices` (CSV columns base_ap1 ... base_ml64).
MAX_VERTICES = 64
#: Shortest heel-to-toe marker distance on the floor that defines a foot's axis [m].
MIN_FOOT_LENGTH = 0.01
_LATERAL = ("midline", "ankle")


@dataclass(frozen=True, slots=True)
class FootModel:
    r"""How a foot's heel and toe (and ankle) markers give its sole on the floor.

    With h, T the heel and toe markers projected on the floor, u the unit vector h → T and v
    = u turned +90° (the foot's left), the sole is the rectangle

    .. math:: \{h + s u + t v : -o_h \le s \le |T - h| + o_t,\ t_- \le t \le t_+\},

    :math:`[t_-, t_+] = [-w/2, w/2]` (``lateral="midline"``: Plug-in Gait's HEE and TOE on the
    foot's long axis) or, with ``lateral="ankle"``, the lateral edge through the ankle marker's
    projection (lateral malleolus, or a 5th-metatarsal marker given in that slot) moved out by
    ``lateral_offset``, the medial edge w inside it. The defaults reproduce the 1-D base of
    :mod:`pushrecovery.analysis.recording`; the offsets are assumptions to state, not data.

    Attributes
    ----------
    width : float
        Sole width w [m], in [0.01, 0.5] (the body's ``foot_width``, preset 0.10 m).
    heel_offset, toe_offset : float
        o_h, o_t: the sole's edges behind the heel marker and ahead of the toe marker [m], in
        [−0.1, 0.1] and [−0.1, 0.2]. 0: the boundary at the markers (the usual MoS
        convention); Plug-in Gait's TOE sits on the 2nd metatarsal head, the toes' tips some
        4-6 cm further (an assumption to state).
    lateral : str
        ``"midline"`` or ``"ankle"`` (above).
    lateral_offset : float
        Lateral edge beyond the ankle marker's projection [m], in [−0.1, 0.1] (``"ankle"``).
    """

    width: float = 0.10
    heel_offset: float = 0.0
    toe_offset: float = 0.0
    lateral: str = "midline"
    lateral_offset: float = 0.0

    def __post_init__(self) -> None:
        for name, low, high in (
            ("width", 0.01, 0.5),
            ("heel_offset", -0.1, 0.1),
            ("toe_offset", -0.1, 0.2),
            ("lateral_offset", -0.1, 0.1),
        ):
            object.__setattr__(self, name, bounded_float(name, getattr(self, name), low, high, "m"))
        if not isinstance(self.lateral, str) or self.lateral not in _LATERAL:
            raise InvalidParameterError(f"lateral must be one of {_LATERAL}, got {self.lateral!r}")


@dataclass(frozen=True, slots=True, eq=False)
class BasePolygons:
    """The base of support per frame: padded convex polygons (module docstring).

    Attributes
    ----------
    vertices : ndarray, shape (n, m, 2)
        Counter-clockwise vertices (ap, ml) [m] of frame i in rows ``[:counts[i]]``; NaN
        beyond.
    counts : ndarray of int64, shape (n,)
        Vertices of each frame's polygon; 0 where the base is unknown.
    source : str
        ``"foot markers"``, ``"base vertex columns"`` or ``"stated feet"``.
    supporting : ndarray of bool, shape (n, k) or None
        Which feet support in each frame (foot markers only).
    names : tuple of str
        The feet's names (foot markers only).
    poses : ndarray, shape (n, k, 3) or None
        Each foot's ankle (ap, ml) [m] (the ankle marker projected on the foot's axis) and
        yaw [rad] (counter-clockwise from +ap), NaN where unknown (foot markers only).
    sole : tuple of float or None
        Median sole about the ankle, left-foot frame: (heel, toe, lateral, medial) [m] (heel
        < 0 behind the ankle; the edges at +lateral and −medial).
    support : Support or None
        The stated feet (:func:`base_from_params`), the same in every frame.
    """

    vertices: FloatArray
    counts: NDArray[np.int64]
    source: str
    supporting: NDArray[np.bool_] | None = None
    names: tuple[str, ...] = ()
    poses: FloatArray | None = None
    sole: tuple[float, float, float, float] | None = None
    support: Support | None = None

    def __len__(self) -> int:
        return int(self.counts.shape[0])

    @property
    def known(self) -> NDArray[np.bool_]:
        """Frames whose base is known (a polygon of 3 or more vertices)."""
        return self.counts >= 3

    @property
    def area(self) -> FloatArray:
        """Area of each frame's polygon [m²] (shoelace formula); NaN where unknown."""
        start, end, valid = edges(self)
        cross = start[..., 0] * end[..., 1] - end[..., 0] * start[..., 1]
        area = 0.5 * np.where(valid, cross, 0.0).sum(axis=1)
        return np.where(self.known, area, np.nan)

    def extents(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Smallest and largest ap, smallest and largest ml of each polygon [m]; NaN unknown."""
        hide = ~self.known[:, None, None]
        low = np.where(hide, np.nan, np.fmin.reduce(self.vertices, axis=1)[:, None])[:, 0]
        high = np.where(hide, np.nan, np.fmax.reduce(self.vertices, axis=1)[:, None])[:, 0]
        return low[:, 0], high[:, 0], low[:, 1], high[:, 1]

    def polygon(self, frame: int) -> ConvexPolygon | None:
        """Return the polygon of one frame as a :class:`~pushrecovery.ground.ConvexPolygon`."""
        frame = whole_number("frame", frame, 0, max(len(self) - 1, 0))
        count = int(self.counts[frame])
        return convex_hull(self.vertices[frame, :count]) if count >= 3 else None


def edges(base: BasePolygons) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """Start and end vertices of every edge, (n, m, 2) each, and which edges exist (n, m)."""
    m = base.vertices.shape[1]
    index = np.arange(m)[None, :]
    count = np.maximum(base.counts, 1)[:, None]
    following = np.where(index + 1 < count, index + 1, 0)
    end = np.take_along_axis(base.vertices, following[..., None], axis=1)
    return base.vertices, end, index < base.counts[:, None]


def foot_soles(foot: Foot, model: FootModel) -> FloatArray:
    """Sole corners of one foot per frame, counter-clockwise (n, 4, 2) [m]; NaN if unknown.

    The rectangle of :class:`FootModel` (module docstring) on the floor; unknown where the heel
    or toe marker is missing or they are closer than :data:`MIN_FOOT_LENGTH` on the floor, and,
    with ``lateral="ankle"``, where the ankle marker is missing.

    Raises
    ------
    PushRecoveryError
        If ``foot`` is not a Foot, ``model`` not a FootModel, or the markers are not (n, 3)
        arrays of one n (NaN: missing; infinities refused).
    """
    require_type("foot", foot, Foot)
    require_type("model", model, FootModel)
    heel, toe, ankle = (
        sample_array(f"{foot.name} {part}", getattr(foot, part), (2,), values="nan")
        for part in ("heel", "toe", "ankle")
    )
    if not heel.shape == toe.shape == ankle.shape or heel.shape[1] != 3:
        raise InvalidParameterError(
            f"foot markers must be (n, 3) arrays of one n, got {heel.shape}, {toe.shape}, "
            f"{ankle.shape}"
        )
    u, length, side = _axes(heel, toe)
    v = np.column_stack([-u[:, 1], u[:, 0]])
    back = heel[:, :2] - model.heel_offset * u
    front = toe[:, :2] + model.toe_offset * u
    if model.lateral == "midline":
        low = np.full(len(u), -0.5 * model.width)
        high = -low
    else:
        across = np.einsum("ij,ij->i", ankle[:, :2] - heel[:, :2], v)
        sign = np.where(across >= 0.0, 1.0, -1.0)
        edge = across + sign * model.lateral_offset
        low = np.minimum(edge, edge - sign * model.width)
        high = low + model.width
    lo, hi = low[:, None] * v, high[:, None] * v
    corners = np.stack([back + lo, front + lo, front + hi, back + hi], axis=1)
    corners[~(length >= MIN_FOOT_LENGTH) | ~np.isfinite(side)] = np.nan
    if model.lateral == "ankle":
        corners[~np.isfinite(ankle[:, :2]).all(axis=1)] = np.nan
    return corners


def _axes(heel: FloatArray, toe: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Return the unit heel → toe vector on the floor, its length, a finite check (NaN)."""
    d = toe[:, :2] - heel[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / length[:, None]
    return u, length, u[:, 0] + u[:, 1]


def base_from_feet(
    feet: Sequence[Foot], model: FootModel, *, contact_height: float
) -> BasePolygons:
    """Return the base of support per frame from foot markers (module docstring, source 1).

    Parameters
    ----------
    feet : tuple of Foot
        The feet (body axes, [m]); named ``left`` and ``right`` for the 2-D verdicts.
    model : FootModel
        The sole of a foot from its markers.
    contact_height : float
        A foot supports while its lower marker is within this of its lowest [m], > 0
        (:func:`~pushrecovery.analysis.recording.support_from_feet`).

    Raises
    ------
    ParameterTypeError
        If ``feet`` is not a tuple or list of Foot or ``model`` not a FootModel.
    InvalidParameterError
        As :func:`~pushrecovery.analysis.recording.support_from_feet` (no foot, bad shapes,
        non-positive ``contact_height``, heel and toe on the wrong side of the ankle).
    """
    require_type("model", model, FootModel)
    feet = tuple(feet) if isinstance(feet, list) else feet
    measured = support_from_feet(feet, contact_height=contact_height, foot_width=model.width)  # type: ignore[arg-type]
    soles = np.stack([foot_soles(foot, model) for foot in feet], axis=1)  # (n, k, 4, 2)
    known = np.asarray(np.isfinite(soles).all(axis=(1, 2, 3)), dtype=bool)
    supporting = measured.supporting & known[:, None]
    points = np.where(supporting[..., None, None], soles, np.nan).reshape(len(soles), -1, 2)
    vertices, counts = _hulls(points)
    poses, sole = _poses(tuple(feet), supporting, model)
    names = tuple(foot.name for foot in feet)
    return BasePolygons(vertices, counts, "foot markers", supporting, names, poses, sole)


def base_from_vertices(vertices: ArrayLike) -> BasePolygons:
    """Return the base of support per frame from polygon vertices (module docstring, source 2).

    Parameters
    ----------
    vertices : array_like, shape (n, k, 2)
        Vertex k of frame i, (ap, ml) [m], in any order (the base is their convex hull); NaN
        marks an absent vertex. CSV columns ``base_ap1, base_ml1, ..., base_apK, base_mlK``.

    Raises
    ------
    InvalidParameterError
        If ``vertices`` is not (n, k, 2) with 3 <= k <= :data:`MAX_VERTICES`, or has an
        infinite value.
    """
    array = sample_array("vertices", vertices, (3,), values="nan")
    if not (3 <= array.shape[1] <= MAX_VERTICES and array.shape[2] == 2):
        raise InvalidParameterError(
            f"vertices must have shape (n, k, 2) with k in [3, {MAX_VERTICES}], got {array.shape}"
        )
    if array.shape[0] > MAX_FRAMES:
        raise InvalidParameterError(f"vertices must have at most {MAX_FRAMES} frames")
    out, counts = _hulls(array)
    return BasePolygons(out, counts, "base vertex columns")


def base_from_params(
    params: BodyParams,
    n: int,
    *,
    stance: str = "double",
    left: FootPose | None = None,
    right: FootPose | None = None,
) -> BasePolygons:
    """Return the stated assumption: the feet of ``Support.from_params`` in ``n`` frames.

    ``params``, ``stance``, ``left``, ``right`` as :meth:`pushrecovery.ground.Support.from_params`
    (default: double support, ankles at (0, ±stance_width/2), yaw 0); ``n`` frames, in [1,
    :data:`~pushrecovery.analysis.recording.MAX_FRAMES`].

    Raises
    ------
    InvalidParameterError
        A bad ``n``, stance or feet (as ``Support.from_params``).
    """
    require_type("params", params, BodyParams)
    n = whole_number("n", n, 1, MAX_FRAMES)
    support = Support.from_params(params, stance, left=left, right=right)
    polygon = support.polygon.vertices
    vertices = np.broadcast_to(polygon, (n, *polygon.shape))
    counts = np.full(n, len(polygon), dtype=np.int64)
    return BasePolygons(vertices, counts, "stated feet", support=support)


def _hulls(points: FloatArray) -> tuple[FloatArray, NDArray[np.int64]]:
    """Convex hull of each frame's finite points: padded CCW vertices (NaN) and counts."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    n, k = points.shape[:2]
    out = np.full((n, k, 2), np.nan)
    counts = np.zeros(n, dtype=np.int64)
    if n:
        hull_kernel(points, out, counts, MIN_EDGE)
    used = int(counts.max()) if n else 0
    return out[:, : max(used, 3)], counts


def _poses(
    feet: tuple[Foot, ...], supporting: NDArray[np.bool_], model: FootModel
) -> tuple[FloatArray, tuple[float, float, float, float] | None]:
    """Per frame and foot (ankle ap, ankle ml, yaw), and the median sole about the ankle."""
    poses, along, length, lateral = [], [], [], []
    for i, foot in enumerate(feet):
        heel, toe, ankle = (np.asarray(getattr(foot, p), float) for p in ("heel", "toe", "ankle"))
        u, size, _ = _axes(heel, toe)
        rel = ankle[:, :2] - heel[:, :2]
        ahead = np.einsum("ij,ij->i", rel, u)
        origin = heel[:, :2] + ahead[:, None] * u
        poses.append(np.column_stack([origin, np.arctan2(u[:, 1], u[:, 0])]))
        on = supporting[:, i]
        along.append(ahead[on])
        length.append(size[on])
        lateral.append(np.abs(rel[:, 1] * u[:, 0] - rel[:, 0] * u[:, 1])[on])
    with warnings.catch_warnings():  # no supporting frame: no sole
        warnings.simplefilter("ignore", RuntimeWarning)
        s, long, side = (float(np.nanmedian(np.concatenate(a))) for a in (along, length, lateral))
    if not (math.isfinite(s) and math.isfinite(long)):
        return np.stack(poses, axis=1), None
    heel_x, toe_x = -s - model.heel_offset, long - s + model.toe_offset
    half = 0.5 * model.width
    out = half if model.lateral == "midline" else side + model.lateral_offset
    return np.stack(poses, axis=1), (heel_x, toe_x, out, model.width - out)
