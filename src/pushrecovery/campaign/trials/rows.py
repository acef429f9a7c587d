"""The rows of a batch of measured trials: one per trial and axis; the summary across trials.

Columns of ``trials.parquet`` (:class:`TrialRow`; SI units, axes ap and ml as in
:mod:`pushrecovery.analysis.recording`); the events are in
:mod:`pushrecovery.campaign.trials.events`. These tables are contracts: columns are added,
never renamed or dropped.

Over 400 lines on purpose: :class:`TrialRow` is the batch table's schema, one documented
field per column, and the functions that fill it, fail it and sum it up read those fields.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pushrecovery.arguments import positive_float, require_type
from pushrecovery.errors import ParameterTypeError
from pushrecovery.params import BodyParams

if TYPE_CHECKING:
    from pushrecovery.analysis.posturography import SwayMeasures
    from pushrecovery.analysis.trial import TrialSummary

__all__ = [
    "TRIAL_FIELDS",
    "TrialRow",
    "batch_summary",
    "check_job",
    "failed_rows",
    "subject_name",
    "sway_rows",
    "trial_rows",
    "write_table",
]

STRATEGIES = ("ankle", "hip", "step", "fall")


@dataclass(frozen=True, slots=True)
class TrialRow:
    """One trial along one axis.

    Attributes
    ----------
    trial, path, subject : str
        The trial's name in the batch, its file, its subject ("" without a subjects table).
    axis : str
        ``ap`` or ``ml``.
    status : str
        ``analysed``; ``posturography only`` (a CoP without a CoM or a force: the sway
        columns, the rest null); or ``failed`` (``error`` says why; the measures are null).
    frames, valid_frames, excluded_frames, interpolated_frames : int
        Frames of the trial, with a verdict, without one, and inside filled gaps.
    rate, duration : float
        Frame rate [Hz] and duration [s].
    mass, com_height, leg_length : float
        The body assumed [kg, m, m]; ``*_source`` where each came from (subjects table, flag,
        file, force plates, preset).
    com_source, support_source : str
        How the CoM and the base of support were obtained.
    heel, toe : float
        The axis' foot edges relative to the ankle used by the verdicts [m].
    most_demanding : str
        The most demanding strategy any frame needed along this axis (ankle, hip, step, fall).
    time_ankle, time_hip, time_step, time_fall : float
        Time the frames needed each strategy along this axis [s].
    min_cop_margin, min_cmp_margin : float
        Smallest margin of the capture point (XCoM) inside the CoP (Eq. 4, Hof's margin of
        stability) and CMP (corrected Eq. 15) regions [m], and its time [s].
    min_cop_margin_normalised : float
        ``min_cop_margin`` / ``leg_length``: Hof's dimensionless margin (Hof et al. 2005).
    min_time_to_leave_cop : float
        Shortest time before the CoM would leave the CoP region at its current motion [s].
    capture_point_min, capture_point_max : float
        Range of the capture point along the axis [m].
    step_events : int
        Runs of frames that needed a step along this axis.
    flight_frames, cop_outside_base_frames : int
        Frames withheld: in flight, and (this axis) with the CoP beyond the base by more than
        ``cop_tolerance`` [m] (docs/analysis.md, "Data checks").
    base_rejected : bool
        The CoP contradicts the base in most loaded frames: ``status`` is ``not classified``.
    onset : float
        Perturbation onset [s] (docs/events.md), null if none was found.
    steps_taken : int
        Steps measured from the foot markers (both axes' rows give the trial's count).
    sway_path_length, sway_mean_velocity, sway_rms_distance, sway_range : float
        Quiet standing only (docs/posturography.md): the CoP's path [m], mean speed [m/s],
        RMS distance from its mean [m] and range [m] along this axis.
    min_mos, min_mos_time : float
        Smallest signed distance of the XCoM to the base polygon (Hof's margin of stability
        in the plane, + inside) [m] and its time [s] (the same on both axes' rows).
    min_mos_normalised : float
        ``min_mos`` / ``leg_length``: Hof's dimensionless margin.
    min_mos_axis : float
        Smallest component margin along this axis, toward the side the CoM moves [m].
    min_time_to_boundary_cop, min_time_to_boundary_xcom : float
        Shortest times to the base's boundary of the CoP and of the XCoM [s]
        (docs/base_polygon.md).
    most_demanding_2d : str
        The most demanding strategy of the 2-D verdicts against the base polygon.
    sway_f50, sway_f95 : float
        Frequencies below which 50 % and 95 % of the axis' sway power lies [Hz].
    sway_ellipse_area, sway_mean_velocity_total : float
        The 95 % prediction ellipse [m²] and the resultant mean speed [m/s] (the same on both
        axes' rows).
    body_source : str
        Where the body's geometry and upper-body inertia came from: de Leva's table (the
        subjects table's ``height`` and ``sex``), or the preset (not scaled to the person).
    excluded_frames_markers : int
        Frames without a verdict because a heel or toe marker is missing (docs/analysis.md,
        "Data checks").
    marker_gap_frames : str
        Those frames per marker, ``"left heel=30; left toe=10"`` ("" when none).
    stray_plates, saturated_channels, zero_offset_channels : str
        Plates loaded under no foot, force channels with a flat top at their extreme, and
        channels offset from zero while unloaded, joined by ``"; "`` ("" when none).
    forward_angle : float
        Angle of the feet's heel -> toe direction from the ap axis [deg], + to the left
        (null without foot markers).
    condition : str
        The trial's condition from the subjects table (``slip``, ``trip``, ...), null when the
        table gives none.
    """

    trial: str
    path: str
    subject: str
    axis: str
    status: str
    error: str | None
    frames: int | None = None
    valid_frames: int | None = None
    excluded_frames: int | None = None
    interpolated_frames: int | None = None
    rate: float | None = None
    duration: float | None = None
    mass: float | None = None
    mass_source: str | None = None
    com_height: float | None = None
    com_height_source: str | None = None
    leg_length: float | None = None
    leg_length_source: str | None = None
    com_source: str | None = None
    support_source: str | None = None
    heel: float | None = None
    toe: float | None = None
    most_demanding: str | None = None
    time_ankle: float | None = None
    time_hip: float | None = None
    time_step: float | None = None
    time_fall: float | None = None
    min_cop_margin: float | None = None
    min_cop_margin_time: float | None = None
    min_cop_margin_normalised: float | None = None
    min_cmp_margin: float | None = None
    min_cmp_margin_time: float | None = None
    min_time_to_leave_cop: float | None = None
    capture_point_min: float | None = None
    capture_point_max: float | None = None
    step_events: int | None = None
    flight_frames: int | None = None
    cop_outside_base_frames: int | None = None
    cop_tolerance: float | None = None
    base_rejected: bool | None = None
    onset: float | None = None
    steps_taken: int | None = None
    min_mos: float | None = None
    min_mos_time: float | None = None
    min_mos_normalised: float | None = None
    min_mos_axis: float | None = None
    min_time_to_boundary_cop: float | None = None
    min_time_to_boundary_xcom: float | None = None
    most_demanding_2d: str | None = None
    sway_path_length: float | None = None
    sway_mean_velocity: float | None = None
    sway_rms_distance: float | None = None
    sway_range: float | None = None
    sway_f50: float | None = None
    sway_f95: float | None = None
    sway_ellipse_area: float | None = None
    sway_mean_velocity_total: float | None = None
    body_source: str | None = None
    excluded_frames_markers: int | None = None
    marker_gap_frames: str | None = None
    stray_plates: str | None = None
    saturated_channels: str | None = None
    zero_offset_channels: str | None = None
    forward_angle: float | None = None
    condition: str | None = None


#: Arrow types of the columns, in order.
TRIAL_FIELDS: tuple[tuple[str, str], ...] = tuple((f.name, str(f.type)) for f in fields(TrialRow))


def check_job(job: object) -> None:
    """Raise unless ``job`` is a trial job, a :class:`~pushrecovery.campaign.trials.TrialJob`.

    Checked by its fields: that module imports this one.
    """
    if not all(hasattr(job, field) for field in ("path", "name", "subject", "flags")):
        raise ParameterTypeError(f"job must be a TrialJob, got {type(job).__name__}")


def subject_name(job: Any) -> str:
    """Return the job's subject ("" without a subjects table)."""
    check_job(job)
    return "" if job.subject is None else str(job.subject.subject)


def _condition(job: Any) -> str | None:
    """Return the job's condition (None without one in the subjects table)."""
    return None if job.subject is None else job.subject.condition


def trial_rows(
    job: Any, summary: TrialSummary, params: BodyParams, sources: dict[str, str]
) -> list[dict[str, Any]]:
    """Return the rows of an analysed trial, from its summary.

    The values are the summary's own (NaN, not yet None: ``json_safe`` them for a JSON file).
    """
    from pushrecovery.analysis.trial import TrialSummary

    check_job(job)
    require_type("summary", summary, TrialSummary)
    require_type("params", params, BodyParams)
    require_type("sources", sources, dict)
    from pushrecovery.analysis.trial.settings import PRESET_BODY

    checks, plane = summary.checks, summary.plane
    rows = []
    for axis, data in summary.directions.items():
        margin, mos = data.min_cop_margin.value, plane.min_mos.value
        times = data.time_in_strategy
        row = TrialRow(
            trial=job.name,
            path=str(job.path),
            subject=subject_name(job),
            condition=_condition(job),
            axis=axis,
            status="analysed",
            error=None,
            frames=summary.frames,
            valid_frames=summary.valid_frames,
            excluded_frames=summary.excluded_frames,
            interpolated_frames=summary.interpolated_frames,
            rate=summary.rate,
            duration=summary.duration,
            mass=summary.params.mass,
            mass_source=summary.mass_source,
            com_height=summary.params.com_height,
            com_height_source=summary.com_height_source,
            leg_length=params.leg_length,
            leg_length_source=sources.get("leg_length", "preset"),
            body_source=sources.get("body", PRESET_BODY),
            com_source=summary.com_source,
            support_source=summary.support_source,
            heel=data.heel,
            toe=data.toe,
            most_demanding=data.most_demanding,
            time_ankle=times["ankle"],
            time_hip=times["hip"],
            time_step=times["step"],
            time_fall=times["fall"],
            min_cop_margin=margin,
            min_cop_margin_time=data.min_cop_margin.time,
            min_cop_margin_normalised=None if margin is None else margin / params.leg_length,
            min_cmp_margin=data.min_cmp_margin.value,
            min_cmp_margin_time=data.min_cmp_margin.time,
            min_time_to_leave_cop=data.min_time_to_leave_cop.value,
            capture_point_min=data.capture_point_min,
            capture_point_max=data.capture_point_max,
            step_events=sum(1 for e in summary.step_events if e.axis == axis),
            flight_frames=int(checks.flight.sum()),
            cop_outside_base_frames=int(checks.cop_outside[axis].sum()),
            cop_tolerance=checks.tolerance,
            base_rejected=checks.base_rejected,
            onset=summary.events.onset.time,
            steps_taken=len(summary.events.measured_steps),
            min_mos=mos,
            min_mos_time=plane.min_mos.time,
            min_mos_normalised=None if mos is None else mos / params.leg_length,
            min_mos_axis=(plane.min_mos_ap if axis == "ap" else plane.min_mos_ml).value,
            min_time_to_boundary_cop=plane.min_time_to_boundary_cop.value,
            min_time_to_boundary_xcom=plane.min_time_to_boundary_xcom.value,
            most_demanding_2d=plane.most_demanding,
            **_sway(summary.sway, axis),
            **checks.row_flags(),
        )
        if row.base_rejected:
            row = replace(
                row, status="not classified", error="the CoP contradicts the base of support"
            )
        rows.append(asdict(row))
    return rows


def _sway(sway: SwayMeasures | None, axis: str) -> dict[str, Any]:
    """Return a trial row's quiet-standing measures (none if the trial is no quiet standing)."""
    if sway is None:
        return {}
    spectrum = sway.spectrum_ap if axis == "ap" else sway.spectrum_ml
    return {
        "sway_path_length": getattr(sway.path_length, axis),
        "sway_mean_velocity": getattr(sway.mean_velocity, axis),
        "sway_rms_distance": getattr(sway.rms_distance, axis),
        "sway_range": sway.range_ap if axis == "ap" else sway.range_ml,
        "sway_f50": spectrum.f50,
        "sway_f95": spectrum.f95,
        "sway_ellipse_area": sway.ellipse.area,
        "sway_mean_velocity_total": sway.mean_velocity.total,
    }


def sway_rows(job: Any, sway: SwayMeasures, rate: float) -> list[dict[str, Any]]:
    """Return the rows of a CoP-only trial: ``posturography only`` with its sway columns."""
    from pushrecovery.analysis.posturography import SwayMeasures

    check_job(job)
    require_type("sway", sway, SwayMeasures)
    rate = positive_float("rate", rate, "Hz")
    return [
        asdict(replace(
            TrialRow(job.name, str(job.path), subject_name(job), axis, "posturography only",
                     None),
            rate=rate, duration=sway.duration, condition=_condition(job), **_sway(sway, axis),
        ))
        for axis in ("ap", "ml")
    ]  # fmt: skip


def failed_rows(job: Any, reason: str) -> list[dict[str, Any]]:
    """Return the rows of a trial that failed: ``status`` failed and the reason."""
    check_job(job)
    require_type("reason", reason, str)
    return [
        asdict(
            TrialRow(
                job.name,
                str(job.path),
                subject_name(job),
                axis,
                "failed",
                reason,
                condition=_condition(job),
            )
        )
        for axis in ("ap", "ml")
    ]


def write_table(
    rows: list[dict[str, Any]], columns: tuple[tuple[str, str], ...] | Any, stem: Path
) -> dict[str, Path]:
    """Write ``rows`` as ``stem.parquet`` and ``stem.csv`` with the typed ``columns``.

    ``columns``: (name, Python type) pairs, or a ``pyarrow.Schema`` (fields with metadata).
    """
    if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
        raise ParameterTypeError("rows must be a list of rows (dicts)")
    require_type("stem", stem, Path)
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    if isinstance(columns, pa.Schema):
        schema = columns
    else:
        types = {"str": pa.string(), "int": pa.int64(), "float": pa.float64(), "bool": pa.bool_()}
        schema = pa.schema(
            [(name, types[kind.split(" ")[0].split("|")[0].strip()]) for name, kind in columns]
        )
    table = pa.Table.from_pylist(rows, schema=schema)
    paths = {stem.name: stem.with_suffix(".parquet"), f"{stem.name}_csv": stem.with_suffix(".csv")}
    pq.write_table(table, paths[stem.name])
    pacsv.write_csv(table, paths[f"{stem.name}_csv"])
    return paths


def _mean_sd(values: list[float]) -> dict[str, float | None]:
    finite = [v for v in values if v is not None and math.isfinite(v)]
    return {
        "mean": statistics.fmean(finite) if finite else None,
        "sd": statistics.stdev(finite) if len(finite) > 1 else None,
        "n": len(finite),
    }


def batch_summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Return the counts and measures across the trials, per subject and axis."""
    if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
        raise ParameterTypeError("rows must be a list of trial rows (dicts)")
    trials = {row["trial"] for row in rows}
    failed = {row["trial"]: row["error"] for row in rows if row["status"] == "failed"}
    subjects: dict[str, Any] = {}
    for name in sorted({row["subject"] for row in rows}):
        mine = [row for row in rows if row["subject"] == name]
        per_axis = {}
        for axis in ("ap", "ml"):
            analysed = [r for r in mine if r["axis"] == axis and r["status"] == "analysed"]
            per_axis[axis] = {
                "trials": len(analysed),
                "most_demanding": {
                    s: sum(1 for r in analysed if r["most_demanding"] == s) for s in STRATEGIES
                },
                "min_cop_margin": _mean_sd([r["min_cop_margin"] for r in analysed]),
                "min_cop_margin_normalised": _mean_sd(
                    [r["min_cop_margin_normalised"] for r in analysed]
                ),
                "min_time_to_leave_cop": _mean_sd([r["min_time_to_leave_cop"] for r in analysed]),
            }
        subjects[name] = {
            "trials": len({row["trial"] for row in mine}),
            "failed": len({row["trial"] for row in mine if row["status"] == "failed"}),
            "axes": per_axis,
        }
    return {
        "trials": len(trials),
        "analysed": len(trials) - len(failed),
        "failed": len(failed),
        "failures": [{"trial": t, "error": e} for t, e in sorted(failed.items())],
        "subjects": subjects,
    }
