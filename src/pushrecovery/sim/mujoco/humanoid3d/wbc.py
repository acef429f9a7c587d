r"""Task-space inverse dynamics as one QP on MuJoCo's own dynamics (docs/humanoid3d.md).

Each control tick solves, for the joint accelerations q̈ ∈ R^nv and one 6-D contact wrench
w_i = (F_i, T_i) per foot on the floor (the force and moment the floor exerts on foot i at
its *sole frame*: the foot body's axes, its origin on the sole plane under the ankle; F_z > 0
pushes the foot up), the weighted least-squares problem (Del Prete, Mansard et al., "TSID",
and Wensing & Orin, "Generation of dynamic humanoid behaviors through task-space control
with conic optimization", ICRA 2013):

.. math:: \min_{x = (\ddot q, w)} \sum_k W_k \lVert A_k x - b_k \rVert^2
          + \epsilon_a \lVert \ddot q \rVert^2 + \epsilon_f \lVert w \rVert^2

subject to

* the floating-base (and every unactuated dof's) rows of the dynamics, with MuJoCo's joint-space
  inertia M (``mj_fullM``, armature included) and bias h = ``qfrc_bias`` − ``qfrc_passive``
  (Coriolis, centrifugal and gravity, minus springs and damping) [N, N m]:
  M_u q̈ + h_u = J_{c,u}^T w (the actuated rows give the torques τ = M_a q̈ + h_a − J_{c,a}^T w);
* each foot fixed on the floor: J_i q̈ + J̇_i q̇ = −k_c J_i q̇ with J_i the 6 × nv world Jacobian
  of the sole frame (``mj_jac``), J̇_i q̇ its bias acceleration (``mj_jacDot``) [m/s², rad/s²]
  and k_c ≥ 0 (``contact_damping``, 0 by default) a damping of a drifting foot [1/s];
  a foot off the floor (:meth:`WholeBodyQP.set_contacts`, a swing) has w_i = 0 instead and no
  wrench inequalities (its motion is a task, :mod:`.wbc_step`);
* unilateral contact F_z ≥ 0 and a linearised friction pyramid |F_x|, |F_y| ≤ μ' F_z with
  μ' = μ/√2 (the square inscribed in Coulomb's cone of μ; μ the larger sliding friction of
  the sole's and the floor's geoms, MuJoCo's mixing rule);
* the CoP p = (−T_y, T_x)/F_z of each wrench inside its foot's sole polygon: for each edge
  n·p ≤ d, n_x (−T_y) + n_y T_x − d F_z ≤ 0 (linear in w);
* yaw friction |T_z| ≤ μ' r F_z, r the sole polygon's inscribed radius about the sole frame's
  origin (a conservative bound of the torsional friction);
* motor limits: the torque of each motor, τ_a / gear, within its ``actuator_ctrlrange``.

The tasks A_k x = b_k are handed in by the controller (:mod:`.wbc_control`): the CoM's
acceleration, exact from Newton's law on the wrenches, m c̈ = m g + Σ_i R_i F_i; the torso's
angular acceleration J_r q̈ + J̇_r q̇; the pelvis height z̈ = J_z q̈ + J̇_z q̇; and the posture
q̈_j. Solved with DAQP (a dense dual active-set solver) in one ``daqp.Model`` kept between
ticks: the equality rows are flagged immutable, and the active set of the last tick is its
warm start. MuJoCo's types appear as ``Any``: its bindings ship no type information.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import convex_hull
from pushrecovery.sim.mujoco.humanoid3d.measure import body_id, colliding_geoms, sole_points

FloatArray = NDArray[np.float64]

__all__ = ["FootContact", "Task", "WbcSolution", "WholeBodyQP", "foot_contact"]

#: Bounds DAQP treats as infinite.
_INF = 1e30
#: DAQP's sense flags: an active, immutable row (an equality).
_EQUALITY = 5


@dataclass(frozen=True)
class FootContact:
    """A foot's sole frame and its wrench constraints.

    Attributes
    ----------
    name, body : str, int
        The foot body's name and id.
    origin : float array, shape (3,)
        The sole frame's origin in the foot body's frame [m]: under the body origin, on the
        sole plane.
    edges : float array, shape (k, 3)
        Rows (n_x, n_y, d) with n·p ≤ d for a CoP p inside the sole polygon, in the sole frame
        [-, -, m] (n a unit outward normal).
    mu : float
        Friction coefficient of the pyramid, μ' = μ/√2 [-].
    yaw_radius : float
        Inscribed radius r of the sole polygon about the frame's origin [m] (|T_z| ≤ μ' r F_z).
    """

    name: str
    body: int
    origin: FloatArray
    edges: FloatArray
    mu: float
    yaw_radius: float

    def constraint_rows(self) -> FloatArray:
        """Return G with G w ≤ 0 for this foot's wrench w = (F, T) [rows, 6].

        Rows: −F_z ≤ 0; ±F_x − μ' F_z ≤ 0; ±F_y − μ' F_z ≤ 0; per edge
        n_y T_x − n_x T_y − d F_z ≤ 0; ±T_z − μ' r F_z ≤ 0.
        """
        mu, rows = self.mu, [[0.0, 0.0, -1.0, 0.0, 0.0, 0.0]]
        for sign in (1.0, -1.0):
            rows.append([sign, 0.0, -mu, 0.0, 0.0, 0.0])
            rows.append([0.0, sign, -mu, 0.0, 0.0, 0.0])
        for nx, ny, d in self.edges:
            rows.append([0.0, 0.0, -d, ny, -nx, 0.0])
        for sign in (1.0, -1.0):
            rows.append([0.0, 0.0, -mu * self.yaw_radius, 0.0, 0.0, sign])
        return np.array(rows, dtype=float)


def foot_contact(model: Any, data: Any, name: str) -> FootContact:
    """Return the :class:`FootContact` of foot body ``name``, measured in ``data``'s pose.

    The sole polygon is the convex hull of the sole points (:func:`~.measure.sole_points`,
    after ``mj_kinematics``) in the foot body's frame; the sole frame's origin is the body
    origin moved along the body's z onto the sole plane. μ is the largest sliding friction of
    the foot's colliding geoms and every geom they can touch (the floor), as MuJoCo mixes two
    geoms' friction by their maximum.

    Raises
    ------
    InvalidParameterError
        If ``name`` is not a body of ``model`` with colliding geoms, or its sole polygon does
        not contain the sole frame's origin (the yaw bound needs it inside).
    """
    try:
        body = body_id(model, name)
    except KeyError:
        raise InvalidParameterError(f"feet must name bodies of the model, got {name!r}") from None
    geoms = colliding_geoms(model, body)
    if not geoms:
        raise InvalidParameterError(f"feet: body {name!r} has no colliding geom (no sole)")
    rot = np.array(data.xmat[body], dtype=float).reshape(3, 3)
    local = (sole_points(model, data, body) - np.asarray(data.xpos[body])) @ rot
    polygon = convex_hull(local[:, :2])
    vertices, following = polygon.vertices, np.roll(polygon.vertices, -1, axis=0)
    direction = following - vertices
    normal = np.column_stack([direction[:, 1], -direction[:, 0]])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    offset = np.einsum("ij,ij->i", normal, vertices)
    if np.any(offset <= 0.0):
        raise InvalidParameterError(
            f"feet: the sole polygon of {name!r} must contain the point under its body origin"
        )
    others = [
        g for g in range(model.ngeom) if int(model.geom_bodyid[g]) != body
        and int(model.geom_conaffinity[g]) & int(model.geom_contype[geoms[0]])
    ]  # fmt: skip
    mu = max(float(model.geom_friction[g, 0]) for g in geoms + others)
    return FootContact(
        name=name,
        body=body,
        origin=np.array([0.0, 0.0, float(local[:, 2].mean())]),
        edges=np.column_stack([normal, offset]),
        mu=mu / math.sqrt(2.0),
        yaw_radius=float(offset.min()),
    )


def _full_inertia(model: Any, data: Any, out: FloatArray) -> None:
    """Write the dense joint-space inertia M into ``out`` (MuJoCo 4's and 3's ``mj_fullM``)."""
    import mujoco

    if hasattr(data, "qM"):  # MuJoCo 3: mj_fullM(m, dst, qM)
        mujoco.mj_fullM(model, out, data.qM)
    else:  # MuJoCo 4: mj_fullM(m, d, dst)
        mujoco.mj_fullM(model, data, out)


@dataclass(frozen=True)
class Task:
    """One weighted task A x = b of the QP (module docstring).

    Attributes
    ----------
    name : str
        For reports.
    matrix, target : float arrays, shapes (k, nv + 6 n_feet) and (k,)
        A over x = (q̈, w_1, …), and b [the task's units: m/s² or rad/s²].
    weight : float
        W > 0 [-].
    """

    name: str
    matrix: FloatArray
    target: FloatArray
    weight: float


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
        Wall time of DAQP's update (its factorisation) and solve [s], and its iterations.
    """

    qacc: FloatArray
    wrenches: FloatArray
    ctrl: FloatArray
    ok: bool
    solve_time: float
    iterations: int


@dataclass
class _Buffers:
    mass: FloatArray
    jac: FloatArray
    jac_dot: FloatArray


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
        self.gear = np.asarray(model.actuator_gear[:, 0], dtype=float)
        self.unactuated = np.setdiff1d(np.arange(nv), self.actuated)
        ranges = np.asarray(model.actuator_ctrlrange, dtype=float)
        limited = np.asarray(model.actuator_ctrllimited, dtype=bool)
        self.ctrl_low = np.where(limited, ranges[:, 0], -np.inf)
        self.ctrl_high = np.where(limited, ranges[:, 1], np.inf)
        self._regular = np.concatenate(
            [np.full(nv, acc_regularisation), np.full(nf, wrench_regularisation)]
        )
        self._foot_rows = [foot.constraint_rows() for foot in self.feet]
        self._n_equal = self.unactuated.size + nf
        self.contacts = np.ones(len(self.feet), dtype=bool)
        self._buf = _Buffers(np.zeros((nv, nv)), np.zeros((nf, nv)), np.zeros(nf))
        self._model: Any = None
        self._last_ctrl = np.zeros(model.nu)
        self.contact_damping = 0.0  # k_c [1/s]: J q̈ + J̇ q̇ = −k_c J q̇ holds a foot still

    def _setup(self, hessian: FloatArray, linear: FloatArray, rows: FloatArray,
               upper: FloatArray, lower: FloatArray) -> None:  # fmt: skip
        import daqp

        sense = np.zeros(rows.shape[0], dtype=np.intc)
        sense[: self._n_equal] = _EQUALITY
        self._model = daqp.Model()
        flag, _ = self._model.setup(hessian, linear, rows, upper, lower, sense)
        if flag < 0:
            raise RuntimeError(f"daqp could not set up the whole-body QP (exit flag {flag})")

    def reset(self) -> None:
        """Forget the warm start (the next solve sets DAQP up afresh); every foot in contact."""
        self._model = None
        self._last_ctrl = np.zeros(self.model.nu)
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
            self._model = None  # other rows: no warm start

    def contact_jacobians(self, data: Any) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Return each foot's world Jacobian J (6 n × nv), J̇ q̇ (6 n) and sole-frame Jacobian.

        Rows per foot: linear then angular. The sole-frame Jacobian is blockwise Rᵀ J, R the
        foot's orientation: its transpose maps a sole-frame wrench to generalised forces.
        """
        import mujoco

        buf, nv = self._buf, self.nv
        local = np.empty_like(buf.jac)
        for i, foot in enumerate(self.feet):
            rot = np.array(data.xmat[foot.body], dtype=float).reshape(3, 3)
            point = np.asarray(data.xpos[foot.body]) + rot @ foot.origin
            jacp, jacr = buf.jac[6 * i : 6 * i + 3], buf.jac[6 * i + 3 : 6 * i + 6]
            mujoco.mj_jac(self.model, data, jacp, jacr, point, foot.body)
            dotp, dotr = np.zeros((3, nv)), np.zeros((3, nv))
            mujoco.mj_jacDot(self.model, data, dotp, dotr, point, foot.body)
            qvel = np.asarray(data.qvel)
            buf.jac_dot[6 * i : 6 * i + 3] = dotp @ qvel
            buf.jac_dot[6 * i + 3 : 6 * i + 6] = dotr @ qvel
            local[6 * i : 6 * i + 3] = rot.T @ jacp
            local[6 * i + 3 : 6 * i + 6] = rot.T @ jacr
        return buf.jac, buf.jac_dot, local

    def solve(self, data: Any, tasks: Sequence[Task]) -> WbcSolution:
        """Solve the QP at the state in ``data`` (its M, bias and kinematics current).

        ``data`` must hold the results of ``mj_forward`` (or ``mj_step1``) for its qpos and
        qvel. Never raises on an infeasible tick: ``ok`` is then False and ``ctrl`` repeats
        the last good command.
        """
        model, nv, buf = self.model, self.nv, self._buf
        _full_inertia(model, data, buf.mass)
        bias = np.asarray(data.qfrc_bias) - np.asarray(data.qfrc_passive)
        jac, jac_dot, local = self.contact_jacobians(data)
        hessian = np.diag(self._regular)
        linear = np.zeros(self.size)
        for task in tasks:
            weighted = task.weight * task.matrix
            hessian += weighted.T @ task.matrix
            linear -= weighted.T @ task.target
        dynamics = np.hstack([buf.mass, -local.T])  # M q̈ − J_cᵀ w = −h (+ τ on actuated rows)
        fixed = np.hstack([jac, np.zeros((jac.shape[0], jac.shape[0]))])
        target = -jac_dot - self.contact_damping * (jac @ np.asarray(data.qvel))
        for i in map(int, np.flatnonzero(~self.contacts)):  # swing: w_i = 0 replaces the fixed rows
            fixed[6 * i : 6 * i + 6] = 0.0
            fixed[6 * i : 6 * i + 6, nv + 6 * i : nv + 6 * i + 6] = np.eye(6)
            target[6 * i : 6 * i + 6] = 0.0
        blocks = [dynamics[self.unactuated], fixed]
        upper = [-bias[self.unactuated], target]
        lower = [-bias[self.unactuated], target]
        for i, g in enumerate(self._foot_rows):
            if not self.contacts[i]:
                continue
            block = np.zeros((g.shape[0], self.size))
            block[:, nv + 6 * i : nv + 6 * i + 6] = g
            blocks.append(block)
            upper.append(np.zeros(g.shape[0]))
            lower.append(np.full(g.shape[0], -_INF))
        torque_rows = dynamics[self.actuated] / self.gear[:, None]  # (M_a q̈ + h_a − J_aᵀ w)/gear
        offset = bias[self.actuated] / self.gear
        blocks.append(torque_rows)
        upper.append(np.minimum(self.ctrl_high - offset, _INF))
        lower.append(np.maximum(self.ctrl_low - offset, -_INF))
        rows = np.ascontiguousarray(np.vstack(blocks))
        high, low = np.concatenate(upper), np.concatenate(lower)
        start = time.perf_counter()  # the solve time includes DAQP's factorisation of H
        if self._model is None:
            self._setup(hessian, linear, rows, high, low)
        else:
            self._model.update(H=hessian, f=linear, A=rows, bupper=high, blower=low)
        x, _, flag, info = self._model.solve()
        elapsed, feet, steps = time.perf_counter() - start, len(self.feet), int(info["iterations"])
        if flag <= 0:
            self._model = None  # the next tick starts cold
            last = self._last_ctrl.copy()
            return WbcSolution(np.zeros(nv), np.zeros((feet, 6)), last, False, elapsed, steps)
        x = np.asarray(x, dtype=float)
        ctrl = np.clip(torque_rows @ x + offset, self.ctrl_low, self.ctrl_high)
        self._last_ctrl = ctrl
        return WbcSolution(x[:nv].copy(), x[nv:].reshape(feet, 6), ctrl, True, elapsed, steps)
