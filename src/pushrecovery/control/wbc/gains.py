"""The gains and weights of the whole-body controller's tasks.

The controller is :mod:`~pushrecovery.control.wbc.controller`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from pushrecovery.errors import InvalidParameterError

__all__ = ["WbcGains"]


@dataclass(frozen=True)
class WbcGains:
    """Gains [1/s, 1/s²] and weights [-] of the tasks (module docstring); all finite, ≥ 0.

    Attributes
    ----------
    dcm : float
        k_ξ, the capture point's return rate [1/s].
    torso_stiffness, torso_damping : float
        k_R [1/s²], d_R [1/s].
    height_stiffness, height_damping : float
        k_z [1/s²], d_z [1/s].
    posture_stiffness, posture_damping : float
        k_q [1/s²], d_q [1/s].
    com_weight, torso_weight, height_weight, posture_weight : float
        W of each task (> 0).
    hip_weight : float
        W of the centroidal momentum task L̇_{x,y} while the hip acts (> 0, :mod:`.hip`).
    hip_torso_weight : float
        The torso task's W while the hip acts (> 0): relaxed, the torso turns.
    return_stiffness, return_damping : float
        k_R [1/s²] and d_R [1/s] of the torso's return to upright after the hip acted.
    """

    dcm: float = 2.0
    torso_stiffness: float = 100.0
    torso_damping: float = 20.0
    height_stiffness: float = 100.0
    height_damping: float = 20.0
    posture_stiffness: float = 25.0
    posture_damping: float = 10.0
    com_weight: float = 10.0
    torso_weight: float = 1.0
    height_weight: float = 1.0
    posture_weight: float = 0.01
    hip_weight: float = 10.0
    hip_torso_weight: float = 1e-3
    return_stiffness: float = 4.0
    return_damping: float = 4.0

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            positive = item.name.endswith("weight")
            if not (
                isinstance(value, int | float)
                and math.isfinite(value)
                and (value > 0.0 if positive else value >= 0.0)
                and value <= 1e6
            ):
                bound = "(0, 1e6]" if positive else "[0, 1e6]"
                raise InvalidParameterError(f"{item.name} must be in {bound}, got {value!r}")
