"""Many measured trials analysed as one batch: local processes or a Dask cluster, resumable.

:func:`find_trials` turns files, folders (searched recursively for ``*.csv`` and ``*.c3d``)
and glob patterns into a sorted list of trials; :func:`run_trials` analyses each one as
``pushrecovery analyze`` does a single file into ``OUT/trials/<trial>/``, its rows last into
``trial.json`` (a trial with that file is finished: ``resume`` skips it), then joins them into
``OUT/trials.parquet`` (:class:`~pushrecovery.campaign.trials.rows.TrialRow`, one row per
trial and axis; a trial that could not be read or analysed is a ``failed`` row),
``OUT/events.parquet`` (:class:`~pushrecovery.campaign.trials.events.EventRow`),
``OUT/steps.parquet`` (:class:`~pushrecovery.campaign.trials.steps.StepRow`, one row per
measured step), their CSV twins and ``OUT/summary.json``. Only the project's own errors make
a ``failed`` row: anything else is a bug and stops the batch. docs/analysis.md, "Many
trials", has the details.

Over 400 lines on purpose: finding, running and joining the trials of a batch share the job,
its result and the resumable state on disk; local processes and Dask run the same jobs.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.campaign.subjects import Subject, subject_for
from pushrecovery.campaign.trials.events import EVENT_FIELDS, EventRow, trial_events
from pushrecovery.campaign.trials.rows import (
    TRIAL_FIELDS,
    TrialRow,
    failed_rows,
    sway_rows,
    trial_rows,
)
from pushrecovery.campaign.trials.steps import StepRow, step_schema, trial_steps
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError
from pushrecovery.extras import require

__all__ = [
    "TRIAL_SUFFIXES",
    "TrialJob",
    "TrialsResult",
    "find_trials",
    "run_trials",
    "trial_jobs",
]

#: File types a folder is searched for.
TRIAL_SUFFIXES = (".csv", ".c3d")
ROW_FILE = "trial.json"
TRIALS_DIR = "trials"
#: Longest trial name [bytes]: a file name, with room for a suffix the outputs add.
MAX_NAME = 200

#: Called in the worker after a trial is analysed: (analysis, its directory) -> files written.
AfterTrial = Callable[[Any, Path], dict[str, str]]


def find_trials(inputs: Sequence[str | Path]) -> tuple[list[Path], Path]:
    """Return the trial files named by ``inputs`` (sorted, each once) and their common root.

    An input is a file, a folder (every ``*.csv`` and ``*.c3d`` below it) or a glob pattern
    (``*``, ``?``, ``[``; ``**`` spans folders).

    Raises
    ------
    InvalidParameterError
        No input, an input that names nothing, or a named file that is not CSV or C3D.
    """
    if isinstance(inputs, str | os.PathLike) or not isinstance(inputs, list | tuple):
        raise ParameterTypeError(f"inputs must be a list of paths, got {type(inputs).__name__}")
    for text in inputs:
        require_type("each of inputs", text, (str, os.PathLike))
    if isinstance(inputs, str | Path) or not inputs:
        raise InvalidParameterError("give at least one trial file, folder or glob pattern")
    found: set[Path] = set()
    for item in inputs:
        text = str(item)
        if not text.strip():  # Path("") is the current folder: every trial below it
            raise InvalidParameterError("a trial path is empty: give a file, folder or pattern")
        path = Path(text)
        if path.is_dir():
            matches = [p for p in path.rglob("*") if p.suffix.lower() in TRIAL_SUFFIXES]
        elif path.exists():
            if not path.is_file():  # a FIFO or a device: read it and wait for ever
                raise InvalidParameterError(f"{text}: not a regular file (a trial is a file)")
            if path.suffix.lower() not in TRIAL_SUFFIXES:
                raise InvalidParameterError(
                    f"{text}: a trial must be a .csv or .c3d file, got {path.suffix or 'none'}"
                )
            matches = [path]
        elif glob.has_magic(text):
            matches = [
                Path(p)
                for p in glob.glob(text, recursive=True)
                if Path(p).suffix.lower() in TRIAL_SUFFIXES and Path(p).is_file()
            ]
        else:
            raise InvalidParameterError(f"{text}: not found (no such file, folder or pattern)")
        if not matches:
            raise InvalidParameterError(f"{text}: no .csv or .c3d trial found there")
        found.update(p.resolve() for p in matches if p.is_file())
    trials = sorted(found)
    root = Path(os.path.commonpath([p.parent for p in trials]))
    return trials, root


@dataclass(frozen=True)
class TrialJob:
    """One trial to analyse: its file, its name in the batch, its subject and options.

    ``reader`` are the reader's keyword options per file type (``{".csv": {...}, ".c3d":
    {...}}``), ``flags`` the body values given on the command line (None: not given),
    ``preset`` and ``params_file`` the base body, ``settings`` an
    :class:`~pushrecovery.analysis.trial.AnalysisSettings`; ``write_events``: a C3D trial's
    folder gets ``events.c3d``, a copy with the events in its EVENT group (docs/events.md).
    """

    path: Path
    name: str
    subject: Subject | None
    reader: dict[str, dict[str, Any]] = field(default_factory=dict)
    flags: dict[str, Any] = field(default_factory=dict)
    preset: str = "paper"
    params_file: str | None = None
    settings: Any = None
    write_events: bool = False


def trial_jobs(
    trials: list[Path],
    root: Path,
    subjects: tuple[Subject, ...] = (),
    **options: Any,
) -> list[TrialJob]:
    """One job per trial; its name is its path below ``root`` (``/`` as ``__``).

    A name longer than :data:`MAX_NAME` bytes (a trial many folders deep: the name is also its
    output folder's, and a file system allows 255 bytes) keeps its end after a hash of the
    whole path, so that it stays unique.
    """
    if not isinstance(trials, list) or not all(isinstance(t, Path) for t in trials):
        raise ParameterTypeError("trials must be a list of paths (find_trials)")
    require_type("root", root, Path)
    require_type("subjects", subjects, tuple)
    jobs = []
    for path in trials:
        relative = path.relative_to(root).as_posix()
        name = relative.replace("/", "__")
        if len(name.encode()) > MAX_NAME:
            digest = hashlib.sha256(name.encode()).hexdigest()[:12]
            tail = name.encode()[-(MAX_NAME - 14) :].decode(errors="ignore")
            name = f"{digest}__{tail}"
        jobs.append(TrialJob(path, name, subject_for(relative, subjects), **options))
    return jobs


@dataclass(frozen=True)
class TrialsResult:
    """A finished batch: the rows of the trials, events and steps, the summary and the files.

    ``trials``, ``events`` and ``steps`` are the rows of ``trials.parquet``,
    ``events.parquet`` and ``steps.parquet``
    (:class:`~pushrecovery.campaign.trials.rows.TrialRow`,
    :class:`~pushrecovery.campaign.trials.events.EventRow` and
    :class:`~pushrecovery.campaign.trials.steps.StepRow` as dicts).
    """

    trials: list[dict[str, Any]]
    events: list[dict[str, Any]]
    summary: dict[str, Any]
    files: dict[str, Path]
    ran: int  # trials analysed by this call (the rest were finished on disk)
    steps: list[dict[str, Any]] = field(default_factory=list)

    def trial_rows(self) -> list[TrialRow]:
        """Return the trials' rows as typed objects."""
        return [TrialRow(**row) for row in self.trials]

    def event_rows(self) -> list[EventRow]:
        """Return the events' rows as typed objects."""
        return [EventRow(**row) for row in self.events]

    def step_rows(self) -> list[StepRow]:
        """Return the steps' rows as typed objects."""
        return [StepRow(**row) for row in self.steps]

    def to_pandas(self, table: str = "trials") -> Any:
        """Return ``trials``, ``events`` or ``steps`` as a ``pandas.DataFrame`` (``tables``).

        Raises
        ------
        InvalidParameterError
            Another table name, or pandas is not installed.
        """
        import pyarrow.parquet as pq

        from pushrecovery.analysis.trial.settings import pandas_table

        if not isinstance(table, str) or table not in ("trials", "events", "steps"):
            raise InvalidParameterError(
                f"table must be 'trials', 'events' or 'steps', got {table!r:.40}"
            )
        return pandas_table(pq.read_table(self.files[table]))


def run_trial(job: TrialJob, out: Path, after: AfterTrial | None = None) -> dict[str, Any]:
    """Analyse one trial into ``out / trials / job.name``; return and store its rows."""
    from pushrecovery.analysis.output import json_safe, write_analysis
    from pushrecovery.analysis.readers import read_recording
    from pushrecovery.analysis.sway_recording import cop_only, recording_sway
    from pushrecovery.analysis.trial import analyze, body_for
    from pushrecovery.presets import load_params

    directory = out / TRIALS_DIR / job.name
    directory.mkdir(parents=True, exist_ok=True)
    try:
        recording = read_recording(job.path, **job.reader.get(job.path.suffix.lower(), {}))
        if cop_only(recording):  # a posturography export: its sway measures only
            measures, rate = recording_sway(recording, job.settings.force_cutoff)
            record = {"trials": json_safe(sway_rows(job, measures, rate)), "events": [],
                      "quality": [], "files": {}}  # fmt: skip
            _write_json(directory / ROW_FILE, record)
            return record
        given = {k: v for k, v in job.flags.items() if v is not None}
        sources = {name: "flag" for name in given}
        if job.subject is not None:
            for name, value in _subject_body(job.subject, job.preset, job.params_file).items():
                given[name], sources[name] = value, "subjects table"
        preset = load_params(job.preset, job.params_file, given)
        person = job.subject if job.subject is not None else None
        found, found_sources = body_for(
            recording,
            mass=given.get("mass"),
            com_height=given.get("com_height"),
            gravity=preset.gravity,
            height=None if person is None else person.height,
            sex=None if person is None else person.sex,
            keep=set(given),
        )
        for name in ("mass", "com_height"):
            if sources.get(name) == "subjects table":
                found_sources[name] = "subjects table"
        sources.update({k: v for k, v in found_sources.items() if k not in sources})
        params = load_params(job.preset, job.params_file, {**given, **found})
        analysis = analyze(recording, params, job.settings, sources=found_sources)
        files = {name: str(path) for name, path in write_analysis(analysis, directory).items()}
        if job.write_events and job.path.suffix.lower() == ".c3d":
            from pushrecovery.analysis.c3d import write_events
            from pushrecovery.analysis.trial.events import c3d_events

            events_c3d = directory / "events.c3d"
            write_events(job.path, events_c3d, c3d_events(analysis.summary.events))
            files["events_c3d"] = str(events_c3d)
        if after is not None:
            files.update(after(analysis, directory))
        quality = [{"trial": job.name, **row} for row in analysis.summary.checks.quality_rows()]
        record = {
            "trials": json_safe(trial_rows(job, analysis.summary, params, sources)),
            "events": json_safe(trial_events(job, analysis.summary)),
            "steps": json_safe([asdict(row) for row in trial_steps(job, analysis.summary)]),
            "quality": json_safe(quality),
            "files": files,
        }
    except (PushRecoveryError, OSError) as exc:  # OSError: the trial's files, not the library
        reason = str(exc)
        if isinstance(exc, OSError):
            reason = f"{job.path}: {exc.strerror or exc}"
        record = {"trials": failed_rows(job, reason), "events": [], "quality": [], "files": {}}
    _write_json(directory / ROW_FILE, record)
    return record


def _subject_body(subject: Subject, preset: str, params_file: str | None) -> dict[str, Any]:
    """Return a subjects-table row's body values; a foot length scales the preset's foot."""
    from pushrecovery.presets import load_params

    values: dict[str, Any] = dict(subject.body())
    if subject.foot_length is not None:
        base = load_params(preset, params_file)
        scale = subject.foot_length / (base.toe - base.heel)
        values["heel"], values["toe"] = base.heel * scale, base.toe * scale
    return values


def _write_json(path: Path, data: Any) -> None:
    partial = path.with_name(f".{path.name}.partial")
    partial.write_text(json.dumps(data, indent=1, allow_nan=False) + "\n")
    os.replace(partial, path)


def run_trials(
    jobs: list[TrialJob],
    out: str | Path,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    after: AfterTrial | None = None,
    progress: Callable[[int], None] | None = None,
) -> TrialsResult:
    """Analyse every job (each into ``out/trials/<trial>/``) and join the tables.

    Parameters
    ----------
    jobs : list of TrialJob
        The trials (:func:`trial_jobs`).
    out : path
        Output folder (created).
    workers : int
        Local worker processes, >= 1 (1: in this process), when no ``scheduler``.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://HOST:PORT``) to run the trials on instead.
    resume : bool
        Keep the trials already finished in ``out`` (their ``trial.json``).
    after : callable, optional
        Run in the worker after each analysed trial (the CLI's plots).
    progress : callable, optional
        Called with the number of trials finished, as they finish.

    Raises
    ------
    InvalidParameterError
        ``workers`` < 1, no jobs, or two jobs with the same name.
    """
    if not isinstance(jobs, list) or not all(isinstance(j, TrialJob) for j in jobs):
        raise ParameterTypeError("jobs must be a list of TrialJob (trial_jobs)")
    require_type("out", out, (str, os.PathLike))
    if not isinstance(workers, int) or isinstance(workers, bool) or workers < 1:
        raise InvalidParameterError(f"workers must be an int >= 1, got {workers!r}")
    if not jobs:
        raise InvalidParameterError("no trials to analyse")
    require("analysis", "pyarrow")
    names = [job.name for job in jobs]
    if len(set(names)) != len(names):
        raise InvalidParameterError("two trials have the same name in the batch")
    out = Path(out)
    (out / TRIALS_DIR).mkdir(parents=True, exist_ok=True)
    done = {
        job.name for job in jobs if resume and (out / TRIALS_DIR / job.name / ROW_FILE).exists()
    }
    todo = [job for job in jobs if job.name not in done]
    if scheduler is not None:
        records = _on_cluster(todo, out, scheduler, after)
    elif workers == 1:
        records = (run_trial(job, out, after) for job in todo)
    else:
        records = _on_processes(todo, out, workers, after)
    for _ in records:
        if progress is not None:
            progress(1)
    return _join(jobs, out, ran=len(todo))


def _on_processes(
    jobs: list[TrialJob], out: Path, workers: int, after: AfterTrial | None
) -> Iterator[dict[str, Any]]:
    from pushrecovery.campaign.isolation import new_pool, quiet_worker_start

    pool = new_pool(workers)
    try:
        with quiet_worker_start():
            pending: set[Future[dict[str, Any]]] = {
                pool.submit(run_trial, job, out, after) for job in jobs
            }
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in finished:
                yield future.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _on_cluster(
    jobs: list[TrialJob], out: Path, scheduler: str, after: AfterTrial | None
) -> Iterator[dict[str, Any]]:
    from distributed import as_completed

    from pushrecovery.campaign.cluster import connect

    client = connect(scheduler)
    try:
        futures = [client.submit(run_trial, job, out, after, pure=False) for job in jobs]
        try:
            for future in as_completed(futures, loop=client.loop):
                yield future.result()
        finally:
            client.cancel(futures)
    finally:
        client.close()


def _join(jobs: list[TrialJob], out: Path, ran: int) -> TrialsResult:
    """Read every trial's rows (in job order) and write the batch's tables and summary."""
    from pushrecovery.analysis.trial.checks import QUALITY_FIELDS
    from pushrecovery.campaign.trials.rows import batch_summary, write_table

    trials: list[dict[str, Any]] = []
    events: list[dict[str, Any]] = []
    steps: list[dict[str, Any]] = []
    quality: list[dict[str, Any]] = []
    for job in jobs:
        record = json.loads((out / TRIALS_DIR / job.name / ROW_FILE).read_text())
        trials += record["trials"]
        events += record["events"]
        steps += record.get("steps", [])  # trials finished before the table existed
        quality += record.get("quality", [])  # trials finished before the table existed
    files = {
        **write_table(trials, TRIAL_FIELDS, out / "trials"),
        **write_table(events, EVENT_FIELDS, out / "events"),
        **write_table(steps, step_schema(), out / "steps"),
        **write_table(quality, (("trial", "str"), *QUALITY_FIELDS), out / "quality"),
    }
    summary = batch_summary(trials)
    _write_json(out / "summary.json", summary)
    files["summary"] = out / "summary.json"
    return TrialsResult(trials, events, summary, files, ran, steps)
