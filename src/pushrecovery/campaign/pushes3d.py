r"""One push of a 3-D campaign as one row (runs on the workers).

:mod:`~pushrecovery.campaign.pushes` dispatches here. The body (``biped3d`` or ``g1``) stands, is
pushed at its torso with J [N s] at the azimuth ψ (:class:`~pushrecovery.sim.push.Push3D`, 10 ms,
after 0.1 s of standing) and the whole-body controller runs with the tasks of the campaign's
controller (``wbc-ankle``: ankles only; ``wbc-hip``: + the hip task; ``wbc-step``: + the hip and the
stepping task; :func:`~pushrecovery.sim.mujoco.humanoid3d.runs3d.run_push3d`) until rest, a fall or
``duration``. The columns of :mod:`~pushrecovery.campaign.pushes` keep their names; in 3-D they
read:

=========================  ==================================================================
``x0``, ``y0``             the standing CoM's ground point r₀ [m] (ankles' midpoint at 0)
``xdot``                   J/m, the CoM velocity the push gives along ψ [m/s]
``predicted``              the ground plane's verdict (``surfaces.classify.classify`` with y,
                           ẏ) for r₀ and the velocity J/m (cos ψ, sin ψ): ankle, hip, step or
                           fall, on the body's double support (``Support.from_params``)
``capture_point``,         ξ = r₀ + J/(m ω) (cos ψ, sin ψ) [m]
``capture_point_y``
``cop_margin``, ...        the plane's signed margins (positive inside) [m]
``used``, ``steps``        the strategy the run used (``sim.result.strategy_used``: step if a
                           step landed, hip if the hip law's m g abs(δ) passed 1 N m, else ankle)
                           if it recovered, else fall; the steps that landed
``peak_hip_torque``        the hip law's largest m g abs(δ) [N m]
``peak_ankle_torque``,     NaN (the WBC's CoP is not recorded per run)
``cop_min``, ``cop_max``
``time``                   simulated time from the push's end to the outcome [s]
``azimuth``                ψ [deg]
``fraction``               J / J*_ankle(ψ) (:func:`~.spec3d.critical_impulse`)
``ankle_critical``         J*_ankle(ψ) = m ω ρ_P(r₀, ψ) [N s]
``predicted_corrected``    the verdict for the push at the torso's height: the velocity
                           × (1 + d/z₀) (docs/validation3d.md, "The critical push from
                           every direction")
``lift_offs``              steps begun (landed or not)
``peak_hip_motor_torque``  largest abs(hip pitch or roll command − its value before) [N m]
``max_torso_tilt``         largest tilt of the upright body [rad]
``peak_torque_ratio``      largest abs(motor command) / its limit over the run [-] (1: saturated)
``failed_ticks``           ticks DAQP did not solve (the last command held)
=========================  ==================================================================

The written file carries these readings as its fields' metadata (:func:`.rows.row_schema`,
family ``"3d"``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pushrecovery.campaign.rows import ERROR_OUTCOME, ERROR_OUTCOME_3D
from pushrecovery.campaign.spec import CampaignSpec, Push
from pushrecovery.campaign.spec3d import critical_impulse, predict_push, push_geometry
from pushrecovery.errors import SimulationDiverged
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.strategy import STRATEGY_CODES, Strategy

__all__ = ["PUSH_TIME", "error_row3d", "predict3d", "run_push3d"]

#: Quiet standing before the push [s].
PUSH_TIME = 0.1


def predict3d(spec: CampaignSpec, push: Push) -> dict[str, Any]:
    """Return the columns of a 3-D push that do not depend on the run (module docstring)."""
    params = push.params
    azimuth = 0.0 if push.azimuth is None else push.azimuth
    (x0, y0), ratio = push_geometry(spec.model, params)
    found, corrected = predict_push(params, (x0, y0), push.impulse, azimuth, ratio)
    reach = STRATEGY_CODES.index(Strategy(spec.strategy))
    xi = found.capture_point_xy or (math.nan, math.nan)
    ankle = critical_impulse(params, (x0, y0), azimuth)
    row: dict[str, Any] = {
        f"param_{name}": value for name, value in zip(spec.sweeps, push.swept, strict=True)
    }
    row.update(
        index=push.index,
        x0=x0,
        xdot=push.xdot,
        impulse=push.impulse,
        predicted=found.strategy.value,
        capture_point=float(xi[0]),
        cop_margin=found.margins["cop"],
        cmp_margin=found.margins["cmp"],
        step_margin=found.margins["step"],
        predicted_steps=-1 if found.steps is None else found.steps,
        predicted_recovers=STRATEGY_CODES.index(found.strategy) <= reach,
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
    from pushrecovery.sim.mujoco.humanoid3d import runs3d
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import PUSH_DURATION, wbc_for
    from pushrecovery.sim.push import Push3D
    from pushrecovery.sim.registry import make_plant

    cache = {} if cache is None else cache
    if push.params not in cache:
        cache[push.params] = make_plant(spec.model, push.params, "mujoco")
    plant = cache[push.params]
    strategy = spec.strategy
    # wbc-hip: the hip task; wbc-step: the plant's own controller (its default hip task,
    # off on the G1, whose pushes it lowers) with stepping; wbc-ankle: the ankles only.
    hip = {"ankle": False, "hip": True}.get(strategy)
    controller = wbc_for(plant, hip=hip, stepping=strategy == "step")
    azimuth = 0.0 if push.azimuth is None else push.azimuth
    try:
        run = runs3d.run_push3d(
            plant, controller, Push3D(push.impulse, azimuth), duration=spec.duration,
            push_time=PUSH_TIME,
        )  # fmt: skip
    except SimulationDiverged as exc:  # this push only: the others of the batch go on
        del cache[push.params]
        return error_row3d(spec, push, f"the physics diverged: {exc}")
    extras = run.extras
    assert extras is not None  # run_push3d's result
    row = predict3d(spec, push)
    stepper = controller.stepper
    row.update(
        outcome=run.outcome.value,
        used=run.strategy_used().value if run.recovered else Strategy.FALL.value,
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
    row = predict3d(spec, push)
    row.update(ERROR_OUTCOME, error=reason)
    row.update(ERROR_OUTCOME_3D)
    return row
