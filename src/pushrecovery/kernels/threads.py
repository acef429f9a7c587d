"""numba's thread count, held at one for a block of work (campaign workers)."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["one_thread"]


@contextmanager
def one_thread() -> Iterator[None]:
    """Run the block with numba's parallel kernels on one thread, then restore the count.

    With one worker process per core, more threads per worker only compete for the cores.
    Where numba is not loaded yet, nothing is done: loading it (about 0.4 s) only to cap its
    threads would cost a campaign that runs no compiled kernel more than it saves, and a
    campaign's pushes query one state at a time, below the size from which kernels go
    parallel. Results do not depend on the thread count.
    """
    numba = sys.modules.get("numba")
    if numba is None:
        yield
        return
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)
