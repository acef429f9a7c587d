"""What the trial readers share: units, the frame's axes, checks of time and plausibility."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.recording import Recording
from pushrecovery.arguments import finite_vector, require_type
from pushrecovery.errors import InputFileError, InvalidParameterError

__all__ = [
    "AP_AXES",
    "COM_MARKER",
    "FOOT_MARKERS",
    "LENGTH_UNITS",
    "MIN_FRAMES",
    "STANDING_PERCENTILE",
    "FloatArray",
    "body_rotation",
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


def _unit_scale(units: str) -> float:
    require_type("units", units, str)
    try:
        return LENGTH_UNITS[units]
    except KeyError:
        raise InvalidParameterError(
            f"units must be one of {', '.join(LENGTH_UNITS)}, got {units!r}"
        ) from None


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
    checks: list[tuple[str, FloatArray | None, float, str]] = [
        ("CoM excursion", _span(recording.com), 5.0, "m"),
        ("CoP excursion", _span(recording.cop), 3.0, "m"),
        ("CoM speed", _largest(recording.com_velocity), 10.0, "m/s"),
    ]
    for axis, edges in recording.base.items():
        width = _largest(edges[:, 1] - edges[:, 0])
        checks.append((f"base of support width along {axis}", width, 2.0, "m"))
    for name, value, limit, unit in checks:
        if value is not None and float(np.max(value)) > limit:
            raise InputFileError(
                f"{path}: {name} of {float(np.max(value)):.4g} {unit} is not a standing body's "
                f"(at most {limit:g} {unit}); {hint}"
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

    Raises
    ------
    ParameterTypeError
        If ``ap_axis`` is not a str.
    InvalidParameterError
        If ``ap_axis`` is not one of the names, or not horizontal, or ``up`` is not a unit
        lab axis (3 numbers).
    """
    require_type("ap_axis", ap_axis, str)
    if ap_axis not in AP_AXES:
        raise InvalidParameterError(f"ap_axis must be one of {', '.join(AP_AXES)}, got {ap_axis!r}")
    vertical = np.array([0.0, 0.0, 1.0]) if up is None else finite_vector("up", up, 3)
    if up is not None and sorted(np.abs(vertical).tolist()) != [0.0, 0.0, 1.0]:
        raise InvalidParameterError(f"up must be a unit lab axis, got {vertical.tolist()}")
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
