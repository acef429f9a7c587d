"""Read a C3D file: markers and force plates (docs/c3d.md for the conventions)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.c3d.content import C3DContent
from pushrecovery.analysis.c3d.header import _check_header
from pushrecovery.analysis.c3d.isolated import run_isolated
from pushrecovery.analysis.c3d.parameters import (
    _LENGTH_UNITS,
    _first_text,
    _lab_up,
    _labels,
    _mass,
    _param,
    _rate,
)
from pushrecovery.analysis.c3d.plates import read_plates
from pushrecovery.analysis.c3d.structure import check_parameter_section, read_parameter_section
from pushrecovery.arguments import non_negative_float
from pushrecovery.errors import InputFileError
from pushrecovery.extras import require

FloatArray = NDArray[np.float64]


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
    limit = non_negative_float("threshold", threshold, "N")
    file = Path(path)
    if not file.exists():
        raise InputFileError(f"{file}: no such file")
    if file.is_dir():
        raise InputFileError(f"{file}: is a directory, not a C3D file")
    try:
        _check_header(file)
        # ezc3d is C++: a record it misreads can end the process, so the section is walked here.
        check_parameter_section(file, read_parameter_section(file))
    except OSError as exc:
        raise InputFileError(f"{file}: cannot read ({_one_line(exc)})") from exc
    require("analysis", "ezc3d", "reading a C3D file")
    content = run_isolated(_read_checked_file, (file, limit), file)
    # A pickle does not keep numpy's read-only flag: the arrays are the file's, not to edit.
    for array in content.markers.values():
        array.setflags(write=False)
    for plate in content.plates:
        for array in (plate.force, plate.cop, plate.free_moment, plate.corners):
            array.setflags(write=False)
    return content


def _read_checked_file(file: Path, limit: float) -> C3DContent:
    """Parse a file that passed the header and parameter checks (in a child process)."""
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
    plates = read_plates(
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


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text[:200]
