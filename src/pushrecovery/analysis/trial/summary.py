"""The summary of a trial's analysis: extremes, time per strategy, steps, exclusions.

:class:`TrialSummary` is what :func:`~pushrecovery.analysis.trial.analyze` returns as
``TrialAnalysis.summary``; :meth:`TrialSummary.to_dict` is ``summary.json`` (and the CLI's
``--json``), whose keys are a contract (docs/analysis.md).

Over 400 lines on purpose: one concept, the summary's typed fields, each with its unit and sign
in its docstring, and the one serialiser that keeps the JSON's keys and order.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.margins import DirectionMargins
from pushrecovery.analysis.margins.plane import Margins2D
from pushrecovery.analysis.output import json_safe
from pushrecovery.analysis.posturography import SwayMeasures
from pushrecovery.analysis.recording import (
    Recording,
    Support,
)
from pushrecovery.analysis.signals import (
    FILTER_ORDER,
    Gap,
    find_gaps,
)
from pushrecovery.analysis.trial.checks import DataChecks
from pushrecovery.analysis.trial.events import TrialEvents, _events_dict
from pushrecovery.analysis.trial.settings import PRESET_BODY
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy

if TYPE_CHECKING:
    from pushrecovery.analysis.trial.settings import AnalysisSettings

__all__ = ["DirectionSummary", "Extreme", "PlaneSummary", "StepEvent", "TrialSummary"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Extreme:
    """The smallest (or largest) finite value of a per-frame measure, and when.

    Attributes
    ----------
    value : float or None
        The value, in the measure's unit and sign (a margin [m], + inside; a time [s]);
        None when no frame has a finite value.
    time : float or None
        Time of its frame [s]; None with ``value``.
    """

    value: float | None
    time: float | None


@dataclass(frozen=True, slots=True)
class DirectionSummary:
    """One axis' verdicts over the trial (``summary.json`` → ``directions.<axis>``).

    Attributes
    ----------
    most_demanding : str or None
        The most demanding strategy any frame needed along the axis (ankle, hip, step, fall);
        None when no frame has a verdict.
    time_in_strategy : dict of str to float
        Time the frames needed each strategy along the axis [s], every strategy listed.
    min_cop_margin, min_cmp_margin : Extreme
        Smallest margin of the capture point inside the CoP (Eq. 4) and the CMP (corrected
        Eq. 15) regions [m] (+ inside, − beyond the edge it moves toward) and its time [s].
    min_time_to_leave_cop, min_time_to_leave_cmp : Extreme
        Shortest time before the CoM would leave the CoP (CMP) region at its motion [s]
        (+inf, never, is no finite value).
    capture_point_min, capture_point_max : float or None
        Range of the capture point along the axis [m], lab frame (ap forward +, ml left +).
    heel, toe : float
        The foot's edges relative to the ankle used by the verdicts [m] (toe ahead +).
    """

    most_demanding: str | None
    time_in_strategy: dict[str, float]
    min_cop_margin: Extreme
    min_cmp_margin: Extreme
    min_time_to_leave_cop: Extreme
    min_time_to_leave_cmp: Extreme
    capture_point_min: float | None
    capture_point_max: float | None
    heel: float
    toe: float


@dataclass(frozen=True, slots=True)
class StepEvent:
    """A run of frames that needs a step along one axis (``summary.json`` → ``step_events``).

    Attributes
    ----------
    axis : str
        ``ap`` or ``ml``.
    time, end : float
        First and last frame of the run [s].
    step_length : float
        The recommended step (Eq. 21), median over the run [m], signed along the axis (ap
        forward +, ml left +).
    step_length_min, step_length_max : float
        Median over the run of the shortest and longest first steps that capture [m]
        (unsigned, in the direction of ``step_length``).
    step_length_onset : float
        The recommended step at the run's first frame [m].
    capture_point : float
        Capture point at the run's first frame [m], lab frame along the axis.
    """

    axis: str
    time: float
    end: float
    step_length: float
    step_length_min: float
    step_length_max: float
    step_length_onset: float
    capture_point: float


@dataclass(frozen=True, slots=True)
class PlaneSummary:
    """The 2-D margins against the base polygon (``summary.json`` → ``plane``).

    Attributes
    ----------
    base_source : str
        Where the base of support came from.
    min_mos, min_mos_ap, min_mos_ml, min_mos_cmp : Extreme
        Smallest signed distance of the XCoM to the base polygon (Hof's margin of stability in
        the plane, + inside) [m], its components along ap and ml toward the side the CoM moves
        [m], and the margin against the CMP region [m] (docs/base_polygon.md).
    min_time_to_boundary_cop, min_time_to_boundary_xcom : Extreme
        Shortest times to the base's boundary of the CoP and of the XCoM [s].
    most_demanding : str or None
        The most demanding strategy of the 2-D verdicts; None without feet to classify against.
    xcom_length : str
        The XCoM's pendulum length: ``com_height`` or ``leg_length``
        (``AnalysisSettings.xcom_length``).
    omega : float
        The XCoM's ω0 = sqrt(g/l) [1/s].
    """

    base_source: str
    min_mos: Extreme
    min_mos_ap: Extreme
    min_mos_ml: Extreme
    min_mos_cmp: Extreme
    min_time_to_boundary_cop: Extreme
    min_time_to_boundary_xcom: Extreme
    most_demanding: str | None
    xcom_length: str = "com_height"
    omega: float = math.nan


@dataclass(frozen=True, slots=True, eq=False)
class TrialSummary:
    """The summary of a trial's analysis; :meth:`to_dict` is ``summary.json``.

    SI units; axes ap (forward +) and ml (the subject's left +) as in
    :mod:`~pushrecovery.analysis.recording`.

    Attributes
    ----------
    source : str
        The file (or what generated the recording).
    frames, valid_frames : int
        Frames of the analysis, and those with a verdict on both axes.
    excluded : dict of str to int
        Frames without a verdict per reason (a frame may have several).
    rate : float or None
        Frame rate [Hz]; None for a single frame.
    duration : float
        Last minus first frame time [s].
    params : BodyParams
        The body assumed (mass [kg], CoM height [m], ω [1/s], ...).
    mass_source, com_height_source : str
        Where mass and CoM height came from (``given`` without ``sources``).
    body_source : str
        Where the body's geometry and upper-body inertia came from: the person's segment
        table (docs/anthropometry.md) or the preset (``given`` without ``sources``).
    com_source, support_source : str
        How the CoM and the base of support were obtained.
    cutoff, force_cutoff : float
        Low-pass cutoffs of the kinematics and of the force plates [Hz] (0: none).
    gaps : tuple of Gap
        Every gap of every signal, filled (interpolated) or not.
    interpolated_frames : int
        Frames inside a filled gap.
    most_demanding : str or None
        The most demanding strategy any frame needed (the more demanding of the two axes).
    time_in_strategy : dict of str to float
        Time the frames needed each strategy [s].
    directions : dict of str to DirectionSummary
        Per axis (ap, ml), its verdicts.
    step_events : tuple of StepEvent
        Every run of frames that needs a step, per axis, in time order.
    notes : tuple of str
        What the reader of the analysis should know (assumptions, withheld verdicts).
    checks : DataChecks
        The data checks: flights and a CoP beyond the base (docs/analysis.md).
    plane : PlaneSummary
        The 2-D margins against the base polygon.
    events : TrialEvents
        Perturbation onset, foot events and measured steps with the verdicts at their frames
        (docs/events.md).
    sway : SwayMeasures or None
        The sway measures of a quiet-standing trial (docs/posturography.md), else None.
    sway_rate : float or None
        The force plates' rate the sway measures were taken at [Hz], with ``sway``.
    """

    source: str
    frames: int
    valid_frames: int
    excluded: dict[str, int]
    rate: float | None
    duration: float
    params: BodyParams
    mass_source: str
    com_height_source: str
    com_source: str
    support_source: str
    cutoff: float
    force_cutoff: float
    gaps: tuple[Gap, ...]
    interpolated_frames: int
    most_demanding: str | None
    time_in_strategy: dict[str, float]
    directions: dict[str, DirectionSummary]
    step_events: tuple[StepEvent, ...]
    notes: tuple[str, ...]
    checks: DataChecks
    plane: PlaneSummary
    events: TrialEvents
    sway: SwayMeasures | None = None
    sway_rate: float | None = None
    body_source: str = "given"

    @property
    def excluded_frames(self) -> int:
        """Frames without a verdict on both axes."""
        return self.frames - self.valid_frames

    def to_dict(self) -> dict[str, Any]:
        """Return ``summary.json`` (and the CLI's ``--json``): plain JSON values, NaN as None.

        Its keys and their order are a contract (docs/analysis.md): added, never renamed or
        dropped.
        """
        params = self.params
        return json_safe(
            {
                "source": self.source,
                "frames": self.frames,
                "valid_frames": self.valid_frames,
                "excluded_frames": self.excluded_frames,
                "excluded": self.excluded,
                "rate": self.rate,
                "duration": self.duration,
                "body": {
                    "mass": params.mass,
                    "mass_source": self.mass_source,
                    "com_height": params.com_height,
                    "com_height_source": self.com_height_source,
                    "omega": params.omega,
                    "body_source": self.body_source,
                },
                "params": params.to_dict(),
                "com_source": self.com_source,
                "support_source": self.support_source,
                "filter": {
                    "type": "Butterworth low-pass, forward-backward (zero lag)",
                    "order": 2 * FILTER_ORDER,
                    "cutoff": self.cutoff,
                    "force_cutoff": self.force_cutoff,
                },
                "gaps": [gap.to_dict() for gap in self.gaps],
                "interpolated_frames": self.interpolated_frames,
                "strategy": {
                    "most_demanding": self.most_demanding,
                    "time_in_strategy": self.time_in_strategy,
                },
                "directions": {
                    axis: _direction_dict(data) for axis, data in self.directions.items()
                },
                "step_events": [_step_dict(event) for event in self.step_events],
                "notes": self.notes,
                "checks": self.checks.to_dict(),
                "plane": asdict(self.plane),
                "events": _events_dict(self.events),
                "posturography": None
                if self.sway is None
                else {
                    **self.sway.to_dict(),
                    "cop_cutoff": self.force_cutoff,
                    "rate": self.sway_rate,
                },
            }
        )


def _direction_dict(data: DirectionSummary) -> dict[str, Any]:
    """Return an axis' ``directions`` entry of ``summary.json``."""
    return {
        "most_demanding": data.most_demanding,
        "time_in_strategy": data.time_in_strategy,
        "min_margin": {"cop": asdict(data.min_cop_margin), "cmp": asdict(data.min_cmp_margin)},
        "min_time_to_leave": {
            "cop": asdict(data.min_time_to_leave_cop),
            "cmp": asdict(data.min_time_to_leave_cmp),
        },
        "capture_point_range": [data.capture_point_min, data.capture_point_max],
        "foot": {"heel": data.heel, "toe": data.toe},
    }


def _step_dict(event: StepEvent) -> dict[str, Any]:
    """Return a ``step_events`` entry of ``summary.json``."""
    return {
        "axis": event.axis,
        "time": event.time,
        "end": event.end,
        "step_length": event.step_length,
        "step_length_range": [event.step_length_min, event.step_length_max],
        "step_length_onset": event.step_length_onset,
        "capture_point": event.capture_point,
    }


def _names(codes: NDArray[np.int8]) -> NDArray[np.object_]:
    """Strategy names of codes; None where invalid (−1)."""
    names = np.array([s.value for s in STRATEGY_CODES] + [None], dtype=object)
    return names[np.where(codes < 0, len(STRATEGY_CODES), codes)]


def _interpolated(time: FloatArray, gaps: list[Gap]) -> NDArray[np.bool_]:
    """Frames inside a filled gap of any signal."""
    flags = np.zeros(len(time), dtype=bool)
    for gap in gaps:
        if gap.filled:
            flags |= (time >= gap.start - 1e-9) & (time <= gap.end + 1e-9)
    return flags


def _exclusions(
    com: FloatArray,
    velocity: FloatArray,
    support: Support,
    invalid: NDArray[np.bool_],
    marker_gap: NDArray[np.bool_],
) -> dict[str, int]:
    """Why frames were excluded (a frame may have several reasons).

    A frame whose base is unknown because a base marker is missing (``marker_gap``) is the
    data checks' to count, not a frame without a supporting foot.
    """
    no_base = ~np.isfinite(support.lower["ap"] + support.lower["ml"]) & ~marker_gap
    reasons = {
        "no CoM": int((~np.isfinite(com).all(axis=1)).sum()),
        "no CoM velocity (segment shorter than 3 frames)": int(
            (np.isfinite(com).all(axis=1) & ~np.isfinite(velocity).all(axis=1)).sum()
        ),
        "no supporting foot": int(no_base.sum()),
    }
    reasons = {k: v for k, v in reasons.items() if v}
    if invalid.any() and not reasons:  # pragma: no cover - every invalid frame has a reason
        reasons["other"] = int(invalid.sum())
    return reasons


def _extreme(values: FloatArray, time: FloatArray, *, lowest: bool = True) -> Extreme:
    """Return the smallest (largest) finite value and its time; None values if none."""
    finite = np.isfinite(values)
    if not finite.any():
        return Extreme(None, None)
    index = np.flatnonzero(finite)[
        np.argmin(values[finite]) if lowest else np.argmax(values[finite])
    ]
    return Extreme(float(values[index]), float(time[index]))


def _time_in(codes: NDArray[np.int8], period: float) -> dict[str, float]:
    return {
        s.value: float(np.count_nonzero(codes == i)) * period for i, s in enumerate(STRATEGY_CODES)
    }


def _most_demanding(codes: NDArray[np.int8]) -> str | None:
    valid = codes[codes >= 0]
    return STRATEGY_CODES[int(valid.max())].value if len(valid) else None


def _step_events(time: FloatArray, per_axis: dict[str, DirectionMargins]) -> tuple[StepEvent, ...]:
    """Every run of frames that needs a step, per axis, with the recommended step.

    The recommended step of an event is the median over its frames: along a fall the stance
    leg swings as a pendulum whose recovering step stays the same, while the first frames are
    marginal (and, after a short push, still inside the filter's transient).
    """
    step = STRATEGY_CODES.index(Strategy.STEP)
    events = []
    for axis, margins in per_axis.items():
        for start, stop in find_gaps(margins.strategy == step):
            span = slice(start, stop)
            events.append(
                StepEvent(
                    axis=axis,
                    time=float(time[start]),
                    end=float(time[stop - 1]),
                    step_length=float(np.median(margins.step_length[span])),
                    step_length_min=float(np.median(margins.step_shortest[span])),
                    step_length_max=float(np.median(margins.step_longest[span])),
                    step_length_onset=float(margins.step_length[start]),
                    capture_point=float(margins.capture_point[start]),
                )
            )
    return tuple(sorted(events, key=lambda event: event.time))


def _plane_summary(
    plane: Margins2D, time: FloatArray, source: str, settings: AnalysisSettings, params: BodyParams
) -> PlaneSummary:
    """Return the smallest 2-D margins and times to boundary, and the 2-D verdict."""
    return PlaneSummary(
        base_source=source,
        min_mos=_extreme(plane.mos, time),
        min_mos_ap=_extreme(plane.mos_ap, time),
        min_mos_ml=_extreme(plane.mos_ml, time),
        min_mos_cmp=_extreme(plane.mos_cmp, time),
        min_time_to_boundary_cop=_extreme(plane.ttb_cop, time),
        min_time_to_boundary_xcom=_extreme(plane.ttb_xcom, time),
        most_demanding=_most_demanding(plane.strategy),
        xcom_length=settings.xcom_length,
        omega=settings.xcom_omega(params),
    )


def _summary(
    recording: Recording,
    time: FloatArray,
    columns: dict[str, NDArray[Any]],
    codes: NDArray[np.int8],
    per_axis: dict[str, DirectionMargins],
    params: BodyParams,
    bodies: dict[str, BodyParams],
    settings: AnalysisSettings,
    gaps: list[Gap],
    *,
    sources: dict[str, str],
    com_source: str,
    support_source: str,
    reasons: dict[str, int],
    notes: list[str],
    checks: DataChecks,
    plane: Margins2D,
    events: TrialEvents,
    sway: tuple[SwayMeasures, float] | None,
) -> TrialSummary:
    period = float(time[-1] - time[0]) / max(len(time) - 1, 1)
    directions = {}
    for axis, margins in per_axis.items():
        directions[axis] = DirectionSummary(
            most_demanding=_most_demanding(margins.strategy),
            time_in_strategy=_time_in(margins.strategy, period),
            min_cop_margin=_extreme(margins.cop, time),
            min_cmp_margin=_extreme(margins.cmp, time),
            min_time_to_leave_cop=_extreme(margins.time_to_leave_cop, time),
            min_time_to_leave_cmp=_extreme(margins.time_to_leave_cmp, time),
            capture_point_min=_extreme(margins.capture_point, time).value,
            capture_point_max=_extreme(margins.capture_point, time, lowest=False).value,
            heel=bodies[axis].heel,
            toe=bodies[axis].toe,
        )
    return TrialSummary(
        source=recording.source,
        frames=len(time),
        valid_frames=int(np.count_nonzero(codes >= 0)),
        excluded=reasons,
        rate=1.0 / period if period > 0 else None,
        duration=float(time[-1] - time[0]),
        params=params,
        mass_source=sources.get("mass", "given"),
        com_height_source=sources.get("com_height", "given"),
        # With sources (the CLI, a batch) the body is the preset unless a person's table gave it.
        body_source=sources.get("body", PRESET_BODY) if sources else "given",
        com_source=com_source,
        support_source=support_source,
        cutoff=settings.cutoff,
        force_cutoff=settings.force_cutoff,
        gaps=tuple(gaps),
        interpolated_frames=int(np.count_nonzero(columns["interpolated"])),
        most_demanding=_most_demanding(codes),
        time_in_strategy=_time_in(codes, period),
        directions=directions,
        step_events=_step_events(time, per_axis),
        notes=tuple(notes),
        checks=checks,
        plane=_plane_summary(plane, time, support_source, settings, params),
        events=events,
        sway=None if sway is None else sway[0],
        sway_rate=None if sway is None else sway[1],
    )
