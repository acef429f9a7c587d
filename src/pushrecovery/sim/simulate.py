"""Closed-loop simulation of any plant with any controller, and the critical push."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pushrecovery._validate import finite_float, positive_float
from pushrecovery.control.base import Controller, StepInfo
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel_plane import PLANE_STATE_LABELS
from pushrecovery.sim.plane_stepping import PlaneSteppingPlant
from pushrecovery.sim.plants import Plant
from pushrecovery.sim.result import Outcome, SimulationResult

__all__ = ["DEFAULT_CONTROL_PERIOD", "RestCriterion", "check_run", "simulate"]

#: Control period when neither the caller nor the controller sets one [s].
DEFAULT_CONTROL_PERIOD = 1e-3
#: Longest run, in control ticks (memory for the trajectory: 8e7 floats at most).
MAX_STEPS = 10_000_000
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
        Largest |ẋ| that counts as at rest [m/s].
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
) -> SimulationResult:
    """Simulate ``controller`` on ``plant`` from ``initial_state`` (sampled-data, ZOH).

    Every ``control_period`` the controller computes a command that the plant holds until the
    next tick. The run ends as ``fell`` as soon as the CoM is beyond the plant's fall limit and
    moving away from the foot (:func:`~pushrecovery.sim.result.is_falling`, an absorbing set),
    as ``recovered`` once the CoM has stayed at rest over the foot with an unsaturated command
    for ``rest.duration``, and as ``undecided`` if neither happens within ``duration``.

    Parameters
    ----------
    plant : Plant
        The model (see :mod:`pushrecovery.sim.plants`).
    controller : Controller
        Any controller; ``reset`` is called here.
    initial_state : ndarray
        Start state, e.g. ``[x, xdot]`` just after the push [m, m/s].
    duration : float
        Longest simulated time [s], > 0.
    control_period : float, optional
        Controller period [s], in (0, duration]; default the controller's own
        ``control_period`` (the MPC's dt), else 1 ms.
    rest : RestCriterion, optional
        Recovery criterion; default ``RestCriterion()``.

    Returns
    -------
    SimulationResult
    """
    state, dt, steps = check_run(plant, controller, initial_state, duration, control_period)
    rest = rest or RestCriterion()
    state = plant.begin(state)
    rest_ticks = max(1, math.ceil(rest.duration / dt - 1e-9))

    states = np.empty((steps + 1, len(state)))
    inputs = np.empty((steps, len(plant.input_labels)))
    states[0] = state
    controller.reset(state)
    outcome, at_rest, k = Outcome.UNDECIDED, 0, 0
    info = StepInfo()
    while k < steps:
        command = controller.compute(k * dt, state)
        step = plant.step(command, dt)
        state, info = step.state, step.info
        controller.observe(info)
        inputs[k] = step.applied
        k += 1
        states[k] = state
        if plant.falling(state):
            outcome = Outcome.FELL
            break
        resting = not command.saturated and plant.at_rest(state, rest.speed)
        at_rest = at_rest + 1 if resting else 0
        if at_rest >= rest_ticks:
            outcome = Outcome.RECOVERED
            break
    return SimulationResult(
        time=np.arange(k + 1, dtype=np.float64) * dt,
        states=states[: k + 1],
        inputs=inputs[:k],
        outcome=outcome,
        model=plant.name,
        controller=controller.name,
        stop_impacts=info.stop_impacts,
        footholds=info.footholds,
        footholds_xy=(tuple(plant.footholds_xy) if isinstance(plant, PlaneSteppingPlant) else ()),
        state_labels=plant.state_labels,
    )


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
    duration or the dynamics.
    """
    duration = positive_float("duration", duration, "s")
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
    state = np.array(initial_state, dtype=np.float64)
    for i, value in enumerate(state):
        finite_float(f"initial_state[{i}]", value)
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
    steps = math.ceil(duration / dt - 1e-9)
    if steps > MAX_STEPS:
        raise InvalidParameterError(
            f"duration / control_period must be <= {MAX_STEPS:g} steps, got {steps:g}"
        )
    if plant.params.omega * dt > MAX_OMEGA_DT:
        raise InvalidParameterError(
            f"control_period must be <= {MAX_OMEGA_DT:g} / omega = "
            f"{MAX_OMEGA_DT / plant.params.omega:g} s for a faithful sampled-data loop, "
            f"got {dt:g}"
        )
    return state, dt, steps
