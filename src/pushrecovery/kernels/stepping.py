"""numba builds of :mod:`pushrecovery.kernels.step_scalar` (cached on disk, no closures).

Imported lazily, only by the vectorised paths and by
:func:`~pushrecovery.surfaces.step.compiled_plan_step`: importing numba alone costs about 0.4 s.

Each pure-Python function of ``step_scalar`` is compiled here as it is written there: the same
code object, run with a namespace in which the names of its callees refer to their compiled
versions (and ``prange`` to ``numba.prange``). Nothing is captured in a closure, so numba's
cache index key (signature, CPU, bytecode hash) is the same in every process and a new process
loads the machine code from ``__pycache__`` instead of compiling it. As the code objects belong
to ``step_scalar.py``, the cache files are named after it and numba discards them whenever that
file changes, including the callees linked into a kernel (numba tracks only the kernel's own
source file). It does not track the options below: after changing them, delete
``__pycache__/step_scalar.*.nb[ic]``.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any

import numba
import numpy as np
from numpy.typing import NDArray

from pushrecovery.kernels import step_scalar

__all__ = [
    "PARALLEL_MIN_SIZE",
    "decide",
    "plan",
    "scalar_decide",
    "solve",
]

#: Arrays from this size on (about 1 ms of work in one thread, at ~1 µs a state) run on numba's
#: thread pool; smaller ones in the calling thread: a parallel launch costs tens of µs, the
#: first one starts the pool (milliseconds), and a busy pool makes for a long tail.
PARALLEL_MIN_SIZE = 1 << 10

#: The scalar entry point's signature: seven floats in, the decision tuple out.
DECIDE_SIGNATURE = numba.types.Tuple(
    (numba.float64, numba.boolean, numba.boolean) + (numba.float64,) * 5
)(*(numba.float64,) * 7)

_NAMESPACE: dict[str, Any] = dict(vars(step_scalar), prange=numba.prange)


def _build(name: str, signature: Any = None, as_name: str | None = None, **options: Any) -> Any:
    """Return a numba dispatcher of ``step_scalar.<name>``, its callees compiled ones.

    With a ``signature`` it is compiled (or loaded from the cache) now, and never again.
    ``as_name`` names the build: numba's cache index is named after the function's qualified
    name, and its key leaves the options out, so the serial and the parallel build of one
    function need names of their own, or each would load the other's machine code.
    """
    function = getattr(step_scalar, name)
    rebound = types.FunctionType(function.__code__, _NAMESPACE, function.__name__)
    rebound.__qualname__ = as_name or name
    rebound.__doc__ = function.__doc__
    return numba.njit(signature, cache=True, nogil=True, **options)(rebound)


def _compile(name: str, **options: Any) -> Any:
    """:func:`_build`, and make ``name`` refer to the result in the compiled namespace."""
    _NAMESPACE[name] = dispatcher = _build(name, **options)
    return dispatcher


# Callees first, so that each kernel finds the compiled versions of the functions it calls.
_compile("capture_residual", inline="always")
_compile("step_angle")
decide = _compile("decide")
_compile("_store", inline="always")
# The array loops, each built serial and parallel (without ``parallel`` numba runs ``prange``
# as ``range``).
_decide_serial = _build("decide_each", as_name="decide_serial")
_decide_parallel = _build("decide_each", as_name="decide_parallel", parallel=True)
_solve_serial = _build("solve_each", as_name="solve_serial")
_solve_parallel = _build("solve_each", as_name="solve_parallel", parallel=True)


def scalar_decide() -> Callable[..., step_scalar.Decision]:
    """:func:`decide` with the float64 signature loaded (from the disk cache) and frozen.

    A new dispatcher of the same code with :data:`DECIDE_SIGNATURE` declared: it never compiles
    on a call (other argument types are converted to float64 or refused).
    """
    return _build("decide", DECIDE_SIGNATURE)


def _flat(array: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.ascontiguousarray(array, dtype=np.float64).reshape(-1)


def plan(
    x: NDArray[np.float64],
    xdot: NDArray[np.float64],
    heel: NDArray[np.float64],
    toe: NDArray[np.float64],
    height: float,
    gravity: float,
    reach: float,
    *,
    parallel: bool | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Compiled ``decide`` over flat arrays of the same size.

    Returns
    -------
    values : ndarray, shape (6, n)
        direction, theta [rad], step_length [m], shortest [m], longest [m], margin [m].
    flags : ndarray of bool, shape (2, n)
        ready, feasible.
    """
    x, xdot, heel, toe = (_flat(a) for a in (x, xdot, heel, toe))
    values = np.empty((6, x.size), dtype=np.float64)
    flags = np.empty((2, x.size), dtype=np.bool_)
    parallel = x.size >= PARALLEL_MIN_SIZE if parallel is None else parallel
    kernel = _decide_parallel if parallel else _decide_serial
    kernel(x, xdot, heel, toe, float(height), float(gravity), float(reach), values, flags)
    return values, flags


def solve(
    energy: NDArray[np.float64],
    lean: NDArray[np.float64],
    target: NDArray[np.float64],
    length: float,
    gravity: float,
    *,
    parallel: bool | None = None,
) -> NDArray[np.float64]:
    """Compiled ``step_angle`` over flat arrays of the same size [rad]."""
    energy, lean, target = (_flat(a) for a in (energy, lean, target))
    out = np.empty_like(energy)
    parallel = energy.size >= PARALLEL_MIN_SIZE if parallel is None else parallel
    kernel = _solve_parallel if parallel else _solve_serial
    kernel(energy, lean, target, float(length), float(gravity), out)
    return out
