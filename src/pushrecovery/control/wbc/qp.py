r"""Task-space inverse dynamics as one QP on MuJoCo's own dynamics (docs/humanoid3d_wbc.md).

Each control tick solves, for the joint accelerations q̈ ∈ R^nv and one 6-D contact wrench
w_i = (F_i, T_i) per foot on the floor (the floor's force and moment on foot i at its sole
frame; F_z > 0 pushes the foot up), the weighted least-squares problem (Del Prete, Mansard et
al., "TSID"; Wensing & Orin, ICRA 2013)

.. math:: \min_{x = (\ddot q, w)} \sum_k W_k \lVert A_k x - b_k \rVert^2
          + \epsilon_a \lVert \ddot q \rVert^2 + \epsilon_f \lVert w \rVert^2

subject to the floating-base rows of the dynamics M_u q̈ + h_u = J_{c,u}^T w, each foot on the
floor fixed, J_i q̈ + J̇_i q̇ = −k_c J_i q̇ (:data:`CONTACT_DAMPING` k_c [1/s]; a swinging foot
has w_i = 0 instead, :meth:`WholeBodyQP.set_contacts`), each foot's contact wrench cone (the
wrenches that friction pyramids at its sole's vertices can give, μ' = μ/√2:
:func:`~.foot_contact.contact_wrench_cone`) and the motor limits; the tasks A_k x = b_k come
from :mod:`~pushrecovery.control.wbc.controller`. Solved with DAQP, its model kept between
ticks, first without the motor rows; :mod:`.kernels.wbc` assembles each tick in place and hands
DAQP its least-distance form. MuJoCo's types appear as ``Any``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.buffers import Buffers
from pushrecovery.control.wbc.foot_contact import FootContact
from pushrecovery.control.wbc.least_distance import LeastDistanceSolver
from pushrecovery.control.wbc.observation import HumanoidObservation
from pushrecovery.control.wbc.tasks.task import Task
from pushrecovery.errors import InvalidParameterError
from pushrecovery.kernels.wbc import add_task, assemble_rows, constraints, sole_frames, sole_origins

FloatArray = NDArray[np.float64]

__all__ = ["CONTACT_DAMPING", "WbcProblem", "WbcSolution"]

#: The default k_c, the damping of a foot's drift in its fixed-foot rows [1/s].
CONTACT_DAMPING = 20.0


@dataclass(frozen=True)
class WbcProblem:
    """The QP min ½ xᵀ H x + fᵀ x s.t. l ≤ A x ≤ u of one tick (:meth:`WholeBodyQP.assemble`).

    Attributes
    ----------
    hessian, linear : float arrays, shapes (size, size) and (size,)
        H = Σ_k W_k A_kᵀ A_k + diag(ε) and f = −Σ_k W_k A_kᵀ b_k.
    rows, upper, lower : float arrays, shapes (m, size), (m,), (m,)
        A, u and l (±1e30: unbounded); the first ``equalities`` rows have l = u.
    equalities : int
        The number of equality rows (the unactuated dynamics, then six per foot).
    """

    hessian: FloatArray
    linear: FloatArray
    rows: FloatArray
    upper: FloatArray
    lower: FloatArray
    equalities: int


@dataclass
class WbcSolution:
    """The QP's solution at one tick.

    Attributes
    ----------
    qacc : float array, shape (nv,)
        q̈ [m/s², rad/s²].
    wrenches : float array, shape (n_feet, 6)
        Each foot's (F, T) in its sole frame [N, N m].
    ctrl : float array, shape (nu,)
        Motor commands τ_a / gear [N m], within ``actuator_ctrlrange``.
    ok : bool
        False when DAQP found no solution (``ctrl`` is then the last good one).
    solve_time, iterations : float, int
        Wall time of the factorisation, DAQP's update and solve (twice when a command left
        its range without the motor rows) [s], and DAQP's iterations.
    """

    qacc: FloatArray
    wrenches: FloatArray
    ctrl: FloatArray
    ok: bool
    solve_time: float
    iterations: int


class WholeBodyQP:
    """The dynamics, contact and limit constraints of one model, and a DAQP workspace.

    Parameters
    ----------
    model : mujoco.MjModel
        A floating-base model (free joint first) whose actuators are motors on hinge or slide
        joints (``actuator_trntype`` joint, gear in ``actuator_gear[:, 0]``).
    feet : sequence of FootContact
        The feet (:func:`foot_contact`), all on the floor until :meth:`set_contacts`.
    acc_regularisation, wrench_regularisation : float
        ε_a [(s²)² weight per (m/s²)²] and ε_f [per N²] of the module docstring, > 0: keep the
        Hessian positive definite.

    Raises
    ------
    InvalidParameterError
        If the model has no free joint first, an actuator is not on a joint, ``feet`` is
        empty, or a regularisation is not in (0, 1].
    """

    def __init__(
        self,
        model: Any,
        feet: Sequence[FootContact],
        acc_regularisation: float = 1e-6,
        wrench_regularisation: float = 1e-8,
    ) -> None:
        import mujoco

        if model.njnt < 1 or int(model.jnt_type[0]) != mujoco.mjtJoint.mjJNT_FREE:
            raise InvalidParameterError("model must have a free joint first (a floating base)")
        if np.any(np.asarray(model.actuator_trntype) != mujoco.mjtTrn.mjTRN_JOINT):
            raise InvalidParameterError("model's actuators must all drive joints")
        if not feet or not all(isinstance(f, FootContact) for f in feet):
            raise InvalidParameterError("feet must be a non-empty sequence of FootContact")
        for name, value in (("acc_regularisation", acc_regularisation),
                            ("wrench_regularisation", wrench_regularisation)):  # fmt: skip
            if not (isinstance(value, int | float) and 0.0 < value <= 1.0):
                raise InvalidParameterError(f"{name} must be in (0, 1], got {value!r}")
        self.model = model
        self.feet = tuple(feet)
        nv, nf = int(model.nv), 6 * len(self.feet)
        self.nv, self.size = nv, nv + nf
        joints = np.asarray(model.actuator_trnid[:, 0], dtype=int)
        self.actuated = np.asarray(model.jnt_dofadr[joints], dtype=int)
        self.gear = np.ascontiguousarray(model.actuator_gear[:, 0], dtype=float)
        self.unactuated = np.setdiff1d(np.arange(nv), self.actuated)
        ranges = np.asarray(model.actuator_ctrlrange, dtype=float)
        limited = np.asarray(model.actuator_ctrllimited, dtype=bool)
        self.ctrl_low = np.where(limited, ranges[:, 0], -np.inf)
        self.ctrl_high = np.where(limited, ranges[:, 1], np.inf)
        self._regular = np.concatenate(
            [np.full(nv, acc_regularisation), np.full(nf, wrench_regularisation)]
        )
        foot_rows = [foot.constraint_rows() for foot in self.feet]
        self._foot_rows = np.ascontiguousarray(np.vstack(foot_rows))
        self._foot_start = np.cumsum([0] + [g.shape[0] for g in foot_rows], dtype=np.int64)
        self._bodies = np.array([foot.body for foot in self.feet], dtype=np.int64)
        self._origins = np.array([foot.origin for foot in self.feet], dtype=float)
        self._n_equal = self.unactuated.size + nf
        self.contacts = np.ones(len(self.feet), dtype=bool)
        rows = self._n_equal + self._foot_rows.shape[0] + int(model.nu)
        self._buf = buf = Buffers(nv, nf, rows, int(model.nu))
        self._views = [(buf.points[i], buf.jac[6 * i : 6 * i + 3], buf.jac[6 * i + 3 : 6 * i + 6],
                        buf.dots[6 * i : 6 * i + 3], buf.dots[6 * i + 3 : 6 * i + 6], int(body))
                       for i, body in enumerate(self._bodies)]  # fmt: skip
        self._regular_matrix = np.diag(self._regular)
        self._solver = LeastDistanceSolver(buf, self._n_equal, self.ctrl_low, self.ctrl_high)
        self.contact_damping = CONTACT_DAMPING  # k_c [1/s]: J q̈ + J̇ q̇ = −k_c J q̇
        # The fast path's arguments after the tasks' (_tick_arguments), for one observation and
        # contact set: MuJoCo's arrays are views of its fixed arena, read anew each tick.
        self._data: HumanoidObservation | None = None
        self._arguments: tuple[Any, ...] = ()

    def reset(self) -> None:
        """Forget the warm start (the next solve sets DAQP up afresh); every foot in contact."""
        self._solver.forget()
        self._solver.last_ctrl = np.zeros(self.model.nu)
        self.contacts[:] = True

    def set_contacts(self, contacts: Sequence[bool]) -> None:
        """Set which feet are on the floor (one bool per foot); a change sets DAQP up afresh.

        A foot off the floor has its wrench forced to zero and no fixed-foot rows.

        Raises
        ------
        InvalidParameterError
            If ``contacts`` is not one bool per foot.
        """
        mask = np.asarray(contacts)
        if mask.shape != self.contacts.shape or mask.dtype != np.bool_:
            raise InvalidParameterError(f"contacts must be one bool per foot, got {contacts!r}")
        if not np.array_equal(mask, self.contacts):
            self.contacts = mask.copy()
            self._data = None  # the fast path's arguments name the contacts
            self._solver.forget()  # other rows: no warm start

    def contact_jacobians(
        self, data: HumanoidObservation
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Return each foot's world Jacobian J (6 n × nv), J̇ q̇ (6 n) and sole-frame Jacobian.

        Rows per foot: linear then angular. The sole-frame Jacobian is blockwise Rᵀ J, R the
        foot's orientation: its transpose maps a sole-frame wrench to generalised forces.
        Written in place into the QP's buffers: valid until the next call.
        """
        buf = self._buf
        self._jacobians(data)
        sole_frames(data.xmat, self._bodies, buf.jac, buf.dots, data.qvel, buf.jac_dot,
                    buf.local)  # fmt: skip
        return buf.jac, buf.jac_dot, buf.local

    def _jacobians(self, data: HumanoidObservation) -> None:
        """Write MuJoCo's J and J̇ of each sole frame into the buffers (``jac``, ``dots``)."""
        if data is not self._data:
            self._tick_arguments(data)
        jac, jac_dot = data.jac, data.jac_dot
        sole_origins(*self._origin_arguments)
        for point, lin, ang, lin_dot, ang_dot, body in self._views:  # rows of buf, per foot
            jac(lin, ang, point, body)
            jac_dot(lin_dot, ang_dot, point, body)

    def assemble(self, data: HumanoidObservation, tasks: Sequence[Task]) -> WbcProblem:
        """Build the QP of the module docstring at the state in ``data`` (:meth:`solve`).

        Written in place into the QP's buffers: the arrays are valid until the next call.

        Raises
        ------
        InvalidParameterError
            If a task's matrix is not (k, m ≤ ``size``) with a target of k rows.
        """
        count = self._assemble(data, tasks)
        buf = self._buf
        return WbcProblem(buf.hessian, buf.linear, buf.rows[:count], buf.upper[:count],
                          buf.lower[:count], self._n_equal)  # fmt: skip

    def _assemble(self, data: HumanoidObservation, tasks: Sequence[Task]) -> int:
        """Write the QP into the buffers (:meth:`assemble`); return its number of rows."""
        checked = []  # every task checked before the buffers change
        for task in tasks:
            matrix = np.ascontiguousarray(task.matrix, dtype=np.float64)
            target = np.ascontiguousarray(task.target, dtype=np.float64)
            if matrix.ndim != 2 or matrix.shape[1] > self.size or target.shape != matrix.shape[:1]:
                raise InvalidParameterError(
                    f"task {task.name!r}: matrix must be (k, m ≤ {self.size}) and target (k,), "
                    f"got {matrix.shape} and {target.shape}"
                )
            checked.append((matrix, target, float(task.weight)))
        buf = self._buf
        self._clear(data)
        for matrix, target, weight in checked:
            add_task(buf.hessian, buf.linear, matrix, target, weight)
        return self._constrain(data)

    def _tick_arguments(self, data: HumanoidObservation) -> None:
        """Gather :func:`.kernels.wbc.assemble_rows`' arrays after the tasks' and k_c.

        Also ``sole_origins``' arguments and the bound ``mj_fullM`` of ``data``.
        """
        buf = self._buf
        self._data = data
        self._inertia = data.inertia_writer(buf.mass)
        self._origin_arguments = (data.xpos, data.xmat, self._bodies, self._origins, buf.points)
        self._arguments = (
            data.xmat, self._bodies, buf.dots, data.qvel, self._regular, buf.mass,
            data.qfrc_bias, data.qfrc_passive, self.contacts, self.unactuated, self.actuated,
            self.gear, self.ctrl_low, self.ctrl_high, self._foot_rows, self._foot_start,
            buf.jac, buf.jac_dot, buf.local, buf.hessian, buf.linear, buf.rows, buf.upper,
            buf.lower, buf.offset,
        )  # fmt: skip

    def _clear(self, data: HumanoidObservation) -> None:
        """Start a tick: M and the contact Jacobians of ``data``, H = diag(ε), f = 0."""
        buf = self._buf
        data.inertia_writer(buf.mass)()
        self.contact_jacobians(data)
        np.copyto(buf.hessian, self._regular_matrix)
        buf.linear.fill(0.0)

    def _constrain(self, data: HumanoidObservation) -> int:
        """Write the constraint rows (after the tasks); return the QP's number of rows."""
        buf = self._buf
        count = constraints(
            buf.mass, data.qfrc_bias, data.qfrc_passive, buf.jac, buf.jac_dot, buf.local,
            data.qvel, self.contacts, self.unactuated, self.actuated, self.gear, self.ctrl_low,
            self.ctrl_high, self._foot_rows, self._foot_start, float(self.contact_damping),
            buf.rows, buf.upper, buf.lower, buf.offset,
        )  # fmt: skip
        return int(count)

    def solve(self, data: HumanoidObservation, tasks: Sequence[Task]) -> WbcSolution:
        """Solve the QP at the state in ``data`` (its M, bias and kinematics current).

        ``data`` must hold the results of ``mj_forward`` (or ``mj_step1``) for its qpos and
        qvel. Never raises on an infeasible tick: ``ok`` is then False and ``ctrl`` repeats
        the last good command.

        Raises
        ------
        InvalidParameterError
            If a task's matrix is not (k, m ≤ ``size``) with a target of k rows.
        """
        return self._solve_assembled(self._assemble(data, tasks))

    def _solve_rows(
        self,
        data: HumanoidObservation,
        matrix: FloatArray,
        target: FloatArray,
        weights: FloatArray,
        count: int,
    ) -> WbcSolution:
        """:meth:`solve` of the first ``count`` stacked task rows, unchecked.

        The controller's fast path: ``matrix`` (≥ count, size), ``target`` and ``weights``
        (≥ count), all C-contiguous float64, row r of weight ``weights[r]``, its tasks' rows in
        their order; after MuJoCo's calls one compiled call (:func:`.kernels.wbc.assemble_rows`)
        instead of a check and a call per task and kernel (the same sums: the same QP to the
        last bit).
        """
        if data is not self._data:
            self._tick_arguments(data)
        self._inertia()  # full_inertia
        self._jacobians(data)
        count = assemble_rows(matrix, target, weights, count, float(self.contact_damping),
                              *self._arguments)  # fmt: skip
        return self._solve_assembled(int(count))

    def _solve_assembled(self, count: int) -> WbcSolution:
        """Solve the QP of ``count`` rows in the buffers (:meth:`solve`, :mod:`.least_distance`)."""
        x, ctrl, elapsed, steps = self._solver.solve(count)
        if x is None:
            feet = len(self.feet)
            return WbcSolution(np.zeros(self.nv), np.zeros((feet, 6)), ctrl, False, elapsed, steps)
        nv = self.nv
        return WbcSolution(x[:nv], x[nv:].reshape(-1, 6), ctrl, True, elapsed, steps)
