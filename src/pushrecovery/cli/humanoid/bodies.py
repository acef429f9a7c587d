"""The body and plant of a ``humanoid`` command's ``--model``: biped3d, g1 or an MJCF file.

:func:`body_3d` is what ``humanoid simulate`` and ``critical-push`` run (an MJCF file's plant is
built once, its body derived from the model); :func:`params_3d` is also the body of the 3-D
``validate`` and ``campaign``; ``bounds --model PATH.xml`` takes an MJCF file's body from
:func:`mjcf_plant`.
"""

from __future__ import annotations

from typing import Any

from pushrecovery.cli.options import params_from

__all__ = ["body_3d", "is_mjcf", "mjcf_body", "mjcf_plant", "params_3d"]


def body_3d(model: str, kwargs: dict[str, Any]) -> tuple[Any, Any]:
    """Return the body of ``--model`` and, for an MJCF file, its plant (None otherwise).

    Raises
    ------
    InvalidParameterError
        As :func:`mjcf_plant` and :func:`params_3d`.
    """
    if is_mjcf(model):
        plant = mjcf_plant(model, kwargs)
        return plant.params, plant
    return params_3d(model, kwargs), None


def is_mjcf(model: str) -> bool:
    """Whether ``--model`` names an MJCF file (``*.xml``) rather than a built-in humanoid."""
    return model.lower().endswith(".xml")


def mjcf_plant(model: str, kwargs: dict[str, Any], *, plant: bool = True) -> Any:
    """Return the plant of ``--model PATH.xml`` from the foot and torso options (popped).

    With ``plant`` False, its :func:`~pushrecovery.sim.mujoco.humanoid3d.mjcf.describe_mjcf`
    description only (the model and body, no controller's plant).

    Raises
    ------
    InvalidParameterError
        If a body flag is given (the model has its own body) or the file, a body or a leg's
        joints are missing (:func:`~pushrecovery.sim.mujoco.humanoid3d.mjcf.describe_mjcf`).
    MissingExtraError
        Without the ``sim`` extra (MuJoCo).
    """
    from pushrecovery.cli.options import PARAM_FLAGS
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.extras import require_extra

    given = [flag for flag, field, _ in PARAM_FLAGS if kwargs.get(field) is not None]
    if given or kwargs.get("params_file") or kwargs.get("preset", "paper") != "paper":
        raise InvalidParameterError(
            f"--model {model} has the model's own body: no --preset, --params or body flags "
            f"(got {(given or ['--preset/--params'])[0]})"
        )
    require_extra("sim", f"--model {model}")
    from pushrecovery.sim.mujoco.humanoid3d.mjcf import MjcfPlant, describe_mjcf

    left, right = kwargs.pop("left_foot_body"), kwargs.pop("right_foot_body")
    if (left is None) != (right is None):
        raise InvalidParameterError(
            "give both --left-foot-body and --right-foot-body, or neither (found by their names)"
        )
    feet = None if left is None else (left, right)
    torso, keyframe = kwargs.pop("torso_body"), kwargs.pop("keyframe")
    if not plant:
        return describe_mjcf(model, feet=feet, torso=torso, keyframe=keyframe)
    return MjcfPlant(model, feet, torso, keyframe)


def mjcf_body(model: str, kwargs: dict[str, Any]) -> tuple[Any, Any]:
    """Return the body of ``--model PATH.xml`` and the file's MjcfSource (options popped).

    Raises
    ------
    InvalidParameterError
        As :func:`mjcf_plant`, or if ``model`` is not an MJCF file (``*.xml``).
    """
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.sim.mjcf_source import MjcfSource

    if not is_mjcf(model):
        raise InvalidParameterError(f"--model must be an MJCF file PATH.xml, got {model!r}")
    keyframe = kwargs.get("keyframe")
    described = mjcf_plant(model, kwargs, plant=False)  # the bodies given or found
    left, right = (described.model.body(i).name for i in described.feet)
    source = MjcfSource(model, (left, right), str(described.torso), keyframe)
    return described.params, source


def params_3d(model: str, kwargs: dict[str, Any]) -> Any:
    """Return the body of a 3-D model: the options' (biped3d) or the robot's own (g1).

    Parameters
    ----------
    model : str
        ``biped3d`` or ``g1``.
    kwargs : dict
        The command's keyword arguments; the body options are popped out of it (biped3d).

    Returns
    -------
    BodyParams
        The body the plant is built from.

    Raises
    ------
    InvalidParameterError
        If ``g1`` is given a preset, a parameter file or a body flag, or a built-in model the
        options of an MJCF file (``--left-foot-body``, ...).
    """
    from pushrecovery.errors import InvalidParameterError

    for option in ("left_foot_body", "right_foot_body", "torso_body", "keyframe"):
        if kwargs.pop(option, None) is not None:
            flag = "--" + option.replace("_", "-")
            raise InvalidParameterError(f"{flag} needs --model PATH.xml (got --model {model})")
    if model != "g1":
        return params_from(kwargs)
    from pushrecovery.cli.options import PARAM_FLAGS

    given = [flag for flag, field, _ in PARAM_FLAGS if kwargs.get(field) is not None]
    if given or kwargs.get("params_file") or kwargs.get("preset", "paper") != "paper":
        raise InvalidParameterError(
            "--model g1 has the robot's own body: no --preset, --params or body flags "
            f"(got {(given or ['--preset/--params'])[0]})"
        )
    from pushrecovery.sim.mujoco.humanoid3d.robots import robot_params

    return robot_params("g1")
