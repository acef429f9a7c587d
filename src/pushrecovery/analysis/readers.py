"""Read measured trials from CSV and C3D files into a :class:`~.recording.Recording`.

CSV (docs/analysis.md): a header row, then one row per frame at a constant rate. Column names
(case-insensitive; ``ap`` anterior-posterior, forward positive; ``ml`` medio-lateral, left
positive; lengths in ``units``, forces in N, time in s):

=====================================  ===================================================
``time``                                required [s]
``com_ap``, ``com_ml``                  CoM position (or give the force-plate columns)
``com_vel_ap``, ``com_vel_ml``          CoM velocity [units/s], optional (else differentiated)
``cop_ap``, ``cop_ml``                  centre of pressure, optional
``force_ap``, ``force_ml``, ``force_v`` ground reaction force on the subject [N], optional
``base_ap_min`` … ``base_ml_max``       base of support edges, optional (all four)
``ankle_ap``, ``ankle_ml``              stance ankle, optional
``com_height``                          CoM height above the ankle, optional
=====================================  ===================================================

Empty cells and ``nan`` are missing samples. C3D: markers and force plates through
:mod:`pushrecovery.analysis.c3d`; the CoM from named markers (Plug-in Gait's ``CentreOfMass``
by default), feet from the Plug-in Gait heel/toe/ankle markers, the force of all plates summed
and their CoPs combined.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.recording import AXES, LOADED, Foot, Recording
from pushrecovery.analysis.signals import resample
from pushrecovery.errors import InputFileError, InvalidParameterError

if TYPE_CHECKING:
    from pushrecovery.analysis.c3d import ForcePlate

__all__ = [
    "AP_AXES",
    "CSV_COLUMNS",
    "FOOT_MARKERS",
    "LENGTH_UNITS",
    "read_c3d_recording",
    "read_csv_recording",
    "read_recording",
]

FloatArray = NDArray[np.float64]

#: Length units a file may use, in metres.
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001}
#: Fewest frames a trial may have (a filter and a derivative need a few).
MIN_FRAMES = 10
#: Lab axis that points forward (anterior) in a C3D file; the lab's z is up.
AP_AXES: tuple[str, ...] = ("x", "-x", "y", "-y", "z", "-z")
#: Plug-in Gait foot markers: (foot, heel, toe, ankle).
FOOT_MARKERS: tuple[tuple[str, str, str, str], ...] = (
    ("left", "LHEE", "LTOE", "LANK"),
    ("right", "RHEE", "RTOE", "RANK"),
)
#: Percentile of the CoM height above the ankles taken as the standing CoM height.
STANDING_PERCENTILE = 95.0
#: Default CoM marker (Plug-in Gait's model output).
COM_MARKER = "CentreOfMass"

_LENGTHS = (
    "com_ap",
    "com_ml",
    "com_vel_ap",
    "com_vel_ml",
    "cop_ap",
    "cop_ml",
    "base_ap_min",
    "base_ap_max",
    "base_ml_min",
    "base_ml_max",
    "ankle_ap",
    "ankle_ml",
    "com_height",
)
_FORCES = ("force_ap", "force_ml", "force_v")
#: Every column the CSV reader knows.
CSV_COLUMNS: tuple[str, ...] = ("time", *_LENGTHS, *_FORCES)
_PAIRS = (
    ("com_ap", "com_ml"),
    ("com_vel_ap", "com_vel_ml"),
    ("cop_ap", "cop_ml"),
    ("ankle_ap", "ankle_ml"),
)


def read_recording(path: str | Path, **options: object) -> Recording:
    """Read a CSV or C3D trial, chosen by the file's extension (``.csv``, ``.c3d``).

    Options are passed to :func:`read_csv_recording` or :func:`read_c3d_recording`.
    """
    path = Path(path)
    _check_file(path)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return read_csv_recording(path, **options)  # type: ignore[arg-type]
    if suffix == ".c3d":
        return read_c3d_recording(path, **options)  # type: ignore[arg-type]
    raise InputFileError(f"{path}: unknown file type {suffix or '(none)'!r}; expected .csv or .c3d")


# --- CSV ---------------------------------------------------------------------------------
def read_csv_recording(path: str | Path, *, units: str = "m") -> Recording:
    """Read a CSV trial (module docstring).

    Parameters
    ----------
    path : str or Path
        The file.
    units : str
        Length unit of the file: ``m``, ``cm`` or ``mm``.

    Returns
    -------
    Recording

    Raises
    ------
    InputFileError
        Missing, empty or malformed file, missing or non-numeric columns, a time column that
        is not increasing at a constant rate, or values implausible in the given units.
    """
    path = Path(path)
    scale = _unit_scale(units)
    table = _read_table(path)
    data = {name: table[name] * (scale if name in _LENGTHS else 1.0) for name in table}
    time = data["time"]
    _check_time(path, time)
    for first, second in _PAIRS:
        if (first in data) != (second in data):
            given, missing = (first, second) if first in data else (second, first)
            raise InputFileError(f"{path}: column {given!r} needs {missing!r} too")
    base_names = [f"base_{axis}_{end}" for axis in AXES for end in ("min", "max")]
    present = [name for name in base_names if name in data]
    if present and len(present) < 4:
        missing_base = sorted(set(base_names) - set(present))
        raise InputFileError(f"{path}: base of support columns missing: {', '.join(missing_base)}")
    has_force = all(name in data for name in (*_FORCES, "cop_ap", "cop_ml"))
    if "com_ap" not in data and not has_force:
        raise InputFileError(
            f"{path}: no CoM: give columns com_ap and com_ml, or force_ap, force_ml, force_v, "
            f"cop_ap and cop_ml; columns found: {', '.join(table) or '(none)'}"
        )

    for name in ("com_ap", "com_ml", "cop_ap", "cop_ml", *_FORCES):
        if name in data and not np.isfinite(data[name]).any():
            raise InputFileError(f"{path}: column {name!r} has no values")
    if "force_v" in data and np.nanmedian(data["force_v"]) < -LOADED:
        raise InputFileError(
            f"{path}: force_v is mostly negative (median {np.nanmedian(data['force_v']):.4g} N): "
            "give the ground reaction force on the subject, up positive (negate a force on "
            "the plate)"
        )
    for axis in AXES:
        low, high = data.get(f"base_{axis}_min"), data.get(f"base_{axis}_max")
        if low is not None and high is not None:
            with np.errstate(invalid="ignore"):
                inverted = high <= low
            if inverted.any():
                row = int(np.flatnonzero(inverted)[0]) + 2
                raise InputFileError(
                    f"{path}: base_{axis}_max must be > base_{axis}_min (an empty or inverted "
                    f"base of support), row {row}"
                )

    def pair(first: str, second: str) -> FloatArray | None:
        return np.column_stack([data[first], data[second]]) if first in data else None

    com = pair("com_ap", "com_ml")
    if com is not None:
        com = np.column_stack([com, np.full(len(time), np.nan)])
    force = (
        np.column_stack([data["force_ap"], data["force_ml"], data["force_v"]])
        if all(name in data for name in _FORCES)
        else None
    )
    cop = pair("cop_ap", "cop_ml")
    base = {
        axis: np.column_stack([data[f"base_{axis}_min"], data[f"base_{axis}_max"]])
        for axis in AXES
        if present
    }
    ankle = {axis: data[f"ankle_{axis}"] for axis in AXES if f"ankle_{axis}" in data}
    com_height = None
    if "com_height" in data and np.isfinite(data["com_height"]).any():
        com_height = float(np.nanmedian(data["com_height"]))
    recording = Recording(
        time=time,
        com=com,
        com_velocity=pair("com_vel_ap", "com_vel_ml"),
        base=base,
        ankle=ankle,
        force_time=time if (force is not None or cop is not None) else None,
        force=force,
        cop=cop,
        com_height=com_height,
        source=str(path),
    )
    _check_plausible(path, recording, units)
    return recording


def _unit_scale(units: str) -> float:
    try:
        return LENGTH_UNITS[units]
    except KeyError:
        raise InvalidParameterError(
            f"units must be one of {', '.join(LENGTH_UNITS)}, got {units!r}"
        ) from None


def _read_table(path: Path) -> dict[str, FloatArray]:
    """Numeric columns of a CSV file by lower-case name (pyarrow's parser)."""
    import pyarrow as pa
    import pyarrow.csv as pacsv

    _check_file(path)
    try:
        table = pacsv.read_csv(
            path,
            convert_options=pacsv.ConvertOptions(
                null_values=["", "nan", "NaN", "NAN", "NA", "null"], strings_can_be_null=True
            ),
        )
    except pa.ArrowInvalid as exc:
        message = " ".join(str(exc).split())
        raise InputFileError(f"{path}: malformed CSV: {message}") from None
    names = [name.strip().lower() for name in table.column_names]
    if len(set(names)) != len(names):
        raise InputFileError(f"{path}: repeated column names: {', '.join(table.column_names)}")
    if "time" not in names:
        raise InputFileError(
            f"{path}: missing column 'time' [s]; columns found: {', '.join(names) or '(none)'}"
        )
    if table.num_rows < MIN_FRAMES:
        raise InputFileError(
            f"{path}: needs at least {MIN_FRAMES} rows of data, got {table.num_rows}"
        )
    columns: dict[str, FloatArray] = {}
    for name, column in zip(names, table.columns, strict=True):
        if name not in CSV_COLUMNS:
            continue  # other columns are the user's own
        if not (pa.types.is_integer(column.type) or pa.types.is_floating(column.type)):
            if pa.types.is_null(column.type):
                columns[name] = np.full(table.num_rows, np.nan)
                continue
            values = column.to_pylist()
            row = next(i for i, v in enumerate(values) if v is not None and not _is_number(v))
            raise InputFileError(
                f"{path}: column {name!r} row {row + 2} is not a number: {str(values[row])[:30]!r}"
            )
        columns[name] = column.to_numpy(zero_copy_only=False).astype(np.float64)
    return columns


def _is_number(value: object) -> bool:
    try:
        float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return True


def _check_file(path: Path) -> None:
    if not path.exists():
        raise InputFileError(f"file not found: {path}")
    if path.is_dir():
        raise InputFileError(f"{path} is a directory, not a file")
    if path.stat().st_size == 0:
        raise InputFileError(f"{path} is empty")


def _check_time(path: Path, time: FloatArray) -> None:
    if not np.isfinite(time).all():
        row = int(np.flatnonzero(~np.isfinite(time))[0]) + 2
        raise InputFileError(f"{path}: time is missing on row {row}; every frame needs a time")
    step = np.diff(time)
    if (step <= 0.0).any():
        row = int(np.flatnonzero(step <= 0.0)[0]) + 3
        raise InputFileError(f"{path}: time must increase from row to row (row {row})")
    period = float(np.median(step))
    uneven = np.abs(step - period) > 0.01 * period
    if uneven.any():
        row = int(np.flatnonzero(uneven)[0]) + 3
        raise InputFileError(
            f"{path}: frames must be evenly spaced in time (period {period:g} s, row {row} "
            f"is {step[row - 3]:g} s after the previous); resample the file"
        )
    rate = 1.0 / period
    if not 1.0 <= rate <= 100_000.0:
        raise InputFileError(
            f"{path}: the time column gives {rate:g} frames per second; time must be in "
            "seconds (1 Hz to 100 kHz)"
        )


def _check_plausible(path: Path, recording: Recording, units: str) -> None:
    """Refuse lengths no standing body produces (a file in mm read as metres, say)."""
    hint = f"check --units (read as {units})"
    checks: list[tuple[str, FloatArray | None, float]] = [
        ("CoM excursion", _span(recording.com), 5.0),
        ("CoP excursion", _span(recording.cop), 3.0),
        ("CoM speed", _largest(recording.com_velocity), 10.0),
    ]
    for axis, edges in recording.base.items():
        checks.append(
            (f"base of support width along {axis}", _largest(edges[:, 1] - edges[:, 0]), 2.0)
        )
    for name, value, limit in checks:
        if value is not None and float(np.max(value)) > limit:
            raise InputFileError(
                f"{path}: {name} of {float(np.max(value)):.4g} m is not a standing body's "
                f"(at most {limit:g} m, m/s); {hint}"
            )
    if recording.com_height is not None and not 0.2 <= recording.com_height <= 3.0:
        raise InputFileError(
            f"{path}: com_height of {recording.com_height:.4g} m is not a body's (0.2 to 3 m); "
            f"{hint}"
        )


def _span(values: FloatArray | None) -> FloatArray | None:
    """Range of each horizontal column (ap, ml) that has data."""
    if values is None:
        return None
    columns = [c for c in values[:, :2].T if np.isfinite(c).any()]
    return np.array([np.nanmax(c) - np.nanmin(c) for c in columns]) if columns else None


def _largest(values: FloatArray | None) -> FloatArray | None:
    if values is None or not np.isfinite(values).any():
        return None
    return np.atleast_1d(np.nanmax(np.abs(values)))


# --- C3D ---------------------------------------------------------------------------------
def body_rotation(ap_axis: str, up: FloatArray | None = None) -> FloatArray:
    """Rows ap, ml, up of the body axes in lab coordinates (ml = up × ap: left).

    Parameters
    ----------
    ap_axis : str
        Lab axis pointing forward: ``x``, ``-x``, ``y``, ``-y``, ``z`` or ``-z``.
    up : ndarray, optional
        The lab's up axis (unit, along a lab axis); default +z.
    """
    if ap_axis not in AP_AXES:
        raise InvalidParameterError(f"ap_axis must be one of {', '.join(AP_AXES)}, got {ap_axis!r}")
    vertical = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, dtype=np.float64)
    sign = -1.0 if ap_axis.startswith("-") else 1.0
    ap = sign * np.eye(3)["xyz".index(ap_axis[-1])]
    if abs(float(ap @ vertical)) > 1e-9:
        raise InvalidParameterError(
            f"--ap-axis must be horizontal: the file's up axis is {_axis_name(vertical)}, "
            f"got {ap_axis}"
        )
    return np.stack([ap, np.cross(vertical, ap), vertical])


def _axis_name(vector: FloatArray) -> str:
    index = int(np.argmax(np.abs(vector)))
    return ("+" if vector[index] > 0 else "-") + "xyz"[index]


def read_c3d_recording(
    path: str | Path,
    *,
    ap_axis: str = "x",
    com_markers: Sequence[str] | None = None,
    feet: Sequence[tuple[str, str, str, str]] | None = None,
) -> Recording:
    """Read a C3D trial: markers, force plates, subject mass.

    Parameters
    ----------
    path : str or Path
        The file.
    ap_axis : str
        Lab axis pointing forward: ``x``, ``-x``, ``y``, ``-y``, ``z`` or ``-z``; it must be
        horizontal (the file's ``POINT:Y_SCREEN`` names the up axis, default +z).
    com_markers : sequence of str, optional
        Markers whose mean is the CoM; default ``CentreOfMass`` when the file has it, else the
        CoM comes from the force plates.
    feet : sequence of (name, heel, toe, ankle), optional
        Foot marker labels; default the Plug-in Gait feet (:data:`FOOT_MARKERS`) present in
        the file.

    Returns
    -------
    Recording
        At the marker rate when the CoM comes from markers, else at the force-plate rate.
    """
    from pushrecovery.analysis.c3d import read_c3d

    path = Path(path)
    body_rotation(ap_axis)  # a bad axis name fails before the file is read
    content = read_c3d(path, threshold=LOADED)
    rotation = body_rotation(ap_axis, content.up)
    markers = {name: values @ rotation.T for name, values in content.markers.items()}
    notes: list[str] = []
    if com_markers is None:
        com_markers = [COM_MARKER] if COM_MARKER in markers else []
    missing = [name for name in com_markers if name not in markers]
    if missing:
        raise InputFileError(
            f"{path}: no marker {missing[0]!r}; markers: {', '.join(markers) or '(none)'}"
        )
    com = np.mean([markers[name] for name in com_markers], axis=0) if com_markers else None
    foot_sets = FOOT_MARKERS if feet is None else tuple(feet)
    found_feet = []
    for name, heel, toe, ankle in foot_sets:
        labels = (heel, toe, ankle)
        if all(label in markers for label in labels):
            found_feet.append(Foot(name, *(markers[label] for label in labels)))
        elif feet is not None:
            absent = next(label for label in labels if label not in markers)
            raise InputFileError(
                f"{path}: no marker {absent!r} for foot {name!r}; markers: {', '.join(markers)}"
            )
    com_height = None
    if com is not None and found_feet:
        ankle_height = np.nanmean([foot.ankle[:, 2] for foot in found_feet], axis=0)
        height = com[:, 2] - ankle_height
        if np.isfinite(height).any():
            # Standing height: a step or a crouch lowers the CoM for part of a trial.
            com_height = float(np.nanpercentile(height, STANDING_PERCENTILE))
    force = cop = force_time = None
    if content.plates:
        force_time = content.analog_time
        total = np.sum([plate.force for plate in content.plates], axis=0)
        force = total @ rotation.T
        cop = _combined_cop(content.plates) @ rotation.T
        cop = cop[:, :2]
        if len(content.plates) > 1:
            notes.append(f"{len(content.plates)} force plates: forces summed, CoPs combined")
    if com is None and force is None:
        raise InputFileError(
            f"{path}: neither a CoM marker ({COM_MARKER!r} or --com-marker) nor force plates"
        )
    time = content.point_time
    if com is None:
        assert force_time is not None
        if found_feet:
            found_feet = [_resampled(foot, time, force_time) for foot in found_feet]
            notes.append("CoM from the force plates: foot markers resampled to their rate")
        time = force_time
    return Recording(
        time=time,
        com=com,
        feet=tuple(found_feet),
        force_time=force_time,
        force=force,
        cop=cop,
        mass=content.mass,
        com_height=com_height,
        source=str(path),
        notes=notes,
    )


def _resampled(foot: Foot, source: FloatArray, target: FloatArray) -> Foot:
    """Resample a foot's markers to other times (:func:`~.signals.resample`)."""
    return Foot(
        foot.name,
        resample(source, foot.heel, target),
        resample(source, foot.toe, target),
        resample(source, foot.ankle, target),
    )


def _combined_cop(plates: Sequence[ForcePlate]) -> FloatArray:
    """CoP of several plates at one height: the vertical-force-weighted mean of their CoPs."""
    weights = []
    points = []
    for plate in plates:
        vertical = plate.force[:, 2]
        cop = plate.cop
        loaded = np.isfinite(cop).all(axis=1) & (vertical > 0.0)
        weights.append(np.where(loaded, vertical, 0.0))
        points.append(np.where(loaded[:, None], cop, 0.0))
    weight = np.sum(weights, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        combined = np.sum([w[:, None] * p for w, p in zip(weights, points, strict=True)], axis=0)
        combined = combined / weight[:, None]
    return np.where((weight > 0.0)[:, None], combined, np.nan)
