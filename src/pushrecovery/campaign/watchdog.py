"""A worker's watchdog: a push that stops answering takes its worker process down with it.

:func:`~pushrecovery.sim.simulate.simulate` stops a push that runs past its wall-time limit
at its next control tick. Code that never returns to the loop (a physics engine stuck in C)
is not stopped that way: in a local worker process (:func:`start`, the pool's initializer) a
thread checks the armed deadline every :data:`PERIOD` seconds and ends its own process with
exit status :data:`HUNG_EXIT` when it has passed. The pool then breaks, and the quarantine
(:mod:`~pushrecovery.campaign.isolation`) finds the push and records it as an ``error`` row.
Outside a worker (no :func:`start`), arming only sets a number.
"""

from __future__ import annotations

import math
import os
import threading
import time

from pushrecovery.arguments import positive_float

__all__ = ["GRACE", "HUNG_EXIT", "ORPHAN_EXIT", "PERIOD", "arm", "disarm", "hung_after", "start"]

#: Longest time a push gets beyond its wall-time limit before its worker counts as hung [s]:
#: the simulation's own check comes first, at its next control tick.
GRACE = 30.0
#: How often the thread looks [s].
PERIOD = 0.5
#: Exit status of a process its watchdog ended (as timeout(1)'s), and of a worker whose
#: campaign is gone.
HUNG_EXIT = 124
ORPHAN_EXIT = 125

_deadline = math.inf  # time.monotonic() past which the current push is hung
_started = False


def hung_after(push_timeout: float) -> float:
    """Wall time [s] after which a push whose limit is ``push_timeout`` [s] counts as hung.

    Its limit, then as long again (at most :data:`GRACE`) for the simulation to notice first.
    """
    push_timeout = positive_float("push_timeout", push_timeout, "s")
    return push_timeout + min(GRACE, push_timeout)


def arm(push_timeout: float) -> None:
    """Watch the push that starts now, whose limit is ``push_timeout`` [s] (:func:`hung_after`)."""
    global _deadline
    _deadline = time.monotonic() + hung_after(push_timeout)


def disarm() -> None:
    """Stop watching: the push is over (until the next :func:`arm`)."""
    global _deadline
    _deadline = math.inf


def _alive(pid: int) -> bool:
    """Whether process ``pid`` still exists (signal 0 only asks)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover - exists, another user's
        return True
    return True


def _watch(campaign: int | None) -> None:
    while True:
        time.sleep(PERIOD)
        if time.monotonic() > _deadline:
            os._exit(HUNG_EXIT)  # at once, whatever the main thread is stuck in
        if campaign is not None and not _alive(campaign):
            os._exit(ORPHAN_EXIT)  # the campaign was killed: nobody will collect the rows


def start(campaign: int | None = None) -> None:
    """Start the watching thread in this process (once; a worker's initializer).

    ``campaign``: the pid of the campaign's process. A worker whose campaign was killed (a
    SIGKILL leaves no time to stop the pool) ends itself within :data:`PERIOD` instead of
    waiting for work forever.
    """
    global _started
    if not _started:
        _started = True
        threading.Thread(
            target=_watch, args=(campaign,), name="pushrecovery-watchdog", daemon=True
        ).start()
