"""Your own humanoid from an MJCF file: its model, standing pose, body parameters and plant.

:func:`describe_mjcf` loads the file (``mujoco.MjSpec``, its own floor, timestep and contact
settings), turns every actuator into a torque motor (:func:`~.robots.torque_motors`) and
measures the body at its standing pose: a keyframe (``keyframe``, by name) or ``qpos0``, the
free root lowered until the soles touch the floor. The body parameters are derived as for the
robots (:func:`~.robots.derive_description`, docs/humanoid3d.md) from the joints the leg
chains hold, found by their axes at that pose (world frame, x forward, y left, z up):

* the **leg** of a foot is the chain of bodies from the floating base's child on the way to the
  foot down to the foot;
* along it, from the hip down, the **hip pitch** is the first hinge whose axis is within 25° of
  ±y and the **hip roll** the first within 25° of ±x; the **ankle pitch** is the last hinge
  within 25° of ±y after the hip pitch, the **ankle roll** the last within 25° of ±x after the
  hip roll (none: an ankle that only pitches).

Feet and torso not named are found by their names (:func:`find_bodies`):

* a **foot** is a body whose name holds ``foot``, ``ankle``, ``toe`` or ``sole`` and none of
  whose descendants does (the last such body of its chain: the G1's ``left_ankle_roll_link``,
  not its ``left_ankle_pitch_link``); it is left if its name holds ``left`` (or starts with
  ``l_``, or ends with ``_l``), right likewise, else by the side of the standing pose it is on
  (y > 0: left);
* the **torso** is the one body whose name holds the first of ``torso``, ``trunk``, ``chest``,
  ``waist``, ``pelvis``, ``base`` that any body's name holds.

Where the rules find no foot for a side, two or more, or several torsos, the error lists the
candidates in one line. A foot or torso that is not a body of the model, or a leg without those
joints, is refused in one line naming it (and, for a missing body, the model's bodies that
could be meant).
:class:`MjcfPlant` is the 3-D plant of such a model (:mod:`.plant3d`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from pushrecovery.arguments import input_file
from pushrecovery.control.wbc.bodies import body_id
from pushrecovery.errors import InputFileError, InvalidParameterError
from pushrecovery.sim.mjcf_source import MjcfSource, model_name
from pushrecovery.sim.mujoco.humanoid3d.plant3d import CONTROL_PERIOD, Humanoid3DPlant
from pushrecovery.sim.mujoco.humanoid3d.robots import (
    LegJoints,
    RobotDescription,
    derive_description,
    torque_motors,
)

__all__ = ["AXIS_TOLERANCE", "MjcfPlant", "describe_mjcf", "load_mjcf"]

#: A hinge is a pitch (roll) joint when its axis is within this angle of ±y (±x) [deg].
AXIS_TOLERANCE = 25.0
#: Words that name a foot or an upper body (the torso's in the order the rules try them).
_HINTS = {
    "foot": ("foot", "ankle", "toe", "sole"),
    "torso": ("torso", "trunk", "chest", "waist", "pelvis", "base"),
}


def load_mjcf(path: str | Path) -> Any:
    """Return the MJCF file ``path`` as a compiled ``mujoco.MjModel`` driven by torque motors.

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a str or a Path.
    InvalidParameterError
        If the file does not exist (or is not a regular file) or MuJoCo cannot read it (its
        message, one line), its first joint is not a free joint (a floating base), or its
        timestep does not divide the whole-body controller's 2 ms period.
    """
    import mujoco

    try:
        file = input_file("path", path)
    except InputFileError as exc:  # missing, a folder, a pipe, a device, empty
        raise InvalidParameterError(f"model must be an MJCF file: {exc}") from None
    try:
        spec = mujoco.MjSpec.from_file(str(file))
        model = torque_motors(spec).compile()
        for i in range(model.nbody):
            model.body(i).name  # noqa: B018 - names MuJoCo cannot decode fail here, not later
    except (ValueError, UnicodeDecodeError) as exc:  # parse and compile errors, bad names
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InvalidParameterError(f"model {file.name}: {first}") from None
    if model.njnt < 1 or int(model.jnt_type[0]) != int(mujoco.mjtJoint.mjJNT_FREE):
        raise InvalidParameterError(
            f"model {file.name} must have a free joint first (a floating base), it has none"
        )
    steps = CONTROL_PERIOD / float(model.opt.timestep)
    if abs(steps - round(steps)) > 1e-9 or round(steps) < 1:
        raise InvalidParameterError(
            f"model {file.name}: its timestep must divide {CONTROL_PERIOD:g} s (the controller's "
            f"period), got {float(model.opt.timestep):g} s"
        )
    return model


def _body(model: Any, name: object, role: str) -> int:
    """Return the id of body ``name`` (``role``: a foot or the torso) or refuse it in one line."""
    if isinstance(name, str):
        try:
            return body_id(model, name)
        except InvalidParameterError:
            pass
    names = [model.body(i).name for i in range(1, model.nbody)]
    words = _HINTS["foot" if "foot" in role else "torso"]
    candidates = [n for n in names if any(w in n.lower() for w in words)] or names
    raise InvalidParameterError(
        f"{role} must be a body of the model, got {str(name)[:40]!r}; candidates: "
        + ", ".join(candidates[:12])
        + (" ..." if len(candidates) > 12 else "")
    )


def _side(name: str) -> str | None:
    """Return ``left`` or ``right`` where a body's name says which, else None."""
    low = name.lower()
    for side, short in (("left", "l"), ("right", "r")):
        if side in low or low.startswith(f"{short}_") or low.endswith(f"_{short}"):
            return side
    return None


def find_bodies(
    model: Any, data: Any, feet: tuple[str, str] | None, torso: str | None
) -> tuple[tuple[str, str], str]:
    """Return the feet (left, right) and torso: those given, else found by the module's rules.

    ``data`` holds the standing pose's kinematics (the side of a foot whose name says none).

    Raises
    ------
    InvalidParameterError
        Where the rules find no body or several for a role, listing the candidates.
    """
    names = [model.body(i).name for i in range(model.nbody)]
    if feet is None:
        words = _HINTS["foot"]
        marked = {i for i in range(1, model.nbody) if any(w in names[i].lower() for w in words)}
        # The last marked body of each chain: no marked body below it.
        ends = [i for i in sorted(marked) if not any(_ancestor(model, i, j) for j in marked)]
        sides: dict[str, list[str]] = {"left": [], "right": []}
        for i in ends:
            side = _side(names[i]) or ("left" if float(data.xpos[i][1]) > 0.0 else "right")
            sides[side].append(names[i])
        if len(sides["left"]) != 1 or len(sides["right"]) != 1:
            raise InvalidParameterError(
                f"feet could not be found by their names (left: {sides['left'] or 'none'}, "
                f"right: {sides['right'] or 'none'}): name them with --left-foot-body and "
                "--right-foot-body"
            )
        feet = (sides["left"][0], sides["right"][0])
    if torso is None:
        for word in _HINTS["torso"]:
            found = [n for n in names[1:] if word in n.lower()]
            if len(found) == 1:
                torso = found[0]
                break
            if found:
                raise InvalidParameterError(
                    f"torso could not be found by its name: {', '.join(found[:12])} all hold "
                    f"{word!r}; name it with --torso-body"
                )
        else:
            raise InvalidParameterError(
                "torso could not be found by its name (none holds "
                f"{', '.join(_HINTS['torso'])}); name it with --torso-body"
            )
    return (feet[0], feet[1]), torso


def _ancestor(model: Any, ancestor: int, body: int) -> bool:
    """Whether ``ancestor`` is above ``body`` in the kinematic tree."""
    while body > 0:
        body = int(model.body_parentid[body])
        if body == ancestor:
            return True
    return False


def _leg_joints(model: Any, foot: int, role: str) -> tuple[int, list[int]]:
    """Return the leg's top body and its hinges from the hip down to ``foot`` (ids)."""
    import mujoco

    chain = [foot]
    while int(model.body_parentid[chain[-1]]) != 0:
        chain.append(int(model.body_parentid[chain[-1]]))
    chain.reverse()  # chain[0] is the floating base; its child on the way is the leg's top
    if len(chain) < 2:
        raise InvalidParameterError(f"{role} must be below the floating base, not it")
    hinges = [
        j
        for b in chain[1:]
        for j in range(int(model.body_jntadr[b]), int(model.body_jntadr[b] + model.body_jntnum[b]))
        if int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_HINGE)
    ]
    return chain[1], hinges


def _axis_joints(data: Any, hinges: list[int], role: str) -> tuple[int, int, int, int | None]:
    """Return (hip pitch, hip roll, ankle pitch, ankle roll) of a leg's hinges (module doc)."""
    cosine = math.cos(math.radians(AXIS_TOLERANCE))

    def along(j: int, axis: int) -> bool:
        return abs(float(data.xaxis[j][axis])) >= cosine

    pitch = [j for j in hinges if along(j, 1)]
    roll = [j for j in hinges if along(j, 0)]
    if len(pitch) < 2 or not roll:
        raise InvalidParameterError(
            f"{role}: its leg needs a hip and an ankle pitch joint (axis within "
            f"{AXIS_TOLERANCE:g}° of y) and a hip roll joint (of x); found {len(pitch)} pitch "
            f"and {len(roll)} roll hinges"
        )
    ankle_roll = roll[-1] if len(roll) > 1 and roll[-1] > roll[0] else None
    return pitch[0], roll[0], pitch[-1], ankle_roll


def describe_mjcf(
    path: str | Path,
    *,
    feet: tuple[str, str] | None = None,
    torso: str | None = None,
    keyframe: str | None = None,
) -> RobotDescription:
    """Return the humanoid of MJCF file ``path``: model, standing pose, body parameters.

    Parameters
    ----------
    path : str or Path
        The MJCF file (robot and floor; a free joint first).
    feet : (str, str), optional
        The left and right foot bodies (default: found by the module's rules).
    torso : str, optional
        The upper body the whole-body controller holds upright and a push named ``"torso"``
        acts on (default: found by the module's rules).
    keyframe : str, optional
        The keyframe of the standing pose (default ``qpos0``).

    Raises
    ------
    InvalidParameterError
        Naming the file, a body, the keyframe or a leg joint that is missing (module docstring).
    """
    import mujoco

    model = load_mjcf(path)
    if feet is not None and not (isinstance(feet, tuple | list) and len(feet) == 2):
        raise InvalidParameterError(f"feet must be two body names (left, right), got {feet!r}")
    if keyframe is None:
        start = np.array(model.qpos0, dtype=float)
    else:
        names = [model.key(i).name for i in range(model.nkey)]
        if keyframe not in names:
            raise InvalidParameterError(
                f"keyframe must be one of the model's {names or '(none)'}, got {keyframe!r}"
            )
        start = np.array(model.key(keyframe).qpos, dtype=float)
    data = mujoco.MjData(model)
    data.qpos[:] = start
    mujoco.mj_kinematics(model, data)
    feet, torso = find_bodies(model, data, feet, torso)
    sides = ("left", "right")
    foot_ids = [_body(model, name, f"{side} foot") for name, side in zip(feet, sides, strict=True)]
    _body(model, torso, "torso")
    legs, found = [], []
    for foot, side in zip(foot_ids, ("left", "right"), strict=True):
        top, hinges = _leg_joints(model, foot, f"{side} foot")
        legs.append(top)
        found.append(_axis_joints(data, hinges, f"{side} foot"))
    rolls = [f[3] for f in found]
    joints = LegJoints(
        hip_pitch=[f[0] for f in found],
        hip_roll=[f[1] for f in found],
        ankle_pitch=[f[2] for f in found],
        ankle_roll=None if None in rolls else [int(r) for r in rolls if r is not None],
    )
    described = derive_description(model_name(path), model, start, legs, foot_ids, joints)
    return replace(described, torso=torso)


class MjcfPlant(Humanoid3DPlant):
    """The 3-D plant of a humanoid from an MJCF file (:func:`describe_mjcf`), its own body.

    Parameters
    ----------
    path : str or Path
        The MJCF file.
    feet : (str, str), optional
        The left and right foot bodies (default: found by their names, module docstring).
    torso : str, optional
        The upper body (held upright; a push named ``"torso"`` acts on it; default: found by
        its name).
    keyframe : str, optional
        The standing pose's keyframe (default ``qpos0``).
    """

    name: ClassVar[str] = "mjcf"
    #: The hip task needs a flywheel-like upper body; off unless asked (as the G1's).
    hip_task: ClassVar[bool] = False

    def __init__(
        self,
        path: str | Path,
        feet: tuple[str, str] | None = None,
        torso: str | None = None,
        keyframe: str | None = None,
    ) -> None:
        described = describe_mjcf(path, feet=feet, torso=torso, keyframe=keyframe)
        self.description = described
        model, upper = described.model, str(described.torso)
        left, right = (model.body(i).name for i in described.feet)
        #: What names this plant for a campaign's workers (the bodies found, if not given).
        self.source = MjcfSource(str(path), (left, right), upper, keyframe)
        super().__init__(described.params, model, described.qpos, (left, right),
                         torso=upper, upright=upper, ankle=described.ankle)  # fmt: skip
