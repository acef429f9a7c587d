"""Run a campaign's batches on this process, local worker processes or a Dask cluster.

The campaign's directory holds ``spec.json`` (written first), each finished batch as
``batches/batch-NNNNNN.parquet`` (written under a temporary name, then renamed: a file there is
always complete), then ``pushes.parquet`` (every push in index order) and ``summary.json``. An
interrupted campaign keeps every finished batch and ``resume`` runs only the missing ones; each
push depends on the spec and its index only, so the result is the same whatever the number of
workers and the order batches finish in (docs/campaigns.md, "Files", "Execution").
"""

from __future__ import annotations

import functools
import json
import os
import re
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.campaign.arrow import table_of_rows
from pushrecovery.campaign.cluster import connect, on_cluster
from pushrecovery.campaign.isolation import (
    batch_deadline,
    new_pool,
    quarantine,
    quiet_worker_start,
)
from pushrecovery.campaign.pushes import run_batch
from pushrecovery.campaign.rows import row_schema
from pushrecovery.campaign.spec import CampaignError, CampaignSpec
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.extras import require_extra

__all__ = ["CampaignError", "CampaignResult", "missing_batches", "read_spec", "run_campaign"]

SPEC_FILE = "spec.json"
PUSHES_FILE = "pushes.parquet"
SUMMARY_FILE = "summary.json"
BATCH_DIR = "batches"
_BATCH = re.compile(r"batch-(\d{6})\.parquet")


@dataclass(frozen=True)
class CampaignResult:
    """A finished campaign: its spec, the summary and files; the pushes read on demand."""

    spec: CampaignSpec
    summary: dict[str, Any]
    directory: Path
    ran: int  # batches simulated by this call (the rest were on disk)

    @property
    def pushes_file(self) -> Path:
        """The Parquet file of every push."""
        return self.directory / PUSHES_FILE

    @functools.cached_property
    def table(self) -> Any:
        """Every push (a ``pyarrow.Table``), read from :attr:`pushes_file` on first use.

        The whole table in memory: for campaigns too large for that, query the Parquet files
        lazily instead (``pyarrow.dataset``, DuckDB, polars; docs/campaigns.md, "At scale").
        """
        return _read(self.pushes_file)


def schema(spec: CampaignSpec) -> Any:
    """Arrow schema of the pushes of ``spec``: its family's (:func:`~.rows.row_schema`)."""
    return row_schema("3d" if spec.is_3d else "planar", tuple(spec.sweeps))


def read_spec(directory: Path) -> CampaignSpec:
    """Return the spec of the campaign in ``directory``."""
    require_type("directory", directory, (str, os.PathLike))
    path = Path(directory) / SPEC_FILE
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise CampaignError(f"no campaign in {directory} (no {SPEC_FILE})") from None
    except (OSError, ValueError) as exc:
        raise CampaignError(f"cannot read {path}: {exc}") from None
    return CampaignSpec.from_dict(data)


def missing_batches(spec: CampaignSpec, directory: Path) -> list[int]:
    """Batch numbers of ``spec`` with no finished file in ``directory``."""
    require_type("spec", spec, CampaignSpec)
    require_type("directory", directory, (str, os.PathLike))
    done = set()
    folder = Path(directory) / BATCH_DIR
    if folder.is_dir():
        for path in folder.iterdir():
            match = _BATCH.fullmatch(path.name)
            if match:
                done.add(int(match.group(1)))
    return [b for b in spec.batch_indices() if b not in done]


def _batch_path(directory: Path, batch: int) -> Path:
    return directory / BATCH_DIR / f"batch-{batch:06d}.parquet"


def _write_batch(spec: CampaignSpec, directory: Path, batch: int, rows: list[dict]) -> None:
    import pyarrow.parquet as pq

    table = table_of_rows(rows, schema(spec))
    path = _batch_path(directory, batch)
    partial = path.with_suffix(".partial")
    pq.write_table(table, partial)
    os.replace(partial, path)  # atomic: a batch file is complete or absent


def _prepare(spec: CampaignSpec, directory: Path, resume: bool) -> None:
    """Write the spec into a new directory, or check it against the stored one."""
    stored = directory / SPEC_FILE
    if stored.exists():
        if not resume:
            raise CampaignError(
                f"{directory} already holds a campaign; pass --resume to complete it or "
                "choose another --out"
            )
        previous = read_spec(directory).to_dict()
        if previous != spec.to_dict():
            changed = sorted(k for k in previous if previous[k] != spec.to_dict().get(k))
            raise CampaignError(
                f"--resume: the campaign in {directory} differs in {', '.join(changed)}"
            )
        return
    (directory / BATCH_DIR).mkdir(parents=True, exist_ok=True)
    partial = stored.with_suffix(".partial")
    partial.write_text(json.dumps(spec.to_dict(), indent=2) + "\n")
    os.replace(partial, stored)


def _cores() -> int:
    """Cores this process may run on (its CPU affinity where the OS has one)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def _serial(spec: CampaignSpec, batches: list[int]) -> Iterator[tuple[int, list[dict]]]:
    for batch in batches:
        yield run_batch(spec, batch)


def _processes(
    spec: CampaignSpec, batches: list[int], workers: int
) -> Iterator[tuple[int, list[dict]]]:
    """Run ``batches`` on a pool of ``workers`` processes (docs: campaign/isolation.py).

    If a worker dies or hangs, the batches it took down with the pool go on in quarantine:
    the push that killed it becomes an ``error`` row, every other push is simulated. A worker
    ends itself when a push hangs (its watchdog); should even that thread be stuck (a C call
    holding the GIL), no batch finishing within :func:`batch_deadline` stops the pool here.
    """
    from concurrent.futures.process import BrokenProcessPool

    pool = new_pool(workers)
    failed: list[int] = []
    try:
        # Ctrl-C reaches the whole process group: the workers ignore it (inherited from the
        # fork server), the parent stops them and says so once.
        with quiet_worker_start():
            pending: dict[Future[tuple[int, list[dict]]], int] = {
                pool.submit(run_batch, spec, batch): batch for batch in batches
            }
        while pending and not failed:
            done, _ = wait(pending, timeout=batch_deadline(spec), return_when=FIRST_COMPLETED)
            if not done:
                _stop_workers(pool)
                break
            for future in done:
                batch = pending.pop(future)
                try:
                    result = future.result()
                except BrokenProcessPool:
                    failed.append(batch)
                    continue
                yield result
        failed += pending.values()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    if failed:
        yield from quarantine(spec, sorted(failed))


def _stop_workers(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's processes (hung: they would never return their batches)."""
    # concurrent.futures has no public way to stop a busy worker before Python 3.14's
    # terminate_workers(); its process table is the one handle there is.
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.kill()


def run_campaign(
    spec: CampaignSpec,
    directory: Path | str,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    max_batches: int | None = None,
    progress: Callable[[int], None] | None = None,
    isolated: bool = True,
) -> CampaignResult | None:
    """Run ``spec`` into ``directory``; return the result, or None if stopped by ``max_batches``.

    Parameters
    ----------
    spec : CampaignSpec
        The campaign.
    directory : path
        Where its files go (``spec.json``, ``batches/``, ``pushes.parquet``, ``summary.json``);
        created if missing.
    workers : int, optional
        Local worker processes; default all cores. Ignored with ``scheduler``.
    scheduler : str, optional
        Address of a running ``dask.distributed`` scheduler to send the batches to.
    resume : bool
        Complete the campaign already in ``directory`` (same spec), running only the batches
        that have no file yet.
    max_batches : int, optional
        Run at most this many batches now (the rest stays missing, for a later ``resume``).
    progress : callable, optional
        Called with the number of pushes of each batch as it finishes (a progress bar's
        ``update``); first with the pushes already on disk.
    isolated : bool
        Run the pushes in worker processes even with ``workers=1`` (default), so that a push
        that crashes or hangs costs one ``error`` row (:mod:`~pushrecovery.campaign.isolation`).
        ``False`` with one worker: in this process (a debugger sees the pushes; a crash ends
        the campaign, a hang is bounded only by ``push_timeout`` at the simulation's ticks).

    Raises
    ------
    CampaignError
        A directory holding another campaign, an unreachable scheduler, a dead worker.
    MissingExtraError
        Without the ``campaign`` extra, or the ``sim`` extra for a MuJoCo campaign.
    """
    require_type("spec", spec, CampaignSpec)
    require_type("directory", directory, (str, os.PathLike))
    if progress is not None and not callable(progress):
        raise ParameterTypeError(f"progress must be callable, got {type(progress).__name__}")
    require_extra("campaign")
    if spec.backend == "mujoco":
        require_extra("sim", "a MuJoCo campaign")
    directory = Path(directory)
    if workers is not None and workers < 1:
        raise InvalidParameterError(f"workers must be >= 1, got {workers}")
    if max_batches is not None and max_batches < 0:
        raise InvalidParameterError(f"max_batches must be >= 0, got {max_batches}")
    # Connect first: an unreachable scheduler leaves no directory behind.
    client = connect(scheduler) if scheduler is not None else None
    try:
        return _run(spec, directory, workers, client, resume, max_batches, progress, isolated)
    finally:
        if client is not None:
            client.close()


def _run(
    spec: CampaignSpec,
    directory: Path,
    workers: int | None,
    client: Any,
    resume: bool,
    max_batches: int | None,
    progress: Callable[[int], None] | None,
    isolated: bool,
) -> CampaignResult | None:
    _prepare(spec, directory, resume)
    todo = missing_batches(spec, directory)
    if progress is not None:
        done_pushes = spec.size - sum(min(spec.batch, spec.size - b * spec.batch) for b in todo)
        if done_pushes:
            progress(done_pushes)
    stopped = max_batches is not None and max_batches < len(todo)
    if stopped:
        todo = todo[:max_batches]
    if client is not None:
        results = on_cluster(spec, todo, client)
    elif not todo:
        results = iter(())
    elif (workers or _cores()) == 1 and not isolated:
        results = _serial(spec, todo)
    else:
        results = _processes(spec, todo, min(workers or _cores(), len(todo)))
    for batch, rows in results:
        _write_batch(spec, directory, batch, rows)
        if progress is not None:
            progress(len(rows))
    if stopped:
        return None
    return finish(spec, directory, ran=len(todo))


def finish(spec: CampaignSpec, directory: Path, ran: int = 0) -> CampaignResult:
    """Join the batch files into ``pushes.parquet`` and write ``summary.json``.

    One batch at a time: each is appended to the file as its row group(s) and added to the
    summary's counts, so the memory is one batch's whatever the campaign's size.
    """
    import pyarrow.parquet as pq

    from pushrecovery.campaign.summary import SummaryTally

    missing = missing_batches(spec, directory)
    if missing:
        raise CampaignError(f"{len(missing)} batches missing in {directory}; rerun with --resume")
    full = schema(spec)
    tally = SummaryTally(spec)
    partial = directory / (PUSHES_FILE + ".partial")
    with pq.ParquetWriter(partial, full) as writer:
        for batch in spec.batch_indices():
            part = _conform(_read(_batch_path(directory, batch)), full)
            writer.write_table(part)
            tally.add(part)
        if not spec.batches:
            writer.write_table(full.empty_table())
    os.replace(partial, directory / PUSHES_FILE)
    summary = tally.result()
    partial = directory / (SUMMARY_FILE + ".partial")
    partial.write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n")
    os.replace(partial, directory / SUMMARY_FILE)
    return CampaignResult(spec, summary, directory, ran)


def _read(path: Path) -> Any:
    """Return the table of the Parquet file ``path`` (not through ``pyarrow.dataset``)."""
    import pyarrow.parquet as pq

    # pq.read_table goes through pyarrow.dataset, whose import imports pandas (0.4 s).
    with pq.ParquetFile(path) as file:
        return file.read()


def _conform(table: Any, full: Any) -> Any:
    """Return a batch's table with the campaign's columns in order.

    Batches written before a column was added (a resumed old campaign) get it as nulls.
    """
    import pyarrow as pa

    if table.schema.equals(full):
        return table
    columns = [
        table.column(field.name).cast(field.type)
        if field.name in table.column_names
        else pa.nulls(table.num_rows, field.type)
        for field in full
    ]
    return pa.Table.from_arrays(columns, schema=full)
