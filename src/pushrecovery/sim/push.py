"""What a push is: an instantaneous jump of the CoM velocity (docs/conventions.md).

In 3-D (:class:`Push3D`, docs/humanoid3d_pushes.md) a push is an impulse J [N s] on a named body,
horizontal, at an azimuth ψ in degrees: 0 forward (+x), 90 to the left (+y).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from pushrecovery.arguments import bounded_float, finite_float, flag, positive_float
from pushrecovery.errors import InvalidParameterError

__all__ = [
    "AZIMUTH_MAX",
    "IMPULSE_MAX",
    "PUSH_DURATION",
    "PUSH_TIME",
    "Direction",
    "Push",
    "Push3D",
    "direction_sign",
    "push_direction",
]

#: Largest abs(azimuth) [deg] a 3-D push accepts (one turn either way).
AZIMUTH_MAX = 360.0
#: Largest impulse [N s] a 3-D push accepts (a thousand times what topples a person).
IMPULSE_MAX = 1e4
#: Default duration of a force push [s].
PUSH_DURATION = 0.01
#: When a 3-D run pushes, after quiet standing, unless told [s]
#: (:func:`~pushrecovery.sim.mujoco.humanoid3d.runs3d.run_push3d`, the 3-D campaigns).
PUSH_TIME = 0.1

#: A push direction along x: ``"forward"`` or ``"backward"``.
Direction = str


def direction_sign(direction: str) -> float:
    """+1.0 for ``"forward"`` (+x), −1.0 for ``"backward"``; anything else raises."""
    if isinstance(direction, str) and direction in ("forward", "backward"):
        return 1.0 if direction == "forward" else -1.0
    raise InvalidParameterError(
        f"direction must be 'forward' or 'backward', got {str(direction)[:40]!r}"
    )


@dataclass(frozen=True, slots=True)
class Push:
    """An impulsive push, given as the CoM velocity jump it causes, and how a plant applies it.

    The analytic models take every push as its jump; the planar MuJoCo plants apply a force
    push as J = m Δẋ [N s] over ``duration`` on ``body`` (``MujocoPlant.apply_push``).

    Parameters
    ----------
    delta_velocity : float
        Jump of the CoM velocity Δẋ [m/s], positive forward (+x).
    kind : {"force", "velocity"}
        ``"force"`` (default): the model's own push (a force on MuJoCo); ``"velocity"``: an
        instantaneous jump of the CoM velocity, the pose kept, on every model.
    duration : float
        How long a force push lasts [s], > 0 (MuJoCo: at least one physics step); 10 ms
        (:data:`PUSH_DURATION`) by default.
    body : str, optional
        The MuJoCo body a force push acts on, at its centre of mass (1 to 100 characters);
        default the plant's pushed body, whose push the CoP map accounts for.
    scheduled : bool
        False (default): push now, the body holding still (CoP under the CoM, no hip torque),
        and return the state just after the push. True: the force acts from the plant's next
        step on, under whatever the controller commands; ``apply_push`` returns the state now.
        A jump is always now.

    Raises
    ------
    InvalidParameterError
        If ``delta_velocity`` is not finite, ``kind`` is neither name, ``duration`` is not
        > 0 or ``body`` is not a name of 1 to 100 characters.
    """

    delta_velocity: float
    kind: Literal["force", "velocity"] = "force"
    duration: float = PUSH_DURATION
    body: str | None = None
    scheduled: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "delta_velocity", finite_float("delta_velocity", self.delta_velocity, "m/s")
        )
        if not isinstance(self.kind, str) or self.kind not in ("force", "velocity"):
            raise InvalidParameterError(
                f"push kind must be 'force' or 'velocity', got {str(self.kind)[:40]!r}"
            )
        # The default needs no check (pushes are many); anything else, an array too, is checked.
        if type(self.duration) is not float or self.duration != PUSH_DURATION:
            object.__setattr__(self, "duration", positive_float("duration", self.duration, "s"))
        if self.body is not None:
            _check_body(self.body)
        if self.scheduled is not False:  # the default needs no check (pushes are many)
            flag("scheduled", self.scheduled)

    @classmethod
    def from_impulse(
        cls,
        impulse: float,
        mass: float,
        *,
        duration: float = PUSH_DURATION,
        body: str | None = None,
        scheduled: bool = False,
    ) -> Push:
        """Return the force push of an impulse J [N s] on a body of mass m [kg]: Δẋ = J / m.

        ``duration``, ``body`` and ``scheduled`` as in :class:`Push`.
        """
        velocity = finite_float("impulse", impulse, "N s") / positive_float("mass", mass, "kg")
        return cls(velocity, "force", duration, body, scheduled)

    def impulse(self, mass: float) -> float:
        """Return the impulse J = m Δẋ [N s] of this push on a body of mass m [kg]."""
        return mass * self.delta_velocity


def _check_body(body: object) -> None:
    """Require a body name a MuJoCo model could have (whether it has it is the plant's check)."""
    if not (isinstance(body, str) and 0 < len(body) <= 100):
        raise InvalidParameterError(
            f"body must be a body name of 1 to 100 characters, got {str(body)[:40]!r}"
        )


def push_direction(azimuth: float) -> tuple[float, float]:
    """Return the horizontal unit vector (cos ψ, sin ψ) of azimuth ψ [deg].

    0 is forward (+x), 90 to the left (+y), 180 backward, −90 (or 270) to the right.

    Raises
    ------
    InvalidParameterError
        If ``azimuth`` is not a finite number in [−360, 360] deg.
    """
    angle = math.radians(bounded_float("azimuth", azimuth, -AZIMUTH_MAX, AZIMUTH_MAX, "deg"))
    return math.cos(angle), math.sin(angle)


@dataclass(frozen=True, slots=True)
class Push3D:
    """A horizontal impulsive push on a named body of a 3-D model (docs/humanoid3d_pushes.md).

    Parameters
    ----------
    impulse : float
        J in [0, :data:`IMPULSE_MAX`] N s.
    azimuth : float
        ψ in [−360, 360] deg, 0 forward (+x), 90 to the left (+y).
    body : str
        The pushed body: ``"torso"`` (the default) is each model's torso (the biped3d's
        ``torso``, the G1's ``torso_link``); any other name is a body of the model.
    scheduled : bool
        As :attr:`Push.scheduled`: False (default) pushes now, the motors holding, and
        ``apply_push`` returns the state after the push (the critical pushes and campaigns);
        True: the force acts from the plant's next step on, under whatever the controller
        commands (a robot's controller reacting through the push, as in the stepping runs).

    Raises
    ------
    InvalidParameterError
        If a field is out of its range, ``body`` is not a non-empty name (at most 100
        characters) or ``scheduled`` is not a bool.
    """

    impulse: float
    azimuth: float = 0.0
    body: str = "torso"
    scheduled: bool = False

    def __post_init__(self) -> None:
        impulse = bounded_float("impulse", self.impulse, 0.0, IMPULSE_MAX, "N s")
        azimuth = bounded_float("azimuth", self.azimuth, -AZIMUTH_MAX, AZIMUTH_MAX, "deg")
        _check_body(self.body)
        if not isinstance(self.scheduled, bool):
            raise InvalidParameterError(f"scheduled must be a bool, got {self.scheduled!r:.40}")
        object.__setattr__(self, "impulse", impulse)
        object.__setattr__(self, "azimuth", azimuth)

    @property
    def direction(self) -> tuple[float, float]:
        """The push's horizontal unit vector (cos ψ, sin ψ)."""
        return push_direction(self.azimuth)

    def force(self, duration: float) -> tuple[float, float, float]:
        """Return the constant force J/Δ (cos ψ, sin ψ, 0) [N] that gives J over Δ [s] > 0."""
        size = self.impulse / positive_float("duration", duration, "s")
        dx, dy = self.direction
        return size * dx, size * dy, 0.0

    def delta_velocity(self, mass: float) -> tuple[float, float]:
        """Return the CoM velocity jump (Δẋ, Δẏ) = J/m (cos ψ, sin ψ) [m/s] on mass m [kg]."""
        size = self.impulse / positive_float("mass", mass, "kg")
        dx, dy = self.direction
        return size * dx, size * dy
