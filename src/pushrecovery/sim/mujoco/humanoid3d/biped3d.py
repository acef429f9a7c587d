"""A 3-D biped generated from a :class:`~pushrecovery.params.BodyParams` (docs/humanoid3d.md).

World frame x forward, y left, z up, SI units; every hinge is positive by the right-hand rule
about its axis (a hip or knee pitch about +y that is positive moves the foot backward).

Bodies and joints
-----------------
``torso``
    The pelvis and the torso, one rigid body on a free joint ``root`` (the floating base), its
    frame at the *hip centre* (midway between the hips). It carries the upper body's mass
    m_u = m − 2 m_leg with its centre of mass c above the hip centre (and a few mm forward or
    back) so that the whole body's CoM stands L = ``com_height`` above the ankles. Its inertia
    about the hip pitch axis (the y line through the hip centre) is I = ``flywheel_inertia``,
    about the hip roll axis (the x line through the hip centre) ``flywheel_inertia_roll``:
    the flywheel of Sec. III in pitch and roll. The principal inertia at its own CoM is that
    minus the parallel-axis term m_u (c² + x_u²) (pitch) or m_u c² (roll); the yaw inertia is
    max((I_x + I_y)/4, abs(I_x − I_y)), the least that keeps the triangle inequalities.
``<side>_thigh``
    At y = ±``stance_width``/2 below the hip centre: a 3-DoF hip, hinges ``<side>_hip_yaw``
    (z), ``<side>_hip_roll`` (x) and ``<side>_hip_pitch`` (y), in that order (a gimbal at one
    point); length ``leg_length``/2.
``<side>_shank``
    Knee hinge ``<side>_knee`` (y), 0 straight, positive flexion; length ``leg_length``/2.
``<side>_foot``
    A 2-DoF ankle, hinges ``<side>_ankle_pitch`` (y) then ``<side>_ankle_roll`` (x), at the foot
    frame's origin, ``ANKLE_HEIGHT`` above the floor; the sole ``<side>_sole`` spans
    [heel, toe] × [−w/2, w/2] (a box) or, with ``foot_polygon``, a prism of that polygon (the
    right foot's mirrored, y → −y), ``2 FOOT_HALF_THICKNESS`` thick under the ankle; a polygon
    sole touches the floor through capsules ``<side>_sole_<k>`` along its edges.

Masses: each leg's thigh, shank and foot carry the fractions :data:`SEGMENT_FRACTIONS` of m
(Winter's anthropometric table), their CoM on the segment at :data:`SEGMENT_COM` of its length
from the proximal joint (the foot's at the sole's centroid); the rest is the torso's. Every
segment's inertia is that of a solid cylinder of radius :data:`SEGMENT_RADIUS` × leg_length.

Motors: one torque motor (gear 1) per joint, named as the joint, clipped to :func:`torque_limits`.
Ranges: :func:`joint_ranges`. The standing posture (all joints 0, the soles on the floor) is
``qpos0`` and the keyframe ``stand``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.wbc.bodies import body_id, check_model
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.humanoid3d.measure import standing_qpos
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT, FOOT_HALF_THICKNESS, model_spec

__all__ = [
    "JOINTS",
    "KNEE_BEND",
    "SEGMENT_COM",
    "SEGMENT_FRACTIONS",
    "SIDES",
    "TIMESTEP",
    "bent_knee_qpos",
    "biped3d_model",
    "build_biped3d",
    "joint_ranges",
    "torque_limits",
    "upper_body_layout",
]

#: Leg names; +y is left.
SIDES = ("left", "right")
KNEE_BEND = 0.3  #: Knee flexion of the standing posture [rad] (:func:`bent_knee_qpos`).
#: One leg's joints from the hip down (each ``<side>_<joint>``), the order of the motors.
JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
#: Segment mass over body mass (Winter, *Biomechanics and Motor Control of Human Movement*,
#: 4th ed., Table 4.1): one thigh, one shank, one foot.
SEGMENT_FRACTIONS = {"thigh": 0.100, "shank": 0.0465, "foot": 0.0145}
#: Segment CoM from the proximal joint over the segment length (Winter, Table 4.1).
SEGMENT_COM = {"thigh": 0.433, "shank": 0.433}
#: Segment radius over leg_length (drawn capsules, and the cylinders of their inertias).
SEGMENT_RADIUS = 0.06
#: Range magnitudes [rad]: hip yaw, hip flexion (at least θmax), knee flexion, ankle pitch and
#: roll (human-like; the flywheel limits θmax act on the hips, :func:`joint_ranges`).
HIP_YAW_MAX = 0.5
HIP_FLEXION_MAX = 2.0
KNEE_MAX = 2.5
ANKLE_PITCH_MAX = 0.8
ANKLE_ROLL_MAX = 0.4
#: Ankle motors can move the CoP this many times past the foot's farthest edge (the CoP, not
#: the motor, limits the paper's ankle strategy).
ANKLE_TORQUE_MARGIN = 1.5
#: Physics step [s]: half the planar models' 1 ms. Under the explicit standing PD
#: (:mod:`.standing`) a trapezoid-footed biped chattered off its feet at 1 ms and stood at 0.5 ms.
TIMESTEP = 5e-4
#: Reflected rotor inertia of every leg joint over m leg_length² [-] (0.036 kg m² for 72 kg and
#: 1 m): keeps the light distal segments stable at the 1 ms step.
ARMATURE_FRACTION = 5e-4


def _foot_outline(params: BodyParams) -> list[tuple[float, float]]:
    """Return the left sole's outline in the foot frame (ankle at the origin) [m]."""
    if params.foot_polygon is not None:
        return [(float(x), float(y)) for x, y in params.foot_polygon]
    half = 0.5 * params.foot_width
    return [(params.heel, -half), (params.toe, -half), (params.toe, half), (params.heel, half)]


def _centroid(outline: list[tuple[float, float]]) -> tuple[float, float]:
    """Return the area centroid of a convex polygon [m] (shoelace formula)."""
    area = cx = cy = 0.0
    for (x0, y0), (x1, y1) in zip(outline, outline[1:] + outline[:1], strict=True):
        cross = x0 * y1 - x1 * y0
        area += cross
        cx += (x0 + x1) * cross
        cy += (y0 + y1) * cross
    return cx / (3.0 * area), cy / (3.0 * area)


def joint_ranges(params: BodyParams) -> dict[str, tuple[float, float]]:
    """Return each leg joint's range (low, high) [rad], the same for both legs.

    The hip's flywheel limits: the torso may lean back at most θmax = ``flywheel_angle_max``
    relative to the thigh (hip pitch ≤ θmax, positive is extension) and roll at most
    ``flywheel_angle_max_roll`` either way; forward the hip flexes to max(θmax,
    ``HIP_FLEXION_MAX``) so the swing leg can reach (its limit on the torso is the
    controller's).
    """
    require_type("params", params, BodyParams)
    pitch, roll = params.flywheel_angle_max, params.flywheel_angle_max_roll
    return {
        "hip_yaw": (-HIP_YAW_MAX, HIP_YAW_MAX),
        "hip_roll": (-roll, roll),
        "hip_pitch": (-max(pitch, HIP_FLEXION_MAX), pitch),
        "knee": (0.0, KNEE_MAX),
        "ankle_pitch": (-ANKLE_PITCH_MAX, ANKLE_PITCH_MAX),
        "ankle_roll": (-ANKLE_ROLL_MAX, ANKLE_ROLL_MAX),
    }


def torque_limits(params: BodyParams) -> dict[str, float]:
    """Return each leg joint's motor torque limit [N m], the same for both legs.

    Hip pitch τmax = ``torque_max`` and hip roll ``torque_max_roll`` (one hip's limit: the
    flywheel torque a single support can exert), hip yaw τmax/2; knee m g leg_length/2 (the
    weight at half a leg's lever); ankle pitch ``ANKLE_TORQUE_MARGIN`` m g max(−heel, toe) and
    roll ``ANKLE_TORQUE_MARGIN`` m g max|y| of the sole (the CoP at the foot's edges).
    """
    require_type("params", params, BodyParams)
    weight = params.weight
    reach_y = max(abs(y) for _, y in _foot_outline(params))
    return {
        "hip_yaw": 0.5 * params.torque_max,
        "hip_roll": params.torque_max_roll,
        "hip_pitch": params.torque_max,
        "knee": 0.5 * weight * params.leg_length,
        "ankle_pitch": ANKLE_TORQUE_MARGIN * weight * max(-params.heel, params.toe),
        "ankle_roll": ANKLE_TORQUE_MARGIN * weight * reach_y,
    }


def upper_body_layout(params: BodyParams) -> tuple[float, float, float]:
    """Return the torso's mass m_u [kg] and its CoM (x_u, c) relative to the hip centre [m].

    (x_u, c) put the whole-body CoM at x = 0 over the ankles and L above them with the legs
    straight: m_u c = m L − Σ legs m_i z_i − m_u ℓ (z from the ankle, ℓ = leg_length), and
    m_u x_u = −2 m_foot x_foot.
    """
    require_type("params", params, BodyParams)
    length = params.leg_length
    mass = params.mass
    thigh, shank, foot = (SEGMENT_FRACTIONS[k] * mass for k in ("thigh", "shank", "foot"))
    upper = mass - 2.0 * (thigh + shank + foot)
    half = 0.5 * length
    legs = 2.0 * (
        thigh * (length - SEGMENT_COM["thigh"] * half)
        + shank * (half - SEGMENT_COM["shank"] * half)
        + foot * (-FOOT_HALF_THICKNESS)
    )
    height = (mass * params.com_height - legs) / upper - length
    forward = -2.0 * foot * _centroid(_foot_outline(params))[0] / upper
    return upper, forward, height


def _torso_inertia(params: BodyParams) -> list[float]:
    """Return the torso's principal inertia at its CoM (roll, pitch, yaw) [kg m^2] (checked)."""
    upper, forward, height = upper_body_layout(params)
    roll = params.flywheel_inertia_roll - upper * height**2
    pitch = params.flywheel_inertia - upper * (height**2 + forward**2)
    for name, value, axis in (
        ("flywheel_inertia_roll", roll, height**2),
        ("flywheel_inertia", pitch, height**2 + forward**2),
    ):
        if value <= 1e-6 * getattr(params, name):
            raise InvalidParameterError(
                f"{name} must be > {upper * axis:.4g} kg m^2 for the 3-D biped (its torso of "
                f"{upper:.4g} kg has its CoM {math.sqrt(axis):.4g} m from the hip axis, to put "
                f"the body's CoM at com_height), got {getattr(params, name):g}"
            )
    return [roll, pitch, max(0.25 * (roll + pitch), abs(roll - pitch))]


def _check(params: BodyParams) -> None:
    """Raise InvalidParameterError for parameters the 3-D biped cannot take."""
    if not isinstance(params, BodyParams):
        raise InvalidParameterError(f"params must be a BodyParams, got {type(params).__name__}")
    for name in ("torque_max", "torque_max_roll"):
        if getattr(params, name) <= 0.0:
            raise InvalidParameterError(
                f"{name} must be in (0, 1e5] N m for the 3-D biped (its hips hold the torso "
                f"up), got {getattr(params, name):g}"
            )
    _, _, height = upper_body_layout(params)
    if not -params.leg_length < height < 2.0 * params.leg_length:
        raise InvalidParameterError(
            "com_height must put the torso's CoM within (−1, 2) leg_length of the hips: "
            f"com_height={params.com_height:g} m, leg_length={params.leg_length:g} m puts it "
            f"{height:.4g} m above them"
        )


def _cylinder(mass: float, radius: float, length: float) -> list[float]:
    """Return the principal inertia (x, y, z) of a solid cylinder along z [kg m^2]."""
    across = mass * (3.0 * radius**2 + length**2) / 12.0
    return [across, across, 0.5 * mass * radius**2]


def _add_sole(spec: Any, foot: Any, params: BodyParams, side: str, sign: float) -> None:
    """Add ``<side>_sole`` (box or polygon prism) to ``foot`` and set the foot's inertia."""
    import mujoco

    outline = [(x, sign * y) for x, y in _foot_outline(params)]
    mass = SEGMENT_FRACTIONS["foot"] * params.mass
    cx, cy = _centroid(outline if sign > 0 else outline[::-1])
    foot.explicitinertial = True
    foot.mass, foot.ipos = mass, [cx, cy, -FOOT_HALF_THICKNESS]
    length, width = params.toe - params.heel, params.foot_width
    thick = 2.0 * FOOT_HALF_THICKNESS
    foot.inertia = [
        mass * (width**2 + thick**2) / 12.0,
        mass * (length**2 + thick**2) / 12.0,
        mass * (length**2 + width**2) / 12.0,
    ]
    if params.foot_polygon is None:
        foot.add_geom(
            name=f"{side}_sole", type=mujoco.mjtGeom.mjGEOM_BOX,
            pos=[0.5 * (params.toe + params.heel), 0.0, -FOOT_HALF_THICKNESS],
            size=[0.5 * length, 0.5 * width, FOOT_HALF_THICKNESS],
            contype=2, conaffinity=1, rgba=[0.3, 0.3, 0.3, 1.0],
        )  # fmt: skip
        return
    # A polygon: a drawn prism and, for contact, a sphere under each vertex (a plane meets a
    # mesh in one point, on which the foot rocks): a capsule along each edge, whose ends are the
    # polygon's vertices.
    vertices = [[x, y, z] for x, y in outline for z in (0.0, -thick)]
    spec.add_mesh(name=f"{side}_sole", uservert=np.ravel(vertices).tolist())
    foot.add_geom(
        name=f"{side}_sole", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"{side}_sole",
        contype=0, conaffinity=0, rgba=[0.3, 0.3, 0.3, 1.0],
    )  # fmt: skip
    z = -FOOT_HALF_THICKNESS
    for k, ((x0, y0), (x1, y1)) in enumerate(zip(outline, outline[1:] + outline[:1], strict=True)):
        foot.add_geom(
            name=f"{side}_sole_{k}", type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            fromto=[x0, y0, z, x1, y1, z], size=[FOOT_HALF_THICKNESS, 0.0, 0.0],
            contype=2, conaffinity=1, rgba=[0.3, 0.3, 0.3, 1.0],
        )  # fmt: skip


def _add_leg(spec: Any, torso: Any, params: BodyParams, side: str, sign: float) -> None:
    """Add one leg (thigh, shank, foot, six hinges) below the hip at y = sign w/2."""
    import mujoco

    ranges = joint_ranges(params)
    half = 0.5 * params.leg_length
    radius = SEGMENT_RADIUS * params.leg_length
    armature = ARMATURE_FRACTION * params.mass * params.leg_length**2
    axes = {"yaw": [0, 0, 1], "roll": [1, 0, 0], "pitch": [0, 1, 0], "knee": [0, 1, 0]}
    colour = [0.4, 0.5, 0.8, 1.0]

    def hinge(body: Any, joint: str, axis: list[int]) -> None:
        body.add_joint(
            name=f"{side}_{joint}",
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=[float(a) for a in axis],
            range=list(ranges[joint]),
            limited=mujoco.mjtLimited.mjLIMITED_TRUE,
            armature=armature,
        )

    def segment(body: Any, name: str, end: float) -> None:
        mass = SEGMENT_FRACTIONS[name] * params.mass
        body.explicitinertial = True
        body.mass, body.ipos = mass, [0.0, 0.0, -SEGMENT_COM[name] * half]
        body.inertia = _cylinder(mass, radius, half)
        body.add_geom(
            name=f"{side}_{name}",
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            fromto=[0.0, 0.0, 0.0, 0.0, 0.0, -end],
            size=[radius, 0.0, 0.0],
            contype=2,
            conaffinity=1,
            rgba=colour,
        )

    thigh = torso.add_body(name=f"{side}_thigh", pos=[0.0, sign * 0.5 * params.stance_width, 0.0])
    for joint in ("hip_yaw", "hip_roll", "hip_pitch"):
        hinge(thigh, joint, axes[joint.split("_")[1]])
    segment(thigh, "thigh", half)
    shank = thigh.add_body(name=f"{side}_shank", pos=[0.0, 0.0, -half])
    hinge(shank, "knee", axes["knee"])
    # The shank's capsule stops a radius and 1.5 cm above the ankle: only the sole meets the floor.
    segment(shank, "shank", max(half - radius - 0.015, 0.5 * half))
    foot = shank.add_body(name=f"{side}_foot", pos=[0.0, 0.0, -half])
    hinge(foot, "ankle_pitch", axes["pitch"])
    hinge(foot, "ankle_roll", axes["roll"])
    _add_sole(spec, foot, params, side, sign)


def build_biped3d(params: BodyParams) -> Any:
    """Return the ``mujoco.MjSpec`` of the 3-D biped for ``params`` (module docstring).

    Raises
    ------
    InvalidParameterError
        If a hip torque limit is 0 (the hips hold the torso), or the body cannot have its CoM
        at ``com_height`` with the torso's inertia about the hips at ``flywheel_inertia``
        (+ roll): the message names the parameter and the range it needs.
    """
    import mujoco

    _check(params)
    inertia = _torso_inertia(params)
    upper, forward, height = upper_body_layout(params)
    spec = model_spec("biped3d", params)
    spec.option.timestep = TIMESTEP
    hip_height = ANKLE_HEIGHT + params.leg_length
    torso = spec.worldbody.add_body(name="torso", pos=[0.0, 0.0, hip_height])
    torso.add_freejoint(name="root")
    torso.explicitinertial = True
    torso.mass, torso.ipos, torso.inertia = upper, [forward, 0.0, height], inertia
    scale = params.leg_length
    torso.add_geom(
        name="pelvis",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.08 * scale, 0.5 * params.stance_width + 0.05 * scale, 0.05 * scale],
        contype=2,
        conaffinity=1,
        rgba=[0.9, 0.6, 0.2, 1.0],
    )
    torso.add_geom(
        name="trunk",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.05 * scale, 0.0, 0.0, max(2.0 * height, 0.5 * scale)],
        size=[0.1 * scale, 0.0, 0.0],
        contype=2,
        conaffinity=1,
        rgba=[0.9, 0.6, 0.2, 1.0],
    )
    for side, sign in zip(SIDES, (1.0, -1.0), strict=True):
        _add_leg(spec, torso, params, side, sign)
    limits = torque_limits(params)
    for side in SIDES:
        for joint in JOINTS:
            motor = spec.add_actuator(
                name=f"{side}_{joint}",
                target=f"{side}_{joint}",
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
            )
            motor.set_to_motor()
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.ctrlrange = [-limits[joint], limits[joint]]
    qpos = [0.0, 0.0, hip_height, 1.0, 0.0, 0.0, 0.0] + [0.0] * (len(SIDES) * len(JOINTS))
    spec.add_key(name="stand", qpos=qpos)
    return spec


def biped3d_model(params: BodyParams) -> Any:
    """Return the compiled ``mujoco.MjModel`` of :func:`build_biped3d`."""
    return build_biped3d(params).compile()


def bent_knee_qpos(model: Any, knee: float = KNEE_BEND) -> NDArray[np.float64]:
    """Return the standing posture, knees bent ``knee`` [rad] (not on their stops), soles on z = 0.

    Hip pitch −knee/2, knee +knee, ankle pitch −knee/2: each foot flat and under its hip.

    Raises
    ------
    InvalidParameterError
        If ``knee`` is not in [0, 1] rad.
    """
    check_model(model)
    if not (isinstance(knee, int | float) and 0.0 <= knee <= 1.0):
        raise InvalidParameterError(f"knee must be in [0, 1] rad, got {knee!r}")
    qpos = np.array(model.key("stand").qpos, dtype=float)
    for side in SIDES:
        for joint, angle in (("hip_pitch", -0.5), ("knee", 1.0), ("ankle_pitch", -0.5)):
            qpos[model.jnt_qposadr[model.joint(f"{side}_{joint}").id]] = angle * knee
    return standing_qpos(model, qpos, [body_id(model, f"{side}_foot") for side in SIDES])
