r"""The stepper's knee guard: a knee near its straight stop is pulled back (a soft limit).

A knee at angle q (0 straight, flexion positive) [rad] below q_min, or reaching it within
50 ms at its velocity q̇ (q + 0.05 min(q̇, 0) < q_min), gets the task

.. math:: \ddot q = k_p (q_{min} - q) - d_p \dot q

of weight W: the QP does not model the joint stop, and a stance knee driven onto it made the
QP infeasible (the torque limits with the contact rows). The stepper runs it at every tick
(:mod:`~pushrecovery.control.wbc.stepper.stepper`; ``StepSettings.knee_min``,
``stiffness``, ``damping``, ``knee_weight``); without stepping the joint guard
(:mod:`~.joint_guard`) keeps the knees off their stops instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.control.wbc.tasks.task import Task

__all__ = []


def knee_guard_tasks(
    model: Any,
    data: HumanoidObservation,
    knees: Sequence[int],
    size: int,
    *,
    knee_min: float,
    stiffness: float,
    damping: float,
    weight: float,
) -> list[Task]:
    """Return one task with a row per knee below ``knee_min`` or reaching it within 50 ms.

    Parameters
    ----------
    model, data : mujoco.MjModel, HumanoidObservation
        The humanoid and its state.
    knees : sequence of int
        The knee joints' ids (hinges; a negative id is skipped: a leg without a knee).
    size : int
        The QP's unknowns (a row is q̈_dof: zeros, 1 at the knee's dof).
    knee_min : float
        q_min [rad].
    stiffness, damping : float
        k_p [1/s²] and d_p [1/s].
    weight : float
        W of the task.

    Returns
    -------
    list of Task
        Empty when no knee is near its stop.
    """
    rows, targets = [], []
    qvel = np.asarray(data.qvel, dtype=float)
    for knee in knees:
        if knee < 0:
            continue
        angle = float(data.qpos[int(model.jnt_qposadr[knee])])
        dof = int(model.jnt_dofadr[knee])
        if angle + 0.05 * min(float(qvel[dof]), 0.0) >= knee_min:
            continue
        row = np.zeros(size)
        row[dof] = 1.0
        rows.append(row)
        targets.append(stiffness * (knee_min - angle) - damping * float(qvel[dof]))
    if not rows:
        return []
    return [Task("knee guard", np.array(rows), np.array(targets), weight)]
