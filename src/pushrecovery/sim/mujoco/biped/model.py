"""The biped's body as a ``mujoco.MjSpec``: segments, masses, joints and motors (docs/biped.md)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.models import (
    ANKLE_HEIGHT,
    FOOT_HALF_THICKNESS,
    FOOT_MASS,
    add_motor,
    add_upper_body,
    model_spec,
)

FloatArray = NDArray[np.float64]

__all__ = ["LEGS", "LEG_MASS", "biped_model", "torso_com"]

# --- model -------------------------------------------------------------------------------------
#: Thigh and shank masses [kg]; with the foot's, one leg's.
THIGH_MASS = 0.5
SHANK_MASS = 0.3
#: Mass of one leg [kg].
LEG_MASS = THIGH_MASS + SHANK_MASS + FOOT_MASS
#: Leg names, in the order of the joints and motors.
LEGS = ("left", "right")
#: Half the distance between the legs, drawn only [m].
HIP_SPREAD = 0.1
THIGH_RADIUS = 0.03
SHANK_RADIUS = 0.025
#: Knee range [rad]: 0 straight (the stop), positive flexion (the shank swings back).
KNEE_MAX = 2.5
#: Reflected rotor inertia of knee and ankle [kg m²]: keeps the 1 ms explicit PD stable on the
#: light shank and foot; 1e-4 of m L² and 1e-3 of it, too small to change the balance.
KNEE_ARMATURE = 0.05
ANKLE_ARMATURE = 0.01


def torso_com(params: BodyParams) -> tuple[float, float]:
    """Return the torso's mass m_u [kg] and its CoM height c above the hip [m].

    m_u c = m (L − ℓ) (L = ``com_height``, ℓ = ``leg_length``): the legs are ℓ long and the
    torso's CoM moves the whole body's by L − ℓ, so the body stands at L plus the legs' own
    lowering, as with ℓ = L (c = 0, the paper's flywheel centred on the hip).

    Raises
    ------
    InvalidParameterError
        If the mass does not exceed the legs' or c is outside (−ℓ/2, ℓ/2).
    """
    require_type("params", params, BodyParams)
    torso_mass = params.mass - 2.0 * LEG_MASS
    if torso_mass <= 0.0:
        raise InvalidParameterError(
            f"mass must exceed the legs' {2.0 * LEG_MASS:g} kg, got {params.mass:g} kg"
        )
    leg = params.leg_length
    height = params.mass * (params.com_height - leg) / torso_mass
    if not -0.5 * leg < height < 0.5 * leg:
        raise InvalidParameterError(
            "com_height must put the biped's torso CoM within ±leg_length/2 of its hip: "
            f"com_height={params.com_height:g} m, leg_length={leg:g} m puts it {height:.4g} m "
            "above it"
        )
    return torso_mass, height


def biped_model(params: BodyParams) -> Any:
    """Return the ``MjSpec`` of the planar ``biped`` for ``params`` (module docstring).

    The legs are ``leg_length`` long; the torso's CoM sits where :func:`torso_com` puts it.

    Raises
    ------
    InvalidParameterError
        As :func:`torso_com`.
    """
    require_type("params", params, BodyParams)
    import mujoco

    torso_mass, torso_height = torso_com(params)
    hinge, capsule = mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtGeom.mjGEOM_CAPSULE
    y_axis, leg_colour = [0.0, 1.0, 0.0], [0.4, 0.5, 0.8, 1.0]
    length = params.leg_length
    segment = 0.5 * length
    limit = params.flywheel_angle_max
    spec = model_spec("biped", params)
    hip = [0.0, 0.0, length + ANKLE_HEIGHT]
    torso = add_upper_body(spec.worldbody, params, torso_mass, hip, torso_height)
    torso.add_joint(name="x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1.0, 0.0, 0.0])
    torso.add_joint(name="z", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 0.0, 1.0])
    torso.add_joint(
        name="pitch",
        type=hinge,
        axis=y_axis,
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        range=[-limit, limit],
    )
    # The joints come before the body's geoms in the compiled model whatever the order here.
    # The shank's capsule ends 1.5 cm above the ankle, so that only the sole reaches the floor.
    shank_end = segment - SHANK_RADIUS - 0.015
    # contype 2 / conaffinity 1: every body geom touches the floor (1/1), none touches another.
    for name, y in zip(LEGS, (HIP_SPREAD, -HIP_SPREAD), strict=True):
        thigh = torso.add_body(name=f"{name}_thigh", pos=[0.0, y, 0.0])
        thigh.add_joint(name=f"{name}_hip", type=hinge, axis=y_axis)
        thigh.add_geom(
            name=f"{name}_thigh", type=capsule, fromto=[0.0, 0.0, 0.0, 0.0, 0.0, -segment],
            size=[THIGH_RADIUS, 0.0, 0.0], mass=THIGH_MASS, contype=2, conaffinity=1,
            rgba=leg_colour,
        )  # fmt: skip
        shank = thigh.add_body(name=f"{name}_shank", pos=[0.0, 0.0, -segment])
        shank.add_joint(
            name=f"{name}_knee", type=hinge, axis=y_axis, range=[0.0, KNEE_MAX],
            solref_limit=[0.005, 1.0], armature=KNEE_ARMATURE,
        )  # fmt: skip
        shank.add_geom(
            name=f"{name}_shank", type=capsule, fromto=[0.0, 0.0, 0.0, 0.0, 0.0, -shank_end],
            size=[SHANK_RADIUS, 0.0, 0.0], mass=SHANK_MASS, contype=2, conaffinity=1,
            rgba=leg_colour,
        )  # fmt: skip
        foot = shank.add_body(name=f"{name}_foot", pos=[0.0, 0.0, -segment])
        foot.add_joint(name=f"{name}_ankle", type=hinge, axis=y_axis, armature=ANKLE_ARMATURE)
        foot.add_geom(
            name=f"{name}_sole", type=mujoco.mjtGeom.mjGEOM_BOX,
            pos=[0.5 * (params.toe + params.heel), 0.0, -FOOT_HALF_THICKNESS],
            size=[0.5 * (params.toe - params.heel), 0.05, FOOT_HALF_THICKNESS],
            mass=FOOT_MASS, contype=2, conaffinity=1, rgba=[0.3, 0.3, 0.3, 1.0],
        )  # fmt: skip
    for name in LEGS:
        for joint in ("hip", "knee", "ankle"):
            add_motor(spec, f"{name}_{joint}")
    return spec
