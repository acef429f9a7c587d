"""Worker processes of a local campaign, and what happens when one dies or hangs.

A push that kills its worker process (a segmentation fault in a physics engine, the memory
killer), or that gives no answer for its ``push_timeout`` plus the watchdog's grace (its
worker then ends itself, :mod:`~pushrecovery.campaign.watchdog`), breaks the whole process
pool, and with it every batch in flight. The campaign then goes on in quarantine
(:func:`quarantine`): each unfinished batch in a process of its own; a batch that fails again
is run push by push, each in a process of its own; the push that kills or hangs its process is
recorded as an ``error`` row (:func:`~pushrecovery.campaign.pushes.error_row`), and every
other push of the campaign is simulated as usual.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any

from pushrecovery.arguments import require_type, whole_number
from pushrecovery.campaign import watchdog
from pushrecovery.campaign.pushes import error_row, run_batch, run_push
from pushrecovery.campaign.spec import CampaignSpec
from pushrecovery.errors import ParameterTypeError

__all__ = ["batch_deadline", "check_batches", "new_pool", "quarantine", "quiet_worker_start"]

BatchRunner = Callable[[CampaignSpec, int], tuple[int, list[dict[str, Any]]]]
PushRunner = Callable[..., dict[str, Any]]


def _ignore_interrupts() -> None:
    """Worker initializer: SIGINT is the parent's to handle (no traceback from each worker)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


_FORK_SERVER = {"started": False}


def _start_fork_server() -> None:
    """Start this process's fork server with SIGINT ignored (once; main thread).

    Every worker is forked from it and inherits the ignored SIGINT, so a Ctrl-C to the process
    group never reaches a worker before its initializer, and the parent never ignores one.
    """
    from multiprocessing import forkserver

    if _FORK_SERVER["started"]:
        return
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            forkserver.ensure_running()
        finally:
            signal.signal(signal.SIGINT, previous)
    else:  # pragma: no cover - a library caller's thread: the workers' initializer only
        forkserver.ensure_running()
    _FORK_SERVER["started"] = True


@contextlib.contextmanager
def quiet_worker_start() -> Iterator[None]:
    """Start worker processes inside this window: none sees a Ctrl-C before its initializer.

    With the fork server (POSIX) the workers inherit its ignored SIGINT and this process keeps
    its own: a Ctrl-C meanwhile interrupts it at once (ignoring SIGINT here while a pool
    started lost such a Ctrl-C, and the campaign ran to its end). Without one (spawn), SIGINT
    is ignored here while the window lasts (main thread only).
    """
    if "forkserver" in multiprocessing.get_all_start_methods():
        _start_fork_server()
        yield
        return
    if threading.current_thread() is not threading.main_thread():  # pragma: no cover
        yield
        return
    ignored = signal.signal(signal.SIGINT, signal.SIG_IGN)  # pragma: no cover - not POSIX
    try:  # pragma: no cover
        yield
    finally:  # pragma: no cover
        signal.signal(signal.SIGINT, ignored)


def _start_worker(campaign: int | None = None) -> None:
    """Worker initializer: Ctrl-C is the parent's.

    A hung push, or the end of the ``campaign`` process, ends this one
    (:mod:`~pushrecovery.campaign.watchdog`).
    """
    _ignore_interrupts()
    watchdog.start(campaign)


def _context() -> multiprocessing.context.ForkServerContext | multiprocessing.context.SpawnContext:
    """Forkserver (or spawn), not fork.

    The parent may already run OpenMP threads (numba's parallel surfaces), which a forked child
    cannot use.
    """
    if "forkserver" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("forkserver")
    return multiprocessing.get_context("spawn")


def new_pool(workers: int) -> ProcessPoolExecutor:
    """Return a pool of ``workers`` processes.

    They ignore Ctrl-C (the parent stops them) and end themselves when a push hangs
    (:mod:`~pushrecovery.campaign.watchdog`).
    """
    workers = whole_number("workers", workers, 1, 1024)
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=_context(),
        initializer=_start_worker,
        initargs=(os.getpid(),),
    )


def batch_deadline(spec: CampaignSpec) -> float:
    """Wall time after which a batch's worker counts as hung [s]: every push at its limit."""
    require_type("spec", spec, CampaignSpec)
    return spec.batch * watchdog.hung_after(spec.push_timeout) + watchdog.GRACE


def _child(
    connection: Any, function: Callable[..., Any], args: tuple[Any, ...], campaign: int
) -> None:
    _start_worker(campaign)
    connection.send(function(*args))
    connection.close()


def _alone(function: Callable[..., Any], args: tuple[Any, ...], timeout: float) -> tuple[str, Any]:
    """Run ``function(*args)`` in a process of its own.

    Returns ("ok", result), ("died", None) if the process died, or ("hung", None) if it gave
    no answer within ``timeout`` seconds (it is then killed).
    """
    receiver, sender = _context().Pipe(duplex=False)
    with quiet_worker_start():
        process = _context().Process(
            target=_child, args=(sender, function, args, os.getpid()), daemon=True
        )
        process.start()
    sender.close()  # only the child writes: a dead child then reads as end-of-file
    try:
        if not receiver.poll(timeout):
            return "hung", None
        try:
            return "ok", receiver.recv()
        except EOFError:  # the child ended without an answer: crashed, or its watchdog
            process.join()
            return ("hung" if process.exitcode == watchdog.HUNG_EXIT else "died"), None
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join()


def _reason(status: str, spec: CampaignSpec) -> str:
    if status == "hung":
        limit = watchdog.hung_after(spec.push_timeout)
        return f"it gave no answer for {limit:g} s of wall time; its worker process was stopped"
    return "its worker process died"


def check_batches(spec: CampaignSpec, batches: object, *runners: object) -> list[int]:
    """Return ``batches`` as batch numbers of ``spec``, its runners checked callable, or raise.

    Called where a run of batches starts, before any result is asked for: the runs are
    generators, which would otherwise meet a bad argument only at their first result.
    """
    require_type("spec", spec, CampaignSpec)
    if isinstance(batches, str | bytes) or not isinstance(batches, Sequence):
        raise ParameterTypeError(f"batches must be a list of batch numbers, got {batches!r:.40}")
    found = [whole_number("a batch number", b, 0, spec.batches - 1) for b in batches]
    if not all(callable(runner) for runner in runners):
        raise ParameterTypeError("batch_runner and push_runner must be callable")
    return found


def quarantine(
    spec: CampaignSpec,
    batches: list[int],
    *,
    batch_runner: BatchRunner = run_batch,
    push_runner: PushRunner = run_push,
) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    """Run ``batches`` one at a time, each in a fresh worker; isolate a push that kills it.

    Yields each batch with its rows in push order, as the pool does. A push that kills its
    process, or that gives no answer within its ``push_timeout`` plus the watchdog's grace, is
    an ``error`` row. ``batch_runner`` and ``push_runner`` are :func:`run_batch` and
    :func:`run_push` (replaceable for tests). The arguments are checked at the call
    (:func:`check_batches`).
    """
    batches = check_batches(spec, batches, batch_runner, push_runner)
    return _quarantine(spec, batches, batch_runner, push_runner)


def _quarantine(
    spec: CampaignSpec, batches: list[int], batch_runner: BatchRunner, push_runner: PushRunner
) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    for batch in batches:
        status, result = _alone(batch_runner, (spec, batch), batch_deadline(spec))
        if status == "ok":
            yield result
            continue
        rows = []
        # The child's watchdog ends a hung push first; the wait is the backstop.
        limit = watchdog.hung_after(spec.push_timeout) + watchdog.GRACE
        for push in spec.pushes(batch):
            status, row = _alone(_watched_push, (push_runner, spec, push), limit)
            rows.append(row if status == "ok" else error_row(spec, push, _reason(status, spec)))
        yield batch, rows


def _watched_push(runner: PushRunner, spec: CampaignSpec, push: Any) -> dict[str, Any]:
    watchdog.arm(spec.push_timeout)
    try:
        return runner(spec, push)
    finally:
        watchdog.disarm()
