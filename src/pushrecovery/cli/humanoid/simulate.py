"""The runs of ``pushrecovery humanoid simulate`` and ``critical-push``: camera and runs.

``humanoid simulate --model biped3d|g1|PATH.xml --azimuth DEG``: the whole-body controller
after a push from any direction (:mod:`pushrecovery.sim.mujoco.humanoid3d.runs3d`); the
commands are in :mod:`pushrecovery.cli.humanoid`, the body and plant of ``--model`` in
:mod:`pushrecovery.cli.humanoid.bodies`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pushrecovery.params import BodyParams
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant
    from pushrecovery.sim.result import SimulationResult

__all__ = ["check_views", "critical_3d", "render_options", "simulate_3d"]


def check_views(
    view_azimuth: float | None, view_elevation: float | None, frame_times: str | None
) -> None:
    """Refuse the camera flags without ``--render``.

    Parameters
    ----------
    view_azimuth, view_elevation : float or None
        ``--view-azimuth``, ``--view-elevation`` [deg].
    frame_times : str or None
        ``--frame-times``.

    Raises
    ------
    InvalidParameterError
        If any of them is given.
    """
    from pushrecovery.errors import InvalidParameterError

    if view_azimuth is not None or view_elevation is not None or frame_times is not None:
        raise InvalidParameterError(
            "--view-azimuth, --view-elevation and --frame-times apply to --render of the 3-D "
            "humanoids"
        )


def render_options(
    azimuth: float | None,
    view_azimuth: float | None,
    view_elevation: float | None,
    frame_times: str | None,
) -> dict[str, Any]:
    """Return the camera and filmstrip times of the 3-D ``--render`` (checked before the run).

    Parameters
    ----------
    azimuth : float or None
        The push's azimuth [deg] (None: 0); the default camera looks across it.
    view_azimuth, view_elevation : float or None
        ``--view-azimuth``, ``--view-elevation`` [deg] (None: the default camera's).
    frame_times : str or None
        ``--frame-times T1,T2,...`` [s] (None: evenly spaced).

    Returns
    -------
    dict
        ``camera`` (``Camera3D``) and ``times`` (list of float or None), the keyword
        arguments of ``render_recording3d``.

    Raises
    ------
    InvalidParameterError
        If a camera angle or the frame times are out of range, naming the flag.
    """
    import itertools
    import math

    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.sim.mujoco.humanoid3d.render3d import default_camera
    from pushrecovery.sim.mujoco.render.scene.humanoid import Camera3D

    camera = default_camera(0.0 if azimuth is None else azimuth)
    try:
        camera = Camera3D(
            camera.azimuth if view_azimuth is None else view_azimuth,
            camera.elevation if view_elevation is None else view_elevation,
        )
    except InvalidParameterError as exc:  # name the flag: "--view-elevation must be ..."
        raise InvalidParameterError(f"--view-{exc}") from None
    times = None
    if frame_times is not None:
        try:
            times = [float(t) for t in frame_times.split(",")]
        except ValueError:
            times = [math.nan]
        if not (
            1 <= len(times) <= 20
            and all(math.isfinite(t) and t >= 0.0 for t in times)
            and all(b > a for a, b in itertools.pairwise(times))
        ):
            raise InvalidParameterError(
                "--frame-times must be 1 to 20 increasing times >= 0 s separated by commas, "
                f"got {frame_times[:40]!r}"
            )
    return {"camera": camera, "times": times}


def _render_3d(
    plant: Humanoid3DPlant, run: SimulationResult, path: str, options: dict[str, Any]
) -> dict[str, Any]:
    """Write the filmstrip PNG and GIF of a recorded 3-D run (the JSON's new keys)."""
    import shutil
    from pathlib import Path

    from pushrecovery.errors import PushRecoveryError
    from pushrecovery.sim.mujoco.humanoid3d.render3d import Recording3D, render_recording3d

    png, gif = render_recording3d(Recording3D.of_plant_run(plant, run), Path(path), **options)
    camera = options["camera"]
    data: dict[str, Any] = {
        "render": [str(png), str(gif)],
        "view": {"azimuth": camera.azimuth, "elevation": camera.elevation},
    }
    if plant.name == "g1":  # pictures of the robot's meshes: its licence beside them
        from pushrecovery.sim.mujoco.humanoid3d.robots import robot_licence

        licence = png.with_suffix(".LICENSE")
        try:
            shutil.copyfile(robot_licence("g1"), licence)
        except OSError as exc:
            raise PushRecoveryError(f"cannot write {licence}: {exc.strerror or exc}") from exc
        data["licence"] = str(licence)
    return data


def simulate_3d(
    model: str,
    params: BodyParams,
    impulse: float | None,
    azimuth: float | None,
    duration: float,
    render: str | None = None,
    pictures: dict[str, Any] | None = None,
    stepping: bool = False,
    slip_limit: float = 0.01,
    plant: Humanoid3DPlant | None = None,
) -> dict[str, Any]:
    """Push a 3-D model at ``azimuth`` and run the whole-body controller (the JSON).

    Parameters
    ----------
    model : str
        ``biped3d`` or ``g1``.
    params : BodyParams
        The body (:func:`params_3d`).
    impulse, azimuth : float or None
        The push at the torso [N s] and its direction [deg] (None: 0).
    duration : float
        Longest simulated time [s].
    render : str or None
        ``--render FILE``: the run is recorded and its filmstrip PNG and GIF written.
    pictures : dict or None
        The camera and frame times of ``render`` (:func:`render_options`).
    stepping : bool
        Whether the controller may step (``wbc_for(plant, stepping=True)``).
    slip_limit : float
        Largest loaded-foot slip of a recovered run [m] (more: ``slipped``).
    plant : Humanoid3DPlant, optional
        The plant (an MJCF file's, :func:`~pushrecovery.cli.humanoid.bodies.body_3d`); default the
        built-in ``model``'s.

    Returns
    -------
    dict
        The run's JSON (a public contract: keys, order and values); ``physics`` is the run's
        :class:`~pushrecovery.sim.physical_checks.PhysicalChecks`; ``predicted_corrected`` the
        ground plane's verdict for the push at the torso's height (velocity × (1 + d/z₀)).
    """
    import numpy as np

    from pushrecovery.sim.mujoco.humanoid3d.plant3d import STATE_LABELS, wbc_for
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import PUSH_TIME, pushed_rows, run_push3d
    from pushrecovery.sim.push import Push3D
    from pushrecovery.sim.registry import make_plant3d
    from pushrecovery.surfaces.classify import classify as classify_state

    # A stepping controller reacts during the push, as validate's step column measures it.
    push = Push3D(
        0.0 if impulse is None else impulse,
        0.0 if azimuth is None else azimuth,
        scheduled=stepping,
    )
    dvx, dvy = push.delta_velocity(params.mass)
    predicted = classify_state(0.0, dvx, params, y=0.0, ydot=dvy)  # the ground plane's verdict
    plant = make_plant3d(model, params) if plant is None else plant
    # The verdict for the push at the torso's height: its velocity × (1 + d/z0)
    # (docs/validation3d.md), a push the ankles cannot hold though J/m alone is inside.
    lever = 1.0 + plant.push_lever / plant.standing_height
    corrected = classify_state(0.0, lever * dvx, params, y=0.0, ydot=lever * dvy)
    wbc = wbc_for(plant, stepping=stepping)
    run = run_push3d(
        plant, wbc, push, duration=duration, record=bool(render), slip_limit=slip_limit
    )
    extras = run.extras
    assert extras is not None  # a pushed run's
    states = run.states[pushed_rows(run)]
    # The state as the push began (the row at its start: a scheduled push lasts several rows)
    # and as its force ended.
    began = int(np.searchsorted(run.time, PUSH_TIME + 1e-9)) - 1
    before, after = run.states[began], run.states[extras.push_row]
    return {
        "recovered": run.recovered,
        "outcome": run.outcome.value,
        "model": model,
        "controller": "wbc",
        "duration": float(run.time[-1]),
        "final_state": dict(zip(STATE_LABELS, (float(v) for v in states[-1]), strict=True)),
        "max_excursion": float(
            np.hypot(states[:, 0] - states[0, 0], states[:, 1] - states[0, 1]).max()
        ),
        "peak_torque": extras.peak_torque,
        "stop_impacts": 0,
        "initial_state": {"x": 0.0, "xdot": 0.0, "y": 0.0, "ydot": 0.0},
        "predicted": predicted.to_dict(),
        "after_push": {
            "x": float(after[0]),
            "xdot": float(after[3]),
            "y": float(after[1]),
            "ydot": float(after[4]),
        },
        "backend": "mujoco",
        "azimuth": push.azimuth,
        "impulse": push.impulse,
        "push_body": push.body,
        "delta_velocity": {
            "expected": [dvx, dvy],
            "measured": [float(after[3] - before[3]), float(after[4] - before[4])],
        },
        "steps": extras.steps,
        "stepping": stepping,
        "strategy": run.strategy_used().value,
        "peak_hip_torque": extras.peak_hip_torque,
        "peak_hip_motor_torque": extras.peak_hip_motor_torque,
        "max_torso_tilt": extras.max_torso_tilt,
        "failed_ticks": extras.failed_ticks,
        "hip_task": plant.hip_task,
        "physics": run.physics.to_dict() if run.physics is not None else None,
        "predicted_corrected": corrected.to_dict(),
    } | (_render_3d(plant, run, render, pictures or {}) if render else {})


def critical_3d(
    model: str,
    params: BodyParams,
    azimuth: float | None,
    tolerance: float,
    duration: float,
    strategy: str | None = None,
    plant: Humanoid3DPlant | None = None,
) -> dict[str, Any]:
    """Bisect the impulse at ``azimuth`` on a 3-D model against the predictions (the JSON).

    Parameters
    ----------
    model, params
        The model and its body, as :func:`simulate_3d`'s.
    azimuth : float or None
        The push's direction [deg] (None: 0).
    tolerance : float
        The final bracket's width as a velocity [m/s] (times the mass: an impulse).
    duration : float
        Longest simulated time per push [s].
    strategy : str or None
        ``ankle`` (the WBC without its hip task), ``hip`` (with it), ``step`` (with stepping,
        reacting during the push), or None: the model's own controller without stepping
        (the biped3d's with its hip task, the G1's and an MJCF model's without).
    plant : Humanoid3DPlant, optional
        The plant (an MJCF file's, :func:`~pushrecovery.cli.humanoid.bodies.body_3d`); default the
        built-in ``model``'s.

    Returns
    -------
    dict
        The search's JSON (a public contract: keys, order and values): the measured critical
        push, then ``predicted`` and ``predicted_corrected``, the ground plane's critical
        impulse of each strategy [N s] (ankle and hip: m ω ρ_R(r₀, ψ), step: the one-step
        region's; corrected: over 1 + d/z₀, the push at the torso's height), ``compared_with``
        (the strategy measured) and the measured push's ``relative_error`` and
        ``corrected_error`` against it.
    """
    from pushrecovery.arguments import positive_float
    from pushrecovery.experiments.validation3d.predict import predicted_critical_impulses
    from pushrecovery.experiments.validation3d.step import predicted_step_critical
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import critical_push3d
    from pushrecovery.sim.registry import make_plant3d

    width = positive_float("tolerance", tolerance, "m/s") * params.mass
    angle = 0.0 if azimuth is None else azimuth
    plant = make_plant3d(model, params) if plant is None else plant
    hip = {"ankle": False, "hip": True}.get(strategy or "")
    found = critical_push3d(
        plant, angle, tolerance=width, duration=duration, hip=hip, stepping=strategy == "step"
    )
    low, high = found.bracket
    origin = plant.standing_origin
    predicted = predicted_critical_impulses(params, angle, origin=origin)
    predicted["step"] = predicted_step_critical(params, angle, origin=origin)
    factor = 1.0 / (1.0 + plant.push_lever / plant.standing_height)
    compared = strategy or ("hip" if plant.hip_task else "ankle")
    return {
        "velocity": found.impulse / params.mass,
        "impulse": found.impulse,
        "bracket": [low / params.mass, high / params.mass],
        "impulse_bracket": [low, high],
        "simulations": found.simulations,
        "model": model,
        "controller": "wbc",
        "x": 0.0,
        "azimuth": angle,
        "backend": "mujoco",
        "strategy": found.strategy,
        "hip_task": plant.hip_task if hip is None else hip,
        "foot_slip": found.foot_slip,
        "predicted": predicted,
        "predicted_corrected": {name: factor * value for name, value in predicted.items()},
        "compared_with": compared,
        "relative_error": (found.impulse - predicted[compared]) / predicted[compared],
        "corrected_error": (found.impulse - factor * predicted[compared])
        / (factor * predicted[compared]),
        "stepping": strategy == "step",
    }
