"""Foot-off and foot-contact from plates or markers, and the steps a subject took, measured.

A foot's own plate gives its events from the unloaded runs of
:func:`~pushrecovery.analysis.events.flight_phases` (:func:`foot_events_from_force`); its heel
and toe markers give them by height and vertical speed above each marker's floor, with
hysteresis (:func:`foot_events_from_markers`); :func:`measured_steps` pairs each foot-off with
the foot's next contact. docs/events.md ("Foot events", "Measured steps") has the rules, their
sources (O'Connor et al. 2007, Ghoussayni et al. 2004) and their limits.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.analysis.events import (
    MIN_DURATION,
    _period,
    _runs,
    flight_phases,
)
from pushrecovery.analysis.recording import LOADED, Foot, _check_feet
from pushrecovery.analysis.signals import _find_gaps, _times, smooth_and_differentiate
from pushrecovery.arguments import finite_float, non_negative_float, positive_float, require_type
from pushrecovery.errors import InvalidParameterError

__all__ = [
    "FootEvent",
    "MeasuredStep",
    "foot_events_from_force",
    "foot_events_from_markers",
    "measured_steps",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True, slots=True)
class FootEvent:
    """A foot leaving or touching the ground.

    Attributes
    ----------
    foot : str
        The foot's (or plate's) name.
    kind : {"foot-off", "foot-contact"}
        Which event.
    time : float
        Time of the event [s]: the first unloaded (foot-off) or loaded (foot-contact) sample.
    source : {"plate", "markers"}
        What detected it.
    """

    foot: str
    kind: Literal["foot-off", "foot-contact"]
    time: float
    source: Literal["plate", "markers"]

    def to_dict(self) -> dict[str, object]:
        """Table row."""
        return {"foot": self.foot, "kind": self.kind, "time": self.time, "source": self.source}


@dataclass(frozen=True, slots=True)
class MeasuredStep:
    """One step: a foot's foot-off and its next foot-contact.

    Attributes
    ----------
    foot : str
        The stepping foot.
    off_time, contact_time : float
        Foot-off and foot-contact [s].
    latency : float or None
        Foot-off minus the perturbation onset [s]; None without an onset.
    duration : float
        Swing time, contact minus foot-off [s].
    length, width : float
        Displacement of the foot along ap (forward +) and ml (left +) [m].
    start_ap, start_ml, end_ap, end_ml : float
        The foot's position (midpoint of its heel and toe markers) before and after the step
        [m]; NaN when its markers are missing throughout the stance.
    """

    foot: str
    off_time: float
    contact_time: float
    latency: float | None
    duration: float
    length: float
    width: float
    start_ap: float
    start_ml: float
    end_ap: float
    end_ml: float

    def to_dict(self) -> dict[str, object]:
        """Table row (NaN as None)."""
        row: dict[str, object] = {}
        for name in self.__slots__:
            value = getattr(self, name)
            row[name] = None if isinstance(value, float) and math.isnan(value) else value
        return row


def foot_events_from_force(
    time: ArrayLike,
    vertical_force: ArrayLike,
    foot: str,
    *,
    threshold: float = LOADED,
    min_duration: float = MIN_DURATION,
) -> list[FootEvent]:
    """Foot-off and foot-contact of one foot from its own plate's vertical force.

    A foot-off is the first sample of an unloaded run (force below ``threshold``, runs merged
    and filtered as in :func:`flight_phases`) that follows load; a foot-contact the first
    loaded sample after such a run. The trial's first and last states are not events.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], finite, strictly increasing.
    vertical_force : array_like, shape (n,)
        Vertical force under this foot only (a plate it alone stands on) [N].
    foot : str
        The foot's name for the events.
    threshold, min_duration : float
        As in :func:`flight_phases` [N], [s].

    Returns
    -------
    list of FootEvent
        In time order, source ``"plate"``.

    Raises
    ------
    ParameterTypeError
        If ``foot`` is not a str.
    InvalidParameterError
        As :func:`flight_phases`.
    """
    require_type("foot", foot, str)
    phases = flight_phases(time, vertical_force, threshold=threshold, min_duration=min_duration)
    times = np.asarray(time, dtype=float)
    return _events_from_mask(foot, times, phases.mask, "plate")


def _events_from_mask(
    foot: str, time: FloatArray, off: BoolArray, source: Literal["plate", "markers"]
) -> list[FootEvent]:
    """Events at the edges of the runs of ``off`` inside the trial."""
    events = []
    for start, stop in _find_gaps(off):
        if start > 0:
            events.append(FootEvent(foot, "foot-off", float(time[start]), source))
        if stop < len(time):
            events.append(FootEvent(foot, "foot-contact", float(time[stop]), source))
    return events


def foot_events_from_markers(
    time: ArrayLike,
    foot: Foot,
    *,
    contact_height: float = 0.03,
    max_speed: float = 0.1,
    cutoff: float = 10.0,
    min_duration: float = MIN_DURATION,
) -> list[FootEvent]:
    """Foot-off and foot-contact of one foot from its heel and toe markers.

    A marker is low while at most ``contact_height`` above its floor (the lowest it gets in the
    trial). Foot-contact is the first frame in which a marker is low and its vertical speed
    (of the heights low-passed at ``cutoff``) is at most ``max_speed``; foot-off the first frame
    in which no marker is low any more. Off-floor runs and contacts shorter than
    ``min_duration`` are merged away; missing frames keep the state before them.

    Parameters
    ----------
    time : array_like, shape (n,)
        Frame times of the markers [s], finite, strictly increasing.
    foot : Foot
        The foot's markers in body axes [m] (n frames, NaN where missing).
    contact_height : float
        Highest a marker on the floor gets above its lowest [m], > 0.
    max_speed : float
        Fastest a marker on the floor moves up or down [m/s], > 0.
    cutoff : float
        Low-pass cutoff of the heights before differentiating [Hz], 0 (none) or in
        (0, rate/2).
    min_duration : float
        Shortest time on or off the floor that counts [s], >= 0.

    Returns
    -------
    list of FootEvent
        In time order, source ``"markers"``; the trial's first and last states are not events.

    Raises
    ------
    ParameterTypeError
        If ``foot`` is not a :class:`~pushrecovery.analysis.recording.Foot`.
    InvalidParameterError
        Bad times, markers that are not (n, 3) arrays of one frame per time, non-positive
        ``contact_height`` or ``max_speed``, a bad ``cutoff`` or a negative ``min_duration``.
    """
    time = _times("time", time)
    _check_feet((foot,))
    if len(foot.heel) != len(time):
        raise InvalidParameterError(
            f"foot markers must have one frame per time ({len(time)}), got {len(foot.heel)}"
        )
    contact_height = positive_float("contact_height", contact_height, "m")
    max_speed = positive_float("max_speed", max_speed, "m/s")
    cutoff = non_negative_float("cutoff", cutoff, "Hz")
    min_duration = non_negative_float("min_duration", min_duration, "s")
    if np.isinf(foot.heel).any() or np.isinf(foot.toe).any():
        raise InvalidParameterError("foot markers must be finite or NaN (missing)")
    heights = np.column_stack([foot.heel[:, 2], foot.toe[:, 2]]).astype(float)
    if len(time) < 3:
        return []
    smooth, speed = smooth_and_differentiate(time, heights, cutoff)
    with warnings.catch_warnings():  # a marker never seen stays NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        floor = np.nanmin(smooth, axis=0)
    known = np.isfinite(smooth) & np.isfinite(speed)
    if not known.any():
        return []
    with np.errstate(invalid="ignore"):
        low = known & (smooth - floor <= contact_height)
        landing = (low & (np.abs(speed) <= max_speed)).any(axis=1)
    # Missing frames keep the state before them (the first known state before the first).
    indices = np.where(known.any(axis=1), np.arange(len(time)), -1)
    last_known = np.maximum.accumulate(indices)
    last_known[last_known < 0] = int(np.flatnonzero(indices >= 0)[0])
    low_foot, landing = low.any(axis=1)[last_known], landing[last_known]
    # Hysteresis: on the floor from the first low and still frame of a low run to its end.
    on_floor = np.zeros(len(time), dtype=bool)
    for start, stop in _find_gaps(low_foot):
        still = np.flatnonzero(landing[start:stop])
        if len(still):
            on_floor[start + still[0] : stop] = True
    off = np.zeros(len(time), dtype=bool)
    for start, stop in _runs(~on_floor, _period(time), min_duration):
        off[start:stop] = True
    return _events_from_mask(foot.name, time, off, "markers")


def measured_steps(
    time: ArrayLike,
    feet: tuple[Foot, ...],
    events: list[FootEvent],
    *,
    onset: float | None = None,
    position: Literal["stance", "event"] = "stance",
) -> list[MeasuredStep]:
    """Measure the steps from foot-off and foot-contact pairs and the markers.

    Each foot-off of a foot pairs with its next foot-contact. The foot's position is the
    midpoint of its heel and toe markers; with ``position="stance"`` the start is its median
    over the stance before the foot-off and the end its median over the stance after the
    contact, with ``position="event"`` the midpoint at the event times. Length and width are
    the ap and ml displacements end − start (forward and leftward positive).

    Parameters
    ----------
    time : array_like, shape (n,)
        Frame times of the markers [s], finite, strictly increasing.
    feet : tuple of Foot
        Markers of the feet the events name [m]; events of feet not given are left out.
    events : list of FootEvent
        From plates or markers, any order; a foot-off not followed by a foot-contact of the
        same foot (the trial ends in the air) makes no step.
    onset : float or None
        Perturbation onset [s] for the latencies (:func:`.events.perturbation_onset`).
    position : {"stance", "event"}
        Where the foot is before and after the step: median over the stance, or at the event.

    Returns
    -------
    list of MeasuredStep
        In the order of the foot-offs.

    Raises
    ------
    ParameterTypeError
        If ``feet`` is not a tuple or list of Foot, ``events`` not a list or tuple of
        FootEvent.
    InvalidParameterError
        Bad times, markers not of one frame per time, a non-finite ``onset``, or a
        ``position`` other than "stance" or "event".
    """
    time = _times("time", time)
    _check_feet(feet)
    if len(feet[0].heel) != len(time):
        raise InvalidParameterError(
            f"feet markers must have one frame per time ({len(time)}), got {len(feet[0].heel)}"
        )
    require_type("events", events, (list, tuple))
    for event in events:
        require_type("each of events", event, FootEvent)
    if onset is not None:
        onset = finite_float("onset", onset, "s")
    if not isinstance(position, str) or position not in ("stance", "event"):
        raise InvalidParameterError(f"position must be 'stance' or 'event', got {position!r}")
    steps = []
    for foot in feet:
        own = sorted((e for e in events if e.foot == foot.name), key=lambda e: e.time)
        middle = 0.5 * (foot.heel[:, :2] + foot.toe[:, :2])
        for i, event in enumerate(own[:-1]):
            after = own[i + 1]
            if event.kind != "foot-off" or after.kind != "foot-contact":
                continue
            before = next(
                (e.time for e in reversed(own[:i]) if e.kind == "foot-contact"), -math.inf
            )
            later = next((e.time for e in own[i + 2 :] if e.kind == "foot-off"), math.inf)
            if position == "stance":
                start = _median(middle, (time >= before) & (time < event.time))
                end = _median(middle, (time >= after.time) & (time < later))
            else:
                start = _at(time, middle, event.time)
                end = _at(time, middle, after.time)
            steps.append(
                MeasuredStep(
                    foot=foot.name,
                    off_time=event.time,
                    contact_time=after.time,
                    latency=None if onset is None else event.time - onset,
                    duration=after.time - event.time,
                    length=float(end[0] - start[0]),
                    width=float(end[1] - start[1]),
                    start_ap=float(start[0]),
                    start_ml=float(start[1]),
                    end_ap=float(end[0]),
                    end_ml=float(end[1]),
                )
            )
    return sorted(steps, key=lambda s: s.off_time)


def _median(values: FloatArray, frames: NDArray[np.bool_]) -> FloatArray:
    """Per-column median over the chosen frames, NaN when none is known."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if not frames.any():
            return np.full(values.shape[1], np.nan)
        return np.asarray(np.nanmedian(values[frames], axis=0))


def _at(time: FloatArray, values: FloatArray, when: float) -> FloatArray:
    """Values linearly at ``when`` (NaN next to missing frames or outside the trial)."""
    return np.array(
        [np.interp(when, time, values[:, j], left=np.nan, right=np.nan) for j in range(2)]
    )
