"""What a push is: an instantaneous jump of the CoM velocity (docs/conventions.md)."""

from __future__ import annotations

from dataclasses import dataclass

from pushrecovery._validate import finite_float, positive_float
from pushrecovery.errors import InvalidParameterError

__all__ = ["Direction", "Push", "direction_sign"]

Direction = str  # "forward" or "backward"


def direction_sign(direction: str) -> float:
    """+1.0 for ``"forward"`` (+x), −1.0 for ``"backward"``; anything else raises."""
    if isinstance(direction, str) and direction in ("forward", "backward"):
        return 1.0 if direction == "forward" else -1.0
    raise InvalidParameterError(
        f"direction must be 'forward' or 'backward', got {str(direction)[:40]!r}"
    )


@dataclass(frozen=True, slots=True)
class Push:
    """An impulsive push, given as the CoM velocity jump it causes.

    Parameters
    ----------
    delta_velocity : float
        Jump of the CoM velocity Δẋ [m/s], positive forward (+x).
    """

    delta_velocity: float

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "delta_velocity", finite_float("delta_velocity", self.delta_velocity, "m/s")
        )

    @classmethod
    def from_impulse(cls, impulse: float, mass: float) -> Push:
        """Push from an impulse J [N s] on a body of mass m [kg]: Δẋ = J / m."""
        return cls(finite_float("impulse", impulse, "N s") / positive_float("mass", mass, "kg"))

    def impulse(self, mass: float) -> float:
        """Return the impulse J = m Δẋ [N s] of this push on a body of mass m [kg]."""
        return mass * self.delta_velocity
