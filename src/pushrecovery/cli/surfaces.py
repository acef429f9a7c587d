"""Commands about decision surfaces: ``bounds``, ``classify`` and ``step``."""

from __future__ import annotations

from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.options import (
    body_options,
    emit,
    mjcf_options,
    params_from,
    range_option,
    support_from,
    support_options,
    value_range_option,
)

__all__ = ["bounds", "classify", "step"]


@click.command(
    short_help="Capture-point bounds of each strategy.",
    epilog=example(
        "pushrecovery bounds", "pushrecovery bounds --torque-max 50 --stance left --json"
    ),
)
@support_options
@body_options
@click.option(
    "--model",
    default=None,
    metavar="PATH.xml",
    help="Your own robot's MJCF file: its body parameters derived from the model (name its "
    "feet and torso with --left-foot-body, --right-foot-body, --torso-body; "
    "docs/your_robot.md) instead of the body flags.",
)
@mjcf_options
def bounds(as_json: bool, model: str | None, **kwargs: Any) -> None:
    """Capture-point bounds of each balance strategy (Eq. 4, corrected Eq. 15).

    Prints the body (params), omega = sqrt(g/L) [1/s] and, on the sagittal line, the
    capture-point interval of the ankle strategy (cop: [heel, toe], Eq. 4) and of the hip
    strategy (cmp: corrected Eq. 15, its margin beyond the foot and the longest bang-bang half
    period t_max [s]) in metres from the ankle, forward positive; the thresholds: the largest
    CoM velocity from x = 0 that each strategy recovers, [backward, forward] [m/s] (steps: for
    each number of steps, and inf, the limit); and on the ground plane (plane) the support
    polygon and the CMP region [m, from the ankles' midpoint, x forward, y left] and the
    thresholds forward, backward, left and right [m/s] for the chosen --stance. With --model
    PATH.xml the body is the MJCF file's, measured at its standing pose.
    """
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.surfaces.bounds import bounds_data

    file = kwargs["params_file"]
    if model is not None:
        if not model.lower().endswith(".xml"):
            raise InvalidParameterError(f"--model must be an MJCF file PATH.xml, got {model!r}")
        from pushrecovery.cli.humanoid.bodies import mjcf_plant

        params = mjcf_plant(model, kwargs, plant=False).params
    else:
        for option in ("left_foot_body", "right_foot_body", "torso_body", "keyframe"):
            if kwargs.pop(option) is not None:
                flag = "--" + option.replace("_", "-")
                raise InvalidParameterError(f"{flag} needs --model PATH.xml")
        params = params_from(kwargs)
    emit(bounds_data(params, support_from(kwargs, params, file)), as_json)


@click.command(
    short_help="Strategy a CoM state needs: ankle, hip, step or fall.",
    epilog=example(
        "pushrecovery classify --x 0.0 --xdot 0.7",
        "pushrecovery classify --x 0.0 --xdot 0.3 --ydot 0.4 --stance left --json",
    ),
)
@click.option(
    "--x", "x", type=float, required=True, help="CoM position, forward, from the ankle(s) [m]."
)
@click.option("--xdot", type=float, required=True, help="CoM velocity, forward [m/s].")
@click.option(
    "--y",
    "y",
    type=float,
    default=None,
    help="CoM position, left [m] (default 0); puts the state on the ground plane.",
)
@click.option(
    "--ydot",
    type=float,
    default=None,
    help="CoM velocity, left [m/s] (default 0); puts the state on the ground plane.",
)
@click.option(
    "--landing-yaw",
    type=float,
    default=None,
    help="Yaw of the plan's landing feet [rad], in [-pi, pi] (default: the stance foot's); "
    "puts the state on the ground plane.",
)
@click.option(
    "--cov",
    default=None,
    metavar="V,V,...",
    help="Covariance of the state estimate, row by row: 4 numbers for (x, xdot) [m², m²/s, "
    "m²/s²], 16 for (x, y, xdot, ydot) on the ground plane; adds the probability of each "
    "verdict (docs/uncertainty.md).",
)
@click.option(
    "--latency",
    default=None,
    metavar="S|LOW:HIGH",
    help="Loop latency [s]: the state is that old when the command acts, the CoP held at the "
    "middle of its region meanwhile; LOW:HIGH for a latency uniform in the range. Adds the "
    "probability of each verdict.",
)
@support_options
@body_options
def classify(
    x: float,
    xdot: float,
    y: float | None,
    ydot: float | None,
    landing_yaw: float | None,
    cov: str | None,
    latency: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Which strategy the CoM state needs: ankle, hip, step or fall.

    Prints the capture point x + xdot/omega [m], the least strategy that recovers the state,
    the margins of the capture point to the CoP, CMP and step bounds [m] (positive inside),
    the number of steps and, for a step, the step and the plan (footholds [m], touchdowns
    [s]). Without --y, --ydot, --stance, --left-foot or --right-foot: the paper's sagittal
    model, x relative to the ankle of a foot [heel, toe]. With any of them: the ground plane,
    x forward and y left in the frame of the feet (by default the ankles' midpoint is the
    origin, in every stance; the --params file's [feet], then the flags, place them), where
    the support polygon and the CMP region are 2-D and the margins are signed distances of the
    capture point to them [m], positive inside. A plan also says whether a step crosses over
    (lands across the stance foot's midline; a note in the table), the landing feet's yaw
    [rad], its peak ankle torque [N m] and horizontal ground force [N], and, when the body
    sets ankle_torque_max and friction (--params file), whether they hold (docs/steps.md).
    With --cov or --latency: the probabilities of ankle, hip, each number of steps and fall
    under that state estimate and loop latency (exact: Gaussian masses of the regions;
    probabilities).
    """
    from pushrecovery.surfaces.classify import classify as classify_state

    file = kwargs["params_file"]
    params = params_from(kwargs)
    planar = (
        y is not None
        or ydot is not None
        or landing_yaw is not None
        or any(kwargs[name] is not None for name in ("stance", "left_foot", "right_foot"))
    )
    if not planar:
        for name in ("stance", "left_foot", "right_foot"):
            kwargs.pop(name)
        result = classify_state(x, xdot, params).to_dict()
        chances = _probabilities([x, xdot], cov, latency, params, None)
        _emit_classified({**result, "state": {"x": x, "xdot": xdot}, **chances}, as_json)
        return
    y, ydot = (0.0 if y is None else y), (0.0 if ydot is None else ydot)
    support = support_from(kwargs, params, file)
    result = classify_state(
        x, xdot, params, y=y, ydot=ydot, support=support, landing_yaw=landing_yaw
    ).to_dict()
    chances = _probabilities([x, y, xdot, ydot], cov, latency, params, support)
    state = {"x": x, "xdot": xdot, "y": y, "ydot": ydot}
    _emit_classified({**result, "state": state, **chances}, as_json)


def _probabilities(
    mean: list[float], cov: str | None, latency: str | None, params: Any, support: Any
) -> dict[str, Any]:
    """``{"probabilities": ...}`` under --cov and --latency, or nothing without them."""
    if cov is None and latency is None:
        return {}
    import numpy as np

    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.surfaces.probability import StateGaussian, verdict_probabilities

    n = len(mean)
    if cov is None:
        matrix = np.zeros((n, n))
    else:
        try:
            values = [float(v) for v in cov.split(",")]
        except ValueError:
            raise InvalidParameterError(
                f"--cov must be {n * n} comma-separated numbers, got {cov!r}"
            ) from None
        if len(values) != n * n:
            names = "(x, xdot)" if n == 2 else "(x, y, xdot, ydot)"
            raise InvalidParameterError(
                f"--cov must be {n * n} numbers for the state {names}, row by row, "
                f"got {len(values)}"
            )
        matrix = np.array(values).reshape(n, n)
    delay: float | tuple[float, float] = 0.0
    if latency is not None:
        try:
            parts = [float(v) for v in latency.split(":")]
        except ValueError:
            parts = []
        if len(parts) not in (1, 2):
            raise InvalidParameterError(f"--latency must be S or LOW:HIGH [s], got {latency!r}")
        delay = parts[0] if len(parts) == 1 else (parts[0], parts[1])
    state = StateGaussian(np.array(mean, dtype=float), matrix)
    found = verdict_probabilities(state, params, support=support, latency=delay)
    return {"probabilities": found.to_dict()}


def _emit_classified(data: dict[str, Any], as_json: bool) -> None:
    """Print a classification; the table notes a plan that crosses over."""
    plan = data.get("plan")
    if not as_json and isinstance(plan, dict) and plan.get("crossover"):
        data["note"] = (
            "the plan crosses over: a foot lands across the stance foot's midline "
            "(a robot that cannot cross its legs sets min_step_width)"
        )
    emit(data, as_json)


@click.command(
    short_help="Optimal step after a push (Sec. IV, Eq. 21).",
    epilog=example(
        "pushrecovery step --v0 0.8", "pushrecovery step --v0-range 0.5 1.0 0.25 --json"
    ),
)
@click.option(
    "--v0",
    "speeds",
    type=float,
    multiple=True,
    help="CoM velocity with the CoM above the stance ankle [m/s], > 0 (repeatable).",
)
@range_option(
    "--v0-range", help_text="Velocities START, START+STEP, ... up to STOP (inclusive) [m/s]."
)
@body_options
def step(
    speeds: tuple[float, ...],
    v0_range: tuple[float, float, float] | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Optimal step (Eq. 21) and the range of recovering steps for initial CoM velocities.

    Sec. IV's stepping model: the CoM above the stance ankle moves forward at v0 [m/s] and the
    swing leg lands at the stance leg's lean theta [rad, positive forward] of Eq. 21, which
    puts the capture point after impact on the new ankle. Prints per v0 theta and its rate
    [rad/s], the time to impact [s], the step length (foot to foot) and the CoM-to-foot
    distance [m], the CoM velocity before (x forward, z up) and after impact [m/s], the CoM
    height after impact [m], the angles and step lengths that recover (the capture point on
    the new foot), the step centred on it, and whether the stance leg stays in compression
    and the step is within max_step_length; with --json, one object for one v0, else a list.
    """
    from pushrecovery.arguments import finite_array
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.models.stepping import step_solution

    params = params_from(kwargs)
    values = list(speeds)
    if v0_range is not None:
        values.extend(value_range_option("--v0-range", v0_range, limit=100_000))
    if not values:
        raise InvalidParameterError("give --v0 V (repeatable) or --v0-range START STOP STEP")
    v0 = finite_array("v0", values)
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
