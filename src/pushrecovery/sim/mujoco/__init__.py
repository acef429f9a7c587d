"""MuJoCo backend: models generated from the parameters and plants behind the Plant protocol."""

from __future__ import annotations

from typing import Any

from pushrecovery.sim.mujoco.biped import MujocoBipedPlant
from pushrecovery.sim.mujoco.pendulums import MujocoFootPlant, MujocoTorsoPlant

__all__ = ["PLANTS"]

#: MuJoCo model name -> plant class (the registry, :mod:`pushrecovery.sim.registry`, names
#: them by import string).
PLANTS: dict[str, type[Any]] = {
    "foot": MujocoFootPlant,
    "torso": MujocoTorsoPlant,
    "biped": MujocoBipedPlant,
}
