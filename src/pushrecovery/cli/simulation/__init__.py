"""Commands that simulate one push or bisect one: ``simulate`` and ``critical-push``.

Their shared options are in :mod:`pushrecovery.cli.simulation.options`. The planar models only:
the 3-D humanoids are ``pushrecovery humanoid simulate`` and ``critical-push``
(:mod:`pushrecovery.cli.humanoid`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.families import humanoid_only
from pushrecovery.cli.options import (
    SUPPORT_KEYS,
    body_options,
    emit,
    needs_plots,
    params_from,
    support_from,
    support_options,
)
from pushrecovery.cli.progress import Progress
from pushrecovery.cli.simulation.options import controller_options, planar_run, timing

__all__ = ["critical_push", "simulate"]


@click.command(
    short_help="Simulate a push; report recovered or fell.",
    epilog=example(
        "pushrecovery simulate --model flywheel --controller mpc --xdot 0.6",
        "pushrecovery simulate --model stepping --controller recovery --impulse 60 "
        "--plot out/step.png",
        "pushrecovery simulate --backend mujoco --model foot --impulse 15 --duration 3 --json",
        "pushrecovery simulate --model stepping-plane --controller recovery-plane --y 0.1 "
        "--ydot -0.5 --stance left",
    ),
)
@planar_run(
    "simulate",
    x_help="CoM position before the push, forward from the ankle (stepping-plane: world frame, "
    "the default feet's midpoint at the origin) [m].",
)
@click.option(
    "--xdot",
    type=float,
    default=None,
    help="CoM velocity just after the push, forward [m/s] (default 0).",
)
@click.option(
    "--y",
    "y",
    type=float,
    default=0.0,
    show_default=True,
    help="stepping-plane only: CoM position, left, world frame as --x [m].",
)
@click.option(
    "--ydot",
    type=float,
    default=0.0,
    show_default=True,
    help="stepping-plane only: CoM velocity, left, just after the push [m/s].",
)
@click.option(
    "--impulse",
    "--push",
    "impulse",
    type=float,
    default=None,
    help="Push as an impulse on the CoM, forward [N s] (instead of --xdot: the velocity "
    "impulse / mass; on MuJoCo a real force over 10 ms).",
)
@timing(duration_help="Longest simulated time [s].")
@click.option(
    "--plot",
    type=click.Path(dir_okay=False),
    default=None,
    callback=needs_plots,
    help="Write a plot of the run (PNG, SVG or PDF by extension).",
)
@click.option(
    "--render",
    type=click.Path(dir_okay=False),
    default=None,
    help="MuJoCo only: write a filmstrip PNG of the run to this file and an animated GIF "
    "beside it (CoM, capture point and CoP drawn).",
)
@support_options
@humanoid_only(
    "simulate", "--azimuth", "--stepping", "--view-azimuth", "--view-elevation", "--frame-times"
)
@body_options
def simulate(
    backend: str,
    model: str,
    controller: str,
    x: float,
    xdot: float | None,
    y: float,
    ydot: float,
    impulse: float | None,
    duration: float,
    control_period: float | None,
    plot: str | None,
    render: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Simulate a push on a model with a controller; report recovered or fell.

    The body stands at --x and is pushed to --xdot (or by --impulse, forward positive); the
    run goes on for --duration or until it has fallen or come to rest. Prints the outcome
    (recovered, fell or undecided: not at rest yet), the final state (SI units, angles in
    rad), the largest CoM excursion [m], the peak torque [N m], the steps taken and the
    surfaces' predicted strategy for the push (with its margins [m], positive inside); on
    MuJoCo also the state the push left and the CoP it measured [m]. With --backend mujoco,
    --impulse is a real force at the CoM over 10 ms (the body holding still meanwhile) and the
    run starts as the push ends. With --model stepping-plane (controller recovery-plane) the
    body stands on the feet of the ground plane, both at their default poses unless --stance,
    --left-foot, --right-foot or the --params file's [feet] place them (poses in the world
    frame, in which --x and --y are too), and --y, --ydot add the sideways part (--impulse
    pushes along x); the output then has the support it started on. The 3-D humanoids are
    'pushrecovery humanoid simulate'.
    """
    from pushrecovery.control.base import make_controller
    from pushrecovery.sim.backend import Measuring, Recording, check_com_state
    from pushrecovery.sim.push import Push
    from pushrecovery.sim.registry import make_plant
    from pushrecovery.sim.simulate import simulate as run
    from pushrecovery.surfaces.classify import classify as classify_state

    file = kwargs["params_file"]
    params = params_from(kwargs)
    velocity = _push_velocity(xdot, impulse, params.mass)
    plane = model == "stepping-plane"
    if not plane:
        from pushrecovery.errors import InvalidParameterError

        if y != 0.0 or ydot != 0.0:
            raise InvalidParameterError("--y and --ydot need --model stepping-plane")
        given = [name for name in SUPPORT_KEYS if kwargs.pop(name) is not None]
        if given:
            flag = "--" + given[0].replace("_", "-")
            raise InvalidParameterError(
                f"{flag} needs --model stepping-plane (the feet on the ground plane), "
                f"got --model {model}"
            )
    support = support_from(kwargs, params, file) if plane else None
    # The models' validity first: its message names the coordinate (the prediction's would
    # only say that the capture point is out of reach).
    check_com_state(x, velocity, params)
    if plane:
        check_com_state(y, ydot, params, ("y", "ydot"))
        predicted = classify_state(x, velocity, params, y=y, ydot=ydot, support=support)
    else:
        predicted = classify_state(x, velocity, params)
    if render and backend != "mujoco":
        from pushrecovery.errors import InvalidParameterError

        raise InvalidParameterError("--render needs --backend mujoco")
    if render:
        from pushrecovery.sim.mujoco.render import require_offscreen_gl

        require_offscreen_gl()  # fail before the run, not after it
    plant = make_plant(model, params, backend, support=support)
    # Frames (an extra forward pass per tick) only for the pictures.
    if render and isinstance(plant, Recording):
        plant.record()
    elif isinstance(plant, Measuring):
        plant.measure()
    if backend == "mujoco" and impulse is not None:
        # A real force at the CoM, over 10 ms, instead of a velocity jump.
        plant.reset(x, 0.0)
        initial = plant.apply_push(Push.from_impulse(impulse, params.mass))
    elif plane:
        from pushrecovery.sim.plane_stepping import PlaneSteppingPlant

        assert isinstance(plant, PlaneSteppingPlant)  # make_plant's for stepping-plane
        initial = plant.reset(x, velocity, y, ydot)
    else:
        initial = plant.reset(x, velocity)
    result = run(
        plant,
        make_controller(controller, params, **controller_options(controller, kwargs)),
        initial,
        duration=duration,
        control_period=control_period,
    )
    data = result.to_dict()
    data["initial_state"] = {"x": x, "xdot": velocity} | ({"y": y, "ydot": ydot} if plane else {})
    data["predicted"] = predicted.to_dict()
    if support is not None:
        data["support"] = support.to_dict()
    if isinstance(plant, Measuring):  # MuJoCo: the state the push left, the CoP it measured
        half = len(initial) // 2
        data["after_push"] = {"x": float(initial[0]), "xdot": float(initial[half])}
        data["measured_cop"] = _measured_cop(plant.measured_cops)
    if render and isinstance(plant, Recording) and plant.frames is not None:
        from pushrecovery.sim.mujoco.render import render_run

        files = render_run(plant.model, plant.frames, Path(render))
        data["render"] = [str(f) for f in files]
    if plot:
        from pushrecovery.plots.runs import save_run

        data["plot"] = str(save_run(result, params, Path(plot)))
    emit(data, as_json)


@click.command(
    "critical-push",
    short_help="Largest recoverable push, against its surface's prediction.",
    epilog=example(
        "pushrecovery critical-push --model lipm --controller ankle-pd --tolerance 0.001",
        "pushrecovery critical-push --model flywheel --controller mpc --direction backward --json",
    ),
)
@planar_run("critical-push", x_help="CoM position before the push, on the foot [m].")
@click.option(
    "--direction",
    type=click.Choice(("forward", "backward")),
    default="forward",
    show_default=True,
    help="Direction of the push: forward (+x) or backward (-x; the velocities printed are "
    "then negative).",
)
@click.option(
    "--tolerance",
    type=float,
    default=1e-4,
    show_default=True,
    help="Width of the final velocity bracket [m/s].",
)
@timing(duration_help="Longest simulated time per push [s].")
@humanoid_only("critical-push", "--azimuth")
@body_options
def critical_push(
    backend: str,
    model: str,
    controller: str,
    x: float,
    direction: str,
    tolerance: float,
    duration: float,
    control_period: float | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Largest recoverable push from x by bisection, against the strategy's surface.

    The body stands at --x on the foot [m, from the ankle] and is pushed along --direction;
    the push, a CoM velocity, is bisected between one that the controller recovers and one
    that falls within --duration, to --tolerance [m/s] (on MuJoCo each push is a real force
    over 10 ms, searched as its velocity impulse / mass). Prints the critical velocity [m/s]
    and impulse [N s] (signed: backward negative), its bracket, the number of simulations and
    the relative error against the prediction of the controller's strategy (ankle: Eq. 4; hip:
    corrected Eq. 15; step: the single-step limit), and on MuJoCo the prediction corrected
    for the CoP margin and the push's duration. The 3-D humanoids are 'pushrecovery humanoid
    critical-push'.
    """
    from pushrecovery.sim.critical import critical_push as search

    params = params_from(kwargs)
    bar = Progress(None, "critical push", "simulation")
    try:
        found = search(
            params,
            model,
            controller,
            x,
            direction,
            tolerance=tolerance,
            duration=duration,
            control_period=control_period,
            controller_options=controller_options(controller, kwargs),
            backend=backend,
            progress=bar.update,
        )
    finally:
        bar.close()
    emit(
        {
            "velocity": found.velocity,
            "impulse": params.mass * found.velocity,
            "predicted_velocity": found.predicted_velocity,
            "predicted_impulse": params.mass * found.predicted_velocity,
            "relative_error": found.relative_error(),
            "bracket": list(found.bracket),
            "simulations": found.iterations,
            "model": model,
            "controller": controller,
            "x": x,
            "direction": direction,
            "backend": backend,
            "predicted": _critical_prediction(params, controller, x, direction, backend),
            # MuJoCo: the run at the critical push (the largest that does not fall).
            "foot_slip": None if found.physics is None else found.physics.foot_slip,
            "peak_force": None if found.physics is None else found.physics.peak_force_ratio,
        },
        as_json,
    )


def _critical_prediction(
    params: Any, controller: str, x: float, direction: str, backend: str
) -> dict[str, Any]:
    """Return the surface's critical push (and the corrected one on MuJoCo)."""
    from pushrecovery.control.base import make_controller
    from pushrecovery.sim.critical import predicted_critical_velocity

    strategy = make_controller(controller, params).strategy
    surface = {"ankle": "Eq. 4", "hip": "corrected Eq. 15", "step": "single-step limit"}[strategy]
    velocity = predicted_critical_velocity(params, strategy, x, direction)
    data: dict[str, Any] = {
        "strategy": strategy,
        "surface": surface,
        "velocity": velocity,
        "impulse": params.mass * velocity,
    }
    if backend == "mujoco" and strategy != "step":
        from pushrecovery.sim.validation import mujoco_corrected_prediction

        sign = 1.0 if direction == "forward" else -1.0
        corrected = mujoco_corrected_prediction(strategy, x, sign, params)
        data["corrected_velocity"] = corrected
        data["corrected_impulse"] = params.mass * corrected
    return data


def _push_velocity(xdot: float | None, impulse: float | None, mass: float) -> float:
    """Return the CoM velocity of ``--xdot`` [m/s] or ``--impulse`` [N s] (not both; else 0)."""
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.sim.push import Push

    if xdot is not None and impulse is not None:
        raise InvalidParameterError("give either --xdot [m/s] or --impulse [N s], not both")
    if impulse is not None:
        return Push.from_impulse(impulse, mass).delta_velocity
    return 0.0 if xdot is None else xdot


def _measured_cop(cops: list[float]) -> dict[str, float | None]:
    """Range of the CoP MuJoCo measured from the contact forces, relative to the ankle [m]."""
    import math

    finite = [cop for cop in cops if not math.isnan(cop)]
    if not finite:
        return {"min": None, "max": None}
    return {"min": min(finite), "max": max(finite)}
