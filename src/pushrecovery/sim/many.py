"""Many pushes of one (model, controller) pair: one entry point, its engine chosen per pair.

As scipy's ``solve_ivp`` chooses a method, :func:`run_many` runs each push through
:func:`~pushrecovery.sim.simulate.simulate` (the ``loop`` engine) or, where the pair has one,
through a faster engine that gives the loop's numbers to the bit (each has its test against the
loop): ``compiled`` (:mod:`pushrecovery.sim.batched`: the pendulum and LIPM under ankle-pd,
Sec. IV's stepping model under recovery) and ``rollout`` (:mod:`pushrecovery.sim.mujoco.rollout`:
MuJoCo's foot under ankle-pd). A push is the CoM standing still at x0 [m] given the velocity
ẋ [m/s] (analytic: a jump; MuJoCo: the force at the CoM delivering m ẋ over 10 ms).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_array, require_type
from pushrecovery.errors import (
    InvalidParameterError,
    ParameterTypeError,
    SimulationDiverged,
    SimulationTimeout,
)
from pushrecovery.params import BodyParams
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.result import Outcome

__all__ = ["COMPILED", "DIVERGED", "ENGINES", "LOOP_UP_TO", "ROLLOUT", "PushRuns", "run_many"]

#: The engines: ``auto`` picks the fastest one the pair has.
ENGINES = ("auto", "loop", "compiled", "rollout")
#: (model, controller) pairs of the analytic backend with a compiled loop (``sim.batched``).
COMPILED = frozenset({("pendulum", "ankle-pd"), ("lipm", "ankle-pd"), ("stepping", "recovery")})
#: (model, controller) pairs of the MuJoCo backend that ``mujoco.rollout`` runs.
ROLLOUT = frozenset({("foot", "ankle-pd")})
#: ``auto`` runs at most this many ``ankle-pd`` pushes through the loop, not the compiled batch:
#: loading the compiled loop (numba's typing machinery, the MPC modules) takes about a second,
#: as long as ~100 pushes through the loop (~10 ms each). The numbers are the same either way.
LOOP_UP_TO = 32
#: The error of a run whose state stopped being finite in a compiled engine.
DIVERGED = "the physics diverged: a state is not finite"


@dataclass(frozen=True, slots=True)
class PushRuns:
    """What :func:`run_many` gives, one entry per push, in order.

    Attributes
    ----------
    outcomes : tuple of Outcome
        Recovered, fell or undecided (as ``SimulationResult.outcome``).
    times : ndarray
        Simulated time at which the run ended: its outcome decided, or the duration [s].
    cop_min, cop_max : ndarray
        Excursion of the CoP the plant applied over the run, relative to the ankle [m] (NaN
        for a run with no step).
    steps : ndarray of int
        Feet that landed (0 without legs).
    peak_hip_torque : ndarray
        Largest abs(hip torque) applied [N m] (0 without an upper body).
    stop_impacts : ndarray of int
        Times the upper body hit its joint stop.
    errors : tuple of str or None
        Why a run has no outcome (the physics diverged, it outran ``push_timeout``); None for
        a run that has one. The other entries of such a run are not to be used.
    engine : str
        The engine that ran the pushes (one of :data:`ENGINES` but ``auto``).
    physics : tuple of PhysicalChecks or None
        Each MuJoCo run's physical checks (``SimulationResult.physics``; its outcome judged
        by them); None on the analytic models, in the ``compiled`` and ``rollout`` engines
        (which do not audit contacts) and for a run with an error. Empty: all None.
    """

    outcomes: tuple[Outcome, ...]
    times: NDArray[np.float64]
    cop_min: NDArray[np.float64]
    cop_max: NDArray[np.float64]
    steps: NDArray[np.int64]
    peak_hip_torque: NDArray[np.float64]
    stop_impacts: NDArray[np.int64]
    errors: tuple[str | None, ...]
    engine: str
    physics: tuple[PhysicalChecks | None, ...] = ()

    def checks(self, k: int) -> PhysicalChecks | None:
        """Return push k's physical checks (None: not audited)."""
        return self.physics[k] if self.physics else None


def run_many(
    model: str,
    controller: str,
    bodies: Sequence[BodyParams],
    x0: Sequence[float],
    xdot: Sequence[float],
    *,
    duration: float,
    backend: str = "analytic",
    engine: str = "auto",
    push_timeout: float | None = None,
    on_start: Callable[[int], None] | None = None,
    latency: float = 0.0,
) -> PushRuns:
    """Simulate ``controller`` on ``model`` after each push (x0[i], xdot[i]) on bodies[i].

    Parameters
    ----------
    model, controller : str
        The plant (``sim.registry``) and the controller (``control.registry``), by name.
    bodies : sequence of BodyParams
        Each push's body.
    x0, xdot : sequence of float
        CoM position before the push [m] and the velocity it gives [m/s], relative to the
        ankle, + forward.
    duration : float
        Longest simulated time per push [s], in (0, 60].
    backend : {"analytic", "mujoco"}
        The physics.
    engine : str
        One of :data:`ENGINES`. ``auto``: ``compiled`` for the pairs of :data:`COMPILED`
        (``ankle-pd`` only from :data:`LOOP_UP_TO` + 1 pushes on), ``rollout`` for those of
        :data:`ROLLOUT`, else ``loop``.
    push_timeout : float, optional
        The loop's wall-time limit per push [s] (a run over it is an error, the others go on);
        the compiled engines' runs are bounded by ``duration``.
    on_start : callable, optional
        Called with the number of pushes about to run as one unit, before each (the loop: 1;
        ``rollout``: the whole batch): a campaign arms its watchdog there.
    latency : float
        The controller reacts this late after the push [s], in [0, 1], the CoP held at the
        foot's middle meanwhile (:func:`~pushrecovery.control.delay.reaction_delay`); above 0
        the pushes run through the loop.

    Returns
    -------
    PushRuns
        One entry per push, in order; a push whose physics diverged or timed out has its
        ``errors`` entry, and the others go on.

    Raises
    ------
    ParameterTypeError
        A name that is not a str; ``bodies``, ``x0`` or ``xdot`` not a sequence.
    InvalidParameterError
        An unknown engine, or one the pair does not have; sequences of different lengths;
        the checks of the plant, the controller and the loop.
    """
    for name, text in (("model", model), ("controller", controller), ("backend", backend),
                       ("engine", engine)):  # fmt: skip
        require_type(name, text, str)
    for name, value in (("bodies", bodies), ("x0", x0), ("xdot", xdot)):
        scalar = isinstance(value, np.ndarray) and value.ndim == 0
        if isinstance(value, str) or not isinstance(value, Sequence | np.ndarray) or scalar:
            raise ParameterTypeError(
                f"{name} must be a sequence (one entry per push), got {type(value).__name__}"
            )
    count = len(bodies)
    # One number per push: the engines index them (a 0-d array has no length).
    starts, speeds = finite_array("x0", x0), finite_array("xdot", xdot)
    if starts.ndim != 1 or speeds.ndim != 1:
        raise InvalidParameterError("x0 and xdot must be one number per push")
    if len(starts) != count or len(speeds) != count:
        raise InvalidParameterError(
            f"bodies, x0 and xdot must have one entry per push, got {count}, {len(x0)}, {len(xdot)}"
        )
    latency = bounded_float("latency", latency, 0.0, 1.0, "s")
    if on_start is not None and not callable(on_start):
        raise ParameterTypeError(f"on_start must be callable, got {type(on_start).__name__}")
    chosen = (
        "loop"
        if latency > 0.0 and engine == "auto"
        else _engine(engine, model, controller, backend, count)
    )
    if latency > 0.0 and chosen != "loop":
        raise InvalidParameterError(f"a latency runs through the loop, not the {chosen!r} engine")
    if chosen == "compiled":
        return _compiled(model, controller, bodies, x0, xdot, duration)
    if chosen == "rollout":
        if on_start is not None:
            on_start(count)
        return _rollout(bodies, x0, xdot, duration)
    return _loop(
        model, controller, bodies, x0, xdot, duration, backend, push_timeout, on_start, latency
    )


def _engine(engine: str, model: str, controller: str, backend: str, count: int) -> str:
    if not isinstance(engine, str) or engine not in ENGINES:
        raise InvalidParameterError(f"engine must be one of {list(ENGINES)}, got {engine!r}")
    pair = (model, controller)
    compiled = backend == "analytic" and pair in COMPILED
    rollout = backend == "mujoco" and pair in ROLLOUT
    if engine == "auto":
        if compiled and not (controller == "ankle-pd" and count <= LOOP_UP_TO):
            return "compiled"
        return "rollout" if rollout else "loop"
    if (engine == "compiled" and not compiled) or (engine == "rollout" and not rollout):
        raise InvalidParameterError(
            f"engine {engine!r} does not run {model} + {controller} on the {backend} backend"
        )
    return engine


def _compiled(
    model: str,
    controller: str,
    bodies: Sequence[BodyParams],
    x0: Sequence[float],
    xdot: Sequence[float],
    duration: float,
) -> PushRuns:
    from pushrecovery.sim.batched import ankle_pd_pushes, recovery_pushes

    if controller == "recovery":
        return recovery_pushes(bodies, x0, xdot, duration=duration)
    return ankle_pd_pushes(model, bodies, x0, xdot, duration=duration)


def _rollout(
    bodies: Sequence[BodyParams], x0: Sequence[float], xdot: Sequence[float], duration: float
) -> PushRuns:
    """One ``mujoco.rollout`` call per body, its pushes in order; the runs in push order."""
    from pushrecovery.sim.mujoco.rollout import ankle_pd_rollout

    members: dict[BodyParams, list[int]] = {}
    for k, body in enumerate(bodies):
        members.setdefault(body, []).append(k)
    count = len(bodies)
    outcomes: list[Outcome] = [Outcome.UNDECIDED] * count
    times, cop_min, cop_max = np.empty(count), np.empty(count), np.empty(count)
    diverged = np.zeros(count, dtype=np.bool_)
    for body, ks in members.items():
        runs = ankle_pd_rollout(body, [x0[k] for k in ks], [xdot[k] for k in ks], duration=duration)
        for j, k in enumerate(ks):
            outcomes[k] = runs.outcomes[j]
        times[ks], cop_min[ks], cop_max[ks], diverged[ks] = (
            runs.times, runs.cop_min, runs.cop_max, runs.diverged,
        )  # fmt: skip
    zeros = np.zeros(count, dtype=np.int64)
    errors = tuple(DIVERGED if d else None for d in diverged.tolist())
    return PushRuns(
        tuple(outcomes), times, cop_min, cop_max, zeros, np.zeros(count), zeros, errors, "rollout"
    )


def _loop(
    model: str,
    controller: str,
    bodies: Sequence[BodyParams],
    x0: Sequence[float],
    xdot: Sequence[float],
    duration: float,
    backend: str,
    push_timeout: float | None,
    on_start: Callable[[int], None] | None,
    latency: float = 0.0,
) -> PushRuns:
    """Each push through ``simulate``; one plant and controller per body (MuJoCo compiles one)."""
    from pushrecovery.control.base import make_controller
    from pushrecovery.control.delay import reaction_delay
    from pushrecovery.sim.critical import pushed_state
    from pushrecovery.sim.registry import make_plant
    from pushrecovery.sim.simulate import simulate

    count = len(bodies)
    outcomes: list[Outcome] = [Outcome.UNDECIDED] * count
    times, cop_min, cop_max = np.full(count, math.nan), np.empty(count), np.empty(count)
    steps, stops = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    peaks = np.zeros(count)
    errors: list[str | None] = [None] * count
    physics: list[PhysicalChecks | None] = [None] * count
    cache: dict[BodyParams, tuple[Any, Any]] = {}
    for k, body in enumerate(bodies):
        if on_start is not None:
            on_start(1)
        if body not in cache:
            made = make_controller(controller, body)
            if latency > 0.0:
                made = reaction_delay(made, latency)
            cache[body] = (make_plant(model, body, backend), made)
        plant, control = cache[body]
        state = pushed_state(plant, x0[k], xdot[k], force=backend == "mujoco")
        try:
            run = simulate(plant, control, state, duration=duration, wall_limit=push_timeout)
        except SimulationDiverged as exc:  # this push only: the others go on
            del cache[body]  # the engine's state is not to be trusted any more
            errors[k] = f"the physics diverged: {exc}"
            continue
        except SimulationTimeout as exc:
            del cache[body]  # stopped mid-run: the next push starts from a fresh engine
            errors[k] = f"too slow: {exc}"
            continue
        cops = run.cops
        outcomes[k] = run.outcome
        times[k] = float(run.time[-1])
        cop_min[k] = float(cops.min()) if cops.size else math.nan
        cop_max[k] = float(cops.max()) if cops.size else math.nan
        steps[k], peaks[k], stops[k] = len(run.footholds) - 1, run.peak_hip_torque, run.stop_impacts
        physics[k] = run.physics
    return PushRuns(
        tuple(outcomes), times, cop_min, cop_max, steps, peaks, stops, tuple(errors), "loop",
        tuple(physics),
    )  # fmt: skip
