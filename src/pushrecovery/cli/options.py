"""Options every command shares: the body parameters and ``--json``; ``--out``, ``--duration``."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import click

if TYPE_CHECKING:
    from pushrecovery.params import BodyParams

F = TypeVar("F", bound=Callable[..., Any])

#: (flag, field, help) for each body parameter; SI units.
PARAM_FLAGS: tuple[tuple[str, str, str], ...] = (
    ("--mass", "mass", "Body mass m [kg]."),
    ("--com-height", "com_height", "CoM height L above the ankle [m]."),
    ("--gravity", "gravity", "Gravity g [m/s^2]."),
    ("--heel", "heel", "Heel edge δ⁻ relative to the ankle, < 0 [m]."),
    ("--toe", "toe", "Toe edge δ⁺ relative to the ankle, > 0 [m]."),
    ("--flywheel-inertia", "flywheel_inertia", "Upper-body inertia I [kg m^2]."),
    ("--torque-max", "torque_max", "Hip torque limit τmax [N m]."),
    ("--flywheel-angle-max", "flywheel_angle_max", "Hip joint limit θmax [rad]."),
    ("--leg-length", "leg_length", "Leg length for stepping [m] (default: CoM height)."),
    ("--max-step-length", "max_step_length", "Longest step, foot to foot [m] (default: leg)."),
    ("--foot-width", "foot_width", "Foot width [m] (rectangular foot)."),
    ("--stance-width", "stance_width", "Ankle-to-ankle distance in double support [m]."),
    (
        "--flywheel-inertia-roll",
        "flywheel_inertia_roll",
        "Upper-body roll inertia [kg m^2] (default: pitch).",
    ),
    ("--torque-max-roll", "torque_max_roll", "Hip roll torque limit [N m] (default: pitch)."),
    (
        "--flywheel-angle-max-roll",
        "flywheel_angle_max_roll",
        "Hip roll joint limit [rad] (default: pitch).",
    ),
    (
        "--min-step-time",
        "min_step_time",
        "Shortest time from deciding to step to touchdown Δt_s [s] (default 0.2).",
    ),
    ("--max-steps", "max_steps", "Most steps of a step verdict (default: where regions stop)."),
    (
        "--min-step-width",
        "min_step_width",
        "Narrowest lateral stance-to-landing ankle distance [m] (default: none, crossovers).",
    ),
    (
        "--ankle-torque-max",
        "ankle_torque_max",
        "Ankle torque limit [N m] the plans' CoPs are checked against (default: none).",
    ),
    (
        "--friction",
        "friction",
        "Friction coefficient μ the plans are checked against (default: none).",
    ),
)


def body_options(func: F) -> F:
    """Add ``--preset``, ``--params FILE``, one flag per parameter and ``--json``."""
    return _body_options(func, None)


def body_options_of(model: str) -> Callable[[F], F]:
    """Return :func:`body_options` whose body flags say that they build ``model`` only.

    Parameters
    ----------
    model : str
        The one model the body flags build (``biped3d``: the G1 has its own body and refuses
        ``--preset``, ``--params`` and the body flags).

    Returns
    -------
    callable
        The click decorator.
    """

    def apply(func: F) -> F:
        return _body_options(func, model)

    return apply


def _body_options(func: F, only: str | None) -> F:
    def text(help_text: str) -> str:
        if only is None:
            return help_text
        if help_text.split()[0][1:].islower():  # "Body mass" -> "body mass"; "CoM", "TOML" kept
            help_text = help_text[0].lower() + help_text[1:]
        return f"{only} only: {help_text}"

    for flag, field, help_text in reversed(PARAM_FLAGS):
        func = click.option(flag, field, type=float, default=None, help=text(help_text))(func)
    func = click.option(
        "--params",
        "params_file",
        type=click.Path(dir_okay=False),
        default=None,
        help=text("TOML file of parameters (overrides the preset)."),
    )(func)
    func = click.option(
        "--preset", default="paper", show_default=True, help=text("Built-in preset.")
    )(func)
    return click.option(
        "--json",
        "as_json",
        is_flag=True,
        help="Print JSON instead of the table; its keys are stable.",
    )(func)


def needs_plots(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
    """Check the ``plots`` extra when ``--plot`` asks for a figure (a click option callback).

    Before the command's work starts, not after it: a campaign or a simulation without
    matplotlib ends at once with one line naming the extra (and the ``--no-plot`` flag).

    Parameters
    ----------
    ctx : click.Context
        The command's context: the extras of its command (:data:`.app.COMMAND_EXTRAS`) are
        checked first.
    param : click.Parameter
        The option (``--plot`` with a path, or the flag ``--plot/--no-plot``).
    value : Any
        Its value: a path, True or False; None or False draws nothing.

    Returns
    -------
    Any
        ``value``, unchanged.

    Raises
    ------
    MissingExtraError
        If a figure is asked for and matplotlib, or an extra of the command, is missing.
    """
    if value:
        from pushrecovery.cli.app import COMMAND_EXTRAS
        from pushrecovery.extras import require_extra

        for extra in COMMAND_EXTRAS.get(ctx.info_name or "", ()):  # the command's own first
            require_extra(extra, f"'{ctx.command_path}'")
        off = getattr(param, "secondary_opts", None)
        require_extra("plots", f"{param.opts[0]}" + (f" (else pass {off[0]})" if off else ""))
    return value


def out_option(default: str | None, help_text: str) -> Callable[[F], F]:
    """Return ``--out DIRECTORY``: required without a ``default``, else shown with it."""
    return click.option(
        "--out",
        type=click.Path(file_okay=False),
        default=default,
        show_default=default is not None,
        required=default is None,
        help=help_text,
    )


def range_option(*decls: str, help_text: str) -> Callable[[F], F]:
    """Return an optional ``START STOP STEP`` option: three floats, None when not given."""
    return click.option(
        *decls, nargs=3, type=float, default=None, metavar="START STOP STEP", help=help_text
    )


def duration_option(default: float | None, help_text: str) -> Callable[[F], F]:
    """Return ``--duration`` [s], the longest run, its ``default`` shown unless None."""
    return click.option(
        "--duration", type=float, default=default, show_default=default is not None, help=help_text
    )


def support_options(func: F) -> F:
    """Add ``--stance``, ``--left-foot`` and ``--right-foot`` (the support on the ground plane)."""
    for flag, text in (
        ("--right-foot", "Right ankle pose X,Y[,YAW] [m, m, rad] (default: 0,-stance_width/2)."),
        ("--left-foot", "Left ankle pose X,Y[,YAW] [m, m, rad] (default: 0,+stance_width/2)."),
    ):
        func = click.option(flag, type=str, default=None, metavar="X,Y[,YAW]", help=text)(func)
    return click.option(
        "--stance",
        type=click.Choice(("double", "left", "right")),
        default=None,
        help="Feet on the ground: the support polygon is the hull of both (double, the "
        "default), or one foot. These three override the --params file's [feet].",
    )(func)


#: The kwargs of :func:`support_options`.
SUPPORT_KEYS = ("stance", "left_foot", "right_foot")


def support_from(kwargs: dict[str, Any], params: BodyParams, file: str | None = None) -> Any:
    """Pop the support options out of a command's kwargs and build the ``Support``.

    The ``[feet]`` of the parameter ``file`` (``--params``), if any, then the flags (later
    wins), as :func:`~pushrecovery.presets.load_support`.
    """
    from pushrecovery.ground.support import FootPose
    from pushrecovery.presets import load_support

    overrides: dict[str, Any] = {"stance": kwargs.pop("stance")}
    for side in ("left", "right"):
        text = kwargs.pop(f"{side}_foot")
        overrides[side] = None if text is None else FootPose.parse(f"--{side}-foot", text)
    return load_support(params, file, overrides)


def params_from(kwargs: dict[str, Any]) -> BodyParams:
    """Pop the parameter options out of a command's kwargs and build the parameter set."""
    overrides = {field: kwargs.pop(field) for _, field, _ in PARAM_FLAGS}
    from pushrecovery.presets import load_params

    return load_params(kwargs.pop("preset"), kwargs.pop("params_file"), overrides)


def emit(data: dict[str, Any], as_json: bool) -> None:
    """Print ``data`` as JSON or as an aligned ``key: value`` table."""
    if as_json:
        click.echo(json.dumps(data, indent=2, allow_nan=False))
        return
    for line in _table(data):
        click.echo(line)


def echo_confusion(
    title: str,
    labels: Sequence[str],
    counts: Sequence[Sequence[int]],
    apart: Mapping[str, Sequence[int]] | None = None,
) -> None:
    """Print a confusion matrix under ``title``: one row and one column per label.

    ``apart``: columns of their own after a bar (the runs neither recovered nor fallen, per
    row), e.g. ``{"undecided": [...], "slipped": [...]}``.
    """
    apart = apart or {}
    click.echo(title)
    bar = " |" if apart else ""
    header = "".join(f"{label:>7}" for label in labels) + bar
    click.echo(" " * 10 + header + "".join(f"{name:>10}" for name in apart))
    for i, (label, row) in enumerate(zip(labels, counts, strict=True)):
        extra = "".join(f"{column[i]:>10}" for column in apart.values())
        click.echo(f"{label:<10}" + "".join(f"{count:>7}" for count in row) + bar + extra)


def _table(data: dict[str, Any], indent: str = "") -> list[str]:
    width = max((len(str(k)) for k in data), default=0)
    lines: list[str] = []
    for key, value in data.items():
        if isinstance(value, dict):
            lines.append(f"{indent}{key}:")
            lines.extend(_table(value, indent + "  "))
        else:
            lines.append(f"{indent}{key:<{width}}  {_fmt(value)}")
    return lines


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    return str(value)


def value_range_option(option: str, triple: tuple[float, float, float], limit: int) -> Any:
    """START, START+STEP, ... up to STOP (inclusive) as an array; at most ``limit`` values."""
    from pushrecovery.campaign.spec import value_range

    return value_range(option, triple, limit)


def mjcf_options(command: Any) -> Any:
    """Add the options of ``--model PATH.xml``: its feet, torso and standing keyframe."""
    for flag, what in (
        ("--keyframe", "--model PATH.xml: the keyframe of the standing pose (default qpos0)."),
        (
            "--torso-body",
            "--model PATH.xml: the upper body held upright and pushed (default: "
            "found by its name, docs/your_robot.md).",
        ),
        (
            "--right-foot-body",
            "--model PATH.xml: the right foot's body (default: found by its name).",
        ),
        (
            "--left-foot-body",
            "--model PATH.xml: the left foot's body (default: found by its name).",
        ),
    ):
        command = click.option(flag, default=None, metavar="NAME", help=what)(command)
    return command
