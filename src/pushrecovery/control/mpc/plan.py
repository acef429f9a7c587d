"""The result of one MPC solve."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["Plan"]

FloatArray = NDArray[np.float64]


class Plan:
    """The first input, and the inputs and predicted states over the horizon on demand.

    A tick needs only the first input; the whole plan is computed (or, from the Riccati
    passes, handed over) the first time it is read. A plain slotted class: one is made per
    tick, and a frozen dataclass with cached properties cost a few µs of the tick.

    Parameters
    ----------
    first_input : ndarray, shape (2,)
        (δ [m], τ [N m]) applied now (receding horizon).
    feasible : bool
        False when the QP had no solution; the inputs are then the saturated fallback.
    inputs, states : ndarray or callable returning one
        The plan's inputs (N, 2), (δ [m], τ [N m]), and predicted states (N + 1, 4),
        ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s], or how to compute them.

    Attributes
    ----------
    first_input : ndarray, shape (2,)
        (δ [m], τ [N m]) applied now.
    feasible : bool
        False when the QP had no solution.
    inputs : ndarray, shape (N, 2)
        (δ [m], τ [N m]) for each step.
    states : ndarray, shape (N + 1, 4)
        Predicted ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s], starting with the measured state.
    """

    __slots__ = ("_inputs", "_states", "feasible", "first_input")

    def __init__(
        self,
        first_input: FloatArray,
        feasible: bool,
        inputs: FloatArray | Callable[[], FloatArray],
        states: FloatArray | Callable[[], FloatArray],
    ) -> None:
        self.first_input = first_input
        self.feasible = feasible
        self._inputs = inputs
        self._states = states

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
        return f"Plan(first_input={self.first_input!r}, feasible={self.feasible})"
