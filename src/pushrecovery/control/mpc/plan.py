"""The result of one MPC solve: the plan over the horizon, how it was found, its active set."""

from __future__ import annotations

import enum
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["Plan", "Status"]

FloatArray = NDArray[np.float64]


class Status(enum.IntEnum):
    """How a plan was found; positive: the plan solves Eq. (17).

    ``VERIFIED``: the Riccati passes verified the KKT conditions exactly. ``CONVERGED``: the
    interior point's own solution, to its tolerance. ``SOLVED``: a solver of the condensed QP
    (DAQP, or qpsolvers' back-end) returned it, to its tolerance. ``FAILED``: this solver found
    no plan (the route goes on to the next one). ``INFEASIBLE``: Eq. (17) has no solution; the
    plan is the saturated fallback.

    The real-time mode (``MPCSettings(realtime=True)``) adds two, when a tick's work budget ran
    out before a plan was verified: ``SHIFTED``, the last plan that solved Eq. (17) (on an
    earlier tick) shifted by one stage per tick since, its first input applied; ``EXHAUSTED``,
    no such plan to shift (none since the last reset, or older than the horizon): the inputs of
    the interior point's unfinished iterate, which the next tick continues, or the saturated
    fallback where there is none. Neither solves this tick's Eq. (17).
    """

    EXHAUSTED = -3
    SHIFTED = -2
    INFEASIBLE = -1
    FAILED = 0
    SOLVED = 1
    CONVERGED = 2
    VERIFIED = 3


_NO_INPUT = np.full(2, np.nan)
_NO_INPUT.setflags(write=False)


class Plan:
    """The first input, and the inputs and predicted states over the horizon on demand.

    What every solver of :mod:`pushrecovery.control.mpc.solvers` returns, and what the
    controller keeps as ``last_plan``. A tick needs only the first input; the whole plan is
    computed (or, from the sparse solvers, handed over) the first time it is read. A plain
    slotted class: one is made per tick, and a frozen dataclass with cached properties cost a
    few µs of the tick.

    Parameters
    ----------
    status : Status
        How it was found (:class:`Status`).
    first_input : ndarray, shape (2,)
        (δ [m], τ [N m]) applied now (receding horizon).
    inputs, states : ndarray or callable returning one
        The plan's inputs (N, 2), (δ [m], τ [N m]), and predicted states (N + 1, 4),
        ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s], or how to compute them.
    active : ndarray of int8, shape (N, 3), optional
        Its active set, rows (δ_i, τ_i, θ_{i+1}), −1 at the lower bound, +1 at the upper;
        None where the solver does not give one.
    iterations : int
        The solver's passes or iterations (0 where not counted).

    Attributes
    ----------
    status : Status
        How it was found.
    feasible : bool
        Whether it solves Eq. (17) (``status`` > 0); False for the saturated fallback.
    first_input : ndarray, shape (2,)
        (δ [m], τ [N m]) applied now.
    inputs : ndarray, shape (N, 2)
        (δ [m], τ [N m]) for each step.
    states : ndarray, shape (N + 1, 4)
        Predicted ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s], starting with the measured state.
    active : ndarray of int8, shape (N, 3), or None
        Its active set.
    iterations : int
        The solver's passes or iterations.
    """

    __slots__ = (
        "_inputs", "_states", "active", "feasible", "first_input", "iterations", "status",
    )  # fmt: skip

    def __init__(
        self,
        status: Status,
        first_input: FloatArray,
        inputs: FloatArray | Callable[[], FloatArray],
        states: FloatArray | Callable[[], FloatArray],
        active: NDArray[np.int8] | None = None,
        iterations: int = 0,
    ) -> None:
        self.status = status
        self.feasible = status > 0
        self.first_input = first_input
        self._inputs = inputs
        self._states = states
        self.active = active
        self.iterations = iterations

    @classmethod
    def failed(cls, active: NDArray[np.int8] | None = None) -> Plan:
        """Return a solver's FAILED plan: no inputs (NaN, empty), ``active`` where it ended."""
        return cls(Status.FAILED, _NO_INPUT, np.empty((0, 2)), np.empty((0, 4)), active)

    @property
    def inputs(self) -> FloatArray:
        """(δ [m], τ [N m]) for each step, shape (N, 2)."""
        inputs = self._inputs
        if callable(inputs):
            inputs = self._inputs = inputs()
        return inputs

    @property
    def states(self) -> FloatArray:
        """Predicted ``[x, θ, ẋ, θ̇]`` X_0..X_N [m, rad, m/s, rad/s], shape (N + 1, 4)."""
        states = self._states
        if callable(states):
            states = self._states = states()
        return states

    def __repr__(self) -> str:
        return f"Plan(status={self.status.name}, first_input={self.first_input!r})"
