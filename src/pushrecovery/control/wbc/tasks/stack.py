"""The whole-body controller's tasks as one stack of rows.

Used by the controller (:mod:`~pushrecovery.control.wbc.controller`) and its QP
(:mod:`~pushrecovery.control.wbc.qp`). The QP's cost Σ_k W_k ‖A_k x − b_k‖² is a sum over rows: row
r of weight W_r adds W_r a_rᵀ a_r to H and −W_r a_rᵀ b_r to f. :class:`TaskStack` keeps every task
of a tick as rows of one matrix (with one target and one weight per row), so that the QP takes them
in one compiled call (``WholeBodyQP._solve_rows``) instead of a :class:`~.task.Task`, a check and a
call per task. Row order: the CoM (2), the torso (3), the pelvis height (1) and the posture
(nv − 6 rows), written in place by the ankle controller's kernel (``kernels.wbc.ankle_targets``),
then the tick's other tasks (the hip's momentum, the stepper's, the joint guard's).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.gains import WbcGains
from pushrecovery.control.wbc.tasks.task import Task

FloatArray = NDArray[np.float64]

__all__ = []

#: Rows beyond the ankle controller's the buffers start with (grown on demand).
_SPARE = 8


class TaskStack:
    """The stacked rows, targets and weights of one tick's tasks (module docstring).

    Parameters
    ----------
    nv, size : int
        The model's dofs and the QP's unknowns (nv + 6 per foot).
    gains : WbcGains
        The weights of the CoM, pelvis and posture rows (the torso's are set each tick).

    Attributes
    ----------
    matrix, targets, weights : float arrays, shapes (rows, size), (rows,), (rows,)
        The rows (over all ``size`` unknowns), their targets and weights; replaced by larger
        arrays when a tick has more rows than ever (read them anew each tick).
    joints : float array, shape (nv − 6, size)
        The posture task's constant rows (read-only): q̈_j for every joint dof.
    pd_gains : float array, shape (6,)
        The gains ``ankle_targets`` writes the rows' targets with: k_R, d_R (the controller
        sets them each tick: the hip's return changes them), k_z, d_z, k_q, d_q.
    """

    def __init__(self, nv: int, size: int, gains: WbcGains) -> None:
        self.nv, self.gains = nv, gains
        self.joints = np.zeros((nv - 6, size))
        self.joints[:, 6:nv] = np.eye(nv - 6)
        self.joints.flags.writeable = False
        self.matrix, self.targets = np.zeros((nv + _SPARE, size)), np.zeros(nv + _SPARE)
        self.matrix[6:nv] = self.joints
        self.weights = np.concatenate([[gains.com_weight] * 2, [0.0] * 3, [gains.height_weight],
                                       [gains.posture_weight] * (nv - 6),
                                       np.zeros(_SPARE)])  # fmt: skip
        self.pd_gains = np.array([gains.torso_stiffness, gains.torso_damping,
                                  gains.height_stiffness, gains.height_damping,
                                  gains.posture_stiffness, gains.posture_damping])  # fmt: skip

    def reserve(self, rows: int) -> None:
        """Grow the buffers to at least ``rows`` rows (kept: the rows already written)."""
        grow = rows - self.matrix.shape[0]
        if grow > 0:
            self.matrix = np.vstack([self.matrix, np.zeros((grow, self.matrix.shape[1]))])
            self.targets = np.concatenate([self.targets, np.zeros(grow)])
            self.weights = np.concatenate([self.weights, np.zeros(grow)])

    def extend(self, tasks: Sequence[Task], start: int | None = None) -> int:
        """Stack ``tasks`` from row ``start`` (default nv); return the number of rows.

        The first nv rows are the ankle controller's. The hip's momentum task acts on the
        wrenches alone, the torso's, pelvis's and posture's on q̈ alone: after them instead of
        between the CoM's and the torso's (the order of :meth:`tasks`), each sum of H and f
        still takes its terms in the same order.
        """
        count = self.nv if start is None else start  # nv: the rows ankle_targets wrote
        for task in tasks:
            rows, columns = task.matrix.shape
            self.reserve(count + rows)  # more rows than ever: grow the buffers
            block = self.matrix[count : count + rows]
            block[:, :columns] = task.matrix
            block[:, columns:] = 0.0
            self.targets[count : count + rows] = task.target
            self.weights[count : count + rows] = task.weight
            count += rows
        return count

    def tasks(self, momentum: Task | None, others: Sequence[Task]) -> list[Task]:
        """Return the ankle controller's rows as :class:`~.task.Task` copies, then the others.

        Order: the CoM, the hip's ``momentum`` (if any), the torso, the pelvis height, the
        posture, then ``others``.
        """
        nv, gains, matrix, targets = self.nv, self.gains, self.matrix, self.targets
        tasks = [Task("com", matrix[:2].copy(), targets[:2].copy(), gains.com_weight)]
        if momentum is not None:
            tasks.append(momentum)
        tasks.append(Task("torso", matrix[2:5, :nv].copy(), targets[2:5].copy(),
                          float(self.weights[2])))  # fmt: skip
        tasks.append(Task("height", matrix[5:6, :nv].copy(), targets[5:6].copy(),
                          gains.height_weight))  # fmt: skip
        tasks.append(Task("posture", self.joints, targets[6:nv].copy(), gains.posture_weight))
        return [*tasks, *others]
