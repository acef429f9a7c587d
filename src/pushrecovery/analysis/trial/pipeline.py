"""The analysis of one measured trial: signals, the CoM, margins and strategies per frame.

Over 400 lines on purpose: :func:`analyze` is the sequence of one trial's stages, kept in one
place so that each stage's inputs and outputs can be read in order.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.base_polygon import BasePolygons
from pushrecovery.analysis.margins import DirectionMargins, direction_margins
from pushrecovery.analysis.margins.plane import Margins2D, margins_2d
from pushrecovery.analysis.posturography import SwayMeasures, quiet_standing, sway_measures
from pushrecovery.analysis.recording import (
    AXES,
    LOADED,
    Recording,
)
from pushrecovery.analysis.signals import (
    Gap,
    repair_gaps,
    resample,
    smooth_and_differentiate,
)
from pushrecovery.analysis.trial.checks import (
    PlateFeet,
    channel_checks,
    check_forward,
    check_frames,
    plate_feet,
)
from pushrecovery.analysis.trial.events import Onset, trial_events
from pushrecovery.analysis.trial.risk import frame_risk
from pushrecovery.analysis.trial.settings import AnalysisSettings, TrialAnalysis
from pushrecovery.analysis.trial.summary import (
    _exclusions,
    _interpolated,
    _names,
    _summary,
)
from pushrecovery.analysis.trial.support import _repair_loaded, _support
from pushrecovery.analysis.zero_point import ZERO_FORCE, com_from_force
from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams

__all__ = [
    "FloatArray",
    "analyze",
]


FloatArray = NDArray[np.float64]


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
    require_type("recording", recording, Recording)
    require_type("params", params, BodyParams)
    if settings is not None:
        require_type("settings", settings, AnalysisSettings)
    if sources is not None and not (
        isinstance(sources, dict)
        and all(isinstance(k, str) and isinstance(v, str) for k, v in sources.items())
    ):
        raise ParameterTypeError("sources must map body values' names to where they came from")
    settings = settings or AnalysisSettings()
    gaps: list[Gap] = []
    notes = list(recording.notes)
    forward = check_forward(recording.feet)  # a wrong --ap-axis: refused
    plates = plate_feet(recording, settings.widths(params)[0], params.weight)
    channels = channel_checks(recording)  # the channels as recorded, stray plates and all
    for flagged, what in (
        ([c.channel for c in channels if c.saturated], "saturated (a flat top at its extreme)"),
        ([c.channel for c in channels if c.offset_flag], "offset from zero while unloaded"),
    ):
        if flagged:
            notes.append(f"force channel {what}: {', '.join(flagged)}")
    if plates.stray:
        recording, note = _without_plates(recording, plates)
        notes.append(note)
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

    plate_force, plate_cop = force, cop  # at the plates' own rate
    if force is not None and force_time is not None:
        force = resample(force_time, force, time)
    if cop is not None and force_time is not None:
        cop = resample(force_time, cop, time)
    support, base, support_source, found, missing = _support(
        recording, time, com, cop, params, settings
    )
    gaps += found
    checks = check_frames(
        time,
        force_time,
        plate_force,
        cop,
        support.lower,
        support.upper,
        missing,
        plates,
        channels,
        forward,
    )
    if checks.base_rejected:
        notes.append(
            f"the measured CoP lies beyond the computed base of support ({support_source}) "
            f"by more than {checks.tolerance * 100:g} cm in {int(checks.contradicted.sum())} "
            f"of {checks.loaded_frames} loaded frames: the base is wrong, no verdict is given"
        )

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
        _withhold(margins, checks.withheld)  # no verdict where the data contradict it
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
    risk = frame_risk(
        time, per_axis, support, params, settings.com_noise, settings.cutoff,
        state={axis: (com[:, i], velocity[:, i]) for i, axis in enumerate(AXES)},
        com_height_sd=settings.com_height_sd,
    )  # fmt: skip
    columns.update({f"{axis}_risk": values for axis, values in risk.items()})
    plane = _plane(
        base, com, velocity, cop, time, params, checks.withheld, settings.xcom_omega(params)
    )
    columns.update(plane.to_columns())
    columns["strategy_2d"] = _names(plane.strategy)
    codes = np.maximum(per_axis["ap"].strategy, per_axis["ml"].strategy)
    invalid = (per_axis["ap"].strategy < 0) | (per_axis["ml"].strategy < 0)
    codes[invalid] = -1
    columns["strategy"] = _names(codes)
    columns["valid"] = ~invalid
    columns["interpolated"] = _interpolated(time, gaps)
    columns["flight"] = checks.flight
    columns["cop_outside_base"] = checks.contradicted

    events = trial_events(
        recording,
        time,
        velocity,
        per_axis,
        params.mass,
        com=com,
        plane=(base, params),
        plates=checks.plates,
        mos={"ap": plane.mos_ap, "ml": plane.mos_ml},
        risk=risk or None,
    )
    sway = _posturography(force_time, plate_cop, plate_force)
    if sway is not None and events.onset.time is not None:
        # Quiet standing has no perturbation: its sway crosses any threshold of a short baseline.
        quiet = Onset(None, events.onset.signal, None, "quiet standing: no perturbation")
        events = replace(events, onset=quiet)
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
        reasons={
            **_exclusions(com, velocity, support, invalid & ~checks.withheld, checks.marker_gap),
            **checks.reasons(),
        },
        checks=checks,
        plane=plane,
        events=events,
        sway=sway,
    )
    if settings.normalise:
        columns.update(_normalised(columns, params))
    return TrialAnalysis(columns, summary, base)


#: Columns that are lengths (margins) and times, and velocities, made dimensionless.
_LENGTH_COLUMNS = ("mos", "mos_ap", "mos_ml", "mos_cmp", "ap_margin_cop", "ml_margin_cop",
                   "ap_margin_cmp", "ml_margin_cmp")  # fmt: skip
_TIME_COLUMNS = ("ttb_cop", "ttb_xcom", "ap_time_to_leave_cop", "ml_time_to_leave_cop")
_VELOCITY_COLUMNS = ("ap_com_velocity", "ml_com_velocity")


def _normalised(columns: dict[str, NDArray[Any]], params: BodyParams) -> dict[str, NDArray[Any]]:
    """Return Hof's dimensionless columns (``*_norm``), l the leg length (Hof 2008).

    Lengths over l, velocities over sqrt(g l), times times sqrt(g / l).
    """
    leg = params.leg_length
    scales = {name: 1.0 / leg for name in _LENGTH_COLUMNS}
    scales.update({name: 1.0 / np.sqrt(params.gravity * leg) for name in _VELOCITY_COLUMNS})
    scales.update({name: np.sqrt(params.gravity / leg) for name in _TIME_COLUMNS})
    return {f"{name}_norm": columns[name] * k for name, k in scales.items() if name in columns}


def _plane(
    base: BasePolygons,
    com: FloatArray,
    velocity: FloatArray,
    cop: FloatArray | None,
    time: FloatArray,
    params: BodyParams,
    withheld: NDArray[np.bool_],
    omega: float,
) -> Margins2D:
    """Return the 2-D margins against the base polygon (docs/base_polygon.md), withheld NaN.

    ``omega`` is the XCoM's ω0 [1/s] (``AnalysisSettings.xcom_omega``).
    """
    cop_velocity = None
    if cop is not None:
        _, cop_velocity = smooth_and_differentiate(time, cop, 0.0)  # already low-passed
    plane = margins_2d(base, com, velocity, params, omega=omega, cop=cop, cop_velocity=cop_velocity)
    for values in plane.to_columns().values():  # views of the measures' own arrays
        if values.dtype.kind == "f":
            values[withheld] = np.nan
    plane.strategy[withheld] = -1
    return plane


def _without_plates(recording: Recording, plates: PlateFeet) -> tuple[Recording, str]:
    """Return the recording without its stray plates' vertical force and CoP, and a note.

    The combined CoP is again the vertical-force-weighted mean of the other plates' CoPs and
    the stray plates' vertical force is taken off the total; their horizontal force, which
    the recording does not keep per plate, stays in the total (the note says so).
    """
    assert recording.force is not None and recording.cop is not None
    kept = [k for k in range(len(recording.plates)) if k not in plates.stray]
    weights = np.zeros(len(recording.cop))
    moments = np.zeros_like(recording.cop)
    for k in kept:
        vertical, cop = recording.plates[k]
        loaded = np.isfinite(cop).all(axis=1) & (vertical > 0.0)
        weights += np.where(loaded, vertical, 0.0)
        moments += np.where(loaded[:, None], vertical[:, None] * cop, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        cop = np.where((weights > 0.0)[:, None], moments / weights[:, None], np.nan)
    force = recording.force.copy()
    for k in plates.stray:
        force[:, 2] -= np.nan_to_num(recording.plates[k][0], nan=0.0)
    names = ", ".join(
        f"plate {k + 1} (peak {plates.peak[k]:.0f} N, {plates.distance[k] * 100:.0f} cm from "
        "the nearest sole)"
        for k in plates.stray
    )
    note = (
        f"loaded under no foot: {names}: no foot's contact, left out of the combined CoP and the "
        "vertical force (its horizontal force stays in the total)"
    )
    return replace(recording, force=force, cop=cop), note


def _withhold(margins: DirectionMargins, frames: NDArray[np.bool_]) -> None:
    """Withhold the verdicts of ``frames``: margins against the base NaN, strategy invalid."""
    for name in ("cop", "cmp", "step", "time_to_leave_cop", "time_to_leave_cmp"):
        getattr(margins, name)[frames] = np.nan
    for name in ("step_length", "step_shortest", "step_longest"):
        getattr(margins, name)[frames] = np.nan
    margins.strategy[frames] = -1
    margins.steps[frames] = -1


def _posturography(
    force_time: FloatArray | None,
    cop: FloatArray | None,
    force: FloatArray | None,
) -> tuple[SwayMeasures, float] | None:
    """Sway measures of a quiet-standing trial (docs/posturography.md) and the rate [Hz].

    The whole trial at the plates' rate, its CoP low-passed at ``force_cutoff``; None when
    the plates are missing or :func:`~pushrecovery.analysis.posturography.quiet_standing`
    says it is no quiet standing, or it is too short for the spectra.
    """
    if force_time is None or cop is None or len(force_time) < 2:
        return None
    rate = 1.0 / float(np.median(np.diff(force_time)))
    try:
        if not quiet_standing(cop, rate, force=force):
            return None
        return sway_measures(cop, rate), rate
    except InvalidParameterError:  # too short for the spectra, or a gap in the CoP
        return None
