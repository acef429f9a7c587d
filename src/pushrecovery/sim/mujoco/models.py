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

The geometry is shared (:func:`foot_xml`) so that the two models differ only by the upper body.
"""

from __future__ import annotations

from pushrecovery.params import BodyParams

__all__ = [
    "ANKLE_HEIGHT",
    "FOOT_MASS",
    "MODEL_BUILDERS",
    "TIMESTEP",
    "foot_model",
    "foot_xml",
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


def header(name: str, params: BodyParams) -> str:
    """``<mujoco>`` opening, options, contact defaults and the floor of every model."""
    return f"""
<mujoco model="pushrecovery-{name}">
  <compiler angle="radian"/>
  <option timestep="{TIMESTEP}" gravity="0 0 {-params.gravity}" integrator="implicitfast"
          cone="pyramidal"/>
  <visual><global offwidth="640" offheight="480"/></visual>
  <default>
    <geom contype="1" conaffinity="1" friction="1.0 0.005 0.0001"
          solref="{CONTACT_TIME} 1" solimp="0.95 0.99 0.001"/>
  </default>
  <worldbody>
    <light pos="0 -2 3" dir="0 1 -1" directional="true"/>
    <geom name="floor" type="plane" size="5 1 0.1" rgba="0.85 0.85 0.85 1"/>
"""


def foot_xml(params: BodyParams, name: str = "foot", x: float = 0.0, inner: str = "") -> str:
    """Return a free (x, z, pitch) foot box, sole geom ``<name>_sole``, holding ``inner``.

    ``inner`` is placed on top of the foot, at the ankle (``ANKLE_HEIGHT`` above the floor).
    """
    half_length = 0.5 * (params.toe - params.heel)
    centre = 0.5 * (params.toe + params.heel)
    sole = "sole" if name == "foot" else f"{name}_sole"
    return f"""
    <body name="{name}" pos="{x} 0 {FOOT_HALF_THICKNESS}">
      <joint name="{name}_x" type="slide" axis="1 0 0"/>
      <joint name="{name}_z" type="slide" axis="0 0 1"/>
      <joint name="{name}_pitch" type="hinge" axis="0 1 0"/>
      <geom name="{sole}" type="box" pos="{centre} 0 0"
            size="{half_length} 0.05 {FOOT_HALF_THICKNESS}" mass="{FOOT_MASS}"
            rgba="0.3 0.3 0.3 1"/>
      {inner}
    </body>
"""


def _rod(length: float) -> str:
    return (
        f'<geom name="rod" type="capsule" fromto="0 0 0 0 0 {length}" size="0.01" '
        f'mass="{ROD_MASS}" contype="2" conaffinity="2" rgba="0.4 0.5 0.8 1"/>'
    )


def foot_model(params: BodyParams) -> str:
    """MJCF text of the ``foot`` model (single inverted pendulum on a foot) for ``params``."""
    length = params.com_height
    body = f"""
      <body name="body" pos="0 0 {FOOT_HALF_THICKNESS}">
        <joint name="ankle" type="hinge" axis="0 1 0"/>
        {_rod(length)}
        <geom name="mass" type="sphere" pos="0 0 {length}" size="{MASS_RADIUS}"
              mass="{params.mass}" contype="2" conaffinity="1" rgba="0.9 0.6 0.2 1"/>
      </body>"""
    return f"""{header("foot", params)}{foot_xml(params, inner=body)}
  </worldbody>
  <actuator>
    <motor name="ankle" joint="ankle" gear="1"/>
  </actuator>
</mujoco>
"""


def torso_model(params: BodyParams) -> str:
    """MJCF text of the ``torso`` model (pendulum + upper body on a hip) for ``params``."""
    length, limit, inertia = params.com_height, params.flywheel_angle_max, params.flywheel_inertia
    body = f"""
      <body name="body" pos="0 0 {FOOT_HALF_THICKNESS}">
        <joint name="ankle" type="hinge" axis="0 1 0"/>
        {_rod(length)}
        <body name="torso" pos="0 0 {length}">
          <joint name="hip" type="hinge" axis="0 1 0" limited="true"
                 range="{-limit} {limit}"/>
          <inertial pos="0 0 0" mass="{params.mass}"
                    diaginertia="{inertia} {inertia} {inertia}"/>
          <geom name="pelvis" type="sphere" size="{MASS_RADIUS}" contype="2" conaffinity="1"
                rgba="0.9 0.6 0.2 1"/>
          <geom name="trunk" type="capsule" fromto="0 0 0 0 0 {TORSO_LENGTH}" size="0.05"
                contype="2" conaffinity="1" rgba="0.9 0.6 0.2 1"/>
        </body>
      </body>"""
    return f"""{header("torso", params)}{foot_xml(params, inner=body)}
  </worldbody>
  <actuator>
    <motor name="ankle" joint="ankle" gear="1"/>
    <motor name="hip" joint="hip" gear="1"/>
  </actuator>
</mujoco>
"""


#: Model name -> MJCF builder.
MODEL_BUILDERS = {"foot": foot_model, "torso": torso_model}
