"""The options and their parsing shared by ``simulate`` and ``critical-push``.

The model and controller choices are read from the registries
(:mod:`pushrecovery.sim.registry`, :mod:`pushrecovery.control.registry`), which name them
without importing them; the 3-D humanoids are ``pushrecovery humanoid``'s.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

import click

from pushrecovery.cli.families import HUMANOID_MODELS, ListedChoice, ModelChoice
from pushrecovery.cli.options import duration_option
from pushrecovery.control.registry import CONTROLLER_NAMES
from pushrecovery.sim.registry import MODELS, MUJOCO_MODELS

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["controller_options", "planar_run", "timing"]


def planar_run(command: str, x_help: str) -> Callable[[F], F]:
    """Return the options that open a planar run's help: the plant, the controller, the start.

    Parameters
    ----------
    command : str
        ``simulate`` or ``critical-push`` (the models and controllers it lists).
    x_help : str
        The help of ``--x``, the CoM's start.

    Returns
    -------
    callable
        The click decorator adding ``--backend``, ``--model``, ``--controller``, ``--kp``,
        ``--kd``, ``--option`` (``options``) and ``--x``, in this order.
    """
    return _with(
        _backend,
        _model(command),
        _controller(command),
        *_gains,
        click.option("--x", "x", type=float, default=0.0, show_default=True, help=x_help),
    )


def timing(duration_help: str) -> Callable[[F], F]:
    """Return ``--duration`` (default 10 s, with ``duration_help``) and ``--control-period``."""
    return _with(
        duration_option(10.0, duration_help),
        click.option(
            "--control-period",
            type=float,
            default=None,
            help="Controller period [s] (default: the controller's own, else 0.001).",
        ),
    )


def controller_options(controller: str, kwargs: dict[str, Any]) -> dict[str, Any]:
    """Pop ``--kp``, ``--kd`` and ``--option`` out of a command's kwargs: the controller's options.

    Parameters
    ----------
    controller : str
        ``--controller``.
    kwargs : dict
        The command's keyword arguments.

    Returns
    -------
    dict
        The keyword arguments of ``make_controller`` given (``stiffness``, ``damping`` and each
        ``--option NAME=VALUE``, its name's ``-`` read as ``_``).

    Raises
    ------
    InvalidParameterError
        If an ``--option`` is not ``NAME=NUMBER``, or ``--kp``/``--kd`` is given to another
        controller than ``ankle-pd``.
    """
    from pushrecovery.errors import InvalidParameterError

    options: dict[str, Any] = {"stiffness": kwargs.pop("kp"), "damping": kwargs.pop("kd")}
    for pair in kwargs.pop("options"):
        name, sep, text = pair.partition("=")
        if not sep or not name:
            raise InvalidParameterError(f"--option must be NAME=VALUE, got {pair!r}")
        try:
            value: Any = int(text) if text.lstrip("+-").isdigit() else float(text)
        except ValueError:
            raise InvalidParameterError(f"--option {name} must be a number, got {text!r}") from None
        options[name.replace("-", "_")] = value
    options = {k: v for k, v in options.items() if v is not None}
    if controller != "ankle-pd" and ("stiffness" in options or "damping" in options):
        raise InvalidParameterError(f"--kp/--kd apply to ankle-pd, not {controller!r}")
    return options


_backend = click.option(
    "--backend",
    type=click.Choice(("analytic", "mujoco")),
    default="analytic",
    show_default=True,
    help="Physics: the analytic models (a push is a velocity jump), or MuJoCo (models foot, "
    "torso, biped; a push is a real force).",
)

#: The models and controllers each planar command does not run: accepted and refused by the
#: command in its own words, but not listed in its help (the critical push is sagittal).
_UNLISTED: dict[str, dict[str, tuple[str, ...]]] = {
    "simulate": {"model": (), "controller": ()},
    "critical-push": {"model": ("stepping-plane",), "controller": ("recovery-plane",)},
}


def _model(command: str) -> Any:
    """``--model`` of the planar ``command``; a 3-D humanoid is refused naming its command."""
    unlisted = _UNLISTED[command]["model"]
    plane = (
        "; on the ground plane: stepping-plane (two feet, --y and --ydot; with recovery-plane)"
        if "stepping-plane" not in unlisted
        else " (the critical push is sagittal: stepping-plane runs with simulate only)"
    )
    return click.option(
        "--model",
        type=ModelChoice(
            tuple(m for m in (*MODELS, *MUJOCO_MODELS) if m not in unlisted),
            elsewhere={m: f"humanoid {command} --model {m}" for m in HUMANOID_MODELS},
            family="a 3-D humanoid",
            unlisted=unlisted,
        ),
        default="lipm",
        show_default=True,
        help="Plant. Analytic: lipm, pendulum (ankle only), flywheel (+ hip), stepping (+ a "
        f"step) on the sagittal line{plane}. MuJoCo (--backend mujoco): foot, torso, biped. "
        "The 3-D humanoids: pushrecovery humanoid.",
    )


def _controller(command: str) -> Any:
    """Return ``--controller`` of the planar ``command``, naming the models of each controller."""
    unlisted = _UNLISTED[command]["controller"]
    plane = "" if "recovery-plane" in unlisted else "; recovery-plane: stepping-plane"
    return click.option(
        "--controller",
        type=ListedChoice(
            tuple(c for c in CONTROLLER_NAMES if c not in unlisted), unlisted=unlisted
        ),
        default="ankle-pd",
        show_default=True,
        help="Controller, for the models it runs: ankle-saturated, ankle-pd, "
        "ankle-capture-point: every model; bang-bang: flywheel, stepping, torso, biped; mpc: "
        f"flywheel, torso; recovery: stepping, biped{plane}.",
    )


_gains = (
    click.option(
        "--kp", type=float, default=None, help="ankle-pd only: ankle stiffness [N m/rad]."
    ),
    click.option(
        "--kd", type=float, default=None, help="ankle-pd only: ankle damping [N m s/rad]."
    ),
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
