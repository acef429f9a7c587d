"""The 3-D biped's standing posture under the whole-body controller, and the push's duration.

The biped stands with its knees bent by ``knee`` (a straight knee sits on its joint stop,
whose constraint force the QP does not model): hip pitch −knee/2, knee +knee, ankle pitch
−knee/2 keep each foot flat and under its hip; the root is lowered onto the floor. A push is
an impulse J [N s] applied as the constant force J/Δ over Δ = :data:`PUSH_DURATION`
(``plant3d.Humanoid3DPlant.apply_push``; the run is ``runs3d.run_push3d``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.bodies import body_id, check_model
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.mujoco.humanoid3d.biped3d import SIDES
from pushrecovery.sim.mujoco.humanoid3d.measure import standing_qpos

FloatArray = NDArray[np.float64]

__all__ = ["KNEE_BEND", "PUSH_DURATION", "bent_knee_qpos"]

#: Knee flexion of the standing posture [rad].
KNEE_BEND = 0.3
#: Duration over which a push's impulse is applied [s].
PUSH_DURATION = 0.01


def bent_knee_qpos(model: Any, knee: float = KNEE_BEND) -> FloatArray:
    """Return the biped's standing posture with knees bent by ``knee`` [rad], soles on z = 0.

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
    feet = [body_id(model, f"{side}_foot") for side in SIDES]
    return standing_qpos(model, qpos, feet)
