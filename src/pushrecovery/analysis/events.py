r"""Trial events from the force plates: perturbation onset, flight phases, quiet windows, mass.

Times [s], forces [N] on the subject, accelerations [m/s²], body axes of
:mod:`~pushrecovery.analysis.recording`; every threshold is a parameter. docs/events.md has the
definitions, the sources, the defaults' reasons and the numbers on real jump files.

* Onset: the first sample after a baseline from which \|x − μ\| > k σ (baseline mean and SD)
  holds for ``min_duration`` (Hodges & Bui 1996), on F_h / m or on the kinematic CoM
  acceleration.
* Flight: total vertical force below ``threshold`` (20 N, :data:`.recording.LOADED`); unloaded
  runs closer than ``min_duration`` merged, shorter ones dropped.
* Quiet: windows loaded throughout whose vertical CoM acceleration a_z = F_z/m − g has an SD
  ≤ ``max_acceleration`` and a mean within it of the still windows' median; the mass is their
  mean force over g.

Over 400 lines on purpose: the events of a trial are read from the same plate signals, with
the same baseline and run-length helpers.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.analysis.recording import LOADED
from pushrecovery.analysis.signals import _find_gaps, _times
from pushrecovery.arguments import (
    bounded_float,
    finite_float,
    non_negative_float,
    positive_float,
    require_type,
    sample_array,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import LIMITS

__all__ = [
    "MIN_DURATION",
    "FlightPhases",
    "QuietMass",
    "flight_phases",
    "mass_from_quiet",
    "perturbation_onset",
    "quiet_windows",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
Interval = tuple[float, float]

#: Shortest flight, contact or unloaded run counted [s]: shorter ones are noise.
MIN_DURATION = 0.02
#: Standard gravity [m/s²], the default of :func:`quiet_windows`.
STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True, slots=True, eq=False)
class FlightPhases:
    """Intervals without ground contact (module docstring).

    Attributes
    ----------
    intervals : tuple of (start, end)
        Each flight from its first unloaded sample to the first loaded one after it (or the
        last sample) [s].
    mask : ndarray of bool, shape (n,)
        True on the samples of a flight (to exclude them).
    threshold : float
        Vertical force below which a sample is unloaded [N].
    """

    intervals: tuple[Interval, ...]
    mask: BoolArray
    threshold: float

    @property
    def duration(self) -> float:
        """Total time in flight [s]."""
        return float(sum(end - start for start, end in self.intervals))

    def to_dict(self) -> dict[str, object]:
        """JSON form."""
        return {
            "threshold": self.threshold,
            "total_duration": self.duration,
            "flights": [{"start": a, "end": b, "duration": b - a} for a, b in self.intervals],
        }


@dataclass(frozen=True, slots=True)
class QuietMass:
    """Body mass from the quiet windows of a trial.

    Attributes
    ----------
    mass : float
        Mean vertical force over the quiet samples divided by g [kg].
    spread : float or None
        SD (n − 1) of the windows' mean forces over g [kg], None with a single window.
    sample_spread : float
        SD (n − 1) of the quiet samples' force over g [kg] (noise and sway).
    windows, duration : int, float
        Number of windows used, and the time they cover [s].
    """

    mass: float
    spread: float | None
    sample_spread: float
    windows: int
    duration: float

    def to_dict(self) -> dict[str, object]:
        """Table row."""
        return asdict(self)


def _period(time: FloatArray) -> float:
    """Median sample period [s] (1 for a single sample)."""
    return float(np.median(np.diff(time))) if len(time) > 1 else 1.0


def _signal(name: str, value: ArrayLike, time: FloatArray) -> FloatArray:
    """Return a one-dimensional signal of one sample per time (NaN missing, no infinities)."""
    signal = sample_array(name, value, values="nan")
    if len(signal) != len(time):
        raise InvalidParameterError(
            f"{name} must have one sample per time ({len(time)}), got {len(signal)}"
        )
    return signal


def _runs(flags: BoolArray, period: float, min_duration: float) -> list[tuple[int, int]]:
    """Find runs [start, stop) of True, merged across shorter gaps, kept if >= min_duration."""
    runs = _find_gaps(flags)
    merged: list[tuple[int, int]] = []
    for start, stop in runs:
        if merged and (start - merged[-1][1]) * period < min_duration - 1e-12:
            merged[-1] = (merged[-1][0], stop)
        else:
            merged.append((start, stop))
    return [(a, b) for a, b in merged if (b - a) * period >= min_duration - 1e-12]


def perturbation_onset(
    time: ArrayLike,
    signal: ArrayLike,
    *,
    baseline: float | tuple[float, float] = 0.5,
    k: float = 3.0,
    min_duration: float = 0.02,
) -> float | None:
    """First time the signal leaves its baseline mean ± k SD for ``min_duration`` (module doc).

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], finite, strictly increasing, at a constant rate.
    signal : array_like, shape (n,)
        E.g. F_ap / m or the CoM acceleration along ap [m/s²]; NaN marks a missing sample.
    baseline : float or (float, float)
        The trial's first ``baseline`` seconds (> 0), or an interval (t0, t1) [s], before the
        perturbation, holding at least 2 finite samples.
    k : float
        Threshold in baseline standard deviations, > 0 (Hodges & Bui compared 1 to 3).
    min_duration : float
        Time the signal must stay beyond the threshold [s], >= 0 (0: one sample).

    Returns
    -------
    float or None
        First sample of the first such run after the baseline [s]; None if there is none.

    Raises
    ------
    InvalidParameterError
        Bad times (not finite, not increasing) or signal (shape, length, infinities), a
        baseline that is no positive duration or interval with 2 finite samples, ``k`` <= 0
        or ``min_duration`` < 0; ParameterTypeError for a baseline of another type.
    """
    time = _times("time", time)
    values = _signal("signal", signal, time)
    start, end = _baseline(baseline, time)
    k = positive_float("k", k)
    min_duration = non_negative_float("min_duration", min_duration, "s")
    inside = (time >= start) & (time <= end) & np.isfinite(values)
    if np.count_nonzero(inside) < 2:
        raise InvalidParameterError(
            f"baseline ({start:g}, {end:g}) s must hold at least 2 finite samples of signal, "
            f"got {np.count_nonzero(inside)}"
        )
    mean, sd = float(np.mean(values[inside])), float(np.std(values[inside], ddof=1))
    with np.errstate(invalid="ignore"):
        beyond = (np.abs(values - mean) > k * sd) & (time > end)
    # Clamped before rounding: a duration beyond the recording needs more samples than it has.
    needed = max(1, math.ceil(min(min_duration / _period(time), len(time) + 1.0) - 1e-9))
    for first, stop in _find_gaps(np.asarray(beyond)):
        if stop - first >= needed:
            return float(time[first])
    return None


def _baseline(baseline: object, time: FloatArray) -> Interval:
    """Return the baseline interval [s] from a duration or a pair."""
    if isinstance(baseline, tuple | list | np.ndarray):
        pair = sample_array("baseline", baseline)
        if pair.shape != (2,) or not pair[0] < pair[1]:
            raise InvalidParameterError(
                f"baseline must be a duration > 0 [s] or an interval (t0, t1) with t0 < t1, "
                f"got {np.asarray(baseline).tolist()}"
            )
        return float(pair[0]), float(pair[1])
    require_type("baseline", baseline, (int, float, np.number))
    duration = positive_float("baseline", baseline, "s")
    return float(time[0]), float(time[0]) + duration


def flight_phases(
    time: ArrayLike,
    vertical_force: ArrayLike,
    *,
    threshold: float = LOADED,
    min_duration: float = MIN_DURATION,
) -> FlightPhases:
    """Find the flight phases: total vertical force below ``threshold`` (module docstring).

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times of the force [s], finite, strictly increasing.
    vertical_force : array_like, shape (n,)
        Total vertical ground reaction force of all plates [N]; NaN samples count as loaded.
    threshold : float
        Force below which the subject is off the ground [N], finite (default 20 N,
        :data:`~pushrecovery.analysis.recording.LOADED`).
    min_duration : float
        Shortest flight, and shortest load between two flights, that counts [s], >= 0.

    Returns
    -------
    FlightPhases

    Raises
    ------
    InvalidParameterError
        Times not finite or not increasing, a force of another shape or length or with
        infinities, a non-finite ``threshold``, or ``min_duration`` < 0.
    """
    time = _times("time", time)
    force = _signal("vertical_force", vertical_force, time)
    threshold = finite_float("threshold", threshold, "N")
    min_duration = non_negative_float("min_duration", min_duration, "s")
    with np.errstate(invalid="ignore"):
        unloaded = np.asarray(force < threshold)
    runs = _runs(unloaded, _period(time), min_duration)
    mask = np.zeros(len(time), dtype=bool)
    intervals = []
    for start, stop in runs:
        mask[start:stop] = True
        intervals.append((float(time[start]), float(time[min(stop, len(time) - 1)])))
    return FlightPhases(tuple(intervals), mask, threshold)


def quiet_windows(
    time: ArrayLike,
    vertical_force: ArrayLike,
    *,
    window: float = 0.5,
    max_acceleration: float = 0.5,
    gravity: float = STANDARD_GRAVITY,
    threshold: float = LOADED,
) -> list[Interval]:
    """Windows in which the body stands still, from the vertical force (module docstring).

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], finite, strictly increasing.
    vertical_force : array_like, shape (n,)
        Total vertical ground reaction force [N]; a window with a missing (NaN) sample is
        never quiet.
    window : float
        Length of the consecutive windows the trial is cut into from its start [s], > 0,
        holding at least 3 samples; a last, shorter part is left out.
    max_acceleration : float
        Largest standard deviation of the vertical CoM acceleration within a window, and
        largest departure of its mean acceleration from the still windows' median [m/s²],
        > 0 (default 0.5 m/s², about 0.05 g).
    gravity : float
        Gravitational acceleration [m/s²], > 0.
    threshold : float
        Every sample of a quiet window carries at least this [N] (no flight), finite.

    Returns
    -------
    list of (start, end)
        The quiet windows [s], each from its first sample to the first sample after it.

    Raises
    ------
    InvalidParameterError
        Bad times or force (as :func:`flight_phases`), ``window`` <= 0 or of fewer than 3
        samples, ``max_acceleration`` outside [1e-6, 100] m/s², ``gravity`` outside [0.1, 100]
        m/s², or a non-finite ``threshold``.
    """
    time = _times("time", time)
    force = _signal("vertical_force", vertical_force, time)
    window = positive_float("window", window, "s")
    # A still window's bound [m/s²]: beyond g it no longer tells standing from falling.
    max_acceleration = bounded_float("max_acceleration", max_acceleration, 1e-6, 100.0, "m/s²")
    gravity = bounded_float("gravity", gravity, *LIMITS["gravity"][:2], "m/s²")
    threshold = finite_float("threshold", threshold, "N")
    size = round(min(window / _period(time), len(time) + 1.0))  # clamped before rounding
    if size < 3:
        raise InvalidParameterError(
            f"window must hold at least 3 samples ({3 * _period(time):g} s at this rate), "
            f"got window={window:g} s"
        )
    count = len(time) // size
    if count == 0:
        return []
    blocks = force[: count * size].reshape(count, size)
    with np.errstate(invalid="ignore"):
        loaded = np.all(blocks >= threshold, axis=1)
    means = np.mean(blocks, axis=1)
    sds = np.std(blocks, axis=1, ddof=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        still = loaded & (gravity * sds <= max_acceleration * means)
    if not still.any():
        return []
    consensus = float(np.median(means[still]))
    kept = still & (np.abs(means - consensus) * gravity <= max_acceleration * consensus)
    ends = np.minimum(np.arange(1, count + 1) * size, len(time) - 1)
    return [(float(time[i * size]), float(time[ends[i]])) for i in np.flatnonzero(kept)]


def _windows(value: object) -> FloatArray:
    """Windows as a (k, 2) array of finite (start, end) with start < end, k >= 1."""
    require_type("windows", value, (list, tuple, np.ndarray))
    array = sample_array("windows", value, (2,))  # type: ignore[arg-type]
    if array.shape[0] == 0 or array.shape[1] != 2 or not (array[:, 0] < array[:, 1]).all():
        raise InvalidParameterError(
            "windows must be at least one (start, end) interval [s] with start < end, "
            f"got an array of shape {array.shape}"
        )
    return array


def mass_from_quiet(
    time: ArrayLike, vertical_force: ArrayLike, gravity: float, windows: ArrayLike
) -> QuietMass:
    """Body mass: mean vertical force over the quiet windows only, over g, with its spread.

    The whole-trial mean equals the weight only for a trial that starts and ends at rest with
    its flights kept (the impulse of F − mg is the change of momentum); without the flights it
    is too high by T / (T − T_flight) (docs/events.md). Quiet windows need neither.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], finite, strictly increasing.
    vertical_force : array_like, shape (n,)
        Total vertical ground reaction force [N], NaN where missing (left out).
    gravity : float
        Gravitational acceleration [m/s²], > 0.
    windows : array_like, shape (k, 2)
        Quiet intervals (start, end) [s], start < end (:func:`quiet_windows`); a window takes
        the samples with start <= t < end.

    Returns
    -------
    QuietMass

    Raises
    ------
    InvalidParameterError
        Bad times or force (as :func:`quiet_windows`), ``gravity`` outside [0.1, 100] m/s²,
        windows that are not (start, end) pairs, or windows holding fewer than 2 finite samples.
    """
    time = _times("time", time)
    force = _signal("vertical_force", vertical_force, time)
    gravity = bounded_float("gravity", gravity, *LIMITS["gravity"][:2], "m/s²")
    intervals = _windows(windows)
    means, samples, duration = [], [], 0.0
    for start, end in intervals:
        inside = (time >= start) & (time < end) & np.isfinite(force)
        if inside.any():
            means.append(float(np.mean(force[inside])))
            samples.append(force[inside])
            duration += float(end - start)
    pooled = np.concatenate(samples) if samples else np.empty(0)
    if len(pooled) < 2:
        raise InvalidParameterError(
            f"windows must hold at least 2 finite samples of vertical_force, got {len(pooled)}"
        )
    spread = float(np.std(means, ddof=1)) / gravity if len(means) > 1 else None
    return QuietMass(
        mass=float(np.mean(pooled)) / gravity,
        spread=spread,
        sample_spread=float(np.std(pooled, ddof=1)) / gravity,
        windows=len(means),
        duration=duration,
    )
