"""What happens during a run besides control ticks: a scheduled push, and observers of steps.

:func:`~pushrecovery.sim.simulate.simulate` is the only closed loop. A gait-lab recording (quiet
standing, a push, the response recorded at the plates' rate) is that loop with a
:class:`ScheduledPush`, a plant step finer than the control period and an :class:`Observer`;
nothing else runs a loop of its own.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from pushrecovery.arguments import finite_float, require_type
from pushrecovery.control.base import Command
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.backend import Step
from pushrecovery.sim.push import Push, Push3D

__all__ = ["ForcePushing", "Observer", "ScheduledPush"]


@dataclass(frozen=True, slots=True)
class ScheduledPush:
    """A push at ``time`` [s] into the run.

    Parameters
    ----------
    time : float
        When the push starts [s], >= 0.
    push : Push or Push3D
        The push the plant's ``apply_push`` applies at ``time``: a :class:`Push`, applied
        scheduled (a velocity jump, or on MuJoCo a force over the following steps,
        :class:`ForcePushing`), or a 3-D push (impulse [N s], azimuth, body) of the 3-D
        humanoids, applied as it says: now, the motors holding, over physics steps of its
        own, or (``scheduled=True``) over the following steps like a planar force push.
    react : bool
        False (default): the body holds still during a force push (CoP under the CoM, no
        hip torque, no step) and the controller restarts on the pushed state as it ends, as
        the critical pushes and the campaigns assume. True: the controller keeps running.
    """

    time: float
    push: Push | Push3D
    react: bool = False

    def __post_init__(self) -> None:
        require_type("push", self.push, (Push, Push3D))
        time = finite_float("push time", self.time, "s")
        if time < 0.0:
            raise InvalidParameterError(f"push time must be >= 0 s, got {time:g}")


@runtime_checkable
class ForcePushing(Protocol):
    """A plant whose force push lasts steps of the run (the MuJoCo plants, planar and 3-D).

    After a scheduled ``apply_push`` (``Push(..., scheduled=True)`` or
    ``Push3D(..., scheduled=True)``) the force acts over the plant's next steps for
    ``push_left``.
    """

    @property
    def push_left(self) -> float:
        """How long the force of the push still acts [s] (0: no push)."""
        ...


class Observer(Protocol):
    """Sees every step of the plant (a recorder of markers and force plates, a logger)."""

    def on_step(self, index: int, step: Step, command: Command) -> None:
        """See plant step ``index`` (0-based, at the plant's step) and the command it held."""
        ...
