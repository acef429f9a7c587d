"""How a kernel runs: compiled by numba (cached on disk), or as the plain Python it is written in.

Every kernel module decorates its functions with :func:`njit` and loops with :data:`prange`
from here. By default these are numba's: the kernels compile (or load from numba's disk cache)
on their first call. After :func:`run_as_python`, the kernel modules imported from then on keep
their functions as written: the same code, run by the interpreter, with ``range`` for
``prange``. numba is then not loaded at all.

That is for a process that answers one question and exits, such as ``pushrecovery classify``:
importing numba and loading the cached machine code costs about 0.6 s, while the plain code of
one state's verdict runs in milliseconds. A long-running process (a balance loop, a campaign, a
test session) keeps the compiled kernels: they are 10-1000x faster per call.

The kernels are written so that both runs give the same numbers: plain float arithmetic in the
same order, the C library's ``math`` functions (:data:`hypot` here, as the interpreter's own
``math.hypot`` rounds differently), stable sorts, and no fast-math where the plain run is used.
``tests/test_plain_kernels.py`` compares a fresh command's output with the compiled library's,
digit for digit.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["njit", "run_as_python"]

_F = TypeVar("_F", bound=Callable[..., Any])

_plain = False


def run_as_python() -> None:
    """Make the kernel modules imported from now on run as plain Python (no numba).

    Modules imported before keep what they had: call this at the start of a process, before
    anything has computed.
    """
    global _plain
    _plain = True


def njit(**options: Any) -> Callable[[_F], _F]:
    """Return ``numba.njit(**options)``, or, after :func:`run_as_python`, no decorator at all."""
    if _plain:
        return _unchanged
    import numba

    decorate: Callable[[_F], _F] = numba.njit(**options)
    return decorate


def _unchanged(function: _F) -> _F:
    return function


def __getattr__(name: str) -> Any:
    # Looked up when a kernel module imports them, so that they follow the mode.
    if name == "prange":  # numba's parallel loop; plain ``range`` in plain Python
        if _plain:
            return range
        import numba

        return numba.prange
    if name == "hypot":
        # Compiled, math.hypot is the C library's hypot, which numpy's is too; the interpreter's
        # math.hypot is its own and differs from it in the last bit for about 1 pair in 500.
        if _plain:
            import numpy

            return numpy.hypot
        return math.hypot
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
