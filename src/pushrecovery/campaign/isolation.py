"""Worker processes of a local campaign, and what happens when one dies.

A push that kills its worker process (a segmentation fault in a physics engine, the memory
killer) breaks the whole process pool, and with it every batch in flight. The campaign then
goes on in quarantine (:func:`quarantine`): each unfinished batch in a fresh one-worker pool;
a batch that breaks its pool again is run push by push, each in a process of its own; the push
that kills its process is recorded as an ``error`` row (:func:`~pushrecovery.campaign.pushes.
error_row`), and every other push of the campaign is simulated as usual.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from pushrecovery.campaign.pushes import error_row, run_batch, run_push
from pushrecovery.campaign.spec import CampaignSpec

__all__ = ["new_pool", "quarantine"]

BatchRunner = Callable[[CampaignSpec, int], tuple[int, list[dict[str, Any]]]]
PushRunner = Callable[..., dict[str, Any]]


def _ignore_interrupts() -> None:
    """Worker initializer: SIGINT is the parent's to handle (no traceback from each worker)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def interrupts_deferred() -> Iterator[None]:
    """Hold SIGINT back while worker processes start; main thread only.

    The processes started meanwhile inherit the blocked signal (a Ctrl-C to the process group
    never reaches them before their initializer ignores it), and this process receives a
    Ctrl-C that came meanwhile as soon as the block ends: it is deferred, not lost (ignoring
    it instead lost a Ctrl-C pressed while the pool started). Where the OS has no signal
    masks, SIGINT is ignored meanwhile.
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
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def new_pool(workers: int) -> ProcessPoolExecutor:
    """Return a pool of ``workers`` processes that ignore Ctrl-C (the parent stops them).

    Not fork: the parent may already run OpenMP threads (numba's parallel surfaces), which a
    forked child cannot use.
    """
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context(method),
        initializer=_ignore_interrupts,
    )


def _alone(function: Callable[..., Any], *args: Any) -> tuple[bool, Any]:
    """Run ``function(*args)`` in a one-worker pool; (False, None) if the worker died."""
    pool = new_pool(1)
    try:
        with interrupts_deferred():
            future = pool.submit(function, *args)
        try:
            return True, future.result()
        except BrokenProcessPool:
            return False, None
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def quarantine(
    spec: CampaignSpec,
    batches: list[int],
    *,
    batch_runner: BatchRunner = run_batch,
    push_runner: PushRunner = run_push,
) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    """Run ``batches`` one at a time, each in a fresh worker; isolate a push that kills it.

    Yields each batch with its rows in push order, as the pool does. ``batch_runner`` and
    ``push_runner`` are :func:`run_batch` and :func:`run_push` (replaceable for tests).
    """
    for batch in batches:
        ok, result = _alone(batch_runner, spec, batch)
        if ok:
            yield result
            continue
        rows = []
        for push in spec.pushes(batch):
            ok, row = _alone(push_runner, spec, push)
            rows.append(row if ok else error_row(spec, push, "its worker process died"))
        yield batch, rows
