"""Small pieces of MuJoCo the plants and the batched rollout share: states, warnings, contacts.

MuJoCo's types appear as ``Any``: its bindings ship no type information.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["integration_spec", "unstable_warnings"]

FloatArray = NDArray[np.float64]


def _mujoco() -> Any:
    import mujoco

    return mujoco


def integration_spec() -> int:
    """MuJoCo's ``mjSTATE_INTEGRATION``: everything the next steps depend on.

    Time, joint positions and velocities, actuator activations, controls, applied forces,
    mocap and the constraint solver's warm start: restoring it reproduces the steps that
    follow to the bit (``tests/test_mujoco_rollout.py`` checks it on the plants).
    """
    return int(_mujoco().mjtState.mjSTATE_INTEGRATION)


def save_state(model: Any, data: Any) -> FloatArray:
    """Return a copy of ``data``'s integration state (:func:`integration_spec`)."""
    mj, spec = _mujoco(), integration_spec()
    state = np.empty(mj.mj_stateSize(model, spec))
    mj.mj_getState(model, data, state, spec)
    return state


def restore_state(model: Any, data: Any, state: FloatArray) -> None:
    """Reset ``data`` (warnings and contacts included), then set a :func:`save_state` state.

    The positions-dependent quantities (contacts, CoM) are computed by the next
    ``mj_forward`` or ``mj_step``.
    """
    mj = _mujoco()
    mj.mj_resetData(model, data)
    mj.mj_setState(model, data, state, integration_spec())


def settle(model: Any, data: Any, steps: int, saved: FloatArray | None = None) -> FloatArray:
    """Settle from MuJoCo's initial state with zero controls for ``steps``; return the state.

    With ``saved`` (a state this function returned for the same model and steps) the settling
    is restored instead of simulated again: bit for bit the same data for the steps after it.
    """
    if saved is not None:
        restore_state(model, data, saved)
        return saved
    mj = _mujoco()
    mj.mj_resetData(model, data)
    data.ctrl[:] = 0.0
    mj.mj_step(model, data, nstep=steps)
    return save_state(model, data)


def unstable_warnings() -> tuple[int, int, int]:
    """Return the warnings after which MuJoCo resets its data: bad qacc, qvel, qpos.

    As dm_control's ``check_divergence`` reads them; ``data.warning.number`` counts each.
    """
    warning = _mujoco().mjtWarning
    return (
        int(warning.mjWARN_BADQACC),
        int(warning.mjWARN_BADQVEL),
        int(warning.mjWARN_BADQPOS),
    )


def touches_floor(data: Any, floor: int, soles: frozenset[int]) -> bool:
    """Whether any geom but a sole touches the floor geom (contacts of the last step)."""
    for g1, g2 in data.contact.geom.tolist():
        other = g2 if g1 == floor else g1 if g2 == floor else -1
        if other >= 0 and other not in soles:
            return True
    return False


def floor_cop_world(
    model: Any, data: Any, floor: int, soles: frozenset[int], force: FloatArray
) -> float:
    """World x of the CoP of the floor's normal forces on the soles [m]; NaN if airborne.

    x_CoP = Σ F_n,i x_i / Σ F_n,i over the sole-floor contacts (``force``: a 6-array buffer).
    """
    mj = _mujoco()
    moment = total = 0.0
    for i in range(data.ncon):
        contact = data.contact[i]
        pair = (contact.geom1, contact.geom2)
        if floor in pair and (pair[0] in soles or pair[1] in soles):
            mj.mj_contactForce(model, data, i, force)
            moment += force[0] * contact.pos[0]
            total += force[0]
    return moment / total if total > 0.0 else math.nan
