"""The ``pushrecovery`` commands. Heavy modules are imported inside each command."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from pushrecovery import __version__
from pushrecovery.cli.options import body_options, emit, params_from

# Kept literal so that --help does not import the models; a test checks them against the
# registries.
MODEL_CHOICES = ("lipm", "pendulum", "flywheel", "stepping")
CONTROLLER_CHOICES = (
    "ankle-saturated",
    "ankle-pd",
    "ankle-capture-point",
    "bang-bang",
    "mpc",
    "recovery",
)


@click.group(
    no_args_is_help=True,
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)
@click.version_option(__version__, prog_name="pushrecovery")
def cli() -> None:
    """Predict whether a pushed humanoid falls, and recover it (Stephens, Humanoid Push Recovery).

    SI units throughout; x is forward, positions are relative to the ankle. Every command
    takes the body-parameter flags and --json.
    """


@cli.command(short_help="Capture-point bounds of each strategy.")
@body_options
def bounds(as_json: bool, **kwargs: Any) -> None:
    """Capture-point bounds of each balance strategy (Eq. 4, corrected Eq. 15)."""
    from pushrecovery.models.flywheel import max_spin_up_time
    from pushrecovery.surfaces.cmp import cmp_offset, cmp_region
    from pushrecovery.surfaces.cop import cop_region
    from pushrecovery.surfaces.step import step_thresholds

    params = params_from(kwargs)
    cop, cmp = cop_region(params), cmp_region(params)
    spin_up = max_spin_up_time(params)
    omega = params.omega
    emit(
        {
            "params": params.to_dict(),
            "omega": params.omega,
            "cop": {"lower": cop.lower, "upper": cop.upper},
            "cmp": {
                "lower": cmp.lower,
                "upper": cmp.upper,
                "margin": cmp_offset(params),
                # JSON has no infinity: without hip torque there is no spin-up at all.
                "t_max": spin_up if spin_up != float("inf") else None,
            },
            # Largest recoverable CoM velocity from x = 0, [backward, forward], per strategy.
            "thresholds": {
                "ankle": [omega * cop.lower, omega * cop.upper],
                "hip": [omega * cmp.lower, omega * cmp.upper],
                "step": list(step_thresholds(params)),
            },
        },
        as_json,
    )


@cli.command(short_help="Strategy a CoM state needs: ankle, hip, step or fall.")
@click.option("--x", "x", type=float, required=True, help="CoM position relative to the ankle [m].")
@click.option("--xdot", type=float, required=True, help="CoM velocity [m/s].")
@body_options
def classify(x: float, xdot: float, as_json: bool, **kwargs: Any) -> None:
    """Which strategy the CoM state (x, xdot) needs: ankle, hip, step or fall."""
    from pushrecovery.surfaces.classify import classify as classify_state

    params = params_from(kwargs)
    result = classify_state(x, xdot, params).to_dict()
    emit({**result, "state": {"x": x, "xdot": xdot}}, as_json)


def _push_velocity(xdot: float | None, impulse: float | None, mass: float) -> float:
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.sim.push import Push

    if xdot is not None and impulse is not None:
        raise InvalidParameterError("give either --xdot [m/s] or --impulse [N s], not both")
    if impulse is not None:
        return Push.from_impulse(impulse, mass).delta_velocity
    return 0.0 if xdot is None else xdot


def _controller_options(
    kp: float | None, kd: float | None, pairs: tuple[str, ...] = ()
) -> dict[str, Any]:
    from pushrecovery.errors import InvalidParameterError

    options: dict[str, Any] = {"stiffness": kp, "damping": kd}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        if not sep or not name:
            raise InvalidParameterError(f"--option must be NAME=VALUE, got {pair!r}")
        try:
            value: Any = int(text) if text.lstrip("+-").isdigit() else float(text)
        except ValueError:
            raise InvalidParameterError(f"--option {name} must be a number, got {text!r}") from None
        options[name.replace("-", "_")] = value
    return {k: v for k, v in options.items() if v is not None}


def _options_for(controller: str, options: dict[str, Any]) -> dict[str, Any]:
    """Drop the ankle-pd gain flags for other controllers (they default to None anyway)."""
    if controller != "ankle-pd":
        for gain in ("stiffness", "damping"):
            if gain in options:
                from pushrecovery.errors import InvalidParameterError

                raise InvalidParameterError(f"--kp/--kd apply to ankle-pd, not {controller!r}")
    return options


_backend = click.option(
    "--backend",
    type=click.Choice(("analytic", "mujoco")),
    default="analytic",
    show_default=True,
    help="Physics: the analytic models, or MuJoCo (model 'foot' so far).",
)
_model = click.option(
    "--model",
    type=click.Choice((*MODEL_CHOICES, "foot")),
    default="lipm",
    show_default=True,
    help="Plant: linear inverted pendulum or nonlinear pendulum.",
)
_controller = click.option(
    "--controller",
    type=click.Choice(CONTROLLER_CHOICES),
    default="ankle-pd",
    show_default=True,
    help="Controller.",
)
_gains = (
    click.option("--kp", type=float, default=None, help="ankle-pd stiffness [N m/rad]."),
    click.option("--kd", type=float, default=None, help="ankle-pd damping [N m s/rad]."),
    click.option(
        "--option",
        "options",
        multiple=True,
        metavar="NAME=VALUE",
        help="Controller option, repeatable: e.g. horizon=30, gamma=1, dt=0.01 (mpc); "
        "switch_time=0.2 (bang-bang).",
    ),
)


def _with(*decorators: Any) -> Any:
    def apply(func: Any) -> Any:
        for decorator in reversed(decorators):
            func = decorator(func)
        return func

    return apply


@cli.command(short_help="Simulate a push; report recovered or fell.")
@_with(_backend, _model, _controller, *_gains)
@click.option(
    "--x", "x", type=float, default=0.0, show_default=True, help="CoM position before the push [m]."
)
@click.option("--xdot", type=float, default=None, help="CoM velocity just after the push [m/s].")
@click.option(
    "--impulse",
    type=float,
    default=None,
    help="Push as an impulse on the CoM [N s] (instead of --xdot).",
)
@click.option(
    "--duration", type=float, default=10.0, show_default=True, help="Longest simulated time [s]."
)
@click.option(
    "--control-period",
    type=float,
    default=None,
    help="Controller period [s] (default: the controller's own, else 0.001).",
)
@click.option(
    "--plot",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write a plot of the run (PNG, SVG or PDF by extension).",
)
@body_options
def simulate(
    backend: str,
    model: str,
    controller: str,
    kp: float | None,
    kd: float | None,
    options: tuple[str, ...],
    x: float,
    xdot: float | None,
    impulse: float | None,
    duration: float,
    control_period: float | None,
    plot: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Simulate a push on a model with a controller; report recovered or fell."""
    from pushrecovery.control.base import make_controller
    from pushrecovery.sim.plants import make_plant
    from pushrecovery.sim.simulate import simulate as run
    from pushrecovery.surfaces.classify import classify as classify_state

    params = params_from(kwargs)
    velocity = _push_velocity(xdot, impulse, params.mass)
    predicted = classify_state(x, velocity, params)
    plant = make_plant(model, params, backend)
    if backend == "mujoco" and impulse is not None:
        # A real force at the CoM, over 10 ms, instead of a velocity jump.
        initial = plant.initial_state(x, 0.0)
        plant.schedule_push(impulse)  # type: ignore[attr-defined]
    else:
        initial = plant.initial_state(x, velocity)
    result = run(
        plant,
        make_controller(
            controller, params, **_options_for(controller, _controller_options(kp, kd, options))
        ),
        initial,
        duration=duration,
        control_period=control_period,
    )
    data = result.to_dict()
    data["initial_state"] = {"x": x, "xdot": velocity}
    data["predicted"] = predicted.to_dict()
    if plot:
        from pushrecovery.plots.runs import save_run

        data["plot"] = str(save_run(result, params, Path(plot)))
    emit(data, as_json)


@cli.command("critical-push", short_help="Largest recoverable push, vs Eq. 4.")
@_with(_backend, _model, _controller, *_gains)
@click.option(
    "--x",
    "x",
    type=float,
    default=0.0,
    show_default=True,
    help="CoM position before the push, on the foot [m].",
)
@click.option(
    "--direction", type=click.Choice(("forward", "backward")), default="forward", show_default=True
)
@click.option(
    "--tolerance",
    type=float,
    default=1e-4,
    show_default=True,
    help="Width of the final velocity bracket [m/s].",
)
@click.option(
    "--duration",
    type=float,
    default=10.0,
    show_default=True,
    help="Longest simulated time per push [s].",
)
@click.option(
    "--control-period",
    type=float,
    default=None,
    help="Controller period [s] (default: the controller's own, else 0.001).",
)
@body_options
def critical_push(
    backend: str,
    model: str,
    controller: str,
    kp: float | None,
    kd: float | None,
    options: tuple[str, ...],
    x: float,
    direction: str,
    tolerance: float,
    duration: float,
    control_period: float | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Largest recoverable push from x by bisection, against the strategy's surface."""
    from pushrecovery.sim.critical import critical_push as search

    params = params_from(kwargs)
    found = search(
        params,
        model,
        controller,
        x,
        direction,
        tolerance=tolerance,
        duration=duration,
        control_period=control_period,
        controller_options=_options_for(controller, _controller_options(kp, kd, options)),
        backend=backend,
    )
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
        },
        as_json,
    )


@cli.command(short_help="Reproduce the paper's figures.")
@click.option(
    "--out",
    type=click.Path(file_okay=False),
    default="out/figures",
    show_default=True,
    help="Directory for the figures.",
)
@click.option(
    "--format",
    "formats",
    multiple=True,
    default=("png", "svg"),
    show_default=True,
    type=click.Choice(("png", "svg", "pdf")),
    help="File formats (repeatable).",
)
@body_options
def figures(out: str, formats: tuple[str, ...], as_json: bool, **kwargs: Any) -> None:
    """Reproduce the paper's figures (Fig. 3, 5, 6) into a directory."""
    from pushrecovery.plots.figures import write_figures

    params = params_from(kwargs)
    files = write_figures(params, Path(out), formats)
    emit({"files": [str(f) for f in files]}, as_json)


@cli.command(short_help="Optimal step after a push (Sec. IV, Eq. 21).")
@click.option(
    "--v0",
    "speeds",
    type=float,
    multiple=True,
    help="CoM velocity with the CoM above the stance ankle [m/s], > 0 (repeatable).",
)
@click.option(
    "--v0-range",
    nargs=3,
    type=float,
    default=None,
    metavar="START STOP STEP",
    help="Velocities START, START+STEP, ... up to STOP (inclusive) [m/s].",
)
@body_options
def step(
    speeds: tuple[float, ...],
    v0_range: tuple[float, float, float] | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Optimal step (Eq. 21) and the range of recovering steps for initial CoM velocities."""
    import numpy as np

    from pushrecovery._validate import finite_array
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.models.stepping import step_solution

    params = params_from(kwargs)
    values = list(speeds)
    if v0_range is not None:
        start, stop, increment = (float(v) for v in finite_array("--v0-range", v0_range))
        if increment <= 0.0 or stop < start:
            raise InvalidParameterError(
                f"--v0-range needs START <= STOP and STEP > 0, got {start:g} {stop:g} {increment:g}"
            )
        count = int(np.floor((stop - start) / increment + 1e-9)) + 1
        if count > 100_000:
            raise InvalidParameterError(f"--v0-range gives {count} velocities; at most 100000")
        values.extend(start + increment * np.arange(count))
    if not values:
        raise InvalidParameterError("give --v0 V (repeatable) or --v0-range START STOP STEP")
    v0 = finite_array("v0", values)
    if np.any(v0 < 1e-6):
        raise InvalidParameterError(
            "v0 must be >= 1e-6 m/s (a forward push; backward steps are the mirror image)"
        )
    sol = step_solution(v0, params.leg_length, params.gravity, params.heel, params.toe)
    reach = params.max_step_length
    rows = [
        {
            "v0": float(sol.v0[i]),
            "theta": float(sol.theta[i]),
            "theta_rate": float(sol.theta_rate[i]),
            "time_to_impact": float(sol.time_to_impact[i]),
            "step_length": float(sol.step_length[i]),
            "com_to_foot": float(sol.com_to_foot[i]),
            "velocity_before": {
                "x": float(sol.velocity_before_x[i]),
                "z": float(sol.velocity_before_z[i]),
            },
            "velocity_after": float(sol.velocity_after[i]),
            "height_after": float(sol.height_after[i]),
            "theta_range": [float(sol.theta_low[i]), float(sol.theta_high[i])],
            "step_length_range": [
                float(sol.step_length_of(sol.theta_low[i])),
                float(sol.step_length_of(sol.theta_high[i])),
            ],
            "centred_theta": float(sol.centred_theta[i]),
            "centred_step_length": float(sol.step_length_of(sol.centred_theta[i])),
            "stance_leg_in_compression": bool(sol.stance_leg_in_compression[i]),
            "within_reach": bool(sol.step_length[i] <= reach),
        }
        for i in range(len(v0))
    ]
    if as_json:
        import json

        click.echo(json.dumps(rows[0] if len(rows) == 1 else rows, indent=2, allow_nan=False))
        return
    for row in rows:
        emit(row, False)
        click.echo("")
