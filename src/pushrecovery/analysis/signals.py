"""Measured signals: gaps, zero-lag low-pass filtering and differentiation (scipy.signal).

A gap is a run of missing (NaN) samples. Gaps up to ``max_gap`` seconds inside a signal are
filled by a cubic spline through the valid samples (as motion-capture software fills
marker gaps) and reported; longer gaps, and missing
samples at either end of a recording (nothing to interpolate from), are left missing and split
the signal into segments that are filtered and differentiated on their own, so that neither
the filter nor the derivative ever reaches across a gap.

The filter is a Butterworth low-pass run forward and backward (``sosfiltfilt``): zero phase
lag, and the magnitude response of a filter of twice the order. The cutoff is the -3 dB
frequency of that forward-backward response: the single-pass design frequency is corrected
by Winter's factor C = (2^(1/n) − 1)^(1/4), n = 2 passes, applied to the pre-warped
frequency, tan(π f_design / rate) = tan(π f_c / rate) / C (Winter, *Biomechanics and Motor
Control of Human Movement*, 4th ed., Sec. 3.4.4.3), so a 6 Hz cutoff really is -3 dB at 6 Hz.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline
from scipy.signal import butter, sosfiltfilt

from pushrecovery.arguments import (
    bounded_float,
    finite_float,
    positive_float,
    require_type,
    sample_array,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

__all__ = [
    "FILTER_ORDER",
    "MAX_RATE",
    "MIN_CUTOFF_RATIO",
    "MIN_RATE",
    "Gap",
    "find_gaps",
    "lowpass",
    "noise_gains",
    "repair_gaps",
    "resample",
    "segments",
    "smooth_and_differentiate",
]

FloatArray = NDArray[np.float64]

#: Order of the Butterworth design; run forward and backward it acts as a 4th-order filter.
FILTER_ORDER = 2
#: The lowest cutoff, as a fraction of the sampling rate: below it the design is singular.
MIN_CUTOFF_RATIO = 1e-6
#: Sampling rates a recording may have [Hz]: a sample per 100 s to a MHz.
MIN_RATE, MAX_RATE = 1e-2, 1e6


@dataclass(frozen=True, slots=True)
class Gap:
    """A run of missing samples of one signal.

    Attributes
    ----------
    signal : str
        Name of the signal (e.g. ``"com"``, ``"cop"``, a marker label).
    start, end : float
        Time of the first and of the last missing sample [s].
    samples : int
        Number of missing samples.
    filled : bool
        True when interpolated, False when left missing (too long, or at an end).
    """

    signal: str
    start: float
    end: float
    samples: int
    filled: bool

    def to_dict(self) -> dict[str, object]:
        """JSON form."""
        return {
            "signal": self.signal,
            "start": self.start,
            "end": self.end,
            "duration": self.end - self.start,
            "samples": self.samples,
            "filled": self.filled,
        }


def _flags(name: str, value: object) -> NDArray[np.bool_]:
    """Return ``value`` as a one-dimensional bool array, or raise naming ``name``."""
    try:
        array = np.asarray(value)
    except ValueError:  # ragged
        raise ParameterTypeError(f"{name} must be a one-dimensional bool array") from None
    if array.dtype != np.bool_ or array.ndim != 1:
        raise ParameterTypeError(
            f"{name} must be a one-dimensional bool array, got {array.dtype} of shape {array.shape}"
        )
    return array


def _times(name: str, value: object) -> FloatArray:
    """Return ``value`` as sample times: one-dimensional, finite, strictly increasing [s]."""
    time = sample_array(name, value)  # type: ignore[arg-type]
    if (np.diff(time) <= 0.0).any():
        raise InvalidParameterError(f"{name} must increase strictly from sample to sample")
    return time


def _same_length(name: str, values: FloatArray, time: FloatArray, time_name: str) -> None:
    if len(values) != len(time):
        raise InvalidParameterError(
            f"{name} must have one sample per {time_name} ({len(time)}), got {len(values)}"
        )


def find_gaps(missing: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Index ranges [start, stop) of the runs of True in ``missing`` (one-dimensional).

    Raises
    ------
    ParameterTypeError
        If ``missing`` is not a one-dimensional bool array.
    """
    return _find_gaps(_flags("missing", missing))


def _find_gaps(missing: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """:func:`find_gaps` of a checked array."""
    edges = np.diff(np.concatenate(([0], missing.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True))


def repair_gaps(
    time: FloatArray, values: FloatArray, max_gap: float, name: str
) -> tuple[FloatArray, list[Gap]]:
    """Fill the short inner gaps of a signal; report every gap.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sample times [s], finite, strictly increasing.
    values : ndarray, shape (n,) or (n, k)
        The signal; a sample is missing when any of its components is NaN (or infinite).
    max_gap : float
        Longest gap that is interpolated, measured between the valid samples either side
        minus one sample period [s], >= 0.
    name : str
        Signal name for the report.

    Returns
    -------
    (values, gaps)
        A copy with the short inner gaps filled (a not-a-knot cubic spline through all the
        valid samples), and the list of gaps in time order.

    Raises
    ------
    ParameterTypeError
        If ``name`` is not a str.
    InvalidParameterError
        Times that are not finite and increasing, values of another shape or length, or a
        negative or non-finite ``max_gap``.
    """
    time = _times("time", time)
    values = np.array(sample_array("values", values, (1, 2), values="any"))
    _same_length("values", values, time, "time")
    max_gap = finite_float("max_gap", max_gap, "s", allowed=">= 0")
    if max_gap < 0.0:
        raise InvalidParameterError(f"max_gap must be >= 0 s, got {max_gap:g}")
    require_type("name", name, str)
    flat = values.reshape(len(values), -1)
    missing = np.asarray(~np.isfinite(flat).all(axis=1))
    gaps: list[Gap] = []
    if not missing.any():
        return values, gaps
    valid = np.flatnonzero(~missing)
    spline = CubicSpline(time[valid], flat[valid], axis=0) if len(valid) >= 4 else None
    for start, stop in _find_gaps(missing):
        inner = start > 0 and stop < len(time)
        # The gap's length: the time with no data, between the valid samples either side.
        span = time[stop] - time[start - 1] if inner else np.inf
        period = (time[-1] - time[0]) / max(len(time) - 1, 1)
        filled = bool(inner and spline is not None and span - period <= max_gap + 1e-12)
        if filled:
            assert spline is not None
            flat[start:stop] = spline(time[start:stop])
        gaps.append(Gap(name, float(time[start]), float(time[stop - 1]), int(stop - start), filled))
    return flat.reshape(values.shape), gaps


def segments(valid: NDArray[np.bool_], shortest: int = 1) -> list[slice]:
    """Contiguous runs of valid samples, as slices, keeping those at least ``shortest`` long.

    Raises
    ------
    ParameterTypeError
        If ``valid`` is not a one-dimensional bool array.
    InvalidParameterError
        If ``shortest`` is not a whole number >= 1.
    """
    valid = _flags("valid", valid)
    shortest = whole_number("shortest", shortest, 1, 2**62)
    return _segments(valid, shortest)


def _segments(valid: NDArray[np.bool_], shortest: int) -> list[slice]:
    """:func:`segments` of checked arguments."""
    return [slice(a, b) for a, b in _find_gaps(valid) if b - a >= shortest]


def lowpass(values: FloatArray, rate: float, cutoff: float) -> FloatArray:
    """Zero-lag Butterworth low-pass of one gap-free segment (module docstring).

    Parameters
    ----------
    values : ndarray, shape (n,) or (n, k)
        Samples along axis 0, all finite.
    rate : float
        Sampling rate [Hz], > 0.
    cutoff : float
        -3 dB frequency of the forward-backward filter [Hz], in (0, rate/2); 0 disables it.

    Returns
    -------
    ndarray
        The filtered samples (the input itself when ``cutoff`` is 0 or the segment is too short
        to filter: fewer than 4 samples).

    Raises
    ------
    InvalidParameterError
        Values that are not finite or not of shape (n,) or (n, k), a non-positive ``rate``,
        or a ``cutoff`` that is not 0 or in (0, rate/2).
    """
    values = sample_array("values", values, (1, 2))
    rate = positive_float("rate", rate, "Hz")
    cutoff = finite_float("cutoff", cutoff, "Hz", allowed=f"0 or in (0, {0.5 * rate:g})")
    if cutoff != 0.0:
        _check_cutoff(cutoff, rate)
    return _lowpass(values, rate, cutoff)


def _check_cutoff(cutoff: float, rate: float) -> None:
    """Refuse a cutoff [Hz] at or past Nyquist, or below a millionth of the rate [Hz]."""
    if not 0.0 < cutoff < 0.5 * rate:
        raise InvalidParameterError(
            f"cutoff must be in (0, {0.5 * rate:g}) Hz (half the sampling rate), got {cutoff:g}"
        )
    if cutoff < MIN_CUTOFF_RATIO * rate:
        raise InvalidParameterError(
            f"cutoff must be 0 or at least {MIN_CUTOFF_RATIO * rate:g} Hz (a millionth of the "
            f"sampling rate: below, the filter's design is singular), got {cutoff:g}"
        )


def _lowpass(values: FloatArray, rate: float, cutoff: float) -> FloatArray:
    """:func:`lowpass` of checked arguments."""
    if cutoff == 0.0 or len(values) < 4:
        return values
    _check_cutoff(cutoff, rate)
    # Winter's correction: the double pass lowers the -3 dB point; design above it.
    correction = (2.0 ** (1.0 / 2.0) - 1.0) ** 0.25
    design = rate / np.pi * np.arctan(np.tan(np.pi * cutoff / rate) / correction)
    sos = butter(FILTER_ORDER, design, btype="low", fs=rate, output="sos")
    padlen = min(3 * (2 * len(sos) + 1), len(values) - 1)
    return sosfiltfilt(sos, values, axis=0, padlen=padlen)


def smooth_and_differentiate(
    time: FloatArray, values: FloatArray, cutoff: float
) -> tuple[FloatArray, FloatArray]:
    """Filter each gap-free segment and differentiate it by central differences.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sample times [s] at a constant rate.
    values : ndarray, shape (n,) or (n, k)
        The signal, NaN where missing.
    cutoff : float
        Low-pass cutoff [Hz] (see :func:`lowpass`), 0 for none.

    Returns
    -------
    (smooth, rate_of_change)
        Both NaN where the signal is missing and on segments shorter than 3 samples (no
        derivative from fewer); rate of change in units per second.

    Raises
    ------
    InvalidParameterError
        Times that are not finite and strictly increasing, values of another shape or length,
        or a ``cutoff`` that is not 0 or in (0, rate/2).
    """
    time = _times("time", time)
    values = sample_array("values", values, (1, 2), values="any")
    _same_length("values", values, time, "time")
    cutoff = finite_float("cutoff", cutoff, "Hz", allowed=">= 0")
    if cutoff < 0.0:
        raise InvalidParameterError(f"cutoff must be >= 0 Hz, got {cutoff:g}")
    rate = (len(time) - 1) / (time[-1] - time[0]) if len(time) > 1 else 1.0
    flat = values.reshape(len(values), -1)
    smooth = np.full_like(flat, np.nan)
    slope = np.full_like(flat, np.nan)
    finite = np.asarray(np.isfinite(flat).all(axis=1))
    for part in _segments(finite, 3):
        smooth[part] = _lowpass(flat[part], rate, cutoff)
        slope[part] = np.gradient(smooth[part], time[part], axis=0)
    return smooth.reshape(values.shape), slope.reshape(values.shape)


def noise_gains(rate: float, cutoff: float) -> tuple[float, float]:
    """Return how :func:`smooth_and_differentiate` scales white noise: (position, rate) gains.

    A signal with independent errors of standard deviation σ at each sample comes out of the
    low-pass with errors of σ·g₀ and its derivative with σ·g₁ [1/s], g² = Σ h_k² over the
    chain's impulse response h (linear and time-invariant away from the ends). Computed from
    the impulse response itself: a unit sample in the middle of ``20 rate / cutoff`` zeros
    (at least 401). For a zero-phase filter the two errors at one sample are uncorrelated.

    Parameters
    ----------
    rate : float
        Sample rate [Hz], in [``MIN_RATE``, ``MAX_RATE``].
    cutoff : float
        Low-pass cutoff [Hz], 0 (none) or in (0, rate/2).
    """
    rate = bounded_float("rate", rate, MIN_RATE, MAX_RATE, "Hz")
    cutoff = finite_float("cutoff", cutoff, "Hz", allowed=">= 0")
    if cutoff < 0.0:
        raise InvalidParameterError(f"cutoff must be >= 0 Hz, got {cutoff:g}")
    ratio = 10.0 * rate / cutoff if cutoff > 0.0 else 0.0  # compared before int(): may be inf
    half = max(200, int(ratio) if ratio <= 10**6 else 10**6 + 1)
    if half > 10**6:
        raise InvalidParameterError(
            f"cutoff must be at least 1e-5 of the rate for the noise gains, got {cutoff:g} Hz "
            f"at {rate:g} Hz"
        )
    impulse = np.zeros(2 * half + 1)
    impulse[half] = 1.0
    time = np.arange(impulse.size) / rate
    smooth, slope = smooth_and_differentiate(time, impulse, cutoff)
    return float(np.sqrt(np.sum(smooth**2))), float(np.sqrt(np.sum(slope**2)))


def resample(source: FloatArray, values: FloatArray, target: FloatArray) -> FloatArray:
    """Values (n, k) at other times, linearly; NaN beyond the ends and next to missing samples.

    Parameters
    ----------
    source : ndarray, shape (n,)
        Times of the samples [s], finite, strictly increasing.
    values : ndarray, shape (n, k)
        The samples, NaN where missing.
    target : ndarray, shape (m,)
        The times wanted [s], finite.

    Returns
    -------
    ndarray, shape (m, k)
        ``values`` itself when the times are the same.

    Raises
    ------
    InvalidParameterError
        Arrays of other shapes or lengths, times that are not finite (source: not increasing),
        or infinite values.
    """
    source = _times("source", source)
    values = sample_array("values", values, (2,), values="nan")
    _same_length("values", values, source, "source time")
    target = sample_array("target", target)
    if len(source) == len(target) and np.array_equal(source, target):
        return values
    return np.column_stack(
        [
            np.interp(target, source, values[:, j], left=np.nan, right=np.nan)
            for j in range(values.shape[1])
        ]
    )
