"""Simulate the pushes of one batch and record each as one row (runs on the workers).

Every row records the push's inputs, what the paper's surfaces predict for the state just after
it, and what the simulation did: a ``dict`` from column name to value, the columns of
:mod:`.rows` (whose :func:`~.rows.row_schema` gives each one's unit and description; positions
relative to the stance ankle). A push without an outcome (its physics diverged, it was too
slow, its worker died) is an error row (:func:`error_row`): ``outcome`` = ``used`` = error, the
simulated columns NaN (counts 0), ``error`` saying why.

The 3-D models (``biped3d``, ``g1``) add columns, null on the others, and read some of them in
3-D (:mod:`.pushes3d`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pushrecovery.campaign import watchdog
from pushrecovery.campaign.pushes3d import error_row3d, run_push3d
from pushrecovery.campaign.rows import COLUMNS, COLUMNS_3D, ERROR_OUTCOME
from pushrecovery.campaign.spec import COMPILED_BATCH, CampaignSpec, Push
from pushrecovery.control.base import make_controller
from pushrecovery.errors import SimulationDiverged, SimulationTimeout
from pushrecovery.params import BodyParams
from pushrecovery.sim.critical import pushed_state
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.result import Outcome, strategy_used
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import (
    STRATEGY_CODES,
    Strategy,
    sagittal_verdicts,
)

if TYPE_CHECKING:
    from pushrecovery.sim.batched import BatchedRuns

__all__ = [
    "COLUMNS",
    "ERROR_OUTCOME",
    "LOOP_UP_TO",
    "ROLLOUT",
    "error_row",
    "run_batch",
    "run_push",
]

#: (model, controller) pairs of the MuJoCo backend simulated in lockstep with mujoco.rollout.
ROLLOUT = frozenset({("foot", "ankle-pd")})
#: A campaign of at most this many pushes of ``ankle-pd`` on ``pendulum`` or ``lipm`` runs
#: them through the one-push loop, not the compiled batch: loading the compiled loop (numba's
#: typing machinery, ``sim.batched`` and the MPC modules it imports) takes about a second, as
#: long as ~100 pushes through the loop (~10 ms each). The rows are the same to the bit either
#: way (tests/test_batched.py).
LOOP_UP_TO = 32


def run_push(
    spec: CampaignSpec, push: Push, cache: dict[BodyParams, Any] | None = None
) -> dict[str, Any]:
    """Simulate one push; return its row (module docstring).

    ``cache`` keeps one plant and controller per body across the pushes of a batch (MuJoCo
    compiles a model per plant).
    """
    cache = {} if cache is None else cache
    if spec.is_3d:
        return run_push3d(spec, push, cache)
    if push.params not in cache:
        cache[push.params] = (
            make_plant(spec.model, push.params, spec.backend),
            make_controller(spec.controller, push.params),
        )
    plant, controller = cache[push.params]
    state = pushed_state(plant, push.x0, push.xdot, force=spec.backend == "mujoco")
    try:
        run = simulate(
            plant, controller, state, duration=spec.duration, wall_limit=spec.push_timeout
        )
    except SimulationDiverged as exc:  # this push only: the others of the batch go on
        del cache[push.params]  # the engine's state is not to be trusted any more
        return error_row(spec, push, f"the physics diverged: {exc}")
    except SimulationTimeout as exc:
        del cache[push.params]  # stopped mid-run: start the next push from a fresh engine
        return error_row(spec, push, f"too slow: {exc}")
    cops = run.cops
    return _row(
        spec,
        push,
        _Simulated(
            outcome=run.outcome,
            used=run.strategy_used() if run.recovered else Strategy.FALL,
            steps=len(run.footholds) - 1,
            peak_hip_torque=run.peak_hip_torque,
            cop_min=float(cops.min()) if cops.size else math.nan,
            cop_max=float(cops.max()) if cops.size else math.nan,
            time=float(run.time[-1]),
            stop_impacts=run.stop_impacts,
        ),
    )


@dataclass(frozen=True, slots=True)
class _Simulated:
    """What a run gives a row (either loop: one push, or the compiled batch)."""

    outcome: Outcome
    used: Strategy
    steps: int
    peak_hip_torque: float
    cop_min: float
    cop_max: float
    time: float
    stop_impacts: int


@dataclass(frozen=True, slots=True)
class _Prediction:
    """What the surfaces predict for a push (the sagittal verdict of ``classify``)."""

    strategy: Strategy
    capture_point: float
    cop_margin: float
    cmp_margin: float
    step_margin: float
    steps: int | None


def _predictions(pushes: list[Push]) -> list[_Prediction]:
    """Return the pushes' verdicts: one vectorised call per body (no plans needed)."""
    found: list[_Prediction | None] = [None] * len(pushes)
    bodies: dict[BodyParams, list[int]] = {}
    for k, push in enumerate(pushes):
        bodies.setdefault(push.params, []).append(k)
    for params, members in bodies.items():
        verdicts = sagittal_verdicts(
            [pushes[k].x0 for k in members], [pushes[k].xdot for k in members], params
        )
        for j, k in enumerate(members):
            found[k] = _Prediction(
                verdicts.strategies[j],
                float(verdicts.capture_point[j]),
                float(verdicts.cop_margin[j]),
                float(verdicts.cmp_margin[j]),
                float(verdicts.line.margin[j]),
                verdicts.steps(j),
            )
    return [f for f in found if f is not None]


def _row(
    spec: CampaignSpec, push: Push, run: _Simulated, found: _Prediction | None = None
) -> dict[str, Any]:
    """Return the row of a simulated push: inputs, prediction and run (module docstring)."""
    peak_cop = max(abs(run.cop_min), abs(run.cop_max))
    row = _inputs_and_prediction(spec, push, found or _predictions([push])[0])
    row.update(
        outcome=run.outcome.value,
        used=run.used.value,
        steps=run.steps,
        peak_hip_torque=run.peak_hip_torque,
        peak_ankle_torque=push.params.weight * peak_cop if math.isfinite(peak_cop) else 0.0,
        cop_min=run.cop_min,
        cop_max=run.cop_max,
        time=run.time,
        stop_impacts=run.stop_impacts,
        error=None,
    )
    return row


def _inputs_and_prediction(spec: CampaignSpec, push: Push, found: _Prediction) -> dict[str, Any]:
    """Return the columns of a row that do not depend on the run: the push and its verdict."""
    # STRATEGY_CODES escalates: a controller of one strategy recovers the lesser's pushes.
    reach = STRATEGY_CODES.index(Strategy(spec.strategy))
    row: dict[str, Any] = {
        f"param_{name}": value for name, value in zip(spec.sweeps, push.swept, strict=True)
    }
    row.update(
        index=push.index,
        x0=push.x0,
        xdot=push.xdot,
        impulse=push.impulse,
        predicted=found.strategy.value,
        capture_point=found.capture_point,
        cop_margin=found.cop_margin,
        cmp_margin=found.cmp_margin,
        step_margin=found.step_margin,
        predicted_steps=-1 if found.steps is None else found.steps,
        predicted_recovers=STRATEGY_CODES.index(found.strategy) <= reach,
    )
    row.update(_NULL_3D)  # every row has every column
    return row


#: The 3-D columns of a planar row: null.
_NULL_3D: dict[str, Any] = dict.fromkeys(COLUMNS_3D)


def _batched_rows(spec: CampaignSpec, pushes: list[Push]) -> list[dict[str, Any]]:
    """Rows of pushes simulated together in a compiled loop (:mod:`pushrecovery.sim.batched`)."""
    from pushrecovery.sim.batched import ankle_pd_pushes, recovery_pushes

    bodies = [p.params for p in pushes]
    starts, speeds = [p.x0 for p in pushes], [p.xdot for p in pushes]
    if spec.controller == "recovery":
        runs = recovery_pushes(bodies, starts, speeds, duration=spec.duration)
    else:
        runs = ankle_pd_pushes(spec.model, bodies, starts, speeds, duration=spec.duration)
    return _rows_of_runs(spec, pushes, runs)


def _rollout_rows(spec: CampaignSpec, pushes: list[Push]) -> list[dict[str, Any]]:
    """Rows of MuJoCo pushes simulated in lockstep (:mod:`pushrecovery.sim.mujoco.rollout`).

    One call per body, the pushes of each in batch order; the rows in push order.
    """
    import numpy as np

    from pushrecovery.sim.batched import BatchedRuns
    from pushrecovery.sim.mujoco.rollout import ankle_pd_rollout

    bodies: dict[BodyParams, list[int]] = {}
    for k, push in enumerate(pushes):
        bodies.setdefault(push.params, []).append(k)
    count = len(pushes)
    outcomes: list[Outcome] = [Outcome.UNDECIDED] * count
    times, cop_min, cop_max = np.empty(count), np.empty(count), np.empty(count)
    diverged = np.zeros(count, dtype=np.bool_)
    for params, members in bodies.items():
        runs = ankle_pd_rollout(
            params,
            [pushes[k].x0 for k in members],
            [pushes[k].xdot for k in members],
            duration=spec.duration,
        )
        for j, k in enumerate(members):
            outcomes[k] = runs.outcomes[j]
        times[members], cop_min[members] = runs.times, runs.cop_min
        cop_max[members], diverged[members] = runs.cop_max, runs.diverged
    zeros = np.zeros(count, dtype=np.int64)
    batched = BatchedRuns(
        tuple(outcomes), times, cop_min, cop_max, zeros, np.zeros(count), zeros, diverged
    )
    return _rows_of_runs(spec, pushes, batched)


def _rows_of_runs(
    spec: CampaignSpec, pushes: list[Push], runs: BatchedRuns
) -> list[dict[str, Any]]:
    """Rows of pushes simulated together: each run's outcome with the push's verdict."""
    rows = []
    predictions = _predictions(pushes)
    # Python floats and ints, as float(a[k]) and int(a[k]) give them (tolist: at C speed).
    diverged, steps, peaks = (
        runs.diverged.tolist(),
        runs.steps.tolist(),
        runs.peak_hip_torque.tolist(),
    )
    lows, highs, times = runs.cop_min.tolist(), runs.cop_max.tolist(), runs.times.tolist()
    impacts = runs.stop_impacts.tolist()
    for k, push in enumerate(pushes):
        if diverged[k]:
            rows.append(error_row(spec, push, "the physics diverged: a state is not finite"))
            continue
        outcome = runs.outcomes[k]
        used = strategy_used(steps[k], peaks[k]) if outcome is Outcome.RECOVERED else Strategy.FALL
        run = _Simulated(outcome, used, steps[k], peaks[k], lows[k], highs[k], times[k], impacts[k])
        rows.append(_row(spec, push, run, predictions[k]))
    return rows


def error_row(spec: CampaignSpec, push: Push, reason: str) -> dict[str, Any]:
    """Return the row of a push without an outcome: the prediction, ``outcome`` = error.

    The simulated columns are NaN (counts 0), ``used`` is ``error`` and ``error`` says why.
    """
    if spec.is_3d:
        return error_row3d(spec, push, reason)
    row = _inputs_and_prediction(spec, push, _predictions([push])[0])
    row.update(ERROR_OUTCOME, error=reason)
    return row


def run_batch(spec: CampaignSpec, batch: int) -> tuple[int, list[dict[str, Any]]]:
    """Simulate batch number ``batch`` of ``spec``; return it with its rows, in push order.

    numba's parallel kernels run on one thread meanwhile: a push queries one state at a time,
    and with one worker per core, more threads per worker only compete for the cores (we saw
    a push whose 102 step queries take 0.04 s take 0.8 s on a busy machine).
    """
    from pushrecovery.kernels.threads import one_thread

    with one_thread():
        try:
            pushes = spec.pushes(batch)
            # COMPILED_BATCH names sim.batched.BATCHED's pairs (a test checks), so that the
            # other campaigns do not import that module (the MPC and its kernels with it).
            pair = (spec.model, spec.controller)
            small = spec.size <= LOOP_UP_TO and spec.controller == "ankle-pd"
            if spec.backend == "analytic" and pair in COMPILED_BATCH and not small:
                return batch, _batched_rows(spec, pushes)
            if spec.backend == "mujoco" and (spec.model, spec.controller) in ROLLOUT:
                # The whole batch at once: the pushes' time limits add up.
                watchdog.arm(spec.push_timeout * len(pushes))
                return batch, _rollout_rows(spec, pushes)
            cache: dict[BodyParams, Any] = {}
            rows = []
            for push in pushes:
                watchdog.arm(spec.push_timeout)
                rows.append(run_push(spec, push, cache))
            return batch, rows
        finally:
            watchdog.disarm()
