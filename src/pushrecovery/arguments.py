"""Small argument checks shared by the public functions (validate once at the boundary)."""

from __future__ import annotations

import math
import os
import stat
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.errors import InputFileError, InvalidParameterError, ParameterTypeError

#: A bound for numbers a formula squares where nothing narrower is checked
#: (:func:`finite_array`'s ``bound``): no quantity of a humanoid comes near, and squares and
#: products stay finite (1e300 < 1.8e308).
MAX_MAGNITUDE = 1e150
_LARGEST = float(np.finfo(np.float64).max)


def require_type(name: str, value: object, kind: type | tuple[type, ...]) -> None:
    """Raise :class:`ParameterTypeError` naming ``name`` unless ``value`` is a ``kind``."""
    if not isinstance(value, kind):
        kinds = kind if isinstance(kind, tuple) else (kind,)
        expected = " or ".join(k.__name__ for k in kinds)
        raise ParameterTypeError(f"{name} must be a {expected}, got {type(value).__name__}")


def finite_float(name: str, value: object, unit: str = "", allowed: str = "") -> float:
    """Return ``value`` as a finite float or raise naming ``name`` (and ``allowed``, e.g. "> 0").

    The message is built only on failure: the checks of a valid call cost a conversion and a
    comparison (tens of nanoseconds), so that they fit functions called in loops.
    """
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(
            f"{_what(name, unit, allowed)}, got {str(value)[:40]!r}"
        ) from None
    if not math.isfinite(number):
        raise InvalidParameterError(f"{_what(name, unit, allowed)}, got {number}")
    return number


def positive_float(name: str, value: object, unit: str = "") -> float:
    """Return ``value`` as a finite float > 0 or raise naming ``name`` and the range."""
    number = finite_float(name, value, unit, allowed="> 0")
    if number <= 0.0:
        raise InvalidParameterError(f"{name} must be > 0{_unit(unit)}, got {name}={number:g}")
    return number


def non_negative_float(name: str, value: object, unit: str = "") -> float:
    """Return ``value`` as a finite float >= 0 or raise naming ``name`` and the range."""
    number = finite_float(name, value, unit, allowed=">= 0")
    if number < 0.0:
        raise InvalidParameterError(f"{name} must be >= 0{_unit(unit)}, got {name}={number:g}")
    return number


def bounded_float(name: str, value: object, low: float, high: float, unit: str = "") -> float:
    """Return ``value`` as a finite float in [``low``, ``high``] or raise naming the range."""
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        number = math.nan  # refused below, with finite_float's message
    if low <= number <= high and math.isfinite(number):  # NaN fails the comparison
        return number
    number = finite_float(name, value, unit, allowed=f"in [{low:g}, {high:g}]")
    raise InvalidParameterError(
        f"{name} must be in [{low:g}, {high:g}]{_unit(unit)}, got {name}={number:g}"
    )


def float_array(name: str, value: ArrayLike) -> NDArray[np.float64]:
    """Return ``value`` as a float64 array (values not checked), or raise naming ``name``.

    None is refused (numpy would read it as NaN), and so are complex numbers (numpy would drop
    their imaginary parts with a warning).
    """
    if value is None:
        raise ParameterTypeError(f"{name} must be a number or an array of numbers, got None")
    if isinstance(value, complex | np.complexfloating) or (
        isinstance(value, np.ndarray) and value.dtype.kind == "c"
    ):
        raise ParameterTypeError(f"{name} must be real numbers, got complex")
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(
            f"{name} must be a number or an array of numbers, got {str(value)[:40]!r}"
        ) from None


def output_array(name: str, value: object, shape: tuple[int, ...]) -> NDArray[np.float64]:
    """Return ``value`` if it is a writeable float64 array of ``shape``, or raise naming ``name``.

    The ``out=`` arguments that save an allocation: a wrong one is refused before any work.
    """
    if not isinstance(value, np.ndarray) or value.dtype != np.float64:
        kind = value.dtype if isinstance(value, np.ndarray) else type(value).__name__
        raise ParameterTypeError(f"{name} must be a float64 numpy array, got {kind}")
    if value.shape != shape or not value.flags.writeable:
        raise InvalidParameterError(
            f"{name} must be a writeable array of shape {shape} (the inputs' broadcast shape), "
            f"got shape {value.shape}" + ("" if value.flags.writeable else ", read-only")
        )
    return value


def output_folder(name: str, value: object) -> Path:
    """Create the folder ``value`` (and its parents) and return it, or raise naming ``name``.

    A path that is a file, a device, empty, too long or not writable is refused in one line.
    """
    if not isinstance(value, str | os.PathLike) or not str(value):
        raise ParameterTypeError(f"{name} must be a folder's path, got {str(value)[:40]!r}")
    folder = Path(value)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InvalidParameterError(
            f"{name}: cannot create the folder {str(folder)[:200]}: {exc.strerror or exc}"
        ) from None
    return folder


def input_path(name: str, value: object) -> Path:
    """Return ``value`` as a Path, or raise :class:`ParameterTypeError` unless str or PathLike."""
    require_type(name, value, (str, os.PathLike))
    return Path(value)  # type: ignore[arg-type]


def input_file(name: str, value: object) -> Path:
    """Return ``value`` as the Path of a regular, non-empty file, or raise naming why.

    A FIFO would block a reader and ``/dev/zero`` never end; a name too long, with a NUL or in a
    symlink loop is refused with the OS's reason, all as :class:`InputFileError` in one line.
    """
    path = input_path(name, value)
    try:
        found = path.stat()
    except FileNotFoundError:
        raise InputFileError(f"file not found: {path}") from None
    except ValueError:  # a NUL in the name
        raise InputFileError(f"{str(path)[:200]!r} is not a file name (a NUL character)") from None
    except OSError as exc:
        raise InputFileError(f"{str(path)[:200]}: {exc.strerror or exc}") from None
    if stat.S_ISDIR(found.st_mode):
        raise InputFileError(f"{path} is a directory, not a file")
    if not stat.S_ISREG(found.st_mode):
        raise InputFileError(f"{path} is not a regular file (a pipe or a device)")
    if found.st_size == 0:
        raise InputFileError(f"{path} is empty")
    return path


def finite_array(
    name: str, value: ArrayLike, bound: float = math.inf, unit: str = ""
) -> NDArray[np.float64]:
    """Return ``value`` as a float64 array with only finite entries, or raise naming ``name``.

    With ``bound``, entries must also lie in ±``bound`` (e.g. :data:`MAX_MAGNITUDE` where
    the formula that follows squares them and nothing narrower is checked).
    """
    array = float_array(name, value)
    # Two reductions, no temporary: NaN propagates into both and fails the comparisons, and
    # so do infinities (the limit is the largest float at most).
    limit = min(bound, _LARGEST)
    if array.size and not (array.max() <= limit and array.min() >= -limit):
        bad = int(np.size(array) - np.count_nonzero(np.isfinite(array)))
        if bad:
            raise InvalidParameterError(f"{name} must be finite, got {bad} non-finite value(s)")
        raise InvalidParameterError(
            f"{name} must have entries in [-{bound:g}, {bound:g}]{_unit(unit)}, "
            f"got {float(np.max(np.abs(array))):g}"
        )
    return array


def _unit(unit: str) -> str:
    return f" [{unit}]" if unit else ""


def _what(name: str, unit: str, allowed: str) -> str:
    return f"{name} must be a finite number{' ' + allowed if allowed else ''}{_unit(unit)}"


def flag(name: str, value: object) -> bool:
    """Return ``value`` as a bool, or raise naming ``name``: True or False only (numpy's too).

    A flag given any other value (a string, None, an object) is refused, not taken by its
    truth value.
    """
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise ParameterTypeError(f"{name} must be True or False, got {str(value)[:40]!r}")


def whole_number(name: str, value: object, low: int, high: int) -> int:
    """Return ``value`` as an int in [``low``, ``high``], or raise naming ``name`` and the range.

    An int or a float with no fractional part (``2.0``, as a TOML file may give it); a bool is
    not a number here.
    """
    if type(value) is int and low <= value <= high:  # the common case, without the checks below
        return value
    what = f"{name} must be a whole number in [{low}, {high}]"
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.number):
        raise ParameterTypeError(f"{what}, got {type(value).__name__}")
    if isinstance(value, float | np.floating) and not float(value).is_integer():  # NaN, inf too
        raise InvalidParameterError(f"{what}, got {name}={value!r}")
    if not low <= value <= high:
        raise InvalidParameterError(f"{what}, got {name}={value:g}")
    return int(value)


def broadcast(**arrays: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """Return the arrays broadcast together, or raise naming them and their shapes."""
    try:
        return list(np.broadcast_arrays(*arrays.values()))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays.items())
        raise InvalidParameterError(f"{', '.join(arrays)} must broadcast, got {shapes}") from None


def finite_vector(
    name: str, value: ArrayLike, size: int, bound: float = math.inf, unit: str = ""
) -> NDArray[np.float64]:
    """Return ``value`` as a finite float array of shape (``size``,), entries in ±``bound``."""
    array = finite_array(name, value)
    if array.shape != (size,):
        raise InvalidParameterError(
            f"{name} must be {size} numbers (shape ({size},)){_unit(unit)}, got shape {array.shape}"
        )
    return finite_array(name, array, bound, unit)


def finite_pair(name: str, value: object, bound: float, unit: str) -> tuple[float, float]:
    """Return ``finite_vector(name, value, 2, bound, unit)`` as two floats.

    A tuple of two Python floats within the bound skips numpy (a tick's cost); anything else
    goes through :func:`finite_vector`, which refuses it by name.
    """
    if type(value) is tuple and len(value) == 2 and all(type(v) is float for v in value):
        a, b = value
        if abs(a) <= bound and abs(b) <= bound:  # False for NaN: refused below, by name
            return a, b
    a, b = finite_vector(name, value, 2, bound, unit).tolist()  # type: ignore[arg-type]
    return a, b


def sample_array(
    name: str, value: ArrayLike, ndims: tuple[int, ...] = (1,), *, values: str = "finite"
) -> NDArray[np.float64]:
    """Return ``value`` as a float array of samples along axis 0, its ``ndim`` one of ``ndims``.

    ``values``: ``"finite"`` refuses NaN and infinities, ``"nan"`` lets NaN mark a missing
    sample (infinities refused), ``"any"`` checks no value.
    """
    array = float_array(name, value)
    if array.ndim not in ndims:
        shapes = " or ".join(["(n,)", "(n, k)", "(n, k, m)"][d - 1] for d in ndims)
        raise InvalidParameterError(f"{name} must be an array of shape {shapes}, got {array.shape}")
    if values != "any":
        bad = np.isinf(array) if values == "nan" else ~np.isfinite(array)
        if bad.any():
            allowed = "finite or NaN (missing)" if values == "nan" else "finite"
            raise InvalidParameterError(
                f"{name} must be {allowed}, got {int(np.count_nonzero(bad))} bad value(s)"
            )
    return array
