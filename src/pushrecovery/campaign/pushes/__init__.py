"""Simulate the pushes of one batch and record each as one row (runs on the workers).

Every row records the push's inputs, what the paper's surfaces predict for the state just after
it, and what the simulation did: a ``dict`` from column name to value, the columns of
:mod:`pushrecovery.campaign.rows` (whose :func:`~pushrecovery.campaign.rows.row_schema`
gives each one's unit and description; positions relative to the stance ankle). A push
without an outcome (its physics diverged, it was too slow, its worker died) is an error row
(:func:`error_row`): ``outcome`` = ``used`` = error, the simulated columns NaN (counts 0),
``error`` saying why.

The 3-D models (``biped3d``, ``g1``) add columns, null on the others, and read some of them in
3-D (:mod:`~pushrecovery.campaign.pushes.humanoid`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pushrecovery.arguments import require_type, whole_number
from pushrecovery.campaign import watchdog
from pushrecovery.campaign.estimates import estimate_columns
from pushrecovery.campaign.pushes.humanoid import error_row3d, run_push3d
from pushrecovery.campaign.rows import (
    COLUMNS,
    COLUMNS_3D,
    COLUMNS_PHYSICS,
    ERROR_OUTCOME,
    physics_columns,
    used_label,
    verdict_columns,
)
from pushrecovery.campaign.spec import CampaignSpec, Push
from pushrecovery.errors import ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.sim.many import COMPILED, LOOP_UP_TO, PushRuns, run_many
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.result import Outcome, strategy_used
from pushrecovery.surfaces.classify import (
    Strategy,
    sagittal_verdicts,
)

__all__ = [
    "COLUMNS",
    "ERROR_OUTCOME",
    "error_row",
    "push_rows",
    "run_batch",
    "run_push",
]


def run_push(spec: CampaignSpec, push: Push) -> dict[str, Any]:
    """Simulate one push through the one-push loop; return its row (module docstring)."""
    require_type("spec", spec, CampaignSpec)
    require_type("push", push, Push)
    return push_rows(spec, [push], engine="loop")[0]


def push_rows(
    spec: CampaignSpec,
    pushes: list[Push],
    *,
    engine: str = "auto",
    on_start: Callable[[int], None] | None = None,
) -> list[dict[str, Any]]:
    """Simulate ``pushes`` of ``spec`` with one engine; return their rows, in order.

    ``engine`` is :func:`~pushrecovery.sim.many.run_many`'s (the 3-D models run the loop);
    the pushes share one plant and controller per body, as a batch does. ``on_start`` is
    called with the number of pushes about to run as one unit (a worker arms its watchdog).
    """
    require_type("spec", spec, CampaignSpec)
    if not isinstance(pushes, list) or not all(isinstance(p, Push) for p in pushes):
        raise ParameterTypeError("pushes must be a list of Push")
    require_type("engine", engine, str)
    if on_start is not None and not callable(on_start):
        raise ParameterTypeError(f"on_start must be callable, got {type(on_start).__name__}")
    if spec.is_3d:
        cache: dict[BodyParams, Any] = {}  # one compiled plant per body
        rows = []
        for push in pushes:
            if on_start is not None:
                on_start(1)
            rows.append(run_push3d(spec, push, cache))
        return rows
    runs = run_many(
        spec.model, spec.controller, [p.params for p in pushes], [p.x0 for p in pushes],
        [p.xdot for p in pushes], duration=spec.duration, backend=spec.backend,
        engine="loop" if spec.latency > 0.0 else engine, push_timeout=spec.push_timeout,
        on_start=on_start, latency=spec.latency,
    )  # fmt: skip
    return _rows_of_runs(spec, pushes, runs)


@dataclass(frozen=True, slots=True)
class _Simulated:
    """What a run gives a row (either loop: one push, or the compiled batch)."""

    outcome: Outcome
    used: str  # a Strategy's value, or the outcome of a run that is neither recovered nor fell
    steps: int
    peak_hip_torque: float
    cop_min: float
    cop_max: float
    time: float
    stop_impacts: int
    physics: PhysicalChecks | None = None


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
        used=run.used,
        steps=run.steps,
        peak_hip_torque=run.peak_hip_torque,
        peak_ankle_torque=push.params.weight * peak_cop if math.isfinite(peak_cop) else 0.0,
        cop_min=run.cop_min,
        cop_max=run.cop_max,
        time=run.time,
        stop_impacts=run.stop_impacts,
        error=None,
        **physics_columns(run.physics),
    )
    return row


def _inputs_and_prediction(spec: CampaignSpec, push: Push, found: _Prediction) -> dict[str, Any]:
    """Return the columns of a row that do not depend on the run: the push and its verdict."""
    margins = (found.cop_margin, found.cmp_margin, found.step_margin)
    row = verdict_columns(
        spec, push, push.x0, found.strategy, found.capture_point, margins, found.steps
    )
    row.update(_NULL_3D)  # every row has every column
    return row


#: The 3-D columns of a planar row, and the physical checks until a MuJoCo run fills them: null.
_NULL_3D: dict[str, Any] = dict.fromkeys(COLUMNS_3D + COLUMNS_PHYSICS)


def _rows_of_runs(spec: CampaignSpec, pushes: list[Push], runs: PushRuns) -> list[dict[str, Any]]:
    """Rows of simulated pushes: each run's outcome with the push's verdict."""
    rows = []
    predictions = _predictions(pushes)
    estimates = estimate_columns(spec, pushes)
    # Python floats and ints, as float(a[k]) and int(a[k]) give them (tolist: at C speed).
    steps, peaks = runs.steps.tolist(), runs.peak_hip_torque.tolist()
    lows, highs, times = runs.cop_min.tolist(), runs.cop_max.tolist(), runs.times.tolist()
    impacts = runs.stop_impacts.tolist()
    for k, push in enumerate(pushes):
        error = runs.errors[k]
        if error is not None:
            rows.append(error_row(spec, push, error))
            continue
        outcome = runs.outcomes[k]
        used = used_label(outcome, strategy_used(steps[k], peaks[k]))
        run = _Simulated(
            outcome, used, steps[k], peaks[k], lows[k], highs[k], times[k], impacts[k],
            runs.checks(k),
        )  # fmt: skip
        rows.append(_row(spec, push, run, predictions[k]) | estimates[k])
    return rows


def error_row(spec: CampaignSpec, push: Push, reason: str) -> dict[str, Any]:
    """Return the row of a push without an outcome: the prediction, ``outcome`` = error.

    The simulated columns are NaN (counts 0), ``used`` is ``error`` and ``error`` says why.
    """
    require_type("spec", spec, CampaignSpec)
    require_type("push", push, Push)
    require_type("reason", reason, str)
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
    require_type("spec", spec, CampaignSpec)
    batch = whole_number("batch", batch, 0, 10**9)
    from pushrecovery.kernels.threads import one_thread

    with one_thread():
        try:
            pushes = spec.pushes(batch)
            # A compiled pair's small ankle-pd campaign takes the loop (sim.many.LOOP_UP_TO),
            # and every batch of a larger one the compiled engine, whatever its size; the rest
            # as run_many picks (MuJoCo's foot + ankle-pd: the rollout, at any size).
            compiled = spec.backend == "analytic" and (spec.model, spec.controller) in COMPILED
            small = spec.size <= LOOP_UP_TO and spec.controller == "ankle-pd"
            engine = (
                "loop" if spec.is_3d or (compiled and small) else "compiled" if compiled else "auto"
            )
            rows = push_rows(
                spec, pushes, engine=engine,
                on_start=lambda count: watchdog.arm(spec.push_timeout * count),
            )  # fmt: skip
            return batch, rows
        finally:
            watchdog.disarm()
