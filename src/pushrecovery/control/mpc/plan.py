"""The result of one MPC solve."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Plan"]


@dataclass(frozen=True, slots=True)
class Plan:
    """Inputs and predicted states over the horizon.

    Attributes
    ----------
    inputs : ndarray, shape (N, 2)
        (δ [m], τ [N m]) for each step.
    states : ndarray, shape (N + 1, 4)
        Predicted ``[x, θ, ẋ, θ̇]``, starting with the measured state.
    feasible : bool
        False when the QP had no solution; ``inputs`` is then the saturated fallback.
    """

    inputs: NDArray[np.float64]
    states: NDArray[np.float64]
    feasible: bool

    @property
    def first_input(self) -> NDArray[np.float64]:
        """The input applied now (receding horizon)."""
        return self.inputs[0]
