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

__all__ = ["GRACE", "HUNG_EXIT", "PERIOD", "arm", "disarm", "hung_after", "start"]

#: Longest time a push gets beyond its wall-time limit before its worker counts as hung [s]:
#: the simulation's own check comes first, at its next control tick.
GRACE = 30.0
#: How often the thread looks [s].
PERIOD = 0.5
#: Exit status of a process its watchdog ended (as timeout(1)'s).
HUNG_EXIT = 124

_deadline = math.inf  # time.monotonic() past which the current push is hung
_started = False


def hung_after(push_timeout: float) -> float:
    """Wall time [s] after which a push whose limit is ``push_timeout`` [s] counts as hung.

    Its limit, then as long again (at most :data:`GRACE`) for the simulation to notice first.
    """
    return push_timeout + min(GRACE, push_timeout)


def arm(push_timeout: float) -> None:
    """Watch the push that starts now, whose limit is ``push_timeout`` [s] (:func:`hung_after`)."""
    global _deadline
    _deadline = time.monotonic() + hung_after(push_timeout)


def disarm() -> None:
    """Stop watching: the push is over (until the next :func:`arm`)."""
    global _deadline
    _deadline = math.inf


def _watch() -> None:
    while True:
        time.sleep(PERIOD)
        if time.monotonic() > _deadline:
            os._exit(HUNG_EXIT)  # at once, whatever the main thread is stuck in


def start() -> None:
    """Start the watching thread in this process (once; a worker's initializer)."""
    global _started
    if not _started:
        _started = True
        threading.Thread(target=_watch, name="pushrecovery-watchdog", daemon=True).start()
