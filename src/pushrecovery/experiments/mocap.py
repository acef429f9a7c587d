"""A MuJoCo push recorded as a gait lab would measure it: markers and force plates, with truth.

:func:`record_push` runs one push on a MuJoCo plant (``foot``, ``torso`` or ``biped``) with its
controller and samples what motion capture and force plates would give
(:mod:`pushrecovery.sim.mujoco.lab`: frames, markers, plates), so that an analysis of measured
data (C3D files) can be tested against what the simulation really did
(:attr:`~pushrecovery.sim.mujoco.lab.MocapRecording.truth`).

Closed loop
-----------
The controller runs from the start of the quiet standing. During a force push the body holds
still as in ``plant.apply_push`` (CoP under the CoM, no hip torque; a human's reaction takes longer
than the 10 ms push) and as the push ends the controller restarts on the pushed state: the
response is then the one of ``pushed_state(..., force=True)`` + ``simulate()`` in the
campaigns and the validation (``react_during_push=True`` keeps the controller running
instead). It is :func:`~pushrecovery.sim.simulate.simulate` itself, with the
push scheduled at the end of the quiet standing, a plant step of one 1 ms physics step and
the lab as an observer: the controller computes a command at its own period, held in between
(zero-order hold), and the fall and rest criteria are the simulator's, from the end of the
push; the run goes on to the end of the recording after a recovery, ``FALL_TAIL`` after a
fall. With 1 ms plant steps the ``foot`` and ``torso`` plants refresh their torque map every
1 ms instead of every ``TORQUE_HOLD`` = 10 ms with the MPC's 20 ms ticks (CHANGELOG.md:
< 0.1 % on critical pushes; docs/performance.md, "Simulation"); ``foot`` with ``ankle-pd``
(1 ms ticks) and ``biped`` (1 ms servos) are unchanged.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from pushrecovery.control.base import make_controller
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.events import ScheduledPush
from pushrecovery.sim.mujoco.lab import (
    STANCE_HALF_WIDTH,
    LabRecorder,
    MocapRecording,
    plate_areas,
    plate_channels,
)
from pushrecovery.sim.mujoco.models import TIMESTEP
from pushrecovery.sim.mujoco.plant import MujocoPlant
from pushrecovery.sim.push import PUSH_DURATION, Push
from pushrecovery.sim.registry import MUJOCO_MODELS, make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.sim.validation import SETUPS
from pushrecovery.surfaces.classify import classify

__all__ = ["DEFAULT_CONTROLLERS", "FALL_TAIL", "record_push"]

#: Controller of each model by default: the one the validation and the campaigns use for it.
DEFAULT_CONTROLLERS: dict[str, str] = {
    model: controller for model, controller in SETUPS["mujoco"].values()
}
#: Time recorded after a fall is detected [s]; a fallen model is no lab data.
FALL_TAIL = 0.1


def _rate_ratio(message: str, numerator: float, denominator: float) -> int:
    """Return numerator / denominator if it is a whole number >= 1, else raise ``message``."""
    ratio = numerator / denominator
    whole = round(ratio)
    if whole < 1 or abs(ratio - whole) > 1e-9 * max(1.0, ratio):
        raise InvalidParameterError(message)
    return whole


def record_push(
    model: str,
    params: BodyParams,
    *,
    x0: float = 0.0,
    xdot: float | None = None,
    impulse: float | None = None,
    controller: str | None = None,
    duration: float = 3.0,
    point_rate: float = 100.0,
    analog_rate: float = 1000.0,
    quiet: float = 0.5,
    react_during_push: bool = False,
) -> MocapRecording:
    """Simulate a push on a MuJoCo model and record it as markers and force plates.

    The body settles, stands at rest at ``x0`` for ``quiet`` seconds with the controller
    running, is pushed, and the response is recorded until ``duration`` (or ``FALL_TAIL``
    after a fall). Frames and conventions: module docstring.

    Parameters
    ----------
    model : {"foot", "torso", "biped"}
        MuJoCo model (:data:`pushrecovery.sim.mujoco.PLANTS`).
    params : BodyParams
        The body.
    x0 : float
        CoM position relative to the stance ankle while standing, before the push [m].
    xdot : float, optional
        Push as a velocity jump: the CoM velocity raised by ``xdot`` at once at the push
        time [m/s], positive forward. The plates see no push, only the response.
    impulse : float, optional
        Push as a real force at the pushed body's CoM, J [N s] (positive forward) over
        ``PUSH_DURATION`` = 10 ms. At most one of ``xdot`` and ``impulse``; neither records
        standing without a push.
    controller : str, optional
        Controller name; default :data:`DEFAULT_CONTROLLERS` (``ankle-pd`` for ``foot``,
        ``mpc`` for ``torso``, ``recovery`` for ``biped``).
    duration : float
        Length of the whole recording, quiet standing included [s], > ``quiet``.
    point_rate : float
        Marker rate [Hz].
    analog_rate : float
        Force-plate rate [Hz]: 1000 (every physics step) or 1000 / n, an integer multiple of
        ``point_rate``. Samples are instantaneous (no anti-alias filter).
    quiet : float
        Quiet standing recorded before the push [s], >= 0.
    react_during_push : bool
        False (default): the body holds still during a force push (CoP under the CoM, no hip
        torque, no step) and the controller restarts on the pushed state as the push ends,
        as ``plant.apply_push`` and the campaigns do, so that the response is the one the surfaces
        predict for ``truth["state_after_push"]``. True: the controller keeps running during
        the push (a scheduled ``apply_push`` before ``simulate``); the ``recovery`` controller then
        plans its step 5-8 ms into the push on a part of the velocity (0.74 m instead of
        0.82 m for 1.3 m/s from x0 = 0).

    Returns
    -------
    MocapRecording
        With ``truth``: ``model``, ``controller``, ``outcome`` (``recovered``, ``fell`` or
        ``undecided``, by the simulator's criteria), ``decided_time`` [s] (NaN: undecided),
        ``push_time`` [s], ``push`` (``kind`` ``force``/``velocity``/``none``, ``impulse``
        [N s], ``velocity`` [m/s], ``duration`` [s], ``body``), ``push_force`` (n_analog,) [N]
        (x force on the pushed body), ``state_after_push`` ``{"x", "xdot"}`` (CoM relative to
        the stance ankle as the plant estimates it when the push ends [m, m/s]),
        ``predicted`` (:func:`~pushrecovery.surfaces.classify.classify` of that state,
        ``to_dict()``), ``used`` (``ankle``, ``hip`` or ``step``, the strategy the run used
        whatever its outcome: ``step`` if the biped stepped, ``hip`` if abs(hip torque) exceeded
        :data:`HIP_TORQUE_THRESHOLD`), ``peak_hip_torque`` [N m], ``hip_torque`` (n_analog,)
        [N m], ``plant_cop`` (n_analog,) (the plant's own ``measured_cop_world()``, world x
        of the CoP of the soles' normal forces on all plates and off them [m]), ``steps``,
        ``step_lengths`` (foot to foot [m], signed), ``footholds`` (world x of every stance
        ankle [m]), ``stance_width`` [m], ``off_plate_samples`` (analog samples with floor
        contacts outside both plates) and ``params`` (the body, as a dict).

    Raises
    ------
    InvalidParameterError
        For an unknown model or controller, both pushes, rates that do not fit the 1 ms step,
        or a duration not longer than ``quiet``.
    """
    if not isinstance(model, str) or model not in MUJOCO_MODELS:
        raise InvalidParameterError(f"model must be one of {sorted(MUJOCO_MODELS)}, got {model!r}")
    if xdot is not None and impulse is not None:
        raise InvalidParameterError("give a push as xdot or as impulse, not both")
    for name, value in (("x0", x0), ("xdot", xdot), ("impulse", impulse)):
        if value is not None and not math.isfinite(value):
            raise InvalidParameterError(f"{name} must be finite, got {value!r}")
    if not (point_rate > 0.0 and analog_rate > 0.0):
        raise InvalidParameterError(
            f"rates must be > 0, got point_rate={point_rate:g}, analog_rate={analog_rate:g}"
        )
    h = TIMESTEP
    decimation = _rate_ratio(
        f"analog_rate must be 1/{h:g} s = {1 / h:g} Hz divided by a whole number, "
        f"got {analog_rate:g}",
        1.0 / analog_rate,
        h,
    )
    per_frame = _rate_ratio(
        f"analog_rate must be a whole multiple of point_rate, got {analog_rate:g} and "
        f"{point_rate:g}",
        analog_rate,
        point_rate,
    )
    if not (math.isfinite(quiet) and quiet >= 0.0):
        raise InvalidParameterError(f"quiet must be >= 0 s, got {quiet!r}")
    if not (math.isfinite(duration) and duration > quiet):
        raise InvalidParameterError(f"duration must exceed quiet = {quiet:g} s, got {duration!r}")
    n_frames = max(1, round(duration * point_rate))
    n_analog = n_frames * per_frame
    total_steps = n_analog * decimation
    push_step = round(quiet / h)
    if push_step >= total_steps:
        raise InvalidParameterError("duration leaves no time after the push")

    name = controller or DEFAULT_CONTROLLERS[model]
    plant = make_plant(model, params, "mujoco")
    if not isinstance(plant, MujocoPlant):  # pragma: no cover - the registry's MuJoCo models
        raise TypeError(f"model {model!r} is not a MuJoCo plant")
    ctrl = make_controller(name, params)
    state = plant.reset(x0, 0.0)
    # The initial stance foot: the first ankle (both feet side by side for the biped).
    first_ankle = float(plant.ankle_x())
    lab = LabRecorder(
        plant,
        model,
        plate_areas(first_ankle + 0.5 * (params.heel + params.toe)),
        frames=n_frames,
        per_frame=per_frame,
        decimation=decimation,
    )
    velocity = xdot if xdot is not None else (impulse or 0.0) / params.mass
    kind = "force" if impulse is not None else "velocity" if xdot is not None else "none"
    push_steps = round(PUSH_DURATION / h) if impulse is not None else 0
    # No push: a zero jump, so that the controller restarts and rest counts from there too.
    scheduled = ScheduledPush(
        push_step * h,
        Push(velocity, "force" if impulse is not None else "velocity"),
        react=react_during_push,
    )
    run = simulate(
        plant,
        ctrl,
        state,
        duration=total_steps * h,
        plant_step=h,
        push=scheduled,
        observers=(lab,),
        keep_running=(math.inf, FALL_TAIL),
    )
    push_end = push_step + push_steps
    end = len(run.time) - 1  # physics steps run
    after = run.states[min(push_end, end)]
    half = len(after) // 2

    # Whole marker frames only (C3D: a fixed number of analog samples per frame).
    frames = max(1, min(n_frames, end // (decimation * per_frame)))
    n_kept = frames * per_frame
    plates = tuple(
        plate_channels(area, lab.forces[:n_kept, j].copy(), lab.moments[:n_kept, j])
        for j, area in enumerate(lab.plates)
    )
    samples = np.arange(n_kept) * decimation
    push_force = np.where(
        (samples >= push_step) & (samples < push_end),
        (impulse or 0.0) / max(push_steps * h, h),
        0.0,
    )
    footholds = list(run.footholds)
    truth: dict[str, object] = {
        "model": model,
        "controller": name,
        "outcome": run.outcome.value,
        "decided_time": math.nan if run.decided_time is None else run.decided_time,
        "push_time": push_step * h,
        "push": {
            "kind": kind,
            "impulse": impulse if impulse is not None else params.mass * (xdot or 0.0),
            "velocity": xdot if xdot is not None else (impulse or 0.0) / params.mass,
            "duration": push_steps * h,
            "body": plant.pushed_body,
        },
        "push_force": push_force,
        "state_after_push": {"x": float(after[0]), "xdot": float(after[half])},
        "predicted": classify(float(after[0]), float(after[half]), params).to_dict(),
        "used": run.strategy_used().value,
        "peak_hip_torque": run.peak_hip_torque,
        "hip_torque": lab.hip_torque[:n_kept],
        "plant_cop": lab.plant_cop[:n_kept],
        "steps": len(footholds) - 1,
        "step_lengths": [b - a for a, b in itertools.pairwise(footholds)],
        "footholds": footholds,
        "stance_width": 2.0 * STANCE_HALF_WIDTH,
        "off_plate_samples": lab.off_plate,
        "foot_events": _foot_events(lab, n_kept, analog_rate),
        "params": dataclasses.asdict(params),
    }
    return MocapRecording(
        point_rate=float(point_rate),
        markers={label: m[:frames] for label, m in lab.marker_frames.items()},
        analog_rate=float(analog_rate),
        plates=plates,
        mass=float(plant.model.body_subtreemass[0]),
        truth=truth,
    )


def _foot_events(lab: LabRecorder, samples: int, rate: float) -> list[dict[str, object]]:
    """Return the feet's true foot-offs and foot-contacts: their floor contact ending, starting.

    Per foot of the biped (``left``, ``right``; none for the one-footed models): the analog
    sample [s] at which the floor's vertical force on the foot's body becomes 0 (foot-off) or
    positive (foot-contact), whatever plate it stands on.
    """
    if lab.model_name != "biped":
        return []
    events: list[dict[str, object]] = []
    for (side, *_), load in zip(lab.feet, lab.foot_load[:samples].T, strict=True):
        loaded = load > 0.0
        for k in np.flatnonzero(np.diff(loaded.astype(np.int8))).tolist():
            events.append(
                {
                    "foot": "left" if side == "L" else "right",
                    "kind": "foot-contact" if loaded[k + 1] else "foot-off",
                    "time": (k + 1) / rate,
                }
            )
    return sorted(events, key=lambda event: event["time"])  # type: ignore[arg-type,return-value]
