"""The rows of a batch of measured trials: one per trial and axis, one per event; the summary.

Columns of ``trials.parquet`` (:class:`TrialRow`; SI units, axes ap and ml as in
:mod:`pushrecovery.analysis.recording`) and of ``events.parquet`` (:class:`EventRow`). These
tables are contracts: columns are added, never renamed or dropped.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

from pushrecovery.params import BodyParams

__all__ = [
    "EVENT_FIELDS",
    "TRIAL_FIELDS",
    "EventRow",
    "TrialRow",
    "batch_summary",
    "failed_rows",
    "trial_events",
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
        ``analysed``, or ``failed`` (``error`` says why; the measures are then null).
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


@dataclass(frozen=True, slots=True)
class EventRow:
    """One event of a trial.

    Attributes
    ----------
    trial, subject, axis : str
        The trial, its subject and the axis of the event.
    kind : str
        ``step needed``: a run of frames whose capture point needed a step.
    time, end : float
        Start and end of the event [s].
    step_length, step_length_min, step_length_max : float
        The recommended step (Eq. 21, median over the event) and its admissible range [m].
    capture_point : float
        Capture point at the start [m], relative to the lab origin along the axis.
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


#: Arrow types of the columns, in order.
TRIAL_FIELDS: tuple[tuple[str, str], ...] = tuple((f.name, str(f.type)) for f in fields(TrialRow))
EVENT_FIELDS: tuple[tuple[str, str], ...] = tuple((f.name, str(f.type)) for f in fields(EventRow))


def _subject(job: Any) -> str:
    return "" if job.subject is None else job.subject.subject


def trial_rows(
    job: Any, summary: dict[str, Any], params: BodyParams, sources: dict[str, str]
) -> list[dict[str, Any]]:
    """Return the rows of an analysed trial, from its summary (``summary.json``)."""
    body = summary["body"]
    rows = []
    for axis, data in summary["directions"].items():
        margin = data["min_margin"]["cop"]["value"]
        times = data["time_in_strategy"]
        row = TrialRow(
            trial=job.name,
            path=str(job.path),
            subject=_subject(job),
            axis=axis,
            status="analysed",
            error=None,
            frames=summary["frames"],
            valid_frames=summary["valid_frames"],
            excluded_frames=summary["excluded_frames"],
            interpolated_frames=summary["interpolated_frames"],
            rate=summary["rate"],
            duration=summary["duration"],
            mass=body["mass"],
            mass_source=body["mass_source"],
            com_height=body["com_height"],
            com_height_source=body["com_height_source"],
            leg_length=params.leg_length,
            leg_length_source=sources.get("leg_length", "preset"),
            com_source=summary["com_source"],
            support_source=summary["support_source"],
            heel=data["foot"]["heel"],
            toe=data["foot"]["toe"],
            most_demanding=data["most_demanding"],
            time_ankle=times["ankle"],
            time_hip=times["hip"],
            time_step=times["step"],
            time_fall=times["fall"],
            min_cop_margin=margin,
            min_cop_margin_time=data["min_margin"]["cop"]["time"],
            min_cop_margin_normalised=None if margin is None else margin / params.leg_length,
            min_cmp_margin=data["min_margin"]["cmp"]["value"],
            min_cmp_margin_time=data["min_margin"]["cmp"]["time"],
            min_time_to_leave_cop=data["min_time_to_leave"]["cop"]["value"],
            capture_point_min=data["capture_point_range"][0],
            capture_point_max=data["capture_point_range"][1],
            step_events=sum(1 for e in summary["step_events"] if e["axis"] == axis),
        )
        rows.append(asdict(row))
    return rows


def failed_rows(job: Any, reason: str) -> list[dict[str, Any]]:
    """Return the rows of a trial that failed: ``status`` failed and the reason."""
    return [
        asdict(TrialRow(job.name, str(job.path), _subject(job), axis, "failed", reason))
        for axis in ("ap", "ml")
    ]


def trial_events(job: Any, summary: dict[str, Any]) -> list[dict[str, Any]]:
    """Return the events of an analysed trial, in time order."""
    return [
        asdict(
            EventRow(
                trial=job.name,
                subject=_subject(job),
                axis=event["axis"],
                kind="step needed",
                time=event["time"],
                end=event["end"],
                step_length=event["step_length"],
                step_length_min=event["step_length_range"][0],
                step_length_max=event["step_length_range"][1],
                capture_point=event["capture_point"],
            )
        )
        for event in summary["step_events"]
    ]


def write_table(
    rows: list[dict[str, Any]], columns: tuple[tuple[str, str], ...], stem: Path
) -> dict[str, Path]:
    """Write ``rows`` as ``stem.parquet`` and ``stem.csv`` with the typed ``columns``."""
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    types = {"str": pa.string(), "int": pa.int64(), "float": pa.float64()}
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
