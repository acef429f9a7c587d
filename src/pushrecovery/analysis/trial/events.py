"""A trial's events: perturbation onset, foot-off and foot-contact, the steps taken (issue 18).

The detections of :mod:`pushrecovery.analysis.events` and
:mod:`pushrecovery.analysis.steps_measured` run on a trial: the onset on the horizontal ground
reaction force over the mass (else on the CoM acceleration of the kinematics, which may lead
the push by up to 1/f_c: prefer plates), the foot events from each foot's own plate (else its
markers), the steps they make; each event with the verdicts of its frame, each step against
the recommended one (:class:`StepComparison`) and the capture region at its foot-off
(:class:`CaptureRegionCheck`). docs/events.md, "How the trial analysis uses them", has the
details.

Over 400 lines on purpose: one concept, a trial's typed events as ``summary.json`` writes them
(the records, and ``trial_events`` with the helpers that fill them).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.c3d.event_group import FOOT_OFF, FOOT_STRIKE, GENERAL, C3DEvent
from pushrecovery.analysis.events import perturbation_onset
from pushrecovery.analysis.margins import DirectionMargins
from pushrecovery.analysis.margins.plane import phase_supports
from pushrecovery.analysis.recording import AXES, Recording
from pushrecovery.analysis.steps_measured import (
    FootEvent,
    MeasuredStep,
    foot_events_from_force,
    foot_events_from_markers,
    measured_steps,
)
from pushrecovery.analysis.trial.checks import PlateFeet
from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.region import capture_region
from pushrecovery.surfaces.classify import STRATEGY_CODES

__all__ = [
    "AxisMargins",
    "CaptureRegionCheck",
    "FrameMargins",
    "Onset",
    "StepComparison",
    "StepTaken",
    "TrialEvents",
    "TriggeredFootEvent",
    "c3d_events",
]

FloatArray = NDArray[np.float64]

#: Baseline of the onset detection: the trial's first seconds [s].
ONSET_BASELINE = 0.5
#: A foot's marker event this close to its plate event of the same kind is that event [s].
SAME_EVENT = 0.1


@dataclass(frozen=True, slots=True)
class AxisMargins:
    """One axis' verdict at one frame.

    Attributes
    ----------
    capture_point : float or None
        Capture point (XCoM) [m], lab frame along the axis (ap forward +, ml left +).
    cop_margin, cmp_margin : float or None
        Its margin inside the CoP (CMP) region [m], + inside.
    time_to_leave_cop : float or None
        Time before the CoM would leave the CoP region at its motion [s].
    strategy : str or None
        The strategy the frame needs along the axis; None where withheld or unknown.
    steps : int or None
        Steps the frame needs along the axis: 0 for ankle and hip, N for step, −1 where no
        ``max_steps`` steps capture (fall); None where withheld or unknown (the N-step verdict).
    step_margin : float or None
        Margin of the capture point inside the region of ``max_steps`` steps [m], + inside.
    mos : float or None
        Hof's margin of stability toward the motion along the axis against the base polygon
        (``mos_ap``, ``mos_ml`` of the frames) [m]; None without a base polygon.
    risk : float or None
        P(the ankle does not suffice) under the analysis' ``com_noise`` (``<axis>_risk`` of
        the frames, dimensionless); None without it.
    """

    capture_point: float | None
    cop_margin: float | None
    cmp_margin: float | None
    time_to_leave_cop: float | None
    strategy: str | None
    steps: int | None = None
    step_margin: float | None = None
    mos: float | None = None
    risk: float | None = None


@dataclass(frozen=True, slots=True)
class FrameMargins:
    """The verdicts of the frame nearest an event: its time [s] and per axis (ap, ml)."""

    frame_time: float
    axes: dict[str, AxisMargins]


@dataclass(frozen=True, slots=True)
class Onset:
    """The perturbation onset.

    Attributes
    ----------
    time : float or None
        Onset [s]; None when none was found (or the trial is quiet standing).
    signal : str
        The signal it was detected on: the horizontal ground reaction force over the mass,
        or the CoM acceleration of the kinematics without plates.
    margins : FrameMargins or None
        The verdicts at the onset's frame.
    note : str or None
        Why no onset is given although the signal crossed its threshold.
    """

    time: float | None
    signal: str
    margins: FrameMargins | None
    note: str | None = None


@dataclass(frozen=True, slots=True)
class TriggeredFootEvent:
    """A foot-off or foot-contact and the verdicts at its frame."""

    event: FootEvent
    margins: FrameMargins


@dataclass(frozen=True, slots=True)
class StepComparison:
    """The step taken along one axis against the recommended one at foot-off.

    Attributes
    ----------
    taken : float or None
        The foot's displacement along the axis [m] (ap forward +, ml left +).
    recommended : float or None
        The step the surfaces recommend at the foot-off frame (Eq. 21) [m], signed.
    shortest, longest : float or None
        The range of first steps that capture the state there [m] (unsigned, in the direction
        of ``recommended``).
    within : bool or None
        Whether ``taken`` lies in that range; None where the frame needed no step.
    margin : float or None
        The step's margin inside that range [m]: min(s − shortest, longest − s) with s the
        step taken in the direction of ``recommended``; + inside, − short of or beyond it;
        None where the frame needed no step or the foot's markers are missing.
    """

    taken: float | None
    recommended: float | None
    shortest: float | None
    longest: float | None
    within: bool | None
    margin: float | None = None


@dataclass(frozen=True, slots=True)
class CaptureRegionCheck:
    """A step's landing against the 2-D one-step capture region at its foot-off.

    Attributes
    ----------
    landing_ankle : tuple of float
        The stepping foot's ankle at its contact frame (ap, ml) [m].
    swing_time : float
        The swing time the region assumes [s].
    margin : float or None
        Signed distance of the landing to the region [m], + inside; None for an empty region.
    within : bool or None
        Whether the landing lies inside.
    empty : bool
        The region is empty: no single step captures the state.
    recommended_foothold : tuple of float or None
        The foothold the region recommends (ap, ml) [m].
    """

    landing_ankle: tuple[float, float]
    swing_time: float
    margin: float | None
    within: bool | None
    empty: bool
    recommended_foothold: tuple[float, ...] | None


@dataclass(frozen=True, slots=True)
class StepTaken:
    """A measured step, the verdicts at its foot-off and foot-contact, and its judgement.

    ``against_recommended`` is per axis (ap, ml); ``capture_region`` None without a two-foot
    base or where the surfaces refuse the state.
    """

    step: MeasuredStep
    at_foot_off: FrameMargins
    at_foot_contact: FrameMargins
    against_recommended: dict[str, StepComparison]
    capture_region: CaptureRegionCheck | None


@dataclass(frozen=True, slots=True)
class TrialEvents:
    """The trial's onset, foot events and measured steps (``summary.json`` → ``events``)."""

    onset: Onset
    foot_events: tuple[TriggeredFootEvent, ...]
    measured_steps: tuple[StepTaken, ...]


def _events_dict(events: TrialEvents) -> dict[str, Any]:
    """Return ``summary.json`` → ``events`` (docs/events.md)."""
    onset = events.onset
    return {
        "onset": {
            "time": onset.time,
            "signal": onset.signal,
            "margins": None if onset.margins is None else _margins_dict(onset.margins),
            **({} if onset.note is None else {"note": onset.note}),
        },
        "foot_events": [
            {**found.event.to_dict(), "margins": _margins_dict(found.margins)}
            for found in events.foot_events
        ],
        "measured_steps": [
            {
                **taken.step.to_dict(),
                "margins_at_foot_off": _margins_dict(taken.at_foot_off),
                "margins_at_foot_contact": _margins_dict(taken.at_foot_contact),
                "against_recommended": {
                    axis: {
                        "taken": c.taken,
                        "recommended": c.recommended,
                        "capture_range": [c.shortest, c.longest],
                        "within": c.within,
                        "margin": c.margin,
                    }
                    for axis, c in taken.against_recommended.items()
                },
                "capture_region": None
                if taken.capture_region is None
                else asdict(taken.capture_region),
            }
            for taken in events.measured_steps
        ],
        "axes": list(AXES),
    }


def _margins_dict(margins: FrameMargins) -> dict[str, Any]:
    return {
        "frame_time": margins.frame_time,
        **{axis: asdict(values) for axis, values in margins.axes.items()},
    }


def _value(array: NDArray[Any], frame: int) -> float | None:
    value = float(array[frame])
    return value if math.isfinite(value) else None


def _margins_at(
    time: FloatArray,
    when: float,
    per_axis: dict[str, DirectionMargins],
    mos: dict[str, FloatArray] | None = None,
    risk: dict[str, FloatArray] | None = None,
) -> FrameMargins:
    """Return the margins of the frame nearest ``when`` [s], per axis.

    ``mos``: per axis, Hof's margin toward the motion of every frame (the plane's ``mos_ap``,
    ``mos_ml``), or None.
    """
    frame = int(np.argmin(np.abs(time - when)))
    axes = {}
    for axis, margins in per_axis.items():
        code = int(margins.strategy[frame])
        axes[axis] = AxisMargins(
            capture_point=_value(margins.capture_point, frame),
            cop_margin=_value(margins.cop, frame),
            cmp_margin=_value(margins.cmp, frame),
            time_to_leave_cop=_value(margins.time_to_leave_cop, frame),
            strategy=STRATEGY_CODES[code].value if code >= 0 else None,
            steps=int(margins.steps[frame]) if code >= 0 else None,
            step_margin=_value(margins.step, frame),
            mos=None if mos is None else _value(mos[axis], frame),
            risk=None if risk is None else _value(risk[axis], frame),
        )
    return FrameMargins(float(time[frame]), axes)


def _onset(
    recording: Recording, time: FloatArray, velocity: FloatArray, mass: float
) -> tuple[float | None, str]:
    """Perturbation onset [s] and the signal it was found on (plates first)."""
    if recording.force is not None and recording.force_time is not None:
        signal_time = recording.force_time
        signal = np.hypot(recording.force[:, 0], recording.force[:, 1]) / mass
        source = "horizontal ground reaction force / mass"
    else:
        signal_time = time
        acceleration = np.gradient(velocity, time, axis=0)
        signal = np.hypot(acceleration[:, 0], acceleration[:, 1])
        source = "CoM acceleration of the kinematics"
    try:
        return perturbation_onset(signal_time, signal, baseline=ONSET_BASELINE), source
    except InvalidParameterError:  # too short, or a baseline without samples
        return None, source


def _compared(
    step: MeasuredStep, time: FloatArray, per_axis: dict[str, DirectionMargins]
) -> dict[str, StepComparison]:
    """Compare the step taken with the recommended one and the capture range at foot-off."""
    frame = int(np.argmin(np.abs(time - step.off_time)))
    taken = {
        axis: None if math.isnan(moved) else moved
        for axis, moved in (("ap", step.length), ("ml", step.width))
    }
    result = {}
    for axis, margins in per_axis.items():
        recommended = _value(margins.step_length, frame)
        shortest = _value(margins.step_shortest, frame)
        longest = _value(margins.step_longest, frame)
        moved = taken[axis]
        within = margin = None
        if recommended is not None and shortest is not None and longest is not None:
            # The range is unsigned, in the direction of the recommended step.
            along = None if moved is None else math.copysign(1.0, recommended) * moved
            within = along is not None and shortest <= along <= longest
            margin = None if along is None else min(along - shortest, longest - along)
        result[axis] = StepComparison(moved, recommended, shortest, longest, within, margin)
    return result


def _foot_events(recording: Recording, owners: dict[int, str]) -> list[FootEvent]:
    """Foot events from each foot's own plate where it has one, and from its markers.

    ``owners``: plate index -> its foot (:func:`~pushrecovery.analysis.trial.checks.plate_feet`);
    a plate not in it (stray: under no foot) makes no events. A plate sees a foot's events
    only while that foot alone stands on it: a foot leaving a plate both feet stood on (a
    step off a shared plate onto the next one) unloads nothing. So every foot's marker events
    count too, except one within :data:`SAME_EVENT` of a plate event of the same foot and kind
    (the plate's, sampled faster, is kept).
    """
    events: list[FootEvent] = []
    for k, name in owners.items():
        vertical = recording.plates[k][0]
        assert recording.force_time is not None
        finite = np.isfinite(vertical)
        events += foot_events_from_force(recording.force_time[finite], vertical[finite], name)
    from_plates = list(events)
    for foot in recording.feet:
        try:
            found = foot_events_from_markers(recording.time, foot)
        except InvalidParameterError:  # a foot whose markers are missing throughout
            continue
        events += [
            event
            for event in found
            if not any(
                seen.foot == event.foot
                and seen.kind == event.kind
                and abs(seen.time - event.time) <= SAME_EVENT
                for seen in from_plates
            )
        ]
    return sorted(events, key=lambda event: event.time)


def _in_capture_region(
    step: MeasuredStep,
    time: FloatArray,
    com: FloatArray,
    velocity: FloatArray,
    plane: tuple[Any, BodyParams] | None,
) -> CaptureRegionCheck | None:
    """Judge the step's landing against the one-step capture region at its foot-off.

    The region (:func:`~pushrecovery.surfaces.capture.region.capture_region`, issue 9: the
    landing foot's ankle positions that capture the state with this step, the foot landing
    after the measured swing time, the hip helping) of the CoM state at the foot-off frame and
    the support just before it; the landing is the stepping foot's ankle at its contact frame.
    None without a two-foot base (feet named left and right) or where the library refuses.
    """
    if plane is None:
        return None
    base, params = plane
    supports, phase, body = phase_supports(base, params)
    names = [name.lower() for name in base.names]
    if body is None or base.poses is None or step.foot.lower() not in names:
        return None
    off = int(np.argmin(np.abs(time - step.off_time)))
    contact = int(np.argmin(np.abs(time - step.contact_time)))
    before = phase[max(off - 1, 0)]
    landing = base.poses[contact, names.index(step.foot.lower()), :2]
    state = (*com[off], *velocity[off])
    if before < 0 or supports[before] is None or not np.isfinite([*state, *landing]).all():
        return None
    swing_time = min(max(step.contact_time - step.off_time, 0.0), 5.0)
    try:
        x, y, xdot, ydot = (float(v) for v in state)
        region = capture_region(
            x, y, xdot, ydot, body, supports[before], swing_time, swing=step.foot.lower()
        )
    except PushRecoveryError:  # a state or support the surfaces refuse
        return None
    margin = (
        None
        if region.polygon is None
        else float(region.polygon.signed_distance(landing[0], landing[1]))
    )
    return CaptureRegionCheck(
        landing_ankle=(float(landing[0]), float(landing[1])),
        swing_time=swing_time,
        margin=margin,
        within=None if margin is None else margin >= 0.0,
        empty=region.polygon is None,
        recommended_foothold=None
        if region.foothold is None
        else tuple(float(v) for v in region.foothold),
    )


def trial_events(
    recording: Recording,
    time: FloatArray,
    velocity: FloatArray,
    per_axis: dict[str, DirectionMargins],
    mass: float,
    *,
    com: FloatArray | None = None,
    plane: tuple[Any, BodyParams] | None = None,
    plates: PlateFeet,
    mos: dict[str, FloatArray] | None = None,
    risk: dict[str, FloatArray] | None = None,
) -> TrialEvents:
    """Return the trial's onset, foot events and steps with their margins.

    ``time`` [s] and ``velocity`` (n, 2) [m/s] are the analysis' frames, ``per_axis`` their
    margins, ``mass`` the subject's [kg]; with ``com`` (n, 2) [m] and ``plane`` (the base
    polygons and the body), each step is also judged against the 2-D capture region at its
    foot-off (``capture_region``). ``plates``: which foot stands on each plate
    (:func:`~pushrecovery.analysis.trial.checks.plate_feet`). ``mos``: per axis, Hof's margin
    toward the motion of every frame (the plane's ``mos_ap``, ``mos_ml``), given to each event's
    margins (:class:`AxisMargins` ``mos``); ``risk`` likewise the frames' ``<axis>_risk``.
    """
    onset, onset_source = _onset(recording, time, velocity, mass)
    events = _foot_events(recording, plates.owners)
    steps = (
        measured_steps(recording.time, recording.feet, events, onset=onset)
        if events and recording.feet
        else []
    )
    return TrialEvents(
        onset=Onset(
            onset,
            onset_source,
            None if onset is None else _margins_at(time, onset, per_axis, mos, risk),
        ),
        foot_events=tuple(
            TriggeredFootEvent(event, _margins_at(time, event.time, per_axis, mos, risk))
            for event in events
        ),
        measured_steps=tuple(
            StepTaken(
                step,
                at_foot_off=_margins_at(time, step.off_time, per_axis, mos, risk),
                at_foot_contact=_margins_at(time, step.contact_time, per_axis, mos, risk),
                against_recommended=_compared(step, time, per_axis),
                capture_region=None
                if com is None
                else _in_capture_region(step, time, com, velocity, plane),
            )
            for step in steps
        ),
    )


def c3d_events(events: TrialEvents) -> list[C3DEvent]:
    """Return a trial's onset and foot events as C3D EVENT entries (``--write-events``).

    A foot named ``left`` or ``right`` (any case) gives the context ``Left`` or ``Right``,
    another foot ``General``; foot-contact is ``Foot Strike``, foot-off ``Foot Off`` (the
    labels gait software expects); the onset is a ``General`` event. Each description says
    what detected it.
    """
    require_type("events", events, TrialEvents)
    found = []
    if events.onset.time is not None:
        found.append(
            C3DEvent(
                events.onset.time, GENERAL, GENERAL, f"perturbation onset ({events.onset.signal})"
            )
        )
    for triggered in events.foot_events:
        event = triggered.event
        side = event.foot.lower()
        found.append(
            C3DEvent(
                event.time,
                side.capitalize() if side in ("left", "right") else GENERAL,
                FOOT_STRIKE if event.kind == "foot-contact" else FOOT_OFF,
                f"{event.foot} {event.kind} from its {event.source} (pushrecovery)",
            )
        )
    return found
