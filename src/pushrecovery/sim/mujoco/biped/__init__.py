"""Planar biped that steps, in MuJoCo (model ``biped``): the stepping model of Sec. IV.

The model (segments, masses, what each parameter maps to), the state, the control (standing,
swing, landing, stance after a landing, trailing leg, feet) and the known limits are described
in docs/biped.md. Modules: :mod:`.model` (the ``MjSpec``), :mod:`.kinematics`, :mod:`.control`
(gains, the swing path, the torque laws) and :mod:`.plant` (the plant behind the contract).
"""

from pushrecovery.sim.mujoco.biped.model import LEG_MASS, biped_model
from pushrecovery.sim.mujoco.biped.plant import MujocoBipedPlant

__all__ = ["LEG_MASS", "MujocoBipedPlant", "biped_model"]
