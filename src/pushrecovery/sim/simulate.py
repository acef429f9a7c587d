"""Closed-loop simulation of any plant with any controller, and the critical push."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from pushrecovery.arguments import finite_array, positive_float, require_type
from pushrecovery.control.base import Command, Controller, StepInfo
from pushrecovery.errors import InvalidParameterError, SimulationDiverged, SimulationTimeout
from pushrecovery.models.flywheel.plane import PLANE_STATE_LABELS
from pushrecovery.sim.backend import Audited, Backend, Clocked, PlantBase
from pushrecovery.sim.events import ForcePushing, Observer, ScheduledPush
from pushrecovery.sim.plants import Plant
from pushrecovery.sim.push import Push
from pushrecovery.sim.result import Outcome, SimulationResult, judge

__all__ = ["DEFAULT_CONTROL_PERIOD", "RestCriterion", "check_run", "simulate"]

#: Control period when neither the caller nor the controller sets one [s].
DEFAULT_CONTROL_PERIOD = 1e-3
#: Longest run, in control ticks (memory for the trajectory: 8e7 floats at most).
MAX_STEPS = 10_000_000
#: Longest simulated time of one run [s]: a push is recovered or lost within seconds, and a
#: bisection of runs that never come to rest (a PD without damping) stays within minutes of
#: wall time (docs/reliability.md).
MAX_DURATION = 60.0
#: Largest ω · control_period: beyond it the hold between ticks dominates the dynamics.
MAX_OMEGA_DT = 0.1
#: Which model a controller of each strategy needs, for the error message.
_MODEL_HINTS = {
    "hip": ": it moves the upper body: use the flywheel model (or torso on mujoco)",
    "step": ": it takes steps: use the stepping model (or biped on mujoco)",
}


@dataclass(frozen=True, slots=True)
class RestCriterion:
    """When a run counts as recovered: at rest, standing, unsaturated, for long enough.

    Rest only counts while the controller's command is unsaturated: a CoM resting against a
    CoP pinned to a foot edge may be creeping over it (capture point a hair beyond the edge),
    while an unsaturated command means the controller still has authority in both directions.

    Parameters
    ----------
    speed : float
        Largest abs(ẋ) that counts as at rest [m/s].
    duration : float
        How long the CoM must stay at rest over the support (the plant's ``at_rest``: on the
        sagittal models heel < x < toe) [s].
    """

    speed: float = 1e-3
    duration: float = 0.5


def simulate(
    plant: Plant,
    controller: Controller,
    initial_state: np.ndarray,
    *,
    duration: float = 10.0,
    control_period: float | None = None,
    rest: RestCriterion | None = None,
    push: ScheduledPush | None = None,
    plant_step: float | None = None,
    observers: Sequence[Observer] = (),
    keep_running: tuple[float, float] = (0.0, 0.0),
    wall_limit: float | None = None,
) -> SimulationResult:
    """Simulate ``controller`` on ``plant`` from ``initial_state`` (sampled-data, ZOH).

    The only closed loop of the project. Every ``control_period`` the controller computes a
    command that the plant holds until the next tick, in steps of ``plant_step``; after every
    step the controller observes the plant's report (an analytic plant's report of its start
    too, right after ``reset``: the stance and feet it starts on) and every observer sees the
    step. At the end of each tick the criteria decide: ``fell`` as soon as the state is in the
    plant's absorbing fall set (beyond the fall limit, moving away), ``recovered`` once the CoM
    has stayed at rest over the support with an unsaturated command for ``rest.duration``;
    ``undecided`` if neither happens within ``duration``.

    Parameters
    ----------
    plant : Plant
        The model, behind the backend contract (:mod:`pushrecovery.sim.backend`).
    controller : Controller
        Any controller whose state labels the plant has; ``reset`` is called here.
    initial_state : ndarray
        Start state, e.g. ``[x, xdot]`` just after the push [m, m/s].
    duration : float
        Longest simulated time [s], > 0.
    control_period : float, optional
        Controller period [s], in (0, duration]; default the controller's own
        ``control_period`` (the MPC's dt), else 1 ms.
    rest : RestCriterion, optional
        Recovery criterion; default ``RestCriterion()``.
    push : ScheduledPush, optional
        A push during the run (e.g. after quiet standing): the criteria only count from
        its end, when the controller restarts (unless ``push.react``). A
        :class:`~pushrecovery.sim.push.Push3D` (the 3-D humanoids) is applied as given: now,
        the motors holding, or ``scheduled`` over the following steps.
    plant_step : float, optional
        The plant's step [s] (default: the control period), a whole fraction of it: a
        recorder that samples faster than the controller ticks.
    observers : sequence of Observer
        Called after every plant step.
    keep_running : (float, float)
        Keep simulating this long [s] after the run is decided as recovered, and as fell
        (``math.inf``: to the end of ``duration``); the outcome stays the first decision.
    wall_limit : float, optional
        Wall time the run may take [s], > 0: past it, at the next control tick,
        :class:`~pushrecovery.errors.SimulationTimeout` is raised (a campaign's push limit).

    Returns
    -------
    SimulationResult
        States at every plant step; ``decided_time`` when the outcome was decided. A
        :class:`~pushrecovery.sim.backend.Clocked` plant's own rows and clock instead (MuJoCo's
        time; a row before and one after a push that lasts physics steps of its own).
    """
    state, dt, ticks = check_run(plant, controller, initial_state, duration, control_period)
    h = dt if plant_step is None else positive_float("plant_step", plant_step, "s")
    if h > dt:
        raise InvalidParameterError(f"plant_step must be <= the control period {dt:g} s, got {h:g}")
    if not all(seconds >= 0.0 for seconds in keep_running):  # NaN fails too
        raise InvalidParameterError(
            f"keep_running must be two durations >= 0 s (inf allowed), got {keep_running!r}"
        )
    rest = rest or RestCriterion()
    rest_ticks = max(1, math.ceil(rest.duration / dt - 1e-9))
    # Whole plant steps per tick, rounded tick by tick (a period that is not a multiple of
    # the plant's step keeps the plant's clock on the controller's).
    total = ticks if h == dt else math.ceil(duration / h - 1e-9)
    start = -1 if push is None else round(push.time / h)
    if push is not None and start >= total:
        raise InvalidParameterError(
            f"push time must be before the end of the run, {duration:g} s, got {push.time:g}"
        )
    if (
        push is not None
        and not isinstance(push.push, Push)
        and isinstance(plant, PlantBase | ForcePushing)
        and "z" not in plant.state_labels  # the 3-D humanoids' force lasts steps too
    ):
        raise InvalidParameterError(
            f"a 3-D push (Push3D) needs a 3-D model, got the {plant.name} model: push with a Push"
        )
    deadline = (
        math.inf
        if wall_limit is None
        else time.perf_counter() + positive_float("wall_limit", wall_limit, "s")
    )
    timed = wall_limit is not None
    hold_until = -1  # the plant step at which the push is over
    settled = push is None  # rest counts once the push is over

    state = plant.begin(state)
    states = np.empty((total + 1, len(state)))
    inputs = np.empty((total, len(plant.input_labels)))
    states[0] = state
    # The controller starts from the plant's report of its start (a user's stance and feet).
    observing = type(controller).observe is not Controller.observe
    start_report = plant.info if observing and isinstance(plant, PlantBase) else None
    controller.reset(state)
    if start_report is not None:
        controller.observe(start_report())
    outcome, decided, at_rest = Outcome.UNDECIDED, -1, 0
    info = StepInfo()
    command = Command(float(state[0]))
    tick, next_tick, origin, end, k = 0, 0, 0, total, 0
    # The hot loop (a campaign runs it millions of times): skip what a run does not use.
    per_tick = round(dt / h) if abs(dt / h - round(dt / h)) < 1e-9 else 0  # 0: round per tick
    pushing = push is not None
    # Bound once per run: a tick's attribute lookups are a visible share of its Python.
    compute, step_plant, falling, plant_at_rest = (
        controller.compute, plant.step, plant.falling, plant.at_rest,
    )  # fmt: skip
    speed, undecided = rest.speed, Outcome.UNDECIDED
    # The analytic plants keep no clock of their own (a protocol's isinstance costs 10 µs).
    clocked = not isinstance(plant, PlantBase) and isinstance(plant, Clocked)
    decided_clock = 0.0
    while k < end:
        if pushing and push is not None:
            if k == start:
                state, hold_until = _start_push(plant, push, state, k, h)
                states[k] = state  # a jump changes the state at this instant
            if k == hold_until and not settled:
                settled = True
                if not push.react:  # the controller restarts on the pushed state
                    controller.reset(state)
                    if start_report is not None:
                        controller.observe(start_report())
                    tick, next_tick, origin = 0, k, k
        if not settled and k >= start >= 0 and push is not None and not push.react:
            command = Command(float(state[0]))  # holding still while the force acts
        elif k == next_tick:
            if timed and time.perf_counter() > deadline:
                raise SimulationTimeout(
                    f"the run took more than its wall-time limit of {wall_limit:g} s "
                    f"(simulated {k * h:g} of {duration:g} s)"
                )
            command = compute(tick * dt, state)
            tick += 1
            next_tick = k + per_tick if per_tick else origin + round(tick * dt / h)
        try:
            step = step_plant(command, h)
        except SimulationDiverged:
            if outcome is not Outcome.FELL:
                raise
            break  # a fallen model blew up: the run ends here
        state, info = step.state, step.info
        if observing:
            controller.observe(info)
        inputs[k] = step.applied
        if observers:
            for observer in observers:
                observer.on_step(k, step, command)
        k += 1
        states[k] = state
        if k != next_tick or outcome is not undecided:
            continue  # the criteria are judged at the end of a control tick
        try:
            fell = falling(state)
        except InvalidParameterError:
            if np.isfinite(state).all():
                raise
            # Not the user's input: the model's own numbers broke down (as MuJoCo's warnings).
            raise SimulationDiverged(
                f"the {plant.name} model's state is not finite at t = {k * h:g} s"
            ) from None
        if fell:
            outcome, decided = Outcome.FELL, k
            decided_clock = plant.clock if clocked else k * h  # type: ignore[attr-defined]
            end = min(end, k + _steps_after(keep_running[1], h))
            continue
        resting = settled and not command.saturated and plant_at_rest(state, speed)
        at_rest = at_rest + 1 if resting else 0
        if at_rest >= rest_ticks:
            outcome, decided = Outcome.RECOVERED, k
            decided_clock = plant.clock if clocked else k * h  # type: ignore[attr-defined]
            end = min(end, k + _steps_after(keep_running[0], h))
    if clocked:  # the plant's own rows (a push of its own steps has a row on either side)
        times, states, inputs = plant.run_rows()  # type: ignore[attr-defined]
    else:
        times, states, inputs = np.arange(k + 1, dtype=np.float64) * h, states[: k + 1], inputs[:k]
    # MuJoCo's runs: what every physics step did (a run at rest that slid is slipped).
    physics = None
    if not isinstance(plant, PlantBase) and isinstance(plant, Audited):
        physics = plant.physical_checks()
    return SimulationResult(
        times, states, inputs, judge(outcome, physics), plant.name, controller.name,
        info.stop_impacts, info.footholds, info.footholds_xy, plant.state_labels,
        decided_time=None if decided < 0 else decided_clock, physics=physics,
    )  # fmt: skip


def _steps_after(seconds: float, h: float) -> int:
    """Plant steps in ``seconds`` [s] after a decision (0: stop at once; inf: no limit)."""
    return MAX_STEPS * 1000 if math.isinf(seconds) else round(seconds / h)


def _start_push(
    plant: Plant, push: ScheduledPush, state: np.ndarray, k: int, h: float
) -> tuple[np.ndarray, int]:
    """Start ``push`` at plant step k; return the state and the step at which it is over.

    A force acts over the plant's following steps (the plant tells how long); a jump (and a
    3-D humanoid's push not scheduled, over its own physics steps) is over at once.
    """
    kick = push.push
    if isinstance(kick, Push) and not kick.scheduled:
        kick = replace(kick, scheduled=True)  # the loop holds the body still itself
    pushed = plant.apply_push(kick)  # type: ignore[arg-type]
    left = plant.push_left if isinstance(plant, ForcePushing) else 0.0
    if left > 0.0:  # nothing changes before the next step
        return state, k + max(1, math.ceil(left / h - 1e-9))
    return pushed, k


def check_run(
    plant: Plant,
    controller: Controller,
    initial_state: np.ndarray,
    duration: float,
    control_period: float | None = None,
) -> tuple[np.ndarray, float, int]:
    """Check a run of :func:`simulate` without running it.

    Returns the start state as a float array, the control period [s] and the number of control
    ticks. Raises :class:`InvalidParameterError` naming what is wrong: a non-finite state, a
    controller that needs another model, a period that does not fit the controller, the
    duration or the dynamics; :class:`ParameterTypeError` when ``plant`` or ``controller``
    is not one.
    """
    require_type("plant", plant, Backend)
    require_type("controller", controller, Controller)
    duration = positive_float("duration", duration, "s")
    if duration > MAX_DURATION:
        raise InvalidParameterError(
            f"duration must be in (0, {MAX_DURATION:g}] s, got duration={duration:g}"
        )
    if control_period is None:
        control_period = controller.control_period or DEFAULT_CONTROL_PERIOD
    elif controller.fixed_period and control_period != controller.control_period:
        raise InvalidParameterError(
            f"controller {controller.name!r} predicts with its own period "
            f"{controller.control_period:g} s; control_period must match it, got {control_period:g}"
        )
    dt = positive_float("control_period", control_period, "s")
    if dt > duration:
        raise InvalidParameterError(
            f"control_period must be <= duration = {duration:g} s, got {dt:g}"
        )
    state = finite_array("initial_state", initial_state).copy()
    if state.ndim != 1:  # its length is the plant's to check (check_state names the labels)
        raise InvalidParameterError(
            f"initial_state must be a 1-D array of {list(plant.state_labels)}, "
            f"got shape {state.shape}"
        )
    plant.check_state(state)
    missing = [label for label in controller.state_labels if label not in plant.state_labels]
    if missing:
        hint = (
            _MODEL_HINTS.get(controller.strategy, "")
            if controller.state_labels != (PLANE_STATE_LABELS)
            else ": use the stepping-plane model"
        )
        raise InvalidParameterError(
            f"controller {controller.name!r} needs the state {list(controller.state_labels)}, "
            f"which model {plant.name!r} {list(plant.state_labels)} lacks{hint}"
        )
    ratio = duration / dt  # +inf for a subnormal period: compared before any rounding
    if ratio - 1e-9 > MAX_STEPS:
        raise InvalidParameterError(
            f"duration / control_period must be <= {MAX_STEPS:g} steps, got {ratio:g}"
        )
    steps = math.ceil(ratio - 1e-9)
    if plant.params.omega * dt > MAX_OMEGA_DT:
        raise InvalidParameterError(
            f"control_period must be <= {MAX_OMEGA_DT:g} / omega = "
            f"{MAX_OMEGA_DT / plant.params.omega:g} s for a faithful sampled-data loop, "
            f"got {dt:g}"
        )
    return state, dt, steps
