r"""One push of a 3-D campaign as one row (runs on the workers).

:mod:`~pushrecovery.campaign.pushes` dispatches here. The body (``biped3d`` or ``g1``) stands, is
pushed at its torso with J [N s] at the azimuth ψ (:class:`~pushrecovery.sim.push.Push3D`, 10 ms,
after 0.1 s of standing) and the whole-body controller runs with the tasks of the campaign's
controller (``wbc-ankle``: ankles only; ``wbc-hip``: + the hip task; ``wbc-step``: + the hip and the
stepping task; :func:`~pushrecovery.sim.mujoco.humanoid3d.runs3d.run_push3d`) until rest, a fall or
``duration``. The columns of :mod:`~pushrecovery.campaign.pushes` keep their names; how each
reads in 3-D, with its unit, is the field metadata of :func:`.rows.row_schema` (family ``"3d"``),
which the written file carries.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.campaign.rows import (
    ERROR_OUTCOME,
    ERROR_OUTCOME_3D,
    physics_columns,
    used_label,
    verdict_columns,
)
from pushrecovery.campaign.spec import CampaignSpec, Push
from pushrecovery.campaign.spec.humanoid import critical_impulse, predict_push, push_geometry
from pushrecovery.errors import SimulationDiverged
from pushrecovery.params import BodyParams
from pushrecovery.sim.push import PUSH_TIME

__all__ = ["PUSH_TIME", "error_row3d", "predict3d", "run_push3d"]


def predict3d(spec: CampaignSpec, push: Push) -> dict[str, Any]:
    """Return the columns of a 3-D push that do not depend on the run: the push and its verdict."""
    require_type("spec", spec, CampaignSpec)
    require_type("push", push, Push)
    params = push.params
    azimuth = 0.0 if push.azimuth is None else push.azimuth
    (x0, y0), ratio = push_geometry(spec.source, params)
    found, corrected = predict_push(params, (x0, y0), push.impulse, azimuth, ratio)
    xi = found.capture_point_xy or (math.nan, math.nan)
    ankle = critical_impulse(params, (x0, y0), azimuth)
    margins = (found.margins["cop"], found.margins["cmp"], found.margins["step"])
    row = verdict_columns(spec, push, x0, found.strategy, float(xi[0]), margins, found.steps)
    row.update(
        azimuth=azimuth,
        fraction=push.impulse / ankle if push.fraction is None else push.fraction,
        ankle_critical=ankle,
        y0=y0,
        capture_point_y=float(xi[1]),
        predicted_corrected=corrected,
    )
    return row


def run_push3d(
    spec: CampaignSpec, push: Push, cache: dict[BodyParams, Any] | None = None
) -> dict[str, Any]:
    """Simulate one push of a 3-D campaign; return its row (module docstring).

    ``cache`` keeps one plant per body across the pushes of a batch.
    """
    require_type("spec", spec, CampaignSpec)
    require_type("push", push, Push)
    if cache is not None:
        require_type("cache", cache, dict)
    from pushrecovery.sim.mujoco.humanoid3d import runs3d
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import PUSH_DURATION, wbc_for
    from pushrecovery.sim.push import Push3D
    from pushrecovery.sim.registry import make_plant3d

    cache = {} if cache is None else cache
    if push.params not in cache:
        cache[push.params] = make_plant3d(spec.source, push.params)
    plant = cache[push.params]
    strategy = spec.strategy
    # wbc-hip: the hip task; wbc-step: the plant's own controller (its default hip task,
    # off on the G1, whose pushes it lowers) with stepping; wbc-ankle: the ankles only.
    hip = {"ankle": False, "hip": True}.get(strategy)
    controller = wbc_for(plant, hip=hip, stepping=strategy == "step")
    azimuth = 0.0 if push.azimuth is None else push.azimuth
    try:
        run = runs3d.run_push3d(
            plant, controller, Push3D(push.impulse, azimuth, scheduled=strategy == "step"),
            duration=spec.duration,
            push_time=PUSH_TIME,
        )  # fmt: skip
    except SimulationDiverged as exc:  # this push only: the others of the batch go on
        del cache[push.params]
        return error_row3d(spec, push, f"the physics diverged: {exc}")
    extras, physics = run.extras, run.physics
    assert extras is not None and physics is not None  # run_push3d's result
    row = predict3d(spec, push)
    stepper = controller.stepper
    row.update(
        outcome=run.outcome.value,
        used=used_label(run.outcome, run.strategy_used()),
        steps=extras.steps,
        peak_hip_torque=extras.peak_hip_torque,
        peak_ankle_torque=math.nan,
        cop_min=math.nan,
        cop_max=math.nan,
        time=float(run.time[-1]) - PUSH_TIME - PUSH_DURATION,
        stop_impacts=0,
        error=None,
        lift_offs=0 if stepper is None else len(stepper.steps),
        peak_hip_motor_torque=extras.peak_hip_motor_torque,
        max_torso_tilt=extras.max_torso_tilt,
        # The motor commands held from the push on (the push's, then each tick's).
        peak_torque_ratio=_torque_ratio(run.inputs[extras.push_row - 1 :], plant.ctrl_range),
        failed_ticks=extras.failed_ticks,
        **physics_columns(physics),
    )
    return row


def _torque_ratio(ctrl: Any, ranges: Any) -> float:
    """Return max over ticks and limited motors of abs(command) / limit [-] (NaN if none)."""
    limits = np.max(np.abs(np.asarray(ranges, dtype=float)), axis=1)
    finite = np.isfinite(limits) & (limits > 0.0)
    if ctrl is None or not np.any(finite):
        return math.nan
    return float(np.max(np.abs(np.asarray(ctrl)[:, finite]) / limits[finite]))


def error_row3d(spec: CampaignSpec, push: Push, reason: str) -> dict[str, Any]:
    """Return the row of a 3-D push without an outcome: the prediction, ``outcome`` = error."""
    require_type("spec", spec, CampaignSpec)
    require_type("push", push, Push)
    require_type("reason", reason, str)
    row = predict3d(spec, push)
    row.update(ERROR_OUTCOME, error=reason)
    row.update(ERROR_OUTCOME_3D)
    return row
