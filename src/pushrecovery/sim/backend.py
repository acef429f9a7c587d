"""The backend contract: what the simulator, the experiments and a test bench rely on of a plant.

Contract (every plant, analytic or MuJoCo, implements it; :func:`~pushrecovery.sim.simulate.
simulate` is written against it alone):

1. A plant is built from :class:`~pushrecovery.params.BodyParams` and has a registry ``name``,
   its ``params``, ``state_labels`` (the entries of its state, positions then velocities, the
   CoM position ``x`` first and its velocity ``xdot`` at ``len // 2``) and ``input_labels``
   (the applied inputs of a step: CoP entries, then torques).
2. ``reset(x, xdot)`` starts a run with the CoM at x [m] moving at ẋ [m/s] and everything else
   at rest (standing; MuJoCo after settling) and returns the state.
3. ``check_state(state)`` raises :class:`~pushrecovery.errors.InvalidParameterError`, naming
   the entry and its range, for a state the model cannot start from; ``begin(state)`` checks
   it and starts a run from it (as returned by ``reset``/``apply_push``, or any valid state),
   returning it. A run's records (footholds, stop impacts, measurements) start here, and
   the feet: the ``stepping-plane`` plant starts every run on its ``start_support`` (a
   stance and foot poses a user may give), which its ``info()`` reports; the loop passes an
   analytic plant's ``info()`` to the controller's ``observe`` right after its ``reset``.
4. ``apply_push(push)`` is the one way to push (:class:`~pushrecovery.sim.push.Push`): a jump
   of the CoM velocity on the analytic models; on MuJoCo a jump (``kind="velocity"``) or a
   force on a body over the push's duration, now with the body holding still, or from the
   next step on (``scheduled``). It returns the state after the push (scheduled: the state
   now).
5. ``step(command, dt)`` holds ``command`` for ``dt`` [s] and returns a :class:`Step`: the new
   state, the inputs the plant applied (commands are clipped to the feet and the torque
   limits: physics, not politeness) and a :class:`~pushrecovery.control.base.StepInfo`
   (stance, footholds, stop impacts, measured CoP). It raises
   :class:`~pushrecovery.errors.SimulationDiverged` if the physics blows up.
6. ``falling(state)`` tells whether the state is in the plant's absorbing fall set
   (docs/conventions.md); ``at_rest(state, speed)`` whether the CoM moves at most ``speed``
   [m/s] over the support.
7. Optional capabilities are their own protocols: :class:`Recording` (frames for rendering),
   :class:`Measuring` (the CoP measured from contact forces), :class:`Clocked` (the plant's
   own clock and rows: MuJoCo's time, a push lasting steps of its own) and :class:`Audited`
   (the physical checks of every physics step since ``reset``: MuJoCo). Check them with
   ``isinstance``; nothing else is looked up by name.
"""

from __future__ import annotations

import math
from typing import ClassVar, NamedTuple, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, float_array, non_negative_float, require_type
from pushrecovery.control.base import Command, StepInfo
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.push import Push

__all__ = [
    "Audited",
    "Backend",
    "Clocked",
    "Measuring",
    "PlantBase",
    "RecordedFrame",
    "Recording",
    "RunRows",
    "Step",
    "check_com_state",
    "over_foot_at_rest",
]

FloatArray = NDArray[np.float64]


class Step(NamedTuple):
    """One step of a plant (contract item 5); a named tuple (made at every tick: cheap).

    Attributes
    ----------
    state : ndarray
        The state after the step (``state_labels``): positions [m] and angles [rad], then
        their rates [m/s], [rad/s].
    applied : tuple of float
        The inputs held over the step (``input_labels``): CoP [m], then torques [N m].
    info : StepInfo
        Stance, footholds, stop impacts and measured CoP.
    """

    state: FloatArray
    applied: tuple[float, ...]
    info: StepInfo


@runtime_checkable
class Backend(Protocol):
    """A plant behind the numbered contract of the module docstring.

    ``isinstance`` checks the names only: the boundary of
    :func:`~pushrecovery.sim.simulate.simulate`.
    """

    name: ClassVar[str]
    state_labels: ClassVar[tuple[str, ...]]
    params: BodyParams

    @property
    def input_labels(self) -> tuple[str, ...]:
        """The applied inputs of a step (item 1): a class's, or a model's own (MuJoCo's motors)."""
        ...

    def reset(self, x: float, xdot: float) -> FloatArray:
        """Start a run standing with the CoM at x [m] moving at ẋ [m/s] (item 2)."""
        ...

    def check_state(self, state: FloatArray) -> None:
        """Raise if the model cannot start from ``state`` (item 3)."""
        ...

    def begin(self, state: FloatArray) -> FloatArray:
        """Start a run from ``state``, checked (item 3)."""
        ...

    def apply_push(self, push: Push) -> FloatArray:
        """Push now; return the state after the push (item 4)."""
        ...

    def step(self, command: Command, dt: float) -> Step:
        """Hold ``command`` for ``dt`` [s] (item 5)."""
        ...

    def falling(self, state: FloatArray) -> bool:
        """Whether ``state`` is in the absorbing fall set (item 6)."""
        ...

    def at_rest(self, state: FloatArray, speed: float) -> bool:
        """Whether the CoM moves at most ``speed`` [m/s] over the support (item 6)."""
        ...


#: One recorded instant: time [s], joint positions, CoM (x, z) [m], capture point x [m] and
#: measured CoP x [m], world frame.
RecordedFrame = tuple[float, FloatArray, tuple[float, float], float, float]


@runtime_checkable
class Recording(Protocol):
    """A plant that records frames for rendering (MuJoCo): its ``model`` and ``frames``."""

    model: object
    frames: list[RecordedFrame] | None

    def record(self) -> None:
        """Record a frame at every step from now on (``frames``)."""
        ...


@runtime_checkable
class Measuring(Protocol):
    """A plant that measures the CoP from its contact forces (MuJoCo)."""

    measured_cops: list[float]

    def measure(self) -> None:
        """Record the measured CoP at every step from now on (``measured_cops``)."""
        ...


class RunRows(NamedTuple):
    """A run's rows as a :class:`Clocked` plant kept them.

    Attributes
    ----------
    time : ndarray, shape (n,)
        The plant's clock at each row [s].
    states : ndarray, shape (n, d)
        The state at each row (``state_labels``): positions [m] and angles [rad], then their
        rates [m/s], [rad/s].
    inputs : ndarray, shape (n - 1, m)
        The inputs held from each row to the next (``input_labels``): CoP [m], then torques
        [N m] (a 3-D humanoid's: its motor commands [N m]).
    """

    time: FloatArray
    states: FloatArray
    inputs: FloatArray


@runtime_checkable
class Clocked(Protocol):
    """A plant with its own clock and rows (MuJoCo's time; a push lasting steps of its own).

    Its rows start at ``begin``; each ``step`` adds one, and so does an ``apply_push`` that
    pushes now (a push that lasts its own physics steps has a row before it and one after
    it; a scheduled push adds none: its force acts within the following steps). The loop reads them
    once, at the end of a run, in place of its own.
    """

    @property
    def clock(self) -> float:
        """The plant's time now [s]."""
        ...

    def run_rows(self) -> RunRows:
        """Return the rows of the run since ``begin``."""
        ...


@runtime_checkable
class Audited(Protocol):
    """A plant whose physics steps are audited (MuJoCo): the run's physical checks.

    The loop puts them in the result and judges its outcome by them
    (:func:`~pushrecovery.sim.result.judge`: a run at rest that slid is ``slipped``).
    """

    def physical_checks(self) -> PhysicalChecks:
        """Return the checks of every physics step since ``reset`` (a force push's included)."""
        ...


def check_com_state(
    x: float, xdot: float, params: BodyParams, names: tuple[str, str] = ("x", "xdot")
) -> None:
    """Reject CoM states outside every model's validity.

    abs(x) < L (the CoM above the ankle's horizon) and abs(ẋ) < 10 sqrt(g L): ten times the speed at
    which an upright pendulum's foot unloads (docs/conventions.md). ``names`` are the
    coordinate's in the messages (``("y", "ydot")`` sideways).
    """
    require_type("params", params, BodyParams)
    pair = isinstance(names, tuple) and len(names) == 2
    if not (pair and all(isinstance(name, str) for name in names)):
        raise ParameterTypeError(f"names must be two coordinate names, got {str(names)[:40]!r}")
    position, velocity = names
    x = finite_float(names[0], x, "m")
    xdot = finite_float(names[1], xdot, "m/s")
    if abs(x) >= params.com_height:
        raise InvalidParameterError(
            f"{position} must satisfy |{position}| < com_height = {params.com_height:g} m, "
            f"got {position}={x:g}"
        )
    speed = 10.0 * math.sqrt(params.gravity * params.com_height)
    if abs(xdot) >= speed:
        raise InvalidParameterError(
            f"{velocity} must satisfy |{velocity}| < 10 sqrt(g L) = {speed:g} m/s, "
            f"got {velocity}={xdot:g}"
        )


def over_foot_at_rest(state: FloatArray, params: BodyParams, speed: float) -> bool:
    """Sagittal rest: abs(ẋ) <= ``speed`` [m/s] and the CoM strictly over the foot (heel, toe).

    ``state`` is a plant's (the CoM position first, its velocity at ``len // 2``; only those
    two are read). It runs at every control tick of a settled run: a float array, a body and
    a Python float pass a few cheap tests; anything else is checked on the slow path.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        If ``state`` is not a one-dimensional array of at least two numbers with a finite
        CoM position and velocity, or ``speed`` is negative or not finite.
    """
    if not (
        type(state) is np.ndarray
        and state.ndim == 1
        and state.shape[0] >= 2
        and type(speed) is float
        and isinstance(params, BodyParams)
    ):
        state, speed = _rest_arguments(state, params, speed)
    x, xdot = float(state[0]), float(state[len(state) // 2])
    if not (math.isfinite(x + xdot + speed) and speed >= 0.0):
        state, speed = _rest_arguments(state, params, speed)
        x, xdot = float(state[0]), float(state[len(state) // 2])  # pragma: no cover - overflow
    return abs(xdot) <= speed and params.heel < x < params.toe


def _rest_arguments(state: object, params: object, speed: object) -> tuple[FloatArray, float]:
    """Check the arguments of :func:`over_foot_at_rest` (its slow path), naming the first bad."""
    require_type("params", params, BodyParams)
    array = float_array("state", state)  # type: ignore[arg-type]
    if array.ndim != 1 or array.shape[0] < 2:
        raise InvalidParameterError(
            f"state must be a one-dimensional array of at least 2 entries, got {array.shape}"
        )
    finite_float("state x", array[0], "m")
    finite_float("state xdot", array[len(array) // 2], "m/s")
    return array, non_negative_float("speed", speed, "m/s")


class PlantBase:
    """The analytic plants' side of the contract: the run's state and records, the template.

    Subclasses implement :meth:`_start` (the state of ``reset``), :meth:`check_state` and
    :meth:`_advance` (one held step of the model, returning the new state and the applied
    inputs); ``step`` keeps the state and builds the :class:`Step`.
    """

    name: ClassVar[str]
    state_labels: ClassVar[tuple[str, ...]]
    input_labels: ClassVar[tuple[str, ...]] = ("cop", "hip_torque")

    def __init__(self, params: BodyParams) -> None:
        require_type("params", params, BodyParams)  # every plant's boundary
        self.params = params
        self.stop_impacts = 0
        self.footholds: list[float] = [0.0]
        self.state: FloatArray = np.zeros(len(self.state_labels))
        self._info_key: tuple[bool, int, int] | None = None
        self._info = StepInfo()

    def _start(self, x: float, xdot: float) -> FloatArray:
        raise NotImplementedError  # pragma: no cover - every plant defines it

    def check_state(self, state: FloatArray) -> None:
        """Raise :class:`InvalidParameterError` if the model cannot start from ``state``."""
        raise NotImplementedError  # pragma: no cover - every plant defines it

    def _advance(self, command: Command, dt: float) -> tuple[FloatArray, tuple[float, ...]]:
        raise NotImplementedError  # pragma: no cover - every plant defines it

    def _restart_records(self) -> None:
        """Clear the run's records (footholds, stop impacts, phase)."""
        self.stop_impacts = 0
        self.footholds = [0.0]

    def _in_stance(self) -> bool:
        """Whether the feet on the ground carry the body (no foot swinging); always, here."""
        return True

    def info(self) -> StepInfo:
        """Return the plant's report of the run so far (contract item 5).

        Kept between steps that change none of it (a new one costs a microsecond a tick).
        """
        key = (self._in_stance(), len(self.footholds), self.stop_impacts)
        if key != self._info_key:
            self._info_key = key
            self._info = StepInfo(key[0], tuple(self.footholds), self.stop_impacts, None)
        return self._info

    def reset(self, x: float, xdot: float) -> FloatArray:
        """Start standing with the CoM at x [m] moving at ẋ [m/s] (contract item 2)."""
        return self.begin(self._start(float(x), float(xdot)))

    def begin(self, state: FloatArray) -> FloatArray:
        """Start a run from ``state``, checked (contract item 3)."""
        state = np.array(state, dtype=np.float64)
        self.check_state(state)
        self._restart_records()
        self.state = state
        return state.copy()

    def apply_push(self, push: Push) -> FloatArray:
        """Add the push's velocity jump to the CoM velocity now (contract item 4).

        Every push is its jump here: ``kind``, ``duration``, ``body`` and ``scheduled`` are
        how MuJoCo applies it.
        """
        state = self.state.copy()
        state[len(state) // 2] += push.delta_velocity
        check_com_state(float(state[0]), float(state[len(state) // 2]), self.params)
        self.state = state
        return state.copy()

    def step(self, command: Command, dt: float) -> Step:
        """Hold ``command`` for ``dt`` [s] (contract item 5).

        The returned state is the plant's own (not copied: a step makes a new array).
        """
        state, applied = self._advance(command, dt)
        self.state = state
        return Step(state, applied, self.info())
