"""numba's thread count, held at one for a block of work (campaign workers)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numba

__all__ = ["one_thread"]


@contextmanager
def one_thread() -> Iterator[None]:
    """Run the block with numba's parallel kernels on one thread, then restore the count.

    With one worker process per core, more threads per worker only compete for the cores.
    """
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)
