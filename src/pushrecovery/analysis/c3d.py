r"""Read and write C3D motion-capture files: markers and force plates, SI units, lab frame.

:func:`read_c3d` returns the markers [m] and, per force plate, the ground reaction force on the
subject [N], the centre of pressure (CoP) [m] and the free moment [N m], all in the lab frame;
:func:`write_c3d` writes the same quantities as a file that third-party readers understand.
The file is parsed by ``ezc3d``; the force-plate computations are ours (pure numpy, below), because
vendors disagree on conventions that ezc3d passes through (see "ezc3d" at the end).

Conventions
-----------
Lab frame
    The file's own frame, z up as Vicon and Qualisys write it (a file whose ``POINT:Y_SCREEN``
    names another axis, e.g. ``+Y``, has that axis taken as up instead).
Plate frame (:func:`plate_frame`)
    The C3D spec numbers ``FORCE_PLATFORM:CORNERS`` by the quadrants of the plate's own frame:
    1 = (+x, +y), 2 = (−x, +y), 3 = (−x, −y), 4 = (+x, −y). Hence
    x̂ ∝ (c1 − c2) + (c4 − c3) and ŷ ∝ (c1 − c4) + (c2 − c3) (each the mean of two parallel
    edges; ŷ is then made orthogonal to x̂; corners listed crossed fall back on corner 1's
    edges c1 − c2 and c1 − c4, as ezc3d uses). The plate's z axis points *into* the plate, away
    from the subject, as on every manufacturer's plate and in the spec; the centre is the mean
    of the corners, the centre of the top surface. For corners in spec order seen from above
    (clockwise in a z-up lab) ẑ = x̂ × ŷ. BioWare lists them the other way round (its own frame
    is z-down), so x̂ × ŷ points up; we keep x̂ and ŷ from the corners, so that the CoP lands
    where the corners say, and take ẑ = −x̂ × ŷ: that frame is a reflection (det −1).
Plate types (``FORCE_PLATFORM:TYPE``), all reduced to the force and the moment about the
centre of the top surface, in the plate frame (:func:`wrench_type2` etc.)
    1: Fx Fy Fz, CoP px py (relative to the plate centre, plate frame), Tz.
    2: Fx Fy Fz Mx My Mz about the transducer origin; ``ORIGIN`` is the vector from that origin
    to the top-surface centre, so its z is < 0. A file with z > 0 stores the manufacturer's
    vector from the surface centre to the origin (AMTI's old sheets): we negate it, as ezc3d.
    3: Kistler, 8 channels fx12 fx34 fy14 fy23 fz1 fz2 fz3 fz4; ``ORIGIN`` = (a, b, az0),
    a and b the sensor offsets (magnitudes), az0 the depth of the sensor plane (files store it
    with either sign; it is −|z| in the z-down frame).
    4: type 2 after ``FORCE_PLATFORM:CAL_MATRIX`` (channels ← CAL_MATRIX · channels; an empty
    matrix is the identity, as Motion Analysis writes it).
    ``FORCE_PLATFORM:ZERO`` (baseline frames) is not applied: in kistler_COP.c3d it names
    frames where the subject already stands on the plate. ``FPCOPPOLY`` (Kistler's CoP
    correction) is not applied.
Units
    Channels follow ``ANALOG:UNITS`` (N, kN; N.m, Nm, N mm, Nmm, ...; mm, cm, m for type-1
    CoP channels); a channel without units is taken as N, N·(point unit) or (point unit), the
    C3D default. ``ORIGIN`` and ``CORNERS`` are in ``POINT:UNITS`` (mm when empty, as in
    BioWare's files). Type-4 channels in volts give N and N·(point unit) after calibration.
Action or reaction
    The spec does not fix whether the channels hold the force on the plate or on the subject:
    amplifiers (AMTI, Kistler, BioWare's exports) give the force on the plate, Fz > 0 under
    load in the z-down frame, while Vicon Nexus stores Fz < 0 under load. A plate can only be
    pushed, so the wrench is multiplied by the sign of the summed Fz of the whole trial (+1 if
    that sum is 0): afterwards Fz > 0 means load.
Outputs (:class:`ForcePlate`)
    ``force`` = −R F, the reaction on the subject in the lab (R = plate frame, F the force on the
    plate): vertical > 0 when loaded. ``cop`` = centre + R c, c = (−My/Fz, Mx/Fz, 0) from the
    moment about the top-surface centre; NaN where Fz < ``threshold``. ``free_moment`` =
    Mz − cx Fy + cy Fx, the moment of the plate about the upward normal through the CoP, acting
    on the subject (right-hand rule about up = the force on the plate's Tz about the z-down
    axis).

Writing (:func:`write_c3d`)
    Markers in mm (``POINT:UNITS`` "mm"), float storage, residual 0 where valid and −1 (with
    zero coordinates) where NaN. Each plate is TYPE 2: Fx Fy Fz [N], Mx My Mz [N mm] of the force
    on the plate in its z-down frame about the top-surface centre, ``ORIGIN`` (0, 0, 0) (so no
    reader's guess about ORIGIN's sign matters), ``CORNERS`` in mm in the spec's order
    (clockwise seen from above). The mass goes to ``PROCESSING:Bodymass`` [kg] (Vicon's).

ezc3d, checked empirically (ezc3d 1.7.2; tests/test_c3d.py)
    ``c['data']['analogs']`` is already scaled, (stored − OFFSET) × SCALE × GEN_SCALE (the
    OFFSET part from ezc3d's source: these files have none): in kistler_COP.c3d every value
    divided by its ``ANALOG:SCALE`` is an integer ADC count and matches the vendor's newtons.
    Points with a negative residual come back as NaN. The header's ``first_frame`` is 0-based
    (the file's first frame − 1). ezc3d stops silently at the end of a truncated file and
    shrinks the header to match; we compare the file size with the header.
    Its force-plate module (``extract_forceplat_data=True``) reports R·channels without deciding
    action or reaction: for our files ``force`` is the force on the plate (−``force`` here),
    ``center_of_pressure`` equals ours (in mm), ``Tz`` is (0, 0, −free moment) [N mm]. For a
    type-3 file with ORIGIN z > 0 (kistler_COP.c3d) it negates the whole ORIGIN, so a and b
    change sign with az0, and its right-handed frame from the anticlockwise corners has z up:
    its CoP is the centre + (cx, cy) + 2|az0|(Fx, Fy)/Fz where ours is the centre − (cx, cy)
    (mirrored through the centre and a 2·58 mm lever on the shear), its force (−Fx, −Fy, Fz)
    where ours is (Fx, Fy, Fz).

Checked against a vendor (kistler_COP.c3d and BioWare's export of it, tests/test_c3d.py)
    BioWare's 50 Hz rows are single 1 kHz samples at t = k · 20 ms, not 20-sample means. Our
    plate-frame CoP from the file differs from BioWare's by at most 0.16 mm (RMS 0.06 mm) over
    all 500 rows; most of it because BioWare used az0 = −57 mm where the file stores 58 mm.
    The mean vertical force, 666.3 N, is the vendor's within 0.05 N.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.errors import InputFileError, InvalidParameterError

__all__ = [
    "C3DContent",
    "ForcePlate",
    "plate_cop_in_plate_frame",
    "plate_frame",
    "read_c3d",
    "wrench_type2",
    "wrench_type3",
    "wrench_type4",
    "write_c3d",
]

FloatArray = NDArray[np.float64]

#: Length units [m per unit] accepted in POINT:UNITS and type-1 CoP channels.
_LENGTH_UNITS: dict[str, float] = {
    "mm": 1e-3,
    "millimeter": 1e-3,
    "millimeters": 1e-3,
    "millimetre": 1e-3,
    "millimetres": 1e-3,
    "cm": 1e-2,
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
}
#: Force units [N per unit].
_FORCE_UNITS: dict[str, float] = {"n": 1.0, "newton": 1.0, "newtons": 1.0, "kn": 1e3}
#: Moment units [N m per unit], after dropping separators (".", " ", "*", "·", "-").
_MOMENT_UNITS: dict[str, float] = {"nm": 1.0, "nmm": 1e-3, "ncm": 1e-2, "knm": 1e3}
#: Mass units [kg per unit].
_MASS_UNITS: dict[str, float] = {"kg": 1.0, "g": 1e-3, "lb": 0.45359237, "lbs": 0.45359237}
#: Where labs store the subject's mass: (group, parameter), looked up case-insensitively.
_MASS_PARAMETERS = (
    ("PROCESSING", "BODYMASS"),
    ("PROCESSING", "MASS"),
    ("SUBJECTS", "MASS"),
    ("SUBJECTS", "WEIGHT"),
    ("SUBJECT", "MASS"),
    ("SUBJECT", "WEIGHT"),
)
#: Channel kinds per plate type: F force, M moment, L length (type-1 CoP).
_CHANNEL_KINDS: dict[int, str] = {1: "FFFLLM", 2: "FFFMMM", 3: "FFFFFFFF", 4: "FFFMMM"}
_WRITE_LABELS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
_WRITE_UNITS = ("N", "N", "N", "Nmm", "Nmm", "Nmm")


# --- Results ---------------------------------------------------------------------------------
# eq=False: the fields are arrays, whose == is elementwise; identity is the honest equality.
@dataclass(frozen=True, slots=True, eq=False)
class ForcePlate:
    """One force plate at the analog rate, lab frame, SI units.

    Parameters
    ----------
    force : ndarray, shape (n, 3)
        Ground reaction force on the subject [N]: minus the force the subject applies to the
        plate; its vertical component is > 0 when someone stands on the plate.
    cop : ndarray, shape (n, 3)
        Centre of pressure on the plate's top surface [m]; NaN where the load (the force on the
        plate along its z-down normal) is below the reader's ``threshold``.
    free_moment : ndarray, shape (n,)
        Moment about the plate's upward normal through the CoP acting on the subject [N m],
        right-hand rule (> 0 turns the subject anticlockwise seen from above); NaN where
        ``cop`` is.
    corners : ndarray, shape (4, 3)
        Plate corners in the file's order (C3D quadrants +x+y, −x+y, −x−y, +x−y) [m].
    """

    force: FloatArray
    cop: FloatArray
    free_moment: FloatArray
    corners: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class C3DContent:
    """What :func:`read_c3d` found in a file, lab frame, SI units.

    Parameters
    ----------
    point_rate : float or None
        Marker frame rate [Hz]; None when the file has no markers.
    markers : dict of str to ndarray, shape (n_points, 3)
        Label -> position [m]; NaN where the marker is missing (negative residual, or all three
        coordinates exactly 0, which many systems write for gaps).
    analog_rate : float or None
        Analog sample rate [Hz]; None without analog channels.
    plates : tuple of ForcePlate
        The force plates, at the analog rate.
    mass : float or None
        Subject mass [kg] when the file stores it (``PROCESSING:Bodymass``,
        ``SUBJECTS:MASS``/``WEIGHT``, ...), else None.
    point_units : str
        ``POINT:UNITS`` as written in the file, e.g. ``"mm"`` ("" when absent; mm is assumed).
    first_time : float
        Time of the first frame [s]: (header first frame − 1) / point_rate; 0 without markers.
    n_points : int
        Number of marker frames (0 without markers).
    n_analog : int
        Number of analog samples (0 without analog channels).
    up : ndarray, shape (3,)
        The lab's up axis (``POINT:Y_SCREEN``, default +z).
    """

    point_rate: float | None
    markers: dict[str, FloatArray]
    analog_rate: float | None
    plates: tuple[ForcePlate, ...]
    mass: float | None
    point_units: str
    first_time: float
    n_points: int = field(default=0)
    n_analog: int = field(default=0)
    up: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))

    @property
    def point_time(self) -> FloatArray:
        """Time of each marker frame [s], shape (n_points,); empty without markers."""
        if self.point_rate is None:
            return np.zeros(0)
        return self.first_time + np.arange(self.n_points) / self.point_rate

    @property
    def analog_time(self) -> FloatArray:
        """Time of each analog sample [s], shape (n_analog,); empty without analogs."""
        if self.analog_rate is None:
            return np.zeros(0)
        return self.first_time + np.arange(self.n_analog) / self.analog_rate


# --- Pure plate geometry and wrenches ----------------------------------------------------------
def plate_frame(
    corners: ArrayLike, up: ArrayLike = (0.0, 0.0, 1.0)
) -> tuple[FloatArray, FloatArray]:
    """Rotation plate -> lab and the top-surface centre of a force plate, from its corners.

    Parameters
    ----------
    corners : array_like, shape (4, 3)
        Corners in the lab frame, in C3D order: the (+x, +y), (−x, +y), (−x, −y), (+x, −y)
        quadrants of the plate frame. Any length unit; ``centre`` comes out in it.
    up : array_like, shape (3,)
        The lab's up direction (default +z); only its sign relative to the plate's normal is
        used.

    Returns
    -------
    rotation : ndarray, shape (3, 3)
        Columns x̂, ŷ, ẑ of the plate frame in lab coordinates (lab = rotation @ plate).
        x̂ ∝ (c1 − c2) + (c4 − c3); ŷ ∝ (c1 − c4) + (c2 − c3) made orthogonal to x̂ (for corners
        listed crossed, where these vanish, x̂ ∝ c1 − c2 and ŷ ∝ c1 − c4 as in ezc3d);
        ẑ = ±x̂ × ŷ, the sign chosen so that ẑ points down (into the plate). For corners
        listed anticlockwise seen from above (BioWare) ẑ = −x̂ × ŷ and ``det(rotation) = −1``;
        a plate on a wall (normal ⟂ up) keeps the right-handed ẑ = x̂ × ŷ.
    centre : ndarray, shape (3,)
        Mean of the corners: the centre of the top surface.

    Raises
    ------
    InvalidParameterError
        If ``corners`` is not (4, 3), not finite, or degenerate (no area).
    """
    points = np.asarray(corners, dtype=np.float64)
    if points.shape != (4, 3) or not np.isfinite(points).all():
        raise InvalidParameterError(
            f"corners must be a finite (4, 3) array, got shape {np.shape(points)}"
        )
    c1, c2, c3, c4 = points
    size = float(np.abs(points - points.mean(axis=0)).max())
    x_axis = (c1 - c2) + (c4 - c3)  # the +x corners minus the -x corners
    y_axis = (c1 - c4) + (c2 - c3)
    normal = np.cross(x_axis, y_axis)
    if np.linalg.norm(normal) <= 1e-6 * size**2:
        # Corners listed crossed (kistler_DJ_2plates.c3d's second plate): trust corner 1 and
        # its two neighbours, as ezc3d does.
        x_axis, y_axis = c1 - c2, c1 - c4
        normal = np.cross(x_axis, y_axis)
    if size == 0.0 or np.linalg.norm(normal) <= 1e-6 * size**2:
        raise InvalidParameterError("corners must span a plate (they are collinear or equal)")
    x_hat = x_axis / np.linalg.norm(x_axis)
    normal /= np.linalg.norm(normal)
    y_hat = np.cross(normal, x_hat)  # in-plane, ⟂ x̂, on ŷ's side
    z_hat = -normal if float(np.dot(normal, np.asarray(up, dtype=np.float64))) > 0.0 else normal
    return np.column_stack([x_hat, y_hat, z_hat]), points.mean(axis=0)


def wrench_type2(channels: ArrayLike, origin: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Force and moment about the top-surface centre from type-2 channels (plate frame, SI).

    Parameters
    ----------
    channels : array_like, shape (n, 6)
        Fx, Fy, Fz [N] and Mx, My, Mz [N m] about the transducer origin, plate frame.
    origin : array_like, shape (3,)
        ``FORCE_PLATFORM:ORIGIN`` [m]: the vector from the transducer origin to the centre of
        the top surface (z < 0 in the z-down frame). Stored with z > 0, it is the vector the
        other way round (the manufacturer's sheet) and is negated.

    Returns
    -------
    force : ndarray, shape (n, 3)
        [N], same sign convention as the channels.
    moment : ndarray, shape (n, 3)
        About the top-surface centre [N m]: M + F × origin.
    """
    data = _channels(channels, 6)
    vector = _vector3("origin", origin)
    if vector[2] > 0.0:
        vector = -vector
    force = data[:, :3]
    return force, data[:, 3:] + np.cross(force, vector)


def wrench_type3(channels: ArrayLike, origin: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Force and moment about the top-surface centre from Kistler's 8 channels (plate frame).

    Kistler's formulas with a = |origin x|, b = |origin y|, az0 = −|origin z|:
    F = (fx12 + fx34, fy14 + fy23, fz1 + fz2 + fz3 + fz4),
    Mx = b (fz1 + fz2 − fz3 − fz4) + Fy az0, My = a (−fz1 + fz2 + fz3 − fz4) − Fx az0,
    Mz = b (−fx12 + fx34) + a (fy14 − fy23). Sensor 1 sits at (+a, +b), 2 at (−a, +b),
    3 at (−a, −b), 4 at (+a, −b), the sensor plane |az0| below the top surface.

    Parameters
    ----------
    channels : array_like, shape (n, 8)
        fx12, fx34, fy14, fy23, fz1, fz2, fz3, fz4 [N].
    origin : array_like, shape (3,)
        ``FORCE_PLATFORM:ORIGIN`` (a, b, az0) [m]; signs are ignored (files differ).

    Returns
    -------
    force : ndarray, shape (n, 3)
        [N], the force on the plate for raw Kistler channels (Fz > 0 under load).
    moment : ndarray, shape (n, 3)
        About the top-surface centre [N m].
    """
    data = _channels(channels, 8)
    a, b, depth = np.abs(_vector3("origin", origin))
    az0 = -depth
    fx12, fx34, fy14, fy23, fz1, fz2, fz3, fz4 = data.T
    fx, fy = fx12 + fx34, fy14 + fy23
    force = np.column_stack([fx, fy, fz1 + fz2 + fz3 + fz4])
    moment = np.column_stack(
        [
            b * (fz1 + fz2 - fz3 - fz4) + fy * az0,
            a * (-fz1 + fz2 + fz3 - fz4) - fx * az0,
            b * (-fx12 + fx34) + a * (fy14 - fy23),
        ]
    )
    return force, moment


def wrench_type4(
    channels: ArrayLike, origin: ArrayLike, cal_matrix: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Type 4: :func:`wrench_type2` of the channels calibrated by ``cal_matrix`` (6 × 6).

    Parameters
    ----------
    channels : array_like, shape (n, 6)
        Raw channels, in units that ``cal_matrix`` turns into N and N m.
    origin : array_like, shape (3,)
        As in :func:`wrench_type2` [m].
    cal_matrix : array_like, shape (6, 6)
        Calibrated = ``cal_matrix @ raw`` for each sample (the C3D parameter's first index is
        the row, as ezc3d reads it).
    """
    matrix = np.asarray(cal_matrix, dtype=np.float64)
    if matrix.shape != (6, 6) or not np.isfinite(matrix).all():
        raise InvalidParameterError(
            f"cal_matrix must be a finite (6, 6) array, got shape {matrix.shape}"
        )
    return wrench_type2(_channels(channels, 6) @ matrix.T, origin)


def plate_cop_in_plate_frame(
    force: ArrayLike, moment: ArrayLike, *, threshold: float = 20.0
) -> tuple[FloatArray, FloatArray]:
    """CoP and free moment in the plate frame from the wrench about the top-surface centre.

    The force acts at c = (cx, cy, 0) on the top surface with a free moment Tz about the
    plate's z axis only, so M = c × F + (0, 0, Tz): cx = −My/Fz, cy = Mx/Fz and
    Tz = Mz − cx Fy + cy Fx.

    Parameters
    ----------
    force : array_like, shape (n, 3)
        Force on the plate [N], z-down plate frame (Fz > 0 under load).
    moment : array_like, shape (n, 3)
        Moment of that force about the top-surface centre [N m] (:func:`wrench_type2` ...).
    threshold : float
        Smallest Fz [N] with a defined CoP, >= 0.

    Returns
    -------
    cop : ndarray, shape (n, 3)
        (cx, cy, 0) relative to the plate centre [m]; NaN where Fz < ``threshold``.
    free_moment : ndarray, shape (n,)
        Tz [N m] about the z-down axis (for the force on the plate); NaN where ``cop`` is. For
        the subject about the upward normal this is the same number.
    """
    limit = _threshold(threshold)
    f = _channels(force, 3, "force")
    m = _channels(moment, 3, "moment")
    if f.shape != m.shape:
        raise InvalidParameterError(f"force and moment differ in shape: {f.shape}, {m.shape}")
    loaded = f[:, 2] >= limit
    fz = np.where(loaded, f[:, 2], np.nan)  # NaN, not inf, where the plate is unloaded
    cx = -m[:, 1] / fz
    cy = m[:, 0] / fz
    cop = np.column_stack([cx, cy, np.where(loaded, 0.0, np.nan)])
    return cop, m[:, 2] - cx * f[:, 1] + cy * f[:, 0]


# --- Reading --------------------------------------------------------------------------------
def read_c3d(path: str | Path, *, threshold: float = 20.0) -> C3DContent:
    """Read the markers, force plates and subject mass of a C3D file (lab frame, SI).

    Parameters
    ----------
    path : str or Path
        The C3D file.
    threshold : float
        Smallest load on a plate [N] for which its CoP is defined, >= 0.

    Returns
    -------
    C3DContent
        Markers at the point rate, plates at the analog rate (conventions: module docstring).

    Raises
    ------
    InputFileError
        One line naming the file and the problem: missing, a directory, not C3D, truncated,
        no frames, an unsupported plate type, missing channels, unknown units.
    InvalidParameterError
        If ``threshold`` is negative or not finite.
    """
    limit = _threshold(threshold)
    file = Path(path)
    if not file.exists():
        raise InputFileError(f"{file}: no such file")
    if file.is_dir():
        raise InputFileError(f"{file}: is a directory, not a C3D file")
    try:
        _check_header(file)
    except OSError as exc:
        raise InputFileError(f"{file}: cannot read ({_one_line(exc)})") from exc
    import ezc3d  # heavy import, only when reading

    try:
        c3d = ezc3d.c3d(str(file))
    except Exception as exc:  # ezc3d raises OSError, RuntimeError, IndexError, ... on bad input
        raise InputFileError(f"{file}: not a readable C3D file ({_one_line(exc)})") from exc
    try:
        return _content(file, c3d, limit)
    except InputFileError:
        raise
    except (KeyError, IndexError, ValueError, TypeError, RuntimeError) as exc:
        raise InputFileError(f"{file}: malformed C3D parameters ({_one_line(exc)})") from exc


def _content(file: Path, c3d: Any, threshold: float) -> C3DContent:
    params = c3d["parameters"]
    points = np.asarray(c3d["data"]["points"], dtype=np.float64)
    analogs = np.asarray(c3d["data"]["analogs"], dtype=np.float64)
    n_markers, n_frames = points.shape[1], points.shape[2]
    n_channels = analogs.shape[1] if analogs.ndim == 3 else 0
    n_analog = analogs.shape[2] if n_channels else 0
    if n_frames == 0 and n_analog == 0:
        raise InputFileError(f"{file}: the file has no frames")

    unit_text = _first_text(_param(params, "POINT", "UNITS"))
    length = _LENGTH_UNITS.get(unit_text.strip().lower()) if unit_text.strip() else 1e-3
    if length is None:
        raise InputFileError(f"{file}: unknown POINT:UNITS {unit_text!r} (expected mm, cm or m)")

    markers: dict[str, FloatArray] = {}
    point_rate: float | None = None
    first_time = 0.0
    if n_markers:
        point_rate = _rate(file, params, "POINT")
        first_time = float(c3d["header"]["points"]["first_frame"]) / point_rate
        trajectories = np.moveaxis(points[:3], 0, -1)  # (markers, frames, xyz)
        for label, xyz in zip(_labels(params, n_markers), trajectories, strict=True):
            values = xyz * length
            values[(values == 0.0).all(axis=1)] = np.nan  # exact zeros: a gap, not the origin
            values.setflags(write=False)
            markers[label] = values

    analog_rate = _rate(file, params, "ANALOG") if n_channels else None
    plates = _plates(
        file, params, analogs[0] if n_channels else np.zeros((0, 0)), length, threshold
    )
    return C3DContent(
        point_rate=point_rate,
        markers=markers,
        analog_rate=analog_rate,
        plates=plates,
        mass=_mass(file, params),
        point_units=unit_text,
        first_time=first_time,
        n_points=n_frames if n_markers else 0,
        n_analog=n_analog,
        up=_lab_up(params),
    )


def _plates(
    file: Path, params: Any, analogs: FloatArray, length: float, threshold: float
) -> tuple[ForcePlate, ...]:
    """Every plate of FORCE_PLATFORM in the lab frame (``analogs``: channels × samples)."""
    used = _param(params, "FORCE_PLATFORM", "USED")
    n_plates = int(np.asarray(used).ravel()[0]) if used is not None and np.size(used) else 0
    if n_plates <= 0:
        return ()
    types = np.asarray(_required(file, params, "FORCE_PLATFORM", "TYPE")).ravel().astype(int)
    corners = np.asarray(_required(file, params, "FORCE_PLATFORM", "CORNERS"), dtype=np.float64)
    origins = np.asarray(_required(file, params, "FORCE_PLATFORM", "ORIGIN"), dtype=np.float64)
    channel = np.asarray(_required(file, params, "FORCE_PLATFORM", "CHANNEL")).astype(int)
    if channel.ndim == 1:
        channel = channel[:, None]
    if types.size < n_plates or corners.size < 12 * n_plates or origins.size < 3 * n_plates:
        raise InputFileError(
            f"{file}: FORCE_PLATFORM describes fewer plates than FORCE_PLATFORM:USED = {n_plates}"
        )
    corners = corners.reshape(3, 4, -1, order="F") if corners.ndim != 3 else corners
    origins = origins.reshape(3, -1, order="F") if origins.ndim != 2 else origins
    unit_values = _param(params, "ANALOG", "UNITS")
    units = [] if unit_values is None else [str(u) for u in np.atleast_1d(unit_values)]
    point_unit = _first_text(_param(params, "POINT", "UNITS")).strip() or "mm"
    up = _lab_up(params)
    plates = []
    for index in range(n_plates):
        kind = int(types[index])
        if kind not in _CHANNEL_KINDS:
            raise InputFileError(
                f"{file}: force plate {index + 1} has unsupported FORCE_PLATFORM:TYPE {kind} "
                "(supported: 1, 2, 3, 4)"
            )
        kinds = _CHANNEL_KINDS[kind]
        numbers: list[int] = (
            [int(n) for n in channel[: len(kinds), index]] if channel.shape[1] > index else []
        )
        if len(numbers) < len(kinds) or min(numbers) < 1 or max(numbers) > analogs.shape[0]:
            raise InputFileError(
                f"{file}: force plate {index + 1} (type {kind}) needs {len(kinds)} analog "
                f"channels; FORCE_PLATFORM:CHANNEL lists {numbers} of "
                f"{analogs.shape[0]} recorded"
            )
        raw = analogs[np.asarray(numbers) - 1].T  # (n, channels)
        scales = np.array(
            [
                _unit_scale(file, units, number - 1, what, point_unit, length, kind == 4)
                for number, what in zip(numbers, kinds, strict=True)
            ]
        )
        origin = origins[:, index] * length
        if kind == 1:
            data = raw * scales
            force = data[:, :3]
            cop = np.column_stack([data[:, 3], data[:, 4], np.zeros(len(data))])
            free = data[:, 5]
            sign = _load_sign(force)
            force, free = sign * force, sign * free
            unloaded = force[:, 2] < threshold
            cop[unloaded] = np.nan
            free = np.where(unloaded, np.nan, free)
        else:
            if kind == 2:
                force, moment = wrench_type2(raw * scales, origin)
            elif kind == 3:
                force, moment = wrench_type3(raw * scales, origin)
            else:  # calibrate first: the units are those of the calibrated outputs
                calibrated = raw @ _cal_matrix(file, params, index).T * scales
                force, moment = wrench_type2(calibrated, origin)
            sign = _load_sign(force)
            force, moment = sign * force, sign * moment
            cop, free = plate_cop_in_plate_frame(force, moment, threshold=threshold)
        rotation, centre = plate_frame(corners[:, :, index].T * length, up)
        grf = -(force @ rotation.T)
        cop_lab = centre + cop @ rotation.T
        lab_corners = corners[:, :, index].T * length
        for array in (grf, cop_lab, free, lab_corners):
            array.setflags(write=False)
        plates.append(ForcePlate(grf, cop_lab, free, lab_corners))
    return tuple(plates)


def _load_sign(force: FloatArray) -> float:
    """+1 if the channels give the force on the plate (summed Fz >= 0), else −1 (Vicon)."""
    return -1.0 if float(np.sum(force[:, 2])) < 0.0 else 1.0


def _unit_scale(
    file: Path,
    units: Sequence[str],
    index: int,
    kind: str,
    point_unit: str,
    length: float,
    calibrated: bool,
) -> float:
    """SI factor of one plate channel from ANALOG:UNITS (kind F, M or L)."""
    text = units[index].strip() if index < len(units) else ""
    key = "".join(ch for ch in text.lower() if ch not in ". *·-_")
    table = {"F": _FORCE_UNITS, "M": _MOMENT_UNITS, "L": _LENGTH_UNITS}[kind]
    if key in table:
        return table[key]
    if not text or calibrated:  # the C3D default: N, N·(point unit), (point unit)
        return {"F": 1.0, "M": length, "L": length}[kind]
    expected = {"F": "N", "M": f"N.m or N.{point_unit}", "L": point_unit}[kind]
    raise InputFileError(
        f"{file}: analog channel {index + 1} has unknown units {text!r} (expected {expected})"
    )


def _cal_matrix(file: Path, params: Any, index: int) -> FloatArray:
    """FORCE_PLATFORM:CAL_MATRIX of one type-4 plate; the identity when stored empty."""
    value = _param(params, "FORCE_PLATFORM", "CAL_MATRIX")
    if value is None:
        raise InputFileError(f"{file}: type-4 force plate {index + 1} without CAL_MATRIX")
    matrix = np.asarray(value, dtype=np.float64)
    if matrix.size == 0:
        return np.eye(6)
    if matrix.ndim == 2:
        matrix = matrix[:, :, None]
    if matrix.shape[:2] != (6, 6) or matrix.shape[2] <= index:
        raise InputFileError(
            f"{file}: FORCE_PLATFORM:CAL_MATRIX has shape {matrix.shape}, "
            f"no 6 × 6 matrix for plate {index + 1}"
        )
    return matrix[:, :, index]


def _lab_up(params: Any) -> FloatArray:
    """Return the lab's up axis: POINT:Y_SCREEN when it names one (e.g. '+Z'), else +z."""
    text = _first_text(_param(params, "POINT", "Y_SCREEN")).strip().upper()
    axes = {"X": 0, "Y": 1, "Z": 2}
    if len(text) == 2 and text[0] in "+-" and text[1] in axes:
        up = np.zeros(3)
        up[axes[text[1]]] = 1.0 if text[0] == "+" else -1.0
        return up
    return np.array([0.0, 0.0, 1.0])


def _mass(file: Path, params: Any) -> float | None:
    """Subject mass [kg] from the first parameter of _MASS_PARAMETERS that holds one."""
    for group, name in _MASS_PARAMETERS:
        value = _param(params, group, name)
        if value is None:
            continue
        try:
            number = float(np.asarray(value, dtype=np.float64).ravel()[0])
        except (ValueError, TypeError, IndexError):
            continue
        if not (math.isfinite(number) and number > 0.0):
            continue  # 0 is a common "not entered"
        units = _param(params, group, f"{name}_UNITS")
        if units is None:
            units = _param(params, group, f"{name}UNITS")
        unit_text = _first_text(units).strip()
        factor = _MASS_UNITS.get(unit_text.lower(), None) if unit_text else 1.0
        if factor is None:
            raise InputFileError(f"{file}: unknown units {unit_text!r} for {group}:{name}")
        return number * factor
    return None


def _check_header(file: Path) -> None:
    """Check the 512-byte header: a C3D file, with frames, not shorter than its data.

    ezc3d stops quietly at the end of a truncated file (and shrinks its header to match), so
    the file size is compared with what the header announces.
    """
    size = file.stat().st_size
    if size == 0:
        raise InputFileError(f"{file}: empty file, not a C3D file")
    with file.open("rb") as stream:
        header = stream.read(512)
        if len(header) < 2 or header[1] != 0x50 or header[0] < 2:  # byte 2 is always 0x50
            raise InputFileError(f"{file}: not a C3D file (no C3D header)")
        if len(header) < 512:
            raise InputFileError(f"{file}: truncated C3D header ({size} bytes of 512)")
        stream.seek((header[0] - 1) * 512 + 3)
        processor = stream.read(1)
    if not processor:
        raise InputFileError(f"{file}: truncated C3D file (no parameter section)")
    kind = processor[0]  # 84 Intel, 85 DEC, 86 MIPS (big-endian)
    endian = ">" if kind == 86 else "<"
    n_points, per_frame, first, last = struct.unpack_from(endian + "4H", header, 2)
    (data_start,) = struct.unpack_from(endian + "H", header, 16)
    if last < first:
        raise InputFileError(f"{file}: the file has no frames")
    # The sign of the header's scale factor (words 7-8) says float (< 0) or integer storage;
    # the sign bit is the top bit of byte 15 (Intel), 13 (DEC's word-swapped float) or 12 (MIPS).
    sign_byte = {85: header[13], 86: header[12]}.get(kind, header[15])
    frames = last - first + 1
    needed = (data_start - 1) * 512 + frames * (4 * n_points + per_frame) * (
        4 if sign_byte & 0x80 else 2
    )
    if size < needed:
        raise InputFileError(
            f"{file}: truncated C3D file ({size} bytes, its header needs {needed})"
        )


def _rate(file: Path, params: Any, group: str) -> float:
    value = _param(params, group, "RATE")
    rate = float(np.asarray(value).ravel()[0]) if value is not None and np.size(value) else 0.0
    if not (math.isfinite(rate) and rate > 0.0):
        raise InputFileError(f"{file}: {group}:RATE must be > 0 Hz, got {rate:g}")
    return rate


def _labels(params: Any, count: int) -> list[str]:
    """Marker labels from POINT:LABELS, LABELS2, ...; unique, 'POINT<i>' where missing."""
    found: list[str] = []
    for suffix in ["", *[str(i) for i in range(2, 100)]]:
        value = _param(params, "POINT", f"LABELS{suffix}")
        if value is None:
            break
        found.extend(str(v).strip() for v in np.atleast_1d(value))
    labels: list[str] = []
    seen: set[str] = set()
    for i in range(count):
        label = found[i] if i < len(found) and found[i] else f"POINT{i + 1}"
        unique, k = label, 2
        while unique in seen:  # C3D does not forbid repeated labels; a dict does
            unique, k = f"{label}_{k}", k + 1
        seen.add(unique)
        labels.append(unique)
    return labels


def _param(params: Any, group: str, name: str) -> Any:
    """Value of GROUP:NAME, case-insensitive, or None."""
    for group_key in params.keys():
        if group_key.upper() != group.upper():
            continue
        entries = params[group_key]
        for key in entries.keys():
            if key.upper() == name.upper() and isinstance(entries[key], Mapping):
                return entries[key].get("value")
    return None


def _required(file: Path, params: Any, group: str, name: str) -> Any:
    value = _param(params, group, name)
    if value is None or not np.size(value):
        raise InputFileError(f"{file}: {group}:{name} is missing")
    return value


def _first_text(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    items = list(value) if not isinstance(value, np.ndarray) else value.ravel().tolist()
    return str(items[0]) if items else ""


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text[:200]


# --- Writing --------------------------------------------------------------------------------
def write_c3d(
    path: str | Path,
    *,
    point_rate: float,
    markers: Mapping[str, ArrayLike],
    analog_rate: float,
    plates: Sequence[tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike]],
    mass: float | None = None,
) -> None:
    """Write markers and force plates (lab frame, SI) as a C3D file that other readers agree on.

    Parameters
    ----------
    path : str or Path
        The file to write (overwritten).
    point_rate : float
        Marker frame rate [Hz], > 0.
    markers : mapping of str to array_like, shape (n_points, 3)
        Label -> position [m], lab frame; NaN rows are gaps (written with residual −1).
    analog_rate : float
        Analog rate [Hz], an integer multiple k of ``point_rate``.
    plates : sequence of (force, cop, free_moment, corners)
        Per plate: force on the subject (n, 3) [N], CoP (n, 3) [m] on the top surface (lab),
        free moment (n,) [N m] on the subject about up, corners (4, 3) [m]; n = k · n_points.
        Corners in the spec's order are clockwise seen from above (z-down plate); corners
        listed anticlockwise (the quadrants of a z-up frame) are written as corners 1, 4, 3, 2,
        the same rectangle in the spec's order, so that other readers agree. A NaN CoP (an
        unloaded plate) is written at the plate centre, a NaN free moment as 0.
    mass : float, optional
        Subject mass [kg], > 0, stored as PROCESSING:Bodymass.

    Raises
    ------
    InvalidParameterError
        On inconsistent sizes or rates, non-finite forces, degenerate corners.
    """
    rate = _positive("point_rate", point_rate)
    a_rate = _positive("analog_rate", analog_rate)
    ratio = a_rate / rate
    per_frame = round(ratio)
    if per_frame < 1 or abs(ratio - per_frame) > 1e-9 * ratio:
        raise InvalidParameterError(
            f"analog_rate must be an integer multiple of point_rate, got {a_rate:g} / {rate:g} Hz"
        )
    labels = list(markers)
    positions = [_marker(label, markers[label]) for label in labels]
    lengths = {len(p) for p in positions}
    if len(lengths) > 1:
        raise InvalidParameterError(f"markers differ in length: {sorted(lengths)}")
    plate_data = [_plate_channels(i, plate) for i, plate in enumerate(plates)]
    samples = {len(channels) for channels, _ in plate_data}
    if len(samples) > 1:
        raise InvalidParameterError(f"plates differ in length: {sorted(samples)}")
    if positions:
        n_points = len(positions[0])
    elif plate_data:
        n_points = len(plate_data[0][0]) // per_frame
    else:
        raise InvalidParameterError("nothing to write: no markers and no plates")
    if n_points == 0:
        raise InvalidParameterError("nothing to write: zero frames")
    if samples and samples != {n_points * per_frame}:
        raise InvalidParameterError(
            f"plates must have {per_frame} samples per marker frame: {n_points * per_frame} "
            f"samples for {n_points} frames, got {samples.pop()}"
        )
    weight = None if mass is None else _positive("mass", mass)
    if any(not isinstance(label, str) or not label.strip() for label in labels):
        raise InvalidParameterError("marker labels must be non-empty strings")

    import ezc3d

    c3d = ezc3d.c3d()
    point = c3d["parameters"]["POINT"]
    point["RATE"]["value"] = np.array([rate])
    point["UNITS"]["value"] = ["mm"]
    point["LABELS"]["value"] = tuple(labels)
    data = np.zeros((4, len(labels), n_points))
    data[3] = 1.0
    residuals = np.zeros((1, len(labels), n_points))
    for j, xyz in enumerate(positions):
        gap = np.logical_not(np.all(np.isfinite(xyz), axis=1))
        data[:3, j] = np.where(gap[:, None], 0.0, xyz * 1000.0).T
        residuals[0, j, gap] = -1.0
    c3d["data"]["points"] = data
    c3d["data"]["meta_points"]["residuals"] = residuals

    analog = c3d["parameters"]["ANALOG"]
    analog["RATE"]["value"] = np.array([a_rate])
    n_plates = len(plate_data)
    c3d["data"]["analogs"] = np.zeros((1, 0, n_points * per_frame))  # ezc3d checks the rates
    if n_plates:
        analog["LABELS"]["value"] = tuple(
            f"{name}{i + 1}" for i in range(n_plates) for name in _WRITE_LABELS
        )
        analog["UNITS"]["value"] = list(_WRITE_UNITS) * n_plates
        c3d["data"]["analogs"] = np.concatenate([ch for ch, _ in plate_data], axis=1).T[None]
        fp = c3d["parameters"]["FORCE_PLATFORM"]
        fp["USED"]["value"] = np.array([n_plates])
        fp["TYPE"]["value"] = np.full(n_plates, 2)
        fp["CORNERS"]["value"] = np.stack([corners.T * 1000.0 for _, corners in plate_data], -1)
        fp["ORIGIN"]["value"] = np.zeros((3, n_plates))
        fp["CHANNEL"]["value"] = np.arange(1, 6 * n_plates + 1).reshape(n_plates, 6).T
    if weight is not None:
        c3d.add_parameter("PROCESSING", "Bodymass", np.array([weight]))
    c3d.write(str(path))


def _plate_channels(index: int, plate: Sequence[ArrayLike]) -> tuple[FloatArray, FloatArray]:
    """Type-2 channels (n, 6) [N, N mm] of one plate to write, and its corners [m]."""
    try:
        force_in, cop_in, moment_in, corners_in = plate
    except (TypeError, ValueError):
        raise InvalidParameterError(
            f"plate {index + 1} must be (force, cop, free_moment, corners)"
        ) from None
    force = _channels(force_in, 3, f"plate {index + 1} force")
    if not np.isfinite(force).all():
        raise InvalidParameterError(f"plate {index + 1} force must be finite")
    cop = _channels(cop_in, 3, f"plate {index + 1} cop")
    free = np.asarray(moment_in, dtype=np.float64).reshape(-1)
    if not (len(cop) == len(force) == len(free)):
        raise InvalidParameterError(
            f"plate {index + 1}: force, cop and free_moment differ in length: "
            f"{len(force)}, {len(cop)}, {len(free)}"
        )
    corners = np.asarray(corners_in, dtype=np.float64)
    rotation, centre = plate_frame(corners)
    if np.linalg.det(rotation) < 0.0:
        # Anticlockwise seen from above (the quadrants of a z-up frame): the same rectangle in
        # the spec's order for a z-down plate keeps corner 1 and swaps the axes.
        corners = corners[[0, 3, 2, 1]]
        rotation, centre = plate_frame(corners)
    on_plate = -(force @ rotation)  # force on the plate, plate frame
    local = (np.where(np.isfinite(cop), cop, centre) - centre) @ rotation
    cx, cy = local[:, 0], local[:, 1]
    tz = np.nan_to_num(free, nan=0.0)
    fx, fy, fz = on_plate.T
    moment = np.column_stack([cy * fz, -cx * fz, cx * fy - cy * fx + tz])  # c × F + Tz ẑ
    return np.column_stack([on_plate, moment * 1000.0]), corners


def _marker(label: str, values: ArrayLike) -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        raise InvalidParameterError(f"marker {label!r} must be (n, 3), got shape {array.shape}")
    if np.isinf(array).any():
        raise InvalidParameterError(f"marker {label!r} has infinite coordinates")
    return array


# --- Small checks ----------------------------------------------------------------------------
def _channels(values: ArrayLike, width: int, name: str = "channels") -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != width:
        raise InvalidParameterError(f"{name} must be (n, {width}), got shape {array.shape}")
    return array


def _vector3(name: str, values: ArrayLike) -> FloatArray:
    array = np.asarray(values, dtype=np.float64).reshape(-1)
    if array.shape != (3,) or not np.isfinite(array).all():
        raise InvalidParameterError(f"{name} must be 3 finite numbers, got {values!r}")
    return array


def _threshold(value: float) -> float:
    number = float(value)
    if not (math.isfinite(number) and number >= 0.0):
        raise InvalidParameterError(f"threshold must be a finite number >= 0 N, got {value!r}")
    return number


def _positive(name: str, value: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(number) and number > 0.0):
        raise InvalidParameterError(f"{name} must be a finite number > 0, got {value!r}")
    return number
