"""Small argument checks shared by the public functions (validate once at the boundary)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.errors import InvalidParameterError, ParameterTypeError


def require_type(name: str, value: object, kind: type | tuple[type, ...]) -> None:
    """Raise :class:`ParameterTypeError` naming ``name`` unless ``value`` is a ``kind``."""
    if not isinstance(value, kind):
        kinds = kind if isinstance(kind, tuple) else (kind,)
        expected = " or ".join(k.__name__ for k in kinds)
        raise ParameterTypeError(f"{name} must be a {expected}, got {type(value).__name__}")


def finite_float(name: str, value: object, unit: str = "", allowed: str = "") -> float:
    """Return ``value`` as a finite float or raise naming ``name`` (and ``allowed``, e.g. "> 0")."""
    what = f"{name} must be a finite number{' ' + allowed if allowed else ''}{_unit(unit)}"
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(f"{what}, got {str(value)[:40]!r}") from None
    if not math.isfinite(number):
        raise InvalidParameterError(f"{what}, got {number}")
    return number


def positive_float(name: str, value: object, unit: str = "") -> float:
    """Return ``value`` as a finite float > 0 or raise naming ``name`` and the range."""
    number = finite_float(name, value, unit, allowed="> 0")
    if number <= 0.0:
        raise InvalidParameterError(f"{name} must be > 0{_unit(unit)}, got {name}={number:g}")
    return number


def bounded_float(name: str, value: object, low: float, high: float, unit: str = "") -> float:
    """Return ``value`` as a finite float in [``low``, ``high``] or raise naming the range."""
    number = finite_float(name, value, unit, allowed=f"in [{low:g}, {high:g}]")
    if not low <= number <= high:
        raise InvalidParameterError(
            f"{name} must be in [{low:g}, {high:g}]{_unit(unit)}, got {name}={number:g}"
        )
    return number


def float_array(name: str, value: ArrayLike) -> NDArray[np.float64]:
    """Return ``value`` as a float64 array (values not checked), or raise naming ``name``."""
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(
            f"{name} must be a number or an array of numbers, got {str(value)[:40]!r}"
        ) from None


def finite_array(name: str, value: ArrayLike) -> NDArray[np.float64]:
    """Return ``value`` as a float64 array with only finite entries, or raise naming ``name``."""
    array = float_array(name, value)
    if not np.isfinite(array).all():
        bad = int(np.size(array) - np.count_nonzero(np.isfinite(array)))
        raise InvalidParameterError(f"{name} must be finite, got {bad} non-finite value(s)")
    return array


def _unit(unit: str) -> str:
    return f" [{unit}]" if unit else ""
