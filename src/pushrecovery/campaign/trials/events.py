"""The events of a batch of measured trials: one row per event (and axis).

Columns of ``events.parquet`` (:class:`EventRow`; SI units). A contract: columns are added,
never renamed or dropped.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from typing import TYPE_CHECKING, Any

from pushrecovery.arguments import require_type
from pushrecovery.campaign.trials.rows import check_job, subject_name

if TYPE_CHECKING:
    from pushrecovery.analysis.trial import TrialSummary
    from pushrecovery.analysis.trial.events import FrameMargins

__all__ = ["EVENT_FIELDS", "EventRow", "trial_events"]


@dataclass(frozen=True, slots=True)
class EventRow:
    """One event of a trial.

    Attributes
    ----------
    trial, subject, axis : str
        The trial, its subject and the axis of the event.
    kind : str
        ``step needed`` (a run of frames whose capture point needed a step), ``onset``,
        ``flight``, ``foot-off``, ``foot-contact`` or ``step`` (a measured step, at its
        foot-off); ``axis`` is empty for flights.
    time, end : float
        Start and end of the event [s] (a step: foot-off and foot-contact).
    step_length, step_length_min, step_length_max : float
        ``step needed``: the recommended step (Eq. 21, median over the event) and its
        admissible range [m]; ``step``: the recommended step at foot-off and the range of
        first steps that capture the state there (the capture region on the axis' line).
    capture_point : float
        Capture point at the start [m], relative to the lab origin along the axis.
    foot, source : str
        The foot of a foot event or step, and what detected it (``markers``, ``plate``).
    cop_margin, strategy : float, str
        The axis' CoP margin [m] and the strategy its frame needed, at the event's time.
    taken, latency, duration : float
        A step's displacement along the axis [m], its foot-off after the onset [s] and its
        swing time [s].
    within : bool
        A step: whether ``taken`` lies in [step_length_min, step_length_max] (null where its
        foot-off frame needed no step).
    capture_region_margin, in_capture_region : float, bool
        A step: the landing ankle's signed distance to the 2-D one-step capture region of the
        state at foot-off [m] (+ inside), and whether it lies inside (null without two named
        feet; the same on both axes' rows).
    """

    trial: str
    subject: str
    axis: str
    kind: str
    time: float | None
    end: float | None = None
    step_length: float | None = None
    step_length_min: float | None = None
    step_length_max: float | None = None
    capture_point: float | None = None
    foot: str | None = None
    source: str | None = None
    cop_margin: float | None = None
    strategy: str | None = None
    taken: float | None = None
    latency: float | None = None
    duration: float | None = None
    within: bool | None = None
    capture_region_margin: float | None = None
    in_capture_region: bool | None = None


#: Arrow types of the columns, in order.
EVENT_FIELDS: tuple[tuple[str, str], ...] = tuple((f.name, str(f.type)) for f in fields(EventRow))


def trial_events(job: Any, summary: TrialSummary) -> list[dict[str, Any]]:
    """Return the events of an analysed trial, in time order (:class:`EventRow`).

    The values are the summary's own (NaN, not yet None: ``json_safe`` them for a JSON file).
    """
    from pushrecovery.analysis.trial import TrialSummary

    check_job(job)
    require_type("summary", summary, TrialSummary)
    subject = subject_name(job)
    rows = [
        EventRow(job.name, subject, event.axis, "step needed", event.time, event.end,
                 event.step_length, event.step_length_min, event.step_length_max,
                 event.capture_point)
        for event in summary.step_events
    ]  # fmt: skip
    for start, end in summary.checks.flights:
        rows.append(EventRow(job.name, subject, "", "flight", start, end))
    events = summary.events
    onset = events.onset
    for axis in ("ap", "ml"):
        if onset.time is not None and onset.margins is not None:
            rows.append(_at(job.name, subject, axis, "onset", onset.time, onset.margins))
        for found in events.foot_events:
            foot = found.event
            rows.append(
                replace(
                    _at(job.name, subject, axis, foot.kind, foot.time, found.margins),
                    foot=foot.foot,
                    source=foot.source,
                )
            )
        for taken in events.measured_steps:
            step, compared = taken.step, taken.against_recommended[axis]
            region = taken.capture_region
            rows.append(
                replace(
                    _at(job.name, subject, axis, "step", step.off_time, taken.at_foot_off),
                    end=step.contact_time,
                    foot=step.foot,
                    source="markers",
                    step_length=compared.recommended,
                    step_length_min=compared.shortest,
                    step_length_max=compared.longest,
                    taken=compared.taken,
                    latency=step.latency,
                    duration=step.duration,
                    within=compared.within,
                    capture_region_margin=None if region is None else region.margin,
                    in_capture_region=None if region is None else region.within,
                )
            )
    rows.sort(key=lambda r: (math.inf if r.time is None else r.time, r.kind, r.axis))
    return [asdict(row) for row in rows]


def _at(
    trial: str, subject: str, axis: str, kind: str, time: float, margins: FrameMargins
) -> EventRow:
    """Return an event row with the axis' margins at the event's frame."""
    here = margins.axes[axis]
    return EventRow(trial, subject, axis, kind, time, capture_point=here.capture_point,
                    cop_margin=here.cop_margin, strategy=here.strategy)  # fmt: skip
