"""The recorded push of a 3-D humanoid's filmstrip: the body, the push and the controller.

A filmstrip shows one push of ``fraction`` × the ankle's predicted critical impulse (the 2-D
prediction of :func:`~pushrecovery.experiments.validation3d.predicted_critical_impulses` along
``azimuth``, from where the body stands), under the whole-body controller with the ankle
strategy, the hip task, or stepping. The report renders it (``report/humanoid3d.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pushrecovery.arguments import bounded_float, positive_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mjcf_source import MjcfSource

if TYPE_CHECKING:
    from pushrecovery.sim.mujoco.humanoid3d.render3d import Recording3D

__all__ = ["STRIP_CONTROLLERS", "STRIP_DURATION", "filmstrip_run"]

#: Shortest simulated time of a filmstrip's run [s] (its frames may end earlier).
STRIP_DURATION = 3.0
#: The controllers a filmstrip runs: the ankles, the hip task, stepping.
STRIP_CONTROLLERS = ("ankle", "hip", "step")


def filmstrip_run(
    params: BodyParams,
    model: str | MjcfSource,
    azimuth: float,
    fraction: float,
    controller: str,
    last_frame: float,
) -> tuple[Recording3D, float, str]:
    """Simulate one filmstrip's push, recorded; return the recording, impulse [N s], outcome.

    Parameters
    ----------
    params : BodyParams
        The biped3d's body (the G1 has its own, ``robot_params("g1")``).
    model : str or MjcfSource
        ``biped3d``, ``g1`` or an MJCF file's humanoid (its own body).
    azimuth : float
        The push's direction [deg], 0 forward (+x), 90 left (+y).
    fraction : float
        The push as a fraction of the ankle's predicted critical impulse, in (0, 10].
    controller : str
        One of :data:`STRIP_CONTROLLERS`.
    last_frame : float
        Time of the filmstrip's last frame [s] > 0; the run lasts at least
        :data:`STRIP_DURATION`, so that the caption's outcome is decided.

    Raises
    ------
    InvalidParameterError
        An unknown ``model`` or ``controller``, or a value out of its range.
    """
    from pushrecovery.control.wbc.controller import WholeBodyController
    from pushrecovery.control.wbc.stepper.settings import StepSettings
    from pushrecovery.experiments.validation3d import predicted_critical_impulses
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import wbc_for
    from pushrecovery.sim.mujoco.humanoid3d.render3d import Recording3D
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import run_push3d
    from pushrecovery.sim.push import Push3D
    from pushrecovery.sim.registry import make_plant3d

    if not isinstance(controller, str) or controller not in STRIP_CONTROLLERS:
        raise InvalidParameterError(
            f"controller must be one of {list(STRIP_CONTROLLERS)}, got {controller!r}"
        )
    fraction = bounded_float("fraction", fraction, 1e-9, 10.0)
    last_frame = positive_float("last_frame", last_frame, "s")
    if model == "g1":
        from pushrecovery.sim.mujoco.humanoid3d.robots import robot_params

        params = robot_params("g1")
    plant = make_plant3d(model, params)
    plant.reset()
    origin = plant.standing_origin  # in the frame of the body's feet
    impulse = fraction * predicted_critical_impulses(plant.params, azimuth, origin=origin)["ankle"]
    if controller == "step":
        wbc = WholeBodyController(plant.model, feet=plant.feet, torso=plant.upright,
                                  observation=plant.observation, hip=None,
                                  stepping=True, params=plant.params,
                                  step_settings=StepSettings(swing_time=0.2))  # fmt: skip
    else:
        wbc = wbc_for(plant, hip=controller == "hip")
    push = Push3D(impulse, azimuth, scheduled=controller == "step")  # a stepper reacts to it
    duration = max(last_frame, STRIP_DURATION)
    run = run_push3d(plant, wbc, push, duration=duration, push_time=0.1, record=True)
    steps = 0 if run.extras is None else run.extras.steps
    outcome = run.outcome.value + (f", {steps} step(s)" if steps else "")
    return Recording3D.of_plant_run(plant, run), impulse, outcome
