"""The controller contract every balance strategy implements.

Contract (what the simulators, the CLI and a robot's control loop may rely on):

1. ``reset(state)`` is called once with the initial state before the first ``compute``.
2. ``compute(t, state)`` is called once per control tick with the time [s] since reset and the
   current state, and returns a :class:`Command` held constant until the next tick.
3. ``state`` is a 1-D float array, positions then velocities; its first entry is the CoM
   position x relative to the ankle [m] and entry ``len(state) // 2`` the CoM velocity ẋ
   [m/s] (``[x, xdot]`` for the ankle models; the flywheel model appends θ and θ̇). On the
   ground plane (``stepping-plane``) it is ``[x, y, θp, θr, ẋ, ẏ, θ̇p, θ̇r]`` in the world
   frame, and the command's ``cop_y``, ``roll_torque``, ``foothold`` and ``touchdown`` apply.
4. The command is always finite and within the body's limits: ``cop`` on the foot
   [heel, toe] [m], ``flywheel_torque`` within ±torque_max [N m]. A controller that cannot
   meet its goal (the state is beyond what it can recover) still returns a saturated finite
   command and sets ``saturated=True``; it never raises inside the loop.
5. ``observe(info)`` is called after every step of the plant with what the plant reports
   beside the state (:class:`StepInfo`: stance, footholds, stop impacts, measured CoP), before
   the next ``compute``. The default ignores it; a controller that steps learns its landings
   from it (a robot's loop passes its own contact detection).
6. ``state_labels`` names the state entries a controller reads; the simulator checks that the
   plant's state has them, by label.
"""

from __future__ import annotations

import importlib
import inspect
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import finite_array, finite_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.lipm import ANKLE_STATE
from pushrecovery.params import BodyParams

if TYPE_CHECKING:
    from pushrecovery.ground.polygon import ConvexPolygon
    from pushrecovery.ground.support import Support

__all__ = [
    "CONTROLLERS",
    "Command",
    "Controller",
    "StepInfo",
    "controller_class",
    "make_controller",
    "register",
]


@dataclass(frozen=True, slots=True)
class Command:
    """One control command, the input U = (δ, τ) of Eq. (16).

    Parameters
    ----------
    cop : float
        Centre of pressure δ relative to the ankle [m], x forward; on the foot.
    flywheel_torque : float
        Hip (flywheel) torque τ on the upper body [N m], positive pitches it forward; 0 for
        the ankle strategy.
    saturated : bool
        True when a limit is active because the controller's goal is out of reach.
    step_length : float or None
        Take a step now: foot-to-foot length, signed (positive forward) [m]. Only the stepping
        model has legs to do it; ``None`` keeps the stance.
    cop_y : float
        On the ground plane: the CoP's y [m] (``cop`` is then its x), world frame.
    roll_torque : float
        On the ground plane: hip torque about the upper body's roll axis [N m], positive moves
        the CMP to the body's left (``flywheel_torque`` is then the pitch torque).
    foothold : tuple of float or None
        On the ground plane: lift the free foot now and land its ankle at (x, y) [m], world
        frame; ``None`` keeps the stance (and an ongoing swing).
    touchdown : float or None
        With ``foothold``: the touchdown time [s] on the controller's clock (time since
        reset); the plant lands no sooner than ``min_step_time`` after the lift.
    swing : str or None
        With ``foothold`` from double support: the foot that steps, ``left`` or ``right``.
    """

    cop: float
    flywheel_torque: float = 0.0
    saturated: bool = False
    step_length: float | None = None
    cop_y: float = 0.0
    roll_torque: float = 0.0
    foothold: tuple[float, float] | None = None
    touchdown: float | None = None
    swing: str | None = None


@dataclass(frozen=True, slots=True)
class StepInfo:
    """What a plant reports after a step, beside the state (contract item 5).

    Attributes
    ----------
    stance : bool
        True while the feet on the ground carry the body (no foot swinging toward a landing).
    footholds : tuple of float
        World x of every stance ankle of the run so far, the first at the start [m].
    stop_impacts : int
        Times the flywheel hit its joint stop at speed during the run.
    measured_cop : float or None
        CoP measured from the contact forces, relative to the stance ankle [m] (NaN while
        airborne); None when the plant does not measure it.
    footholds_xy : tuple of (float, float)
        World (x, y) of every stance ankle of the run so far on the ground plane [m]; empty
        for a sagittal plant.
    support : ConvexPolygon or None
        The support polygon (world xy [m]) of a controller that steps, as its last command
        gave it (the feet it keeps on the floor): the 3-D plants' fall set and rest read it
        (a capture point beyond it is what a step answers); None: the plant's own support.
    feet : Support or None
        On the ground plane: the feet on the ground now, as the plant (or a robot's contact
        detection) measures them: the stance and both foot poses
        (:class:`~pushrecovery.ground.support.Support`); a controller that steps adopts them in
        ``observe``. None: not reported.
    """

    stance: bool = True
    footholds: tuple[float, ...] = (0.0,)
    stop_impacts: int = 0
    measured_cop: float | None = None
    footholds_xy: tuple[tuple[float, float], ...] = ()
    support: ConvexPolygon | None = None
    feet: Support | None = None


class Controller(ABC):
    """Base class of all controllers; see the module docstring for the contract."""

    #: Name used by the CLI and the registry.
    name: ClassVar[str]
    #: Strategy whose decision surface predicts this controller (``ankle``, ``hip``, ``step``).
    strategy: ClassVar[str] = "ankle"
    #: Period the controller is designed for [s]; ``None`` lets the simulator choose.
    control_period: float | None = None
    #: True when the controller's internal model assumes exactly ``control_period``.
    fixed_period: ClassVar[bool] = False
    #: The state entries the controller reads (contract item 6); the plant's must include
    #: them. By default the CoM position and velocity, which every plant has.
    state_labels: ClassVar[tuple[str, ...]] = ANKLE_STATE

    def __init__(self, params: BodyParams) -> None:
        require_type("params", params, BodyParams)  # every controller's boundary
        self.params = params

    @abstractmethod
    def reset(self, state: NDArray[np.float64]) -> None:
        """Prepare for a new run starting at ``state``."""

    @abstractmethod
    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """Return the command for time ``t`` [s] and ``state``."""

    def command(self, t: float, state: ArrayLike) -> Command:
        """Return :meth:`compute`'s command after checking ``t`` and ``state`` (a user's loop).

        :meth:`compute` is the unchecked kernel :func:`~pushrecovery.sim.simulate.simulate`
        calls at every tick, once it has checked the run; call this one from your own loop.

        Raises
        ------
        InvalidParameterError
            If ``t`` is not finite, or ``state`` is not a 1-D array of finite numbers with at
            least one entry per :attr:`state_labels`.
        """
        time = finite_float("t", t, "s")
        values = finite_array("state", state)
        if values.ndim != 1 or values.size < len(self.state_labels):
            raise InvalidParameterError(
                f"state must be a 1-D array of at least {len(self.state_labels)} values "
                f"{list(self.state_labels)}, got shape {values.shape}"
            )
        return self.compute(time, values)

    def observe(self, info: StepInfo) -> None:  # noqa: B027 - optional hook, no-op default
        """Take the plant's report of its last step (contract item 5); ignored by default."""

    @classmethod
    def option_names(cls) -> tuple[str, ...]:
        """Keyword options the constructor takes besides ``params``."""
        signature = inspect.signature(cls.__init__)
        return tuple(name for name in signature.parameters if name not in ("self", "params"))

    def clip_cop(self, cop: float) -> tuple[float, bool]:
        """Clip a CoP to the foot [heel, toe]; also return whether it was clipped."""
        heel, toe = self.params.heel, self.params.toe
        if cop > toe:
            return toe, True
        if cop < heel:
            return heel, True
        return cop, False


ControllerFactory = Callable[..., Controller]

#: Controller name -> class, filled by :func:`register`.
CONTROLLERS: dict[str, type[Controller]] = {}


def register(cls: type[Controller]) -> type[Controller]:
    """Class decorator adding a controller to :data:`CONTROLLERS` under ``cls.name``."""
    CONTROLLERS[cls.name] = cls
    return cls


def controller_class(name: str) -> type[Controller]:
    """Return the controller class registered as ``name`` (built-in ones imported on demand).

    Raises
    ------
    InvalidParameterError
        If ``name`` is not registered.
    """
    from pushrecovery.control.registry import CONTROLLER_PATHS

    require_type("name", name, str)
    if name not in CONTROLLERS and name in CONTROLLER_PATHS:
        module, _, _ = CONTROLLER_PATHS[name].partition(":")
        importlib.import_module(module)  # its @register fills CONTROLLERS
    try:
        return CONTROLLERS[name]
    except KeyError:
        names = sorted({*CONTROLLERS, *CONTROLLER_PATHS})
        raise InvalidParameterError(
            f"controller must be one of {names}, got controller={name!r}"
        ) from None


def make_controller(name: str, params: BodyParams, **options: Any) -> Controller:
    """Build the registered controller ``name`` for ``params``.

    Raises
    ------
    InvalidParameterError
        If ``name`` is not registered, or an option is not one of its constructor's.
    """
    cls = controller_class(name)
    unknown = sorted(set(options) - set(cls.option_names()))
    if unknown:
        raise InvalidParameterError(
            f"controller {name!r} has no option {unknown[0]!r}; its options are: "
            f"{', '.join(cls.option_names()) or 'none'}"
        )
    return cls(params, **options)
