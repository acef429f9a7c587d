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

A foot or torso that is not a body of the model, or a leg without those joints, is refused in
one line naming it (and, for a missing body, the model's bodies that could be meant).
:class:`MjcfPlant` is the 3-D plant of such a model (:mod:`.plant3d`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from pushrecovery.control.wbc.bodies import body_id
from pushrecovery.errors import InvalidParameterError
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
#: Words that name a foot or an upper body, for the candidates of a missing body's error.
_HINTS = {
    "foot": ("foot", "ankle", "toe", "sole"),
    "torso": ("torso", "pelvis", "trunk", "base", "waist", "chest"),
}


def load_mjcf(path: str | Path) -> Any:
    """Return the MJCF file ``path`` as a compiled ``mujoco.MjModel`` driven by torque motors.

    Raises
    ------
    InvalidParameterError
        If the file does not exist or MuJoCo cannot read it (its message, one line), its first
        joint is not a free joint (a floating base), or its timestep does not divide the
        whole-body controller's 2 ms period.
    """
    import mujoco

    file = Path(path)
    if not file.is_file():
        raise InvalidParameterError(f"model must be an MJCF file, got {str(path)[:80]!r}")
    try:
        spec = mujoco.MjSpec.from_file(str(file))
        model = torque_motors(spec).compile()
    except ValueError as exc:  # MuJoCo's parse and compile errors
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
        except KeyError:
            pass
    names = [model.body(i).name for i in range(1, model.nbody)]
    words = _HINTS["foot" if "foot" in role else "torso"]
    candidates = [n for n in names if any(w in n.lower() for w in words)] or names
    raise InvalidParameterError(
        f"{role} must be a body of the model, got {str(name)[:40]!r}; candidates: "
        + ", ".join(candidates[:12])
        + (" ..." if len(candidates) > 12 else "")
    )


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
    feet: tuple[str, str],
    torso: str,
    keyframe: str | None = None,
) -> RobotDescription:
    """Return the humanoid of MJCF file ``path``: model, standing pose, body parameters.

    Parameters
    ----------
    path : str or Path
        The MJCF file (robot and floor; a free joint first).
    feet : (str, str)
        The left and right foot bodies.
    torso : str
        The upper body the whole-body controller holds upright and a push named ``"torso"``
        acts on.
    keyframe : str, optional
        The keyframe of the standing pose (default ``qpos0``).

    Raises
    ------
    InvalidParameterError
        Naming the file, a body, the keyframe or a leg joint that is missing (module docstring).
    """
    import mujoco

    model = load_mjcf(path)
    if not (isinstance(feet, tuple | list) and len(feet) == 2):
        raise InvalidParameterError(f"feet must be two body names (left, right), got {feet!r}")
    sides = ("left", "right")
    foot_ids = [_body(model, name, f"{side} foot") for name, side in zip(feet, sides, strict=True)]
    _body(model, torso, "torso")
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
    return derive_description(model_name(path), model, start, legs, foot_ids, joints)


class MjcfPlant(Humanoid3DPlant):
    """The 3-D plant of a humanoid from an MJCF file (:func:`describe_mjcf`), its own body.

    Parameters
    ----------
    path : str or Path
        The MJCF file.
    feet : (str, str)
        The left and right foot bodies.
    torso : str
        The upper body (held upright; a push named ``"torso"`` acts on it).
    keyframe : str, optional
        The standing pose's keyframe (default ``qpos0``).
    """

    name: ClassVar[str] = "mjcf"
    #: The hip task needs a flywheel-like upper body; off unless asked (as the G1's).
    hip_task: ClassVar[bool] = False

    def __init__(
        self, path: str | Path, feet: tuple[str, str], torso: str, keyframe: str | None = None
    ) -> None:
        described = describe_mjcf(path, feet=feet, torso=torso, keyframe=keyframe)
        self.description = described
        #: What names this plant for a campaign's workers.
        self.source = MjcfSource(str(path), (feet[0], feet[1]), torso, keyframe)
        super().__init__(described.params, described.model, described.qpos, tuple(feet),
                         torso=torso, upright=torso)  # fmt: skip
