"""The report's formatting: numbers, percentages and images as ``data:`` URIs.

Used by the section builders (table cells) and as the templates' filters (``report/render.py``).
"""

from __future__ import annotations

import base64
import math
from pathlib import Path

import numpy as np

from pushrecovery.arguments import require_type, whole_number
from pushrecovery.errors import ParameterTypeError

__all__ = ["data_uri", "num", "percent", "percent_within"]


def _number(value: object) -> float | None:
    """``value`` as a float (NaN and infinities kept: they print as signs), None as None."""
    if value is None:
        return None
    if isinstance(value, str | bytes) or not isinstance(value, int | float | np.number):
        raise ParameterTypeError(f"value must be a number or None, got {type(value).__name__}")
    return float(value)


def num(value: float | None, digits: int = 4) -> str:
    """Format a number with ``digits`` significant digits; an em dash for None or NaN."""
    value, digits = _number(value), whole_number("digits", digits, 1, 17)
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if isinstance(value, float) and math.isinf(value):
        return "∞" if value > 0 else "−∞"
    return f"{value:.{digits}g}".replace("-", "−")


def percent(value: float | None, digits: int = 1) -> str:
    """Format a fraction as a signed percentage (``+1.2 %``); an em dash for None or NaN."""
    value, digits = _number(value), whole_number("digits", digits, 0, 17)
    if value is None or math.isnan(value):
        return "—"
    return f"{100.0 * value:+.{digits}f} %".replace("-", "−")


def percent_interval(low: float, high: float, reference: float) -> str:
    """Format the interval of errors (low/reference − 1, high/reference − 1) as percentages.

    A bisected critical push is known to lie in its bracket [low, high]: its error against a
    prediction is an interval, ``−14.3 … −13.9 %`` (smaller first; a backward push's negative
    velocities over a negative reference read as magnitudes); an em dash without a reference.
    """
    if not (reference and math.isfinite(reference)):
        return "—"
    first, last = sorted((low / reference - 1.0, high / reference - 1.0))
    return f"{percent(first).removesuffix(' %')} … {percent(last)}"


def percent_within(value: float | None, resolution: float | None) -> str:
    """Format a fraction as a percentage no finer than ``resolution`` (a fraction), with it.

    ``+27 % ± 4 %`` for a value known to ±0.04; one more digit per factor of ten finer, up
    to two decimals; :func:`percent` when the resolution is unknown.
    """
    value, resolution = _number(value), _number(resolution)
    if value is None or math.isnan(value) or resolution is None or not resolution > 0.0:
        return percent(value)
    digits = min(2, max(0, math.ceil(-math.log10(100.0 * resolution))))
    return f"{100.0 * value:+.{digits}f} % ± {100.0 * resolution:.{digits}f} %".replace("-", "−")


def data_uri(path: Path) -> str:
    """Encode the file at ``path`` (PNG, GIF or SVG) as a base64 ``data:`` URI."""
    require_type("path", path, Path)
    kinds = {".png": "image/png", ".gif": "image/gif", ".svg": "image/svg+xml"}
    kind = kinds.get(Path(path).suffix.lower(), "application/octet-stream")
    encoded = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f"data:{kind};base64,{encoded}"
