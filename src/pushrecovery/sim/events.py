"""What happens during a run besides control ticks: a scheduled push, and observers of steps.

:func:`~pushrecovery.sim.simulate.simulate` is the only closed loop. A gait-lab recording (quiet
standing, a push, the response recorded at the plates' rate) is that loop with a
:class:`ScheduledPush`, a plant step finer than the control period and an :class:`Observer`;
nothing else runs a loop of its own.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, require_type
from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.backend import Step
from pushrecovery.sim.push import Push, Push3D

__all__ = ["ForcePushing", "Observer", "ScheduledPush", "VelocityJumping"]


@dataclass(frozen=True, slots=True)
class ScheduledPush:
    """A push at ``time`` [s] into the run.

    Parameters
    ----------
    time : float
        When the push starts [s], >= 0.
    push : Push or Push3D
        The velocity jump it stands for (Δẋ [m/s]; the impulse is m Δẋ), or a 3-D push
        (impulse [N s], azimuth, body) that the plant's ``apply_push`` applies (the 3-D
        humanoids, whose push lasts physics steps of their own).
    kind : {"force", "velocity"}
        ``force``: a force on the pushed body over the plant's push duration (plants with
        :class:`ForcePushing`; others take the jump); ``velocity``: an instantaneous jump.
    react : bool
        False (default): the body holds still during a force push (CoP under the CoM, no
        hip torque, no step) and the controller restarts on the pushed state as it ends, as
        the critical pushes and the campaigns assume. True: the controller keeps running.
    """

    time: float
    push: Push | Push3D
    kind: Literal["force", "velocity"] = "force"
    react: bool = False

    def __post_init__(self) -> None:
        require_type("push", self.push, (Push, Push3D))
        time = finite_float("push time", self.time, "s")
        if time < 0.0:
            raise InvalidParameterError(f"push time must be >= 0 s, got {time:g}")
        if self.kind not in ("force", "velocity"):
            raise InvalidParameterError(
                f"push kind must be 'force' or 'velocity', got {self.kind!r}"
            )


@runtime_checkable
class ForcePushing(Protocol):
    """A plant whose pushes are forces over time (MuJoCo)."""

    def schedule_push(self, impulse: float) -> float:
        """Push with ``impulse`` [N s] from the next step on; return how long it lasts [s]."""
        ...


@runtime_checkable
class VelocityJumping(Protocol):
    """A plant whose CoM velocity can jump by Δẋ [m/s] now (the analytic push)."""

    def jump_velocity(self, delta: float) -> NDArray[np.float64]:
        """Add ``delta`` [m/s] to the CoM velocity now; return the state."""
        ...


class Observer(Protocol):
    """Sees every step of the plant (a recorder of markers and force plates, a logger)."""

    def on_step(self, index: int, step: Step, command: Command) -> None:
        """See plant step ``index`` (0-based, at the plant's step) and the command it held."""
        ...
