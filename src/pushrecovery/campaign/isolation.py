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
import signal
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from typing import Any

from pushrecovery.campaign import watchdog
from pushrecovery.campaign.pushes import error_row, run_batch, run_push
from pushrecovery.campaign.spec import CampaignSpec

__all__ = ["batch_deadline", "interrupts_deferred", "new_pool", "quarantine"]

BatchRunner = Callable[[CampaignSpec, int], tuple[int, list[dict[str, Any]]]]
PushRunner = Callable[..., dict[str, Any]]


def _ignore_interrupts() -> None:
    """Worker initializer: SIGINT is the parent's to handle (no traceback from each worker)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def interrupts_deferred() -> Iterator[None]:
    """Hold SIGINT back while worker processes start; main thread only.

    The processes started meanwhile inherit the main thread's blocked signal (a Ctrl-C to the
    process group never reaches them before their initializer ignores it). This process gets a
    Ctrl-C that came meanwhile once the window closes: it is deferred, not lost (ignoring it
    instead lost a Ctrl-C pressed while the pool started). A signal the OS hands to another
    thread (numpy's BLAS threads do not block it) runs a handler that only notes it. Where the
    OS has no signal masks, SIGINT is ignored meanwhile.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - not POSIX
        ignored = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, ignored)
        return
    noted: list[int] = []
    handler = signal.signal(signal.SIGINT, lambda number, frame: noted.append(number))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)  # one blocked here arrives now
    if noted:
        raise KeyboardInterrupt


def _start_worker() -> None:
    """Worker initializer: Ctrl-C is the parent's; a hung push kills this process (watchdog)."""
    _ignore_interrupts()
    watchdog.start()


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
    return ProcessPoolExecutor(
        max_workers=workers, mp_context=_context(), initializer=_start_worker
    )


def batch_deadline(spec: CampaignSpec) -> float:
    """Wall time after which a batch's worker counts as hung [s]: every push at its limit."""
    return spec.batch * watchdog.hung_after(spec.push_timeout) + watchdog.GRACE


def _child(connection: Any, function: Callable[..., Any], args: tuple[Any, ...]) -> None:
    _start_worker()
    connection.send(function(*args))
    connection.close()


def _alone(function: Callable[..., Any], args: tuple[Any, ...], timeout: float) -> tuple[str, Any]:
    """Run ``function(*args)`` in a process of its own.

    Returns ("ok", result), ("died", None) if the process died, or ("hung", None) if it gave
    no answer within ``timeout`` seconds (it is then killed).
    """
    receiver, sender = _context().Pipe(duplex=False)
    with interrupts_deferred():
        process = _context().Process(target=_child, args=(sender, function, args), daemon=True)
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
    :func:`run_push` (replaceable for tests).
    """
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
