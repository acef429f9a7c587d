"""MJCF models generated from a :class:`~pushrecovery.params.BodyParams` (sagittal plane).

Every model stands on real feet: thin boxes spanning [heel, toe] that rest on the floor and are
free in x, z and pitch, so a foot tips when its CoP reaches an edge. The ankle hinge sits
``ANKLE_HEIGHT`` above the floor (the paper's ankle is on the floor). MuJoCo hinges about +y
are positive leaning forward (x ahead of z).

``foot``: a massless-like rod of length L with the mass m in a small sphere at its top, on an
ankle: the paper's single inverted pendulum (Fig. 3b), L being the ankle-to-CoM distance.

``torso``: the same rod (the legs) up to a hip hinge at height L, limited to ±θmax, carrying an
upper body of mass m whose centre of mass is *at the hip* with inertia I about it: the
flywheel of Sec. III (Fig. 6), m and L as for ``foot``, I the upper body's inertia about the
hip. Turning the upper body does not move the CoM, as in the paper.

Each model is built as a ``mujoco.MjSpec`` (named elements, no MJCF text); the parts are shared
(:func:`model_spec`, :func:`add_foot`, :func:`add_upper_body`, :func:`add_motor`) so that the
models differ only by what they add. MuJoCo's types appear as ``Any``: its bindings ship no
type information.
"""

from __future__ import annotations

from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.params import BodyParams

__all__ = [
    "ANKLE_HEIGHT",
    "FOOT_MASS",
    "MODEL_BUILDERS",
    "TIMESTEP",
    "foot_model",
    "model_spec",
    "torso_model",
]

#: Half-thickness of the foot box [m]; the ankle sits on top of it.
FOOT_HALF_THICKNESS = 0.005
#: Ankle height above the floor [m].
ANKLE_HEIGHT = 2 * FOOT_HALF_THICKNESS
#: Mass of a foot [kg] (small: the paper's foot is massless).
FOOT_MASS = 0.2
#: Mass of the rod standing for massless legs [kg].
ROD_MASS = 1e-3
#: Radius of the sphere holding the body's mass in ``foot`` [m].
MASS_RADIUS = 0.03
#: Length of the drawn upper body above the hip in ``torso`` [m] (no mass: looks only).
TORSO_LENGTH = 0.5
#: Simulation step [s]: half the contact time constant, MuJoCo's stability limit for it.
TIMESTEP = 1e-3
#: Contact time constant [s].
CONTACT_TIME = 2e-3


def model_spec(name: str, params: BodyParams) -> Any:
    """Return a new ``mujoco.MjSpec``: options, contact defaults, the light and the floor.

    The shared part of every model (the ``<mujoco>`` header of an MJCF file). Every contact's
    sliding friction is ``params.friction`` when given, else 1.
    """
    require_type("name", name, str)
    require_type("params", params, BodyParams)
    import mujoco

    spec = mujoco.MjSpec()
    spec.modelname = f"pushrecovery-{name}"
    spec.compiler.degree = False  # angles in radians
    spec.option.timestep = TIMESTEP
    spec.option.gravity = [0.0, 0.0, -params.gravity]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_PYRAMIDAL
    spec.visual.global_.offwidth = 640
    spec.visual.global_.offheight = 480
    geom = spec.default.geom
    geom.contype, geom.conaffinity = 1, 1
    geom.friction = [1.0 if params.friction is None else params.friction, 0.005, 0.0001]
    geom.solref = [CONTACT_TIME, 1.0]
    geom.solimp[:3] = [0.95, 0.99, 0.001]
    spec.worldbody.add_light(
        pos=[0.0, -2.0, 3.0], dir=[0.0, 1.0, -1.0], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )
    spec.worldbody.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[5.0, 1.0, 0.1],
        rgba=[0.85, 0.85, 0.85, 1.0],
    )
    return spec


def add_foot(parent: Any, params: BodyParams, name: str = "foot", x: float = 0.0) -> Any:
    """Add a free (x, z, pitch) foot box to ``parent``, sole geom ``<name>_sole``; return it.

    Its ankle (where the leg attaches) is ``ANKLE_HEIGHT`` above the floor, at the box's top:
    children go at ``pos = (0, 0, FOOT_HALF_THICKNESS)``.
    """
    import mujoco

    foot = parent.add_body(name=name, pos=[x, 0.0, FOOT_HALF_THICKNESS])
    for axis, kind, joint in (
        ([1.0, 0.0, 0.0], mujoco.mjtJoint.mjJNT_SLIDE, "x"),
        ([0.0, 0.0, 1.0], mujoco.mjtJoint.mjJNT_SLIDE, "z"),
        ([0.0, 1.0, 0.0], mujoco.mjtJoint.mjJNT_HINGE, "pitch"),
    ):
        foot.add_joint(name=f"{name}_{joint}", type=kind, axis=axis)
    foot.add_geom(
        name="sole" if name == "foot" else f"{name}_sole",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        pos=[0.5 * (params.toe + params.heel), 0.0, 0.0],
        size=[0.5 * (params.toe - params.heel), 0.05, FOOT_HALF_THICKNESS],
        mass=FOOT_MASS,
        rgba=[0.3, 0.3, 0.3, 1.0],
    )
    return foot


def _leg_body(foot: Any, length: float) -> Any:
    """Add the rod standing for massless legs on an ankle hinge on top of ``foot``."""
    import mujoco

    body = foot.add_body(name="body", pos=[0.0, 0.0, FOOT_HALF_THICKNESS])
    body.add_joint(name="ankle", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 1.0, 0.0])
    body.add_geom(
        name="rod",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.0, 0.0, 0.0, length],
        size=[0.01, 0.0, 0.0],
        mass=ROD_MASS,
        contype=2,
        conaffinity=2,
        rgba=[0.4, 0.5, 0.8, 1.0],
    )
    return body


def add_motor(spec: Any, joint: str) -> None:
    """Add a torque motor (gear 1) on ``joint``, named as it."""
    import mujoco

    motor = spec.add_actuator(name=joint, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    motor.set_to_motor()


def add_upper_body(
    parent: Any, params: BodyParams, mass: float, pos: list[float], com: float = 0.0
) -> Any:
    """Add the upper body ``torso`` at ``pos``: ``mass`` [kg] ``com`` [m] above its origin.

    Its inertia about its CoM is I (``params.flywheel_inertia``). Drawn as a pelvis sphere and
    a trunk; its joint (the hip of ``torso``, the floating base of ``biped``) is the caller's.
    """
    import mujoco

    torso = parent.add_body(name="torso", pos=pos)
    torso.explicitinertial = True
    torso.mass, torso.ipos = mass, [0.0, 0.0, com]
    torso.inertia = [params.flywheel_inertia] * 3
    torso.add_geom(
        name="pelvis",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[MASS_RADIUS, 0.0, 0.0],
        contype=2,
        conaffinity=1,
        rgba=[0.9, 0.6, 0.2, 1.0],
    )
    torso.add_geom(
        name="trunk",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.0, 0.0, 0.0, TORSO_LENGTH],
        size=[0.05, 0.0, 0.0],
        contype=2,
        conaffinity=1,
        rgba=[0.9, 0.6, 0.2, 1.0],
    )
    return torso


def foot_model(params: BodyParams) -> Any:
    """Return the ``MjSpec`` of the ``foot`` model (single inverted pendulum on a foot)."""
    require_type("params", params, BodyParams)
    import mujoco

    spec = model_spec("foot", params)
    body = _leg_body(add_foot(spec.worldbody, params), params.com_height)
    body.add_geom(
        name="mass",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        pos=[0.0, 0.0, params.com_height],
        size=[MASS_RADIUS, 0.0, 0.0],
        mass=params.mass,
        contype=2,
        conaffinity=1,
        rgba=[0.9, 0.6, 0.2, 1.0],
    )
    add_motor(spec, "ankle")
    return spec


def torso_model(params: BodyParams) -> Any:
    """Return the ``MjSpec`` of the ``torso`` model (pendulum + upper body on a hip)."""
    require_type("params", params, BodyParams)
    import mujoco

    spec = model_spec("torso", params)
    body = _leg_body(add_foot(spec.worldbody, params), params.com_height)
    torso = add_upper_body(body, params, params.mass, [0.0, 0.0, params.com_height])
    limit = params.flywheel_angle_max
    torso.add_joint(
        name="hip",
        type=mujoco.mjtJoint.mjJNT_HINGE,
        axis=[0.0, 1.0, 0.0],
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        range=[-limit, limit],
    )
    add_motor(spec, "ankle")
    add_motor(spec, "hip")
    return spec


MODEL_BUILDERS = {"foot": foot_model, "torso": torso_model}
