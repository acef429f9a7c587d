"""Measured trials from CSV files: columns, units and their checks."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from pushrecovery.analysis.readers.c3d_files import read_c3d_recording
from pushrecovery.analysis.readers.common import (
    MIN_FRAMES,
    FloatArray,
    _check_plausible,
    _check_time,
    _unit_scale,
)
from pushrecovery.analysis.recording import AXES, LOADED, Recording
from pushrecovery.arguments import input_file, input_path
from pushrecovery.errors import InputFileError
from pushrecovery.extras import require

__all__ = [
    "CSV_COLUMNS",
    "read_csv_recording",
    "read_recording",
]


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
#: The base polygon's vertex columns, ``base_ap1, base_ml1, ..., base_apK, base_mlK`` [length].
VERTEX_COLUMN = re.compile(r"base_(ap|ml)([1-9][0-9]?)")


_PAIRS = (
    ("com_ap", "com_ml"),
    ("com_vel_ap", "com_vel_ml"),
    ("cop_ap", "cop_ml"),
    ("ankle_ap", "ankle_ml"),
)


def read_recording(path: str | Path, **options: object) -> Recording:
    """Read a CSV or C3D trial, chosen by the file's extension (``.csv``, ``.c3d``).

    Options are passed to :func:`read_csv_recording` or :func:`read_c3d_recording`.

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a str or path.
    InputFileError
        Missing or empty file, an unknown extension, or what the reader raises.
    """
    path = input_path("path", path)
    input_file("path", path)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return read_csv_recording(path, **options)  # type: ignore[arg-type]
    if suffix == ".c3d":
        return read_c3d_recording(path, **options)  # type: ignore[arg-type]
    raise InputFileError(f"{path}: unknown file type {suffix or '(none)'!r}; expected .csv or .c3d")


# --- CSV ---------------------------------------------------------------------------------
def read_csv_recording(path: str | Path, *, units: str = "m") -> Recording:
    """Read a CSV trial (columns: :data:`CSV_COLUMNS`, docs/analysis.md "CSV format").

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
    ParameterTypeError
        If ``path`` is not a str or path.
    InputFileError
        Missing, empty or malformed file, missing or non-numeric columns, a time column that
        is not increasing at a constant rate, or values implausible in the given units.
    """
    path = input_path("path", path)
    scale = _unit_scale(units)
    table = _read_table(path)
    lengths = {name for name in table if name in _LENGTHS or VERTEX_COLUMN.fullmatch(name)}
    data = {name: table[name] * (scale if name in lengths else 1.0) for name in table}
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
    # A CoP alone is a posturography trial: its sway measures, no margins.
    if "com_ap" not in data and not has_force and "cop_ap" not in data:
        raise InputFileError(
            f"{path}: no CoM: give columns com_ap and com_ml, or force_ap, force_ml, force_v, "
            "cop_ap and cop_ml (or cop_ap and cop_ml alone: the sway measures only); columns "
            f"found: {', '.join(table) or '(none)'}"
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
    vertices = _vertices(path, data)
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
        base_vertices=vertices,
    )
    _check_plausible(path, recording, units)
    return recording


def _vertices(path: Path, data: dict[str, FloatArray]) -> FloatArray | None:
    """Return the base polygon's vertices (n, K, 2) from ``base_apK``/``base_mlK``, or None.

    Vertex k needs both its columns; K = 3 at least (docs/base_polygon.md). NaN cells are
    absent vertices of that frame (the base is the hull of the others).
    """
    found: dict[int, dict[str, FloatArray]] = {}
    for name, values in data.items():
        match = VERTEX_COLUMN.fullmatch(name)
        if match:
            found.setdefault(int(match.group(2)), {})[match.group(1)] = values
    if not found:
        return None
    for k in sorted(found):
        for axis in AXES:
            if axis not in found[k]:
                raise InputFileError(
                    f"{path}: column base_{axis}{k} is missing: vertex {k} needs both"
                )
    if len(found) < 3:
        raise InputFileError(
            f"{path}: a base polygon needs at least 3 vertices (base_ap1, base_ml1, ...), "
            f"got {len(found)}"
        )
    return np.stack(
        [np.column_stack([found[k]["ap"], found[k]["ml"]]) for k in sorted(found)], axis=1
    )


def _read_table(path: Path) -> dict[str, FloatArray]:
    """Numeric columns of a CSV file by lower-case name (pyarrow's parser)."""
    require("analysis", "pyarrow", "reading a CSV trial")
    import pyarrow as pa
    import pyarrow.csv as pacsv

    input_file("path", path)
    try:
        table = pacsv.read_csv(
            path,
            convert_options=pacsv.ConvertOptions(
                null_values=["", "nan", "NaN", "NAN", "NA", "null"], strings_can_be_null=True
            ),
        )
        # pyarrow checks the values' UTF-8 but not the header's: decode the names here.
        names = [name.strip().lower() for name in table.column_names]
    except pa.ArrowInvalid as exc:
        message = " ".join(str(exc).split())
        raise InputFileError(f"{path}: malformed CSV: {message}") from None
    except UnicodeDecodeError:
        raise InputFileError(f"{path}: malformed CSV: the header is not UTF-8 text") from None
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
        if name not in CSV_COLUMNS and not VERTEX_COLUMN.fullmatch(name):
            continue  # other columns are the user's own
        if not (pa.types.is_integer(column.type) or pa.types.is_floating(column.type)):
            if pa.types.is_null(column.type):
                columns[name] = np.full(table.num_rows, np.nan)
                continue
            values = column.to_pylist()
            row = next(
                (i for i, v in enumerate(values) if v is not None and not _is_number(v)), None
            )
            if row is not None:
                raise InputFileError(
                    f"{path}: column {name!r} row {row + 2} is not a number: "
                    f"{str(values[row])[:30]!r}"
                )
            # Numbers pyarrow would not parse but Python does ("0.02\f": surrounding spaces).
            columns[name] = np.array(
                [np.nan if v is None else float(v) for v in values], dtype=np.float64
            )
            continue
        columns[name] = column.to_numpy(zero_copy_only=False).astype(np.float64)
    return columns


def _is_number(value: object) -> bool:
    try:
        float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False
    return True
