r"""The joint-range guard of the whole-body controller: keep every joint off its stops.

The QP (:mod:`~pushrecovery.control.wbc.qp`) does not model a joint's range: a task that drives
a joint onto its stop gets a wrong answer, and a leg on the knee's stop is straight, a
singularity of the contact Jacobian. (On the biped3d's hip push the knees straightened onto
their stop; with the guard they stay at 0.098 rad.) :class:`JointGuard` gives each guarded
joint (by default the knees, :class:`GuardSettings`) with range [q_lo, q_hi] and margin μ_q,
while its predicted position q̂ = q + T min(q̇, 0) is within the margin, the task

.. math:: \ddot q = k \max(q_{lo} + \mu_q - q, 0) - d \min(\dot q, 0)

of weight W (and the mirror image at q_hi; an edge inside which the reference posture lies
moves to the posture, :meth:`JointGuard.set_posture`): a damper on the approach and a spring
back to the margin's edge, never a pull towards the stop. A soft task, not a hard bound, which
could conflict with the contact rows and the torque limits (docs/humanoid3d_wbc.md, "The QP").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.tasks.task import Task
from pushrecovery.errors import InvalidParameterError
from pushrecovery.kernels.wbc import guard_rows

FloatArray = NDArray[np.float64]

__all__ = ["GuardSettings"]


@dataclass(frozen=True)
class GuardSettings:
    """The joint-range guard's settings (module docstring); all finite.

    Attributes
    ----------
    joints : tuple of str
        The guarded joints: each limited hinge or slide joint whose name contains one of
        these (default the knees: a straight knee is the leg's singularity; guarding every
        joint also held the swing ankle's roll inside its margin against the stepping task's
        foot orientation, and the biped's lateral step fell).
    margin : float
        μ_q, the distance kept from each stop [rad or m], in [0, 1].
    horizon : float
        T, the look-ahead [s], in [0, 1].
    stiffness, damping : float
        k [1/s²] and d [1/s], in [0, 1e6].
    weight : float
        W of the guard's task, in (0, 1e6].
    """

    joints: tuple[str, ...] = ("knee",)
    margin: float = 0.1
    horizon: float = 0.05
    stiffness: float = 400.0
    damping: float = 40.0
    weight: float = 10.0

    def __post_init__(self) -> None:
        bounds = {"margin": (0.0, 1.0), "horizon": (0.0, 1.0), "stiffness": (0.0, 1e6),
                  "damping": (0.0, 1e6), "weight": (0.0, 1e6)}  # fmt: skip
        if not (isinstance(self.joints, tuple) and all(isinstance(j, str) for j in self.joints)):
            raise InvalidParameterError(f"joints must be a tuple of str, got {self.joints!r}")
        for item in fields(self)[1:]:
            value = getattr(self, item.name)
            low, high = bounds[item.name]
            positive = item.name == "weight"
            if not (
                isinstance(value, int | float)
                and math.isfinite(value)
                and (low < value if positive else low <= value)
                and value <= high
            ):
                left = "(" if positive else "["
                raise InvalidParameterError(
                    f"{item.name} must be in {left}{low:g}, {high:g}], got {value!r}"
                )


class JointGuard:
    """Tasks that keep each limited joint of a model inside its range (module docstring).

    Parameters
    ----------
    model : mujoco.MjModel
        The humanoid; its limited hinge and slide joints are guarded.
    settings : GuardSettings, optional
        Margin, look-ahead, gains and weight.

    Raises
    ------
    InvalidParameterError
        If ``settings`` is not a :class:`GuardSettings`.
    """

    def __init__(self, model: Any, settings: GuardSettings | None = None) -> None:
        import mujoco

        settings = GuardSettings() if settings is None else settings
        if not isinstance(settings, GuardSettings):
            raise InvalidParameterError(
                f"guard must be a GuardSettings, got {type(settings).__name__}"
            )
        self.settings = settings
        kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
        joints = [j for j in range(int(model.njnt))
                  if int(model.jnt_type[j]) in kinds and bool(model.jnt_limited[j])
                  and any(part in model.joint(j).name for part in settings.joints)]  # fmt: skip
        self.qpos = np.array([int(model.jnt_qposadr[j]) for j in joints], dtype=np.intp)
        self.dofs = np.array([int(model.jnt_dofadr[j]) for j in joints], dtype=np.intp)
        ranges = np.asarray(model.jnt_range, dtype=float)[joints].reshape(-1, 2)
        # The margin, but never past the range's middle.
        inset = np.minimum(settings.margin, 0.25 * (ranges[:, 1] - ranges[:, 0]))
        self.edges = np.column_stack([ranges[:, 0] + inset, ranges[:, 1] - inset])
        self._matrices: dict[tuple[int, ...], FloatArray] = {}  # task_rows' A, by nv and dofs
        # guard_rows' arrays: each joint's (qpos, dof) addresses; T, k, d, W as floats.
        self._addresses = np.column_stack([self.qpos, self.dofs]).astype(np.int64)
        self._settings = np.array([settings.horizon, settings.stiffness, settings.damping,
                                   settings.weight], dtype=float)  # fmt: skip
        self.set_posture(np.full(int(model.nq), np.nan))

    def set_posture(self, qpos: FloatArray) -> None:
        """Move each margin's edge to the posture ``qpos`` [rad or m] where it lies inside.

        The guard never drives a joint away from the posture it balances in.
        """
        q = np.asarray(qpos, dtype=float)[self.qpos]
        self.low = np.fmin(self.edges[:, 0], q)  # NaN (no posture): the margin's edge
        self.high = np.fmax(self.edges[:, 1], q)
        self._bounds = np.column_stack([self.low, self.high])

    def task_rows(
        self, qpos: FloatArray, qvel: FloatArray, nv: int
    ) -> tuple[FloatArray, FloatArray]:
        """Return the guard's task (A over q̈, b [rad/s² or m/s²]) now (module docstring).

        No rows when no joint's predicted position is within its margin. A is shared between
        calls (read-only).
        """
        n = self.qpos.size
        stack, targets = np.zeros((n, nv)), np.empty(n)
        count = guard_rows(np.asarray(qpos, dtype=float), np.asarray(qvel, dtype=float),
                           self._addresses, self._bounds, self._settings, stack, targets,
                           np.empty(n), 0)  # fmt: skip
        # The rows q̈_dof of a set of dofs are constant: one shared, read-only matrix per set
        # (the G1's knees sit within their margins at its keyframe: rows at every tick).
        dofs = [int(np.argmax(row)) for row in stack[:count]]
        key = (nv, *dofs)
        matrix = self._matrices.get(key)
        if matrix is None:
            matrix = self._matrices[key] = stack[:count].copy()
            matrix.flags.writeable = False
        return matrix, targets[:count].copy()

    def tasks(self, qpos: FloatArray, qvel: FloatArray, nv: int) -> list[Task]:
        """Return :meth:`task_rows` as a :class:`~.task.Task` (none without rows)."""
        matrix, target = self.task_rows(qpos, qvel, nv)
        return [Task("joint guard", matrix, target, self.settings.weight)] if target.size else []

    def _stack_rows(
        self, qpos: FloatArray, qvel: FloatArray, stack: FloatArray, targets: FloatArray,
        weights: FloatArray, start: int,
    ) -> int:  # fmt: skip
        """Write :meth:`task_rows`' task as stacked rows from row ``start``; return their end.

        The controller's fast path (:class:`~.stack.TaskStack`): row r of ``stack``
        (over all the QP's unknowns, zeros beyond q̈) with ``targets[r]`` and weight
        ``weights[r]`` = W, in one compiled call instead of a task's arrays, a
        :class:`~.task.Task` and its copy into the stack. The caller reserves a row for each
        guarded joint after ``start`` (the kernel does not check its writes).
        """
        if start + self.qpos.size > min(stack.shape[0], targets.shape[0], weights.shape[0]):
            raise ValueError(f"the task stack has no room for the guard's rows after {start}")
        return int(guard_rows(qpos, qvel, self._addresses, self._bounds, self._settings, stack,
                              targets, weights, start))  # fmt: skip
