"""MJCF models generated from a :class:`~pushrecovery.params.BodyParams` (sagittal plane).

``foot``: a rigid body on a foot. The foot is a thin box spanning [heel, toe] that rests on the
floor and is free in x, z and pitch, so it tips when the CoP reaches an edge. The ankle hinge sits
``ANKLE_HEIGHT`` above the floor (the paper's ankle is on the floor). The body is a massless-like
rod of length L with the mass m in a small sphere at its top: the paper's single inverted pendulum
with L the ankle-to-CoM distance. An ankle motor applies the ankle torque.
"""

from __future__ import annotations

from pushrecovery.params import BodyParams

__all__ = ["ANKLE_HEIGHT", "FOOT_MASS", "foot_model"]

#: Half-thickness of the foot box [m]; the ankle sits on top of it.
FOOT_HALF_THICKNESS = 0.005
#: Ankle height above the floor [m].
ANKLE_HEIGHT = 2 * FOOT_HALF_THICKNESS
#: Mass of the foot [kg] (small: the paper's foot is massless).
FOOT_MASS = 0.2
#: Radius of the sphere holding the body's mass [m].
MASS_RADIUS = 0.03
#: Simulation step [s].
TIMESTEP = 5e-4


def foot_model(params: BodyParams) -> str:
    """MJCF text of the ``foot`` model for ``params``."""
    half_length = 0.5 * (params.toe - params.heel)
    centre = 0.5 * (params.toe + params.heel)
    length = params.com_height
    return f"""
<mujoco model="pushrecovery-foot">
  <option timestep="{TIMESTEP}" gravity="0 0 {-params.gravity}" integrator="implicitfast"/>
  <default>
    <geom contype="1" conaffinity="1" friction="1.0 0.005 0.0001" solref="0.002 1"
          solimp="0.95 0.99 0.001"/>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="5 1 0.1" rgba="0.8 0.8 0.8 1"/>
    <body name="foot" pos="0 0 {FOOT_HALF_THICKNESS}">
      <joint name="foot_x" type="slide" axis="1 0 0"/>
      <joint name="foot_z" type="slide" axis="0 0 1"/>
      <joint name="foot_pitch" type="hinge" axis="0 1 0"/>
      <geom name="sole" type="box" pos="{centre} 0 0"
            size="{half_length} 0.05 {FOOT_HALF_THICKNESS}" mass="{FOOT_MASS}"/>
      <body name="body" pos="0 0 {FOOT_HALF_THICKNESS}">
        <joint name="ankle" type="hinge" axis="0 1 0" damping="0"/>
        <geom name="rod" type="capsule" fromto="0 0 0 0 0 {length}" size="0.01" mass="1e-3"
              contype="2" conaffinity="2"/>
        <geom name="mass" type="sphere" pos="0 0 {length}" size="{MASS_RADIUS}"
              mass="{params.mass}" contype="2" conaffinity="1"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="ankle" joint="ankle" gear="1" ctrllimited="false"/>
  </actuator>
</mujoco>
"""
