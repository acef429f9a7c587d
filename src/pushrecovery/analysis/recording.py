"""A measured trial in body axes, and the base of support it implies.

Body axes: **ap** (anterior-posterior, forward positive), **ml** (medio-lateral, positive to
the subject's left, so that ap, ml, up is right-handed) and **up**. Every length is in metres in
the lab frame, rotated onto those axes; forces are the ground reaction force *on the subject*
[N]. A reader (:mod:`pushrecovery.analysis.readers`) turns a CSV or C3D file into a
:class:`Recording`; :mod:`pushrecovery.analysis.trial` analyses it.

Base of support. From foot markers (heel, toe and ankle of each foot), a foot supports in a
frame when its lower marker is within ``contact_height`` of the lowest that marker gets in the
trial (the foot is on the floor). Along ap the base spans the rearmost supporting heel marker
to the foremost supporting toe marker; along ml it spans the supporting feet's markers widened
by half the foot width on each side (heel and toe markers sit on the foot's midline; the ankle
marker, on the lateral malleolus, is left out). The stance ankle of the stepping model is the
supporting ankle nearest the capture point (across: the foot's midline). A frame in which any
foot's heel or toe marker is missing has no known base (the markers left would give a smaller
one).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, positive_float, require_type, whole_number
from pushrecovery.errors import InvalidParameterError

__all__ = ["AXES", "LOADED", "Foot", "Recording", "Support", "fixed_feet", "support_from_feet"]

FloatArray = NDArray[np.float64]

#: Vertical force below which a plate counts as unloaded: CoP and CMP undefined [N].
LOADED = 20.0
#: The two horizontal body axes, in output order.
AXES: tuple[str, str] = ("ap", "ml")


@dataclass(frozen=True, slots=True)
class Foot:
    """Heel, toe and ankle positions of one foot, (n, 3) arrays in body axes [m]."""

    name: str
    heel: FloatArray
    toe: FloatArray
    ankle: FloatArray


@dataclass(frozen=True, slots=True)
class Recording:
    """A measured trial, body axes, SI units; NaN marks missing samples.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Frame times of the kinematics [s], constant rate.
    com : ndarray, shape (n, 3) or None
        CoM position [m]; None when only force plates were recorded.
    com_velocity : ndarray, shape (n, 2) or None
        Measured CoM velocity (ap, ml) [m/s]; None to differentiate the position.
    feet : tuple of Foot
        Foot markers at the frame times (empty when the file has none).
    base : dict
        Explicit base of support per axis, (n, 2) [min, max] [m] (CSV columns).
    ankle : dict
        Explicit stance ankle per axis, (n,) [m] (CSV columns).
    force_time : ndarray, shape (m,) or None
        Sample times of the force-plate signals [s].
    force : ndarray, shape (m, 3) or None
        Ground reaction force on the subject (ap, ml, up) [N].
    cop : ndarray, shape (m, 2) or None
        Centre of pressure (ap, ml) [m].
    mass : float or None
        Subject mass stored in the file [kg].
    com_height : float or None
        CoM height above the ankle measured in the file [m].
    source : str
        File the trial came from.
    notes : list of str
        What the reader repaired or assumed.
    base_vertices : ndarray, shape (n, k, 2) or None
        The base of support as polygon vertices (ap, ml) per frame [m] (CSV columns
        ``base_ap1, base_ml1, ...``); NaN marks an absent vertex.
    plates : tuple of (ndarray, ndarray)
        Each force plate's vertical force (m,) [N] and CoP (m, 2) (ap, ml) [m] at
        ``force_time`` (C3D files with more than one plate): the foot events per plate.
    """

    time: FloatArray
    com: FloatArray | None = None
    com_velocity: FloatArray | None = None
    feet: tuple[Foot, ...] = ()
    base: dict[str, FloatArray] = field(default_factory=dict)
    ankle: dict[str, FloatArray] = field(default_factory=dict)
    force_time: FloatArray | None = None
    force: FloatArray | None = None
    cop: FloatArray | None = None
    mass: float | None = None
    com_height: float | None = None
    source: str = ""
    notes: list[str] = field(default_factory=list)
    base_vertices: FloatArray | None = None
    plates: tuple[tuple[FloatArray, FloatArray], ...] = ()


@dataclass(frozen=True, slots=True)
class Support:
    """Base of support per frame and the single foot's extents.

    Attributes
    ----------
    lower, upper : dict
        Per axis, (n,) base edges [m] (NaN where no foot supports).
    ankles : dict
        Per axis, (n, k) ankle positions of the k feet, NaN where a foot does not support.
    foot : dict
        Per axis, (heel, toe): the edges of one foot relative to its ankle [m].
    supporting : ndarray, shape (n, k) of bool
        Which feet support in each frame.
    """

    lower: dict[str, FloatArray]
    upper: dict[str, FloatArray]
    ankles: dict[str, FloatArray]
    foot: dict[str, tuple[float, float]]
    supporting: NDArray[np.bool_]

    def stance_ankle(self, axis: str, capture: FloatArray) -> FloatArray:
        """Return the supporting ankle nearest the capture point on ``axis`` [m], NaN if none."""
        ankles = self.ankles[axis]
        distance = np.abs(ankles - capture[:, None])
        missing = ~np.isfinite(distance).any(axis=1)
        nearest = np.argmin(np.where(np.isfinite(distance), distance, np.inf), axis=1)
        chosen = ankles[np.arange(len(ankles)), nearest]
        return np.where(missing, np.nan, chosen)


def support_from_feet(
    feet: tuple[Foot, ...], *, contact_height: float, foot_width: float
) -> Support:
    """Find the base of support from foot markers (module docstring).

    Parameters
    ----------
    feet : tuple of Foot
        At least one foot.
    contact_height : float
        A foot supports while its lower marker is within this of its lowest [m], > 0.
    foot_width : float
        Width of a foot across its markers' line [m], > 0.

    Returns
    -------
    Support

    Raises
    ------
    ParameterTypeError
        If ``feet`` is not a tuple or list of :class:`Foot`.
    InvalidParameterError
        No foot, markers that are not (n, 3) arrays of the same n, a non-positive or
        non-finite ``contact_height`` or ``foot_width``, or heel and toe markers on the wrong
        side of the ankle markers.
    """
    _check_feet(feet)
    contact_height = positive_float("contact_height", contact_height, "m")
    foot_width = positive_float("foot_width", foot_width, "m")
    heel = np.stack([f.heel for f in feet], axis=1)  # (n, k, 3)
    toe = np.stack([f.toe for f in feet], axis=1)
    ankle = np.stack([f.ankle for f in feet], axis=1)
    low = np.fmin(heel[..., 2], toe[..., 2])
    with warnings.catch_warnings():  # a foot never seen stays NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        floor = np.nanmin(low, axis=0)
    with np.errstate(invalid="ignore"):
        supporting = low <= floor + contact_height
    # A missing heel or toe marker may be an edge of the base (and its foot may be on the
    # floor or not): the base is unknown, not the smaller base of the markers left.
    unknown = ~(np.isfinite(heel).all(axis=(1, 2)) & np.isfinite(toe).all(axis=(1, 2)))
    ap = (heel[..., 0], toe[..., 0])
    # Across, heel and toe only: Plug-in Gait's ankle marker sits on the lateral malleolus.
    ml = np.stack([heel[..., 1], toe[..., 1]], axis=-1)
    hide = ~supporting
    with warnings.catch_warnings():  # frames with no supporting foot stay NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        lower = {
            "ap": np.nanmin(np.where(hide, np.nan, ap[0]), axis=1),
            "ml": np.nanmin(np.where(hide[..., None], np.nan, ml), axis=(1, 2)) - foot_width / 2,
        }
        upper = {
            "ap": np.nanmax(np.where(hide, np.nan, ap[1]), axis=1),
            "ml": np.nanmax(np.where(hide[..., None], np.nan, ml), axis=(1, 2)) + foot_width / 2,
        }
        rel_heel = np.nanmedian(np.where(hide, np.nan, heel[..., 0] - ankle[..., 0]))
        rel_toe = np.nanmedian(np.where(hide, np.nan, toe[..., 0] - ankle[..., 0]))
    if not (np.isfinite(rel_heel) and np.isfinite(rel_toe) and rel_heel < 0.0 < rel_toe):
        raise InvalidParameterError(
            "the heel markers must lie behind and the toe markers ahead of the ankle markers "
            f"along ap (got heel {rel_heel:+.3f} m, toe {rel_toe:+.3f} m from the ankle); "
            "check --ap-axis"
        )
    for edges in (lower, upper):
        for axis in AXES:
            edges[axis][unknown] = np.nan
    midline = 0.5 * (heel[..., 1] + toe[..., 1])
    ankles = {
        "ap": np.where(hide, np.nan, ankle[..., 0]),
        "ml": np.where(hide, np.nan, midline),
    }
    foot = {"ap": (float(rel_heel), float(rel_toe)), "ml": (-foot_width / 2, foot_width / 2)}
    return Support(lower, upper, ankles, foot, supporting)


def _check_feet(feet: object) -> None:
    """Refuse anything but a non-empty tuple or list of feet with (n, 3) markers of one n."""
    require_type("feet", feet, (tuple, list))
    assert isinstance(feet, tuple | list)
    if not feet:
        raise InvalidParameterError("feet must name at least one foot")
    shapes = set()
    for foot in feet:
        require_type("each of feet", foot, Foot)
        for part in (foot.heel, foot.toe, foot.ankle):
            shapes.add(np.shape(part))
    if len(shapes) != 1 or len(next(iter(shapes))) != 2 or next(iter(shapes))[1] != 3:
        raise InvalidParameterError(
            f"foot markers must be (n, 3) arrays of one n, got shapes {sorted(shapes)}"
        )


#: Most frames :func:`fixed_feet` builds (a day at 1 kHz).
MAX_FRAMES = 100_000_000


def fixed_feet(
    n: int, ankle_ap: float, ankle_ml: float, heel: float, toe: float, stance_width: float
) -> tuple[Foot, ...]:
    """Two flat feet that never move: ankles ``stance_width`` apart around (ankle_ap, ankle_ml).

    Parameters are lab positions along the body axes and the foot's edges relative to the
    ankle [m]; markers are placed on the floor (up = 0).

    Raises
    ------
    InvalidParameterError
        If ``n`` is not a whole number in [1, :data:`MAX_FRAMES`], a length is not finite,
        ``heel`` >= ``toe`` or ``stance_width`` < 0.
    """
    n = whole_number("n", n, 1, MAX_FRAMES)
    ankle_ap = finite_float("ankle_ap", ankle_ap, "m")
    ankle_ml = finite_float("ankle_ml", ankle_ml, "m")
    heel = finite_float("heel", heel, "m")
    toe = finite_float("toe", toe, "m")
    stance_width = finite_float("stance_width", stance_width, "m", allowed=">= 0")
    if heel >= toe:
        raise InvalidParameterError(f"heel must be < toe, got heel={heel:g} m, toe={toe:g} m")
    if stance_width < 0.0:
        raise InvalidParameterError(f"stance_width must be >= 0 m, got {stance_width:g}")
    feet = []
    for name, side in (("left", 0.5), ("right", -0.5)):
        ml = ankle_ml + side * stance_width

        def at(ap: float, ml: float = ml) -> FloatArray:
            return np.tile([ap, ml, 0.0], (n, 1))

        feet.append(Foot(name, at(ankle_ap + heel), at(ankle_ap + toe), at(ankle_ap)))
    return tuple(feet)
