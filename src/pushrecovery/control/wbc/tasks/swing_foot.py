r"""The swing foot's task of the whole-body QP: the sole frame tracks its reference.

World frame, x forward, y left, z up, SI units. While a foot swings (the stepper,
:mod:`~pushrecovery.control.wbc.stepper.stepper`), its sole frame (origin p, orientation R)
follows the reference p_ref(t), v_ref, a_ref of the step's plan:

.. math:: J_p \ddot q + \dot J_p \dot q = a_{ref} + k_p (p_{ref} - p) + d_p (v_{ref} - v),
          \qquad
          J_r \ddot q + \dot J_r \dot q = -k_R e - d_R \omega,

e the rotation vector of R R₀ᵀ (R₀ the foot's orientation at lift-off) and ω its angular
velocity. The vertical row weighs ``lift_weight`` times W (a foot that stays on the floor
cannot step); gains and weights are the stepper's
(:class:`~pushrecovery.control.wbc.stepper.settings.StepSettings`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.control.wbc.stepper.plan import rotation_vector
from pushrecovery.control.wbc.stepper.settings import StepSettings
from pushrecovery.control.wbc.tasks.task import Task

FloatArray = NDArray[np.float64]

__all__ = []


def swing_foot_task(
    data: HumanoidObservation,
    body: int,
    sole: tuple[FloatArray, FloatArray],
    lift_off: FloatArray,
    reference: tuple[FloatArray, FloatArray, FloatArray],
    settings: StepSettings,
    size: int,
    nv: int,
) -> Task:
    """Return the swing foot's task: J q̈ = a_des − J̇ q̇ over 6 rows (linear, angular).

    Parameters
    ----------
    data : HumanoidObservation
        The humanoid's state (after ``mj_forward`` or ``mj_step1``).
    body : int
        The foot body's id.
    sole : tuple of float arrays, shapes (3,) and (3, 3)
        The sole frame's origin p [m] and orientation R now (world).
    lift_off : float array, shape (3, 3)
        R₀, the sole frame's orientation at lift-off.
    reference : tuple of float arrays, shape (3,) each
        p_ref [m], v_ref [m/s] and a_ref [m/s²] now (world).
    settings : StepSettings
        k_p, d_p (``stiffness``, ``damping``), k_R, d_R (``turn_stiffness``,
        ``turn_damping``), W (``weight``) and the vertical row's ``lift_weight``.
    size, nv : int
        The QP's unknowns and the model's dofs: the task's matrix is (6, size), zeros beyond q̈.
    """
    s, (point, rot) = settings, sole
    jacp, jacr = np.zeros((3, nv)), np.zeros((3, nv))
    dotp, dotr = np.zeros((3, nv)), np.zeros((3, nv))
    data.jac(jacp, jacr, point, body)
    data.jac_dot(dotp, dotr, point, body)
    qvel = np.asarray(data.qvel, dtype=float)
    p_ref, v_ref, a_ref = reference
    linear = a_ref + s.stiffness * (p_ref - point) + s.damping * (v_ref - jacp @ qvel)
    error = rotation_vector(rot @ lift_off.T)
    angular = -s.turn_stiffness * error - s.turn_damping * (jacr @ qvel)
    matrix = np.zeros((6, size))
    matrix[:3, :nv], matrix[3:, :nv] = jacp, jacr
    target = np.concatenate([linear - dotp @ qvel, angular - dotr @ qvel])
    scale = math.sqrt(s.lift_weight)  # the vertical row weighs lift_weight × W
    matrix[2] *= scale
    target[2] *= scale
    return Task("swing", matrix, target, s.weight)
