"""The Unitree G1 under the whole-body controller (docs/humanoid3d_wbc.md).

The G1 of :func:`~.robots.describe_robot` (torque motors, 1 ms steps, its ``stand`` keyframe
lowered onto the floor): feet ``left_ankle_roll_link`` and ``right_ankle_roll_link`` (four
contact spheres each; the sole frame and polygon come from their bottoms, as
:func:`~.robots.robot_params` measures them), ``torso_link`` held upright and at its height,
and every other joint (legs, waist, arms) in the posture task. Pushes at ``torso_link``
(``plant3d.G1Plant``, ``runs3d.run_push3d``).
"""

from __future__ import annotations

from typing import Any

from pushrecovery.arguments import finite_float, require_type
from pushrecovery.control.wbc.bodies import sole_points
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.control.wbc.gains import WbcGains
from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.ground.polygon import convex_hull
from pushrecovery.sim.mujoco.humanoid3d.robots import RobotDescription

__all__ = ["G1_FEET", "G1_TORSO", "g1_ankle_impulse", "g1_controller"]

#: The G1's foot bodies (left, right) and the body the torso task holds upright.
G1_FEET = ("left_ankle_roll_link", "right_ankle_roll_link")
G1_TORSO = "torso_link"


def g1_controller(
    robot: RobotDescription,
    observation: HumanoidObservation,
    gains: WbcGains | None = None,
    *,
    hip: bool = False,
) -> WholeBodyController:
    """Return a :class:`WholeBodyController` for the G1 ``robot`` (its params for the hip).

    ``observation`` is the run's (:func:`~pushrecovery.control.wbc.observation.mujoco_observation`).
    """
    require_type("robot", robot, RobotDescription)
    return WholeBodyController(robot.model, G1_FEET, G1_TORSO, gains, observation=observation,
                               hip=robot.params if hip else None)  # fmt: skip


def g1_ankle_impulse(robot: RobotDescription, azimuth: float = 0.0) -> float:
    """Return the CoP region's critical impulse m ω × (CoM's ray to the soles' hull) [N s]."""
    require_type("robot", robot, RobotDescription)
    azimuth = finite_float("azimuth", azimuth, "rad")
    import mujoco

    model, params = robot.model, robot.params
    data = mujoco.MjData(model)
    data.qpos[:] = robot.qpos
    mujoco.mj_forward(model, data)
    hull = convex_hull(_soles(model, data, robot.feet)[:, :2])
    com = data.subtree_com[0]
    return params.mass * params.omega * hull.ray_distance(float(com[0]), float(com[1]), azimuth)


def _soles(model: Any, data: Any, feet: list[int]) -> Any:
    import numpy as np

    return np.vstack([sole_points(model, data, foot) for foot in feet])
