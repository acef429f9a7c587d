"""Analyse a measured trial: per-frame capture point, margins, strategy and step, and a summary.

The pipeline (docs/analysis.md):

1. Force-plate signals (ground reaction force, CoP): short gaps interpolated, zero-lag
   Butterworth low-pass at ``force_cutoff`` (:mod:`~pushrecovery.analysis.signals`).
2. CoM: from the file (markers or CSV columns), gaps repaired, low-pass at ``cutoff`` and
   differentiated; or, with force plates only, by zero-point-to-zero-point integration of the
   horizontal force (:mod:`~pushrecovery.analysis.zero_point`), at the force-plate rate.
3. Base of support per frame: from foot markers, from CSV columns, or two fixed feet
   (:mod:`~pushrecovery.analysis.recording`).
4. Per axis (ap, ml): capture point, CoP / CMP / step margins, strategy, time to leave the
   regions, recommended step (:mod:`~pushrecovery.analysis.margins`); the frame's strategy is
   the more demanding of the two axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.margins import DirectionMargins, direction_margins
from pushrecovery.analysis.recording import (
    AXES,
    LOADED,
    Foot,
    Recording,
    Support,
    fixed_feet,
    support_from_feet,
)
from pushrecovery.analysis.signals import (
    FILTER_ORDER,
    Gap,
    find_gaps,
    repair_gaps,
    resample,
    smooth_and_differentiate,
)
from pushrecovery.analysis.zero_point import ZERO_FORCE, com_from_force
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy

__all__ = ["AnalysisSettings", "TrialAnalysis", "analyze", "body_for"]

FloatArray = NDArray[np.float64]

#: Assumed distance of the mean CoP ahead of the ankle in quiet standing when nothing in the
#: file locates the feet [m] (the gravity line falls a few cm in front of the ankle joint).
COP_AHEAD_OF_ANKLE = 0.05


@dataclass(frozen=True, slots=True)
class AnalysisSettings:
    """How a trial is processed; all SI.

    Parameters
    ----------
    cutoff : float
        Low-pass cutoff of the CoM and marker trajectories [Hz]; 0 for none. 6 Hz is the usual
        choice for whole-body kinematics (Winter).
    force_cutoff : float
        Low-pass cutoff of the force-plate signals [Hz]; 0 for none.
    max_gap : float
        Longest gap that is interpolated [s], >= 0; longer gaps are excluded.
    contact_height : float
        A foot supports while its lower marker is within this of its lowest [m], > 0.
    foot_width : float or None
        Foot width, for the medio-lateral base around the foot markers [m], > 0; None: the
        body's ``foot_width`` (:class:`~pushrecovery.params.BodyParams`).
    stance_width : float or None
        Ankle-to-ankle distance of the fixed feet assumed without foot data [m], >= 0; None:
        the body's ``stance_width``.
    ankle_ap, ankle_ml : float or None
        Lab position of the fixed feet (midpoint of the ankles) [m]; default from the mean
        CoP (ap: ``COP_AHEAD_OF_ANKLE`` behind it) or, without a CoP, the mean CoM.
    """

    cutoff: float = 6.0
    force_cutoff: float = 10.0
    max_gap: float = 0.1
    contact_height: float = 0.02
    foot_width: float | None = None
    stance_width: float | None = None
    ankle_ap: float | None = None
    ankle_ml: float | None = None

    def widths(self, params: BodyParams) -> tuple[float, float]:
        """Foot width and stance width [m]: these settings', else the body's."""
        return (
            params.foot_width if self.foot_width is None else self.foot_width,
            params.stance_width if self.stance_width is None else self.stance_width,
        )

    def __post_init__(self) -> None:
        for name in ("cutoff", "force_cutoff", "max_gap", "stance_width"):
            value = getattr(self, name)
            if value is None:
                continue
            if not (math.isfinite(value) and value >= 0.0):
                raise InvalidParameterError(f"{name} must be a finite number >= 0, got {value}")
        for name in ("contact_height", "foot_width"):
            value = getattr(self, name)
            if value is None:
                continue
            if not (math.isfinite(value) and value > 0.0):
                raise InvalidParameterError(f"{name} must be a finite number > 0, got {value}")
        for name in ("ankle_ap", "ankle_ml"):
            value = getattr(self, name)
            if value is not None and not math.isfinite(value):
                raise InvalidParameterError(f"{name} must be finite, got {value}")


@dataclass(frozen=True, slots=True)
class TrialAnalysis:
    """Result of :func:`analyze`: the per-frame table and the summary (``summary.json``)."""

    columns: dict[str, NDArray[Any]]
    summary: dict[str, Any]

    @property
    def time(self) -> FloatArray:
        """Frame times [s]."""
        return self.columns["time"]


def body_for(
    recording: Recording,
    *,
    mass: float | None,
    com_height: float | None,
    gravity: float,
) -> tuple[dict[str, float], dict[str, str]]:
    """Subject mass and CoM height: a flag, else the file, else the force plates.

    Parameters
    ----------
    recording : Recording
        The trial.
    mass, com_height : float or None
        Values given as flags [kg, m].
    gravity : float
        g [m/s^2], to weigh the subject on the force plates.

    Returns
    -------
    (values, sources)
        ``mass`` and ``com_height`` found (to override the preset with, see
        :func:`pushrecovery.params.load_params`; a quantity the file does not give is left
        out), and where each came from: ``flag``, ``file``, ``force plates`` (mean vertical
        force / g while loaded) or ``preset``.
    """
    values: dict[str, float] = {}
    sources = {"mass": "preset", "com_height": "preset"}
    if mass is not None:
        values["mass"], sources["mass"] = mass, "flag"
    elif recording.mass is not None:
        values["mass"], sources["mass"] = recording.mass, "file"
    elif recording.force is not None:
        vertical = recording.force[:, 2]
        loaded = vertical[vertical > LOADED]
        if len(loaded):
            values["mass"] = float(np.mean(loaded)) / gravity
            sources["mass"] = "force plates (mean vertical force / g)"
    if com_height is not None:
        values["com_height"], sources["com_height"] = com_height, "flag"
    elif recording.com_height is not None:
        values["com_height"], sources["com_height"] = recording.com_height, "file"
    return values, sources


def analyze(
    recording: Recording,
    params: BodyParams,
    settings: AnalysisSettings | None = None,
    *,
    sources: dict[str, str] | None = None,
) -> TrialAnalysis:
    """Analyse a trial (module docstring).

    Parameters
    ----------
    recording : Recording
        The measured trial (:mod:`pushrecovery.analysis.readers`).
    params : BodyParams
        The body: mass, CoM height (ω), hip limits, leg and reach; its heel and toe are the
        foot's edges when the file does not locate them (see :func:`body_for`).
    settings : AnalysisSettings, optional
        Filtering, gaps and support options.
    sources : dict, optional
        Where mass and CoM height came from, for the summary.

    Returns
    -------
    TrialAnalysis

    Raises
    ------
    InvalidParameterError
        When the trial has no usable CoM (neither positions nor a ground reaction force that
        crosses zero), or the base of support is inconsistent.
    """
    settings = settings or AnalysisSettings()
    gaps: list[Gap] = []
    notes = list(recording.notes)
    force_time = recording.force_time
    force = cop = None
    if recording.force is not None and force_time is not None:
        force, found = repair_gaps(force_time, recording.force, settings.max_gap, "force")
        gaps += found
        force, _ = smooth_and_differentiate(force_time, force, settings.force_cutoff)
    if recording.cop is not None and force_time is not None:
        cop, found = _repair_loaded(force_time, recording.cop, force, settings.max_gap)
        gaps += found
        cop, _ = smooth_and_differentiate(force_time, cop, settings.force_cutoff)

    if recording.com is not None:
        time = recording.time
        com, found = repair_gaps(time, recording.com[:, :2], settings.max_gap, "com")
        gaps += found
        com, velocity = smooth_and_differentiate(time, com, settings.cutoff)
        if recording.com_velocity is not None:
            measured, found = repair_gaps(
                time, recording.com_velocity, settings.max_gap, "com_velocity"
            )
            gaps += found
            velocity, _ = smooth_and_differentiate(time, measured, settings.cutoff)
        com_source = "file"
    else:
        if force is None or cop is None or force_time is None:
            raise InvalidParameterError(
                "the trial has no CoM: give CoM markers or columns, or force plates (ground "
                "reaction force and CoP) to integrate it from"
            )
        time = force_time
        com = np.empty((len(time), 2))
        velocity = np.empty((len(time), 2))
        for i in range(2):
            com[:, i], _ = com_from_force(
                time, force[:, i], cop[:, i], params.mass, tolerance=ZERO_FORCE * params.weight
            )
        # Each interval's velocity has its own constant: it jumps at the zero points. The
        # integrated position is continuous; low-pass it like a measured CoM and differentiate.
        com, velocity = smooth_and_differentiate(time, com, settings.cutoff)
        com_source = "zero-point-to-zero-point integration of the ground reaction force"
        notes.append(
            "CoM integrated from the force plates: an external push is no ground reaction "
            "force, so its impulse is missing between the zero points around it"
        )

    if force is not None and force_time is not None:
        force = resample(force_time, force, time)
    if cop is not None and force_time is not None:
        cop = resample(force_time, cop, time)
    support, support_source, found = _support(recording, time, com, cop, params, settings)
    gaps += found

    columns: dict[str, NDArray[Any]] = {"time": time}
    per_axis: dict[str, DirectionMargins] = {}
    bodies: dict[str, BodyParams] = {}
    for i, axis in enumerate(AXES):
        heel, toe = support.foot[axis]
        body = replace(params, heel=heel, toe=toe)
        bodies[axis] = body
        capture = com[:, i] + velocity[:, i] / params.omega
        ankle = support.stance_ankle(axis, capture)
        cmp = None
        if force is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                loaded = force[:, 2] > LOADED
                cmp = np.where(
                    loaded, com[:, i] - params.com_height * force[:, i] / force[:, 2], np.nan
                )
        axis_cop = None if cop is None else cop[:, i]
        margins = direction_margins(
            com[:, i],
            velocity[:, i],
            support.lower[axis],
            support.upper[axis],
            ankle,
            body,
            cop=axis_cop,
            cmp=cmp,
        )
        per_axis[axis] = margins
        nan = np.full(len(time), np.nan)
        columns.update(
            {
                f"{axis}_com": com[:, i],
                f"{axis}_com_velocity": velocity[:, i],
                f"{axis}_cop": nan if axis_cop is None else axis_cop,
                f"{axis}_cmp": nan if cmp is None else cmp,
                f"{axis}_capture_point": margins.capture_point,
                f"{axis}_base_min": support.lower[axis],
                f"{axis}_base_max": support.upper[axis],
                f"{axis}_ankle": ankle,
                f"{axis}_margin_cop": margins.cop,
                f"{axis}_margin_cmp": margins.cmp,
                f"{axis}_margin_step": margins.step,
                f"{axis}_strategy": _names(margins.strategy),
                f"{axis}_time_to_leave_cop": margins.time_to_leave_cop,
                f"{axis}_time_to_leave_cmp": margins.time_to_leave_cmp,
                f"{axis}_step_length": margins.step_length,
                f"{axis}_step_length_min": margins.step_shortest,
                f"{axis}_step_length_max": margins.step_longest,
                f"{axis}_steps": margins.steps,
            }
        )
    codes = np.maximum(per_axis["ap"].strategy, per_axis["ml"].strategy)
    invalid = (per_axis["ap"].strategy < 0) | (per_axis["ml"].strategy < 0)
    codes[invalid] = -1
    columns["strategy"] = _names(codes)
    columns["valid"] = ~invalid
    columns["interpolated"] = _interpolated(time, gaps)

    summary = _summary(
        recording,
        time,
        columns,
        codes,
        per_axis,
        params,
        bodies,
        settings,
        gaps,
        sources=sources or {},
        com_source=com_source,
        support_source=support_source,
        notes=notes,
        reasons=_exclusions(com, velocity, support, invalid),
    )
    return TrialAnalysis(columns, summary)


def _repair_loaded(
    time: FloatArray, cop: FloatArray, force: FloatArray | None, max_gap: float
) -> tuple[FloatArray, list[Gap]]:
    """Repair CoP gaps; while the plates are unloaded the CoP is undefined, not a gap."""
    repaired, gaps = repair_gaps(time, cop, max_gap, "cop")
    if force is not None:
        unloaded = ~(force[:, 2] > LOADED)
        repaired[unloaded] = np.nan
    return repaired, gaps


def _support(
    recording: Recording,
    time: FloatArray,
    com: FloatArray,
    cop: FloatArray | None,
    params: BodyParams,
    settings: AnalysisSettings,
) -> tuple[Support, str, list[Gap]]:
    """Build the base of support from the feet, CSV columns, or two assumed fixed feet."""
    gaps: list[Gap] = []
    if recording.feet:
        measured: list[Foot] = []
        for foot in recording.feet:
            parts = []
            for part in ("heel", "toe", "ankle"):
                values = resample(recording.time, getattr(foot, part), time)
                values, found = repair_gaps(time, values, settings.max_gap, f"{foot.name} {part}")
                gaps += found
                parts.append(values)
            measured.append(Foot(foot.name, *parts))
        support = support_from_feet(
            tuple(measured),
            contact_height=settings.contact_height,
            foot_width=settings.widths(params)[0],
        )
        return support, "foot markers", gaps
    if recording.base:
        return _explicit_support(recording, time, params, settings), "base columns", gaps
    centre = cop if cop is not None and np.isfinite(cop).any() else com
    if not np.isfinite(centre).any():
        raise InvalidParameterError(
            "nothing locates the feet: the trial has no CoP and no CoM values; give "
            "--ankle-ap and --ankle-ml"
        )
    ankle_ap = settings.ankle_ap
    ankle_ml = settings.ankle_ml
    assumed = []
    if ankle_ap is None:
        ankle_ap = float(np.nanmean(centre[:, 0])) - COP_AHEAD_OF_ANKLE
        what = "CoP" if centre is cop else "CoM"
        assumed.append(f"ankles {COP_AHEAD_OF_ANKLE:g} m behind the mean {what}")
    if ankle_ml is None:
        ankle_ml = float(np.nanmean(centre[:, 1]))
        assumed.append("centred on it medio-laterally")
    foot_width, stance_width = settings.widths(params)
    feet = fixed_feet(len(time), ankle_ap, ankle_ml, params.heel, params.toe, stance_width)
    support = support_from_feet(feet, contact_height=settings.contact_height, foot_width=foot_width)
    source = "fixed feet (heel/toe flags, --stance-width)"
    if assumed:
        source += ": " + ", ".join(assumed)
    return support, source, gaps


def _explicit_support(
    recording: Recording, time: FloatArray, params: BodyParams, settings: AnalysisSettings
) -> Support:
    """Support from CSV columns: base edges, optionally the stance ankle, per axis."""
    lower, upper, ankles = {}, {}, {}
    for axis in AXES:
        if axis not in recording.base:
            raise InvalidParameterError(
                f"give the base of support along both axes: base_{axis}_min and base_{axis}_max "
                "columns are missing"
            )
        edges = recording.base[axis]
        lower[axis], upper[axis] = edges[:, 0], edges[:, 1]
        if axis in recording.ankle:
            ankle = recording.ankle[axis]
        elif axis == "ap":
            ankle = lower[axis] - params.heel  # the ankle |heel| in front of the rear edge
        else:
            ankle = 0.5 * (lower[axis] + upper[axis])
        ankles[axis] = ankle[:, None]
    foot = {
        "ap": (params.heel, params.toe),
        "ml": (-settings.widths(params)[0] / 2, settings.widths(params)[0] / 2),
    }
    supporting = np.isfinite(lower["ap"])[:, None]
    return Support(lower, upper, ankles, foot, supporting)


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
    com: FloatArray, velocity: FloatArray, support: Support, invalid: NDArray[np.bool_]
) -> dict[str, int]:
    """Why frames were excluded (a frame may have several reasons)."""
    reasons = {
        "no CoM": int((~np.isfinite(com).all(axis=1)).sum()),
        "no CoM velocity (segment shorter than 3 frames)": int(
            (np.isfinite(com).all(axis=1) & ~np.isfinite(velocity).all(axis=1)).sum()
        ),
        "no supporting foot": int((~np.isfinite(support.lower["ap"] + support.lower["ml"])).sum()),
    }
    reasons = {k: v for k, v in reasons.items() if v}
    if invalid.any() and not reasons:  # pragma: no cover - every invalid frame has a reason
        reasons["other"] = int(invalid.sum())
    return reasons


def _extreme(values: FloatArray, time: FloatArray, *, lowest: bool = True) -> dict[str, Any]:
    """Return the smallest (largest) finite value and its time; None values if none."""
    finite = np.isfinite(values)
    if not finite.any():
        return {"value": None, "time": None}
    index = np.flatnonzero(finite)[
        np.argmin(values[finite]) if lowest else np.argmax(values[finite])
    ]
    return {"value": float(values[index]), "time": float(time[index])}


def _time_in(codes: NDArray[np.int8], period: float) -> dict[str, float]:
    return {
        s.value: float(np.count_nonzero(codes == i)) * period for i, s in enumerate(STRATEGY_CODES)
    }


def _most_demanding(codes: NDArray[np.int8]) -> str | None:
    valid = codes[codes >= 0]
    return STRATEGY_CODES[int(valid.max())].value if len(valid) else None


def _step_events(time: FloatArray, per_axis: dict[str, DirectionMargins]) -> list[dict[str, Any]]:
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
                {
                    "axis": axis,
                    "time": float(time[start]),
                    "end": float(time[stop - 1]),
                    "step_length": float(np.median(margins.step_length[span])),
                    "step_length_range": [
                        float(np.median(margins.step_shortest[span])),
                        float(np.median(margins.step_longest[span])),
                    ],
                    "step_length_onset": float(margins.step_length[start]),
                    "capture_point": float(margins.capture_point[start]),
                }
            )
    return sorted(events, key=lambda event: event["time"])


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
) -> dict[str, Any]:
    period = (time[-1] - time[0]) / max(len(time) - 1, 1)
    directions = {}
    for axis, margins in per_axis.items():
        directions[axis] = {
            "most_demanding": _most_demanding(margins.strategy),
            "time_in_strategy": _time_in(margins.strategy, period),
            "min_margin": {
                "cop": _extreme(margins.cop, time),
                "cmp": _extreme(margins.cmp, time),
            },
            "min_time_to_leave": {
                "cop": _extreme(margins.time_to_leave_cop, time),
                "cmp": _extreme(margins.time_to_leave_cmp, time),
            },
            "capture_point_range": [
                _extreme(margins.capture_point, time)["value"],
                _extreme(margins.capture_point, time, lowest=False)["value"],
            ],
            "foot": {"heel": bodies[axis].heel, "toe": bodies[axis].toe},
        }
    valid = int(np.count_nonzero(codes >= 0))
    return {
        "source": recording.source,
        "frames": len(time),
        "valid_frames": valid,
        "excluded_frames": len(time) - valid,
        "excluded": reasons,
        "rate": 1.0 / period if period > 0 else None,
        "duration": float(time[-1] - time[0]),
        "body": {
            "mass": params.mass,
            "mass_source": sources.get("mass", "given"),
            "com_height": params.com_height,
            "com_height_source": sources.get("com_height", "given"),
            "omega": params.omega,
        },
        "params": params.to_dict(),
        "com_source": com_source,
        "support_source": support_source,
        "filter": {
            "type": "Butterworth low-pass, forward-backward (zero lag)",
            "order": 2 * FILTER_ORDER,
            "cutoff": settings.cutoff,
            "force_cutoff": settings.force_cutoff,
        },
        "gaps": [gap.to_dict() for gap in gaps],
        "interpolated_frames": int(np.count_nonzero(columns["interpolated"])),
        "strategy": {
            "most_demanding": _most_demanding(codes),
            "time_in_strategy": _time_in(codes, period),
        },
        "directions": directions,
        "step_events": _step_events(time, per_axis),
        "notes": notes,
    }
