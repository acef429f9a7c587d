"""The result of one MPC solve."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

__all__ = ["Plan"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Plan:
    """The first input, and the inputs and predicted states over the horizon on demand.

    A tick needs only the first input; the whole plan costs two matrix-vector products of
    the horizon's size, so it is computed the first time it is read.

    Attributes
    ----------
    first_input : ndarray, shape (2,)
        (δ [m], τ [N m]) applied now (receding horizon).
    feasible : bool
        False when the QP had no solution; the inputs are then the saturated fallback.
    inputs : ndarray, shape (N, 2)
        (δ [m], τ [N m]) for each step.
    states : ndarray, shape (N + 1, 4)
        Predicted ``[x, θ, ẋ, θ̇]``, starting with the measured state.
    """

    first_input: FloatArray
    feasible: bool
    _inputs: Callable[[], FloatArray] = field(repr=False)
    _states: Callable[[], FloatArray] = field(repr=False)

    @cached_property
    def inputs(self) -> FloatArray:
        """(δ [m], τ [N m]) for each step, shape (N, 2)."""
        return self._inputs()

    @cached_property
    def states(self) -> FloatArray:
        """Predicted ``[x, θ, ẋ, θ̇]`` X_0..X_N, shape (N + 1, 4)."""
        return self._states()
