"""C3D parameters read case-insensitively: units, calibration, lab axes, rates, labels, mass."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InputFileError

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
