"""The options and their parsing shared by ``simulate`` and ``critical-push``.

The model and controller choices are read from the registries
(:mod:`pushrecovery.sim.registry`, :mod:`pushrecovery.control.registry`), which name them
without importing them.
"""

from __future__ import annotations

from typing import Any

import click

from pushrecovery.cli.families import HUMANOID_MODELS, ListedChoice, ModelChoice
from pushrecovery.control.registry import CONTROLLER_NAMES
from pushrecovery.sim.registry import MODELS, MUJOCO_MODELS

__all__ = ["CONTROLLER_CHOICES", "MODEL_CHOICES", "MUJOCO_MODEL_CHOICES"]

#: The ``--model`` and ``--controller`` choices (the planar models; the 3-D humanoids are
#: ``pushrecovery humanoid``'s).
MODEL_CHOICES = MODELS
MUJOCO_MODEL_CHOICES = MUJOCO_MODELS
CONTROLLER_CHOICES = CONTROLLER_NAMES


def _push_velocity(xdot: float | None, impulse: float | None, mass: float) -> float:
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
            tuple(m for m in (*MODEL_CHOICES, *MUJOCO_MODEL_CHOICES) if m not in unlisted),
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
            tuple(c for c in CONTROLLER_CHOICES if c not in unlisted), unlisted=unlisted
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
