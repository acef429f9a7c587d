"""Simulation results and the outcome criterion."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

__all__ = ["Outcome", "SimulationResult", "is_falling"]


class Outcome(StrEnum):
    """How a simulated push ended (docs/conventions.md, "Outcome")."""

    RECOVERED = "recovered"
    FELL = "fell"
    UNDECIDED = "undecided"


def is_falling(x: float, xdot: float, heel: float, toe: float) -> bool:
    """Tell whether the CoM is beyond a foot edge and moving away from the foot.

    The state is then lost for any CoP on the foot: for the LIPM ẍ = ω² (x − δ) > 0 when
    x > δ⁺ ≥ δ; for the pendulum m L² θ̈ = m g L sinθ − τ and τ ≤ τ(δ⁺) < m g L sinθ when
    L sinθ > δ⁺ and θ̇ ≥ 0 (docs/conventions.md). Mirror for the heel.
    """
    return (x > toe and xdot >= 0.0) or (x < heel and xdot <= 0.0)


@dataclass(frozen=True, slots=True)
class SimulationResult:
    """A simulated run.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s].
    states : ndarray, shape (n, d)
        States at those times (``[x, xdot]`` for the ankle models) [m, m/s].
    cops : ndarray, shape (n - 1,)
        CoP applied over each control period [m].
    outcome : Outcome
        ``recovered``, ``fell`` or ``undecided`` (neither within the duration).
    model, controller : str
        Registry names of the plant and the controller.
    """

    time: NDArray[np.float64]
    states: NDArray[np.float64]
    cops: NDArray[np.float64]
    outcome: Outcome
    model: str
    controller: str

    @property
    def recovered(self) -> bool:
        """True when the body came to rest standing."""
        return self.outcome is Outcome.RECOVERED

    @property
    def final_state(self) -> NDArray[np.float64]:
        """The last state."""
        return self.states[-1]

    def to_dict(self) -> dict[str, object]:
        """JSON summary (the ``simulate`` contract); trajectories are not included."""
        x, xdot = self.final_state[0], self.final_state[len(self.final_state) // 2]
        return {
            "recovered": self.recovered,
            "outcome": self.outcome.value,
            "model": self.model,
            "controller": self.controller,
            "duration": float(self.time[-1]),
            "final_state": {"x": float(x), "xdot": float(xdot)},
            # simulate() always runs at least one control tick, so cops is never empty.
            "peak_cop": {"min": float(self.cops.min()), "max": float(self.cops.max())},
            "max_excursion": float(np.abs(self.states[:, 0]).max()),
        }
