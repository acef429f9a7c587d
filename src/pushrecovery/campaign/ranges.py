"""The ranges of a campaign's grid: START, START + STEP, ... up to STOP (inclusive)."""

from __future__ import annotations

import math

import numpy as np

from pushrecovery.arguments import whole_number
from pushrecovery.errors import InvalidParameterError

__all__ = ["MAX_PUSHES", "Range", "interval", "value_range"]

#: Largest campaign accepted [pushes].
MAX_PUSHES = 1_000_000

Range = tuple[float, float, float]


def _triple(name: str, triple: object) -> tuple[float, float, float]:
    """START, STOP, STEP as floats (not yet checked finite), or raise naming ``name``."""
    try:
        start, stop, increment = (float(v) for v in triple)  # type: ignore[attr-defined]
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(f"{name} needs START STOP STEP, got {triple!r:.60}") from None
    return start, stop, increment


def value_range(name: str, triple: Range, limit: int = MAX_PUSHES) -> np.ndarray:
    """START, START + STEP, ... up to STOP inclusive; STEP > 0, START <= STOP, finite.

    Raises
    ------
    InvalidParameterError
        Naming ``name`` when the range is empty, not finite or longer than ``limit``.
    """
    start, stop, increment = _triple(name, triple)
    limit = whole_number("limit", limit, 1, MAX_PUSHES)
    if not all(math.isfinite(v) for v in (start, stop, increment)):
        raise InvalidParameterError(f"{name} must be finite, got {start:g} {stop:g} {increment:g}")
    if increment <= 0.0 or stop < start:
        raise InvalidParameterError(
            f"{name} needs START <= STOP and STEP > 0, got {start:g} {stop:g} {increment:g}"
        )
    spans = (stop - start) / increment
    if not math.isfinite(spans):  # a subnormal STEP: too many values to count
        raise InvalidParameterError(
            f"{name} gives too many values (STEP {increment:g} over {stop - start:g}); "
            f"at most {limit}"
        )
    count = int(np.floor(spans + 1e-9)) + 1
    if count > limit:
        raise InvalidParameterError(f"{name} gives {count} values; at most {limit}")
    # Rounded to 12 digits: 0.1 * 3 is 0.3 in the results, not 0.30000000000000004; never
    # beyond STOP.
    return np.minimum(np.round(start + increment * np.arange(count), 12), stop)


def interval(name: str, triple: Range) -> tuple[float, float]:
    """START and STOP of a range whose STEP is not used (random samples): finite, ordered."""
    start, stop, _ = _triple(name, triple)
    if not (math.isfinite(start) and math.isfinite(stop)) or stop < start:
        raise InvalidParameterError(f"{name} needs finite START <= STOP, got {start:g} {stop:g}")
    return start, stop
