r"""The whole-body balance controller: the ankle strategy's tasks for :class:`~.wbc.WholeBodyQP`.

Tasks, each an acceleration a PD law asks for (world frame, x forward, y left, z up, SI):

* **CoM, CoP balancing (ankle)**: with ω = sqrt(g/z_c) (z_c the CoM height above the soles at
  reset), the capture point ξ = c + ċ/ω (:func:`~pushrecovery.surfaces.plane.capture_point_xy`)
  and its rest point ξ₀ (the CoM's ground point at reset), the desired CoP is the DCM law

  .. math:: \mathbf p_{des} = \operatorname{clip}_P\big(\boldsymbol\xi
            + (k_\xi/\omega)(\boldsymbol\xi - \boldsymbol\xi_0)\big),
            \qquad \ddot{\mathbf c}_{xy} = \omega^2 (\mathbf c_{xy} - \mathbf p_{des}),

  clipped to the support polygon P of the feet (the convex hull of their soles, the ``Support``
  of the plane's surfaces). Unclipped, ξ̇ = ω(ξ − p) = −k_ξ (ξ − ξ₀): the capture point returns
  to ξ₀ at rate k_ξ; clipped, the CoP stays on the edge of P, the saturated CoP balancing of
  Eq. (3), which recovers every state whose ξ is inside P (Eq. 4). In the QP the CoM task is
  exact from Newton's law, m c̈ = m g + Σ R_i F_i (z row: c̈_z = 0 is left to the pelvis).
* **Torso upright**: α = −k_R e − d_R ω_t, e the rotation vector of R_t R_t0ᵀ (R_t0 the torso's
  orientation at reset), ω_t its angular velocity [rad/s²].
* **Pelvis height**: z̈ = k_z (z_0 − z) − d_z ż of the torso body's origin [m/s²].
* **Posture**: q̈_j = k_q (q_j0 − q_j) − d_q q̇_j of every joint dof [rad/s²].

Weights (:class:`WbcGains`): CoM 10, torso 1, pelvis 1, posture 0.01: the CoM law dominates,
the torso stays upright (no hip strategy) and the posture fills the null space.

Contract: :class:`WholeBodyController` has the ``reset(state)`` / ``compute(t, state)`` pair of
:class:`~pushrecovery.control.base.Controller`, with one deviation: its ``state`` is the
``mujoco.MjData`` (positions, velocities and everything ``mj_forward`` computed from them),
and ``compute`` returns the motor commands ``ctrl`` [N m] instead of a ``Command``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon, convex_hull
from pushrecovery.sim.mujoco.humanoid3d.measure import body_id, sole_points
from pushrecovery.sim.mujoco.humanoid3d.wbc import (
    FootContact,
    Task,
    WbcSolution,
    WholeBodyQP,
    foot_contact,
)
from pushrecovery.surfaces.plane import capture_point_xy

FloatArray = NDArray[np.float64]

__all__ = ["WbcGains", "WholeBodyController"]


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


def _rotation_vector(rot: FloatArray) -> FloatArray:
    """Return the rotation vector (axis × angle) of rotation matrix ``rot`` [rad]."""
    angle = math.acos(max(-1.0, min(1.0, 0.5 * (float(np.trace(rot)) - 1.0))))
    axial = 0.5 * np.array([rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]])
    if angle < 1e-9:
        return axial
    return axial * (angle / math.sin(angle))


class WholeBodyController:
    """Ankle-strategy whole-body control of a floating-base humanoid (module docstring).

    Parameters
    ----------
    model : mujoco.MjModel
        The humanoid (free joint first, torque motors on joints).
    feet : sequence of str
        Names of the foot bodies, all on the floor at reset and kept there.
    torso : str
        Name of the body held upright (its origin's height is the pelvis task).
    gains : WbcGains, optional
        Task gains and weights.

    Raises
    ------
    InvalidParameterError
        If a name is not a body of ``model``, ``feet`` is empty or repeats a body, the model
        has joints other than the free root and hinges or slides, or ``gains`` is not a
        :class:`WbcGains`.
    """

    #: The period the gains are meant for [s] (500 Hz).
    control_period = 0.002

    def __init__(
        self,
        model: Any,
        feet: Sequence[str] = ("left_foot", "right_foot"),
        torso: str = "torso",
        gains: WbcGains | None = None,
    ) -> None:
        if isinstance(feet, str) or not feet or len(set(feet)) != len(feet):
            raise InvalidParameterError(f"feet must be distinct body names, got {feet!r}")
        for name in (*feet, torso):
            try:
                body_id(model, name)
            except KeyError:
                raise InvalidParameterError(f"no body {name!r} in the model") from None
        if int(model.nq) - 7 != int(model.nv) - 6:
            raise InvalidParameterError(
                "model must have a free joint and hinge or slide joints only (nq − 7 = nv − 6)"
            )
        gains = WbcGains() if gains is None else gains
        if not isinstance(gains, WbcGains):
            raise InvalidParameterError(f"gains must be a WbcGains, got {type(gains).__name__}")
        self.model, self.gains = model, gains
        self.foot_names, self.torso = tuple(feet), body_id(model, torso)
        self.mass = float(model.body_subtreemass[0])
        self.gravity = np.array(model.opt.gravity, dtype=float)
        self.qp: WholeBodyQP | None = None
        self.feet: tuple[FootContact, ...] = ()
        self.support: ConvexPolygon | None = None
        self.last: WbcSolution | None = None
        self.desired_cop = np.zeros(2)

    def reset(self, state: Any) -> None:
        """Take the reference posture, feet and balance point from ``state`` (an MjData).

        ``state`` must hold ``mj_forward``'s results; the feet must be on the floor.
        """
        model, data = self.model, state
        self.feet = tuple(foot_contact(model, data, name) for name in self.foot_names)
        self.qp = WholeBodyQP(model, self.feet)
        soles = np.vstack([sole_points(model, data, foot.body) for foot in self.feet])
        self.support = convex_hull(soles[:, :2])
        com = np.array(data.subtree_com[0], dtype=float)
        self.rest = com[:2].copy()
        floor = float(soles[:, 2].mean())
        self.omega = math.sqrt(float(np.linalg.norm(self.gravity)) / (com[2] - floor))
        self.posture = np.array(data.qpos[7:], dtype=float)
        self.height = float(data.xpos[self.torso][2])
        self.upright = np.array(data.xmat[self.torso], dtype=float).reshape(3, 3)
        self.last = None

    def cop_target(self, data: Any) -> FloatArray:
        """Return the DCM law's CoP p_des clipped to the support polygon [m] (world xy).

        Computes the CoM velocity (``mj_subtreeVel``, which ``mj_forward`` leaves stale).
        """
        import mujoco

        mujoco.mj_subtreeVel(self.model, data)
        com = np.asarray(data.subtree_com[0])
        velocity = np.asarray(data.subtree_linvel[0])
        xi_x, xi_y = capture_point_xy(com[0], com[1], velocity[0], velocity[1], self.omega)
        xi = np.array([float(xi_x), float(xi_y)])
        cop = xi + (self.gains.dcm / self.omega) * (xi - self.rest)
        assert self.support is not None
        if not bool(self.support.contains(cop[0], cop[1])):
            cop = np.array(self.support.nearest_point(float(cop[0]), float(cop[1])))
        return cop

    def tasks(self, data: Any) -> list[Task]:
        """Return the QP's tasks at the state in ``data`` (module docstring)."""
        import mujoco

        assert self.qp is not None
        model, gains, nv, size = self.model, self.gains, self.qp.nv, self.qp.size
        # CoM: m c̈ = m g + Σ R_i F_i, rows x and y.
        com = np.asarray(data.subtree_com[0])
        self.desired_cop = self.cop_target(data)
        com_acc = self.omega**2 * (com[:2] - self.desired_cop)
        com_rows = np.zeros((2, size))
        for i, foot in enumerate(self.feet):
            rot = np.array(data.xmat[foot.body], dtype=float).reshape(3, 3)
            com_rows[:, nv + 6 * i : nv + 6 * i + 3] = rot[:2] / self.mass
        tasks = [Task("com", com_rows, com_acc - self.gravity[:2], gains.com_weight)]
        # Torso orientation and pelvis height: J q̈ + J̇ q̇ = a_des.
        point = np.array(data.xpos[self.torso], dtype=float)
        jacp, jacr = np.zeros((3, nv)), np.zeros((3, nv))
        dotp, dotr = np.zeros((3, nv)), np.zeros((3, nv))
        mujoco.mj_jac(model, data, jacp, jacr, point, self.torso)
        mujoco.mj_jacDot(model, data, dotp, dotr, point, self.torso)
        qvel = np.asarray(data.qvel, dtype=float)
        rot = np.array(data.xmat[self.torso], dtype=float).reshape(3, 3)
        error = _rotation_vector(rot @ self.upright.T)
        spin = jacr @ qvel
        alpha = -gains.torso_stiffness * error - gains.torso_damping * spin - dotr @ qvel
        tasks.append(Task("torso", np.hstack([jacr, np.zeros((3, size - nv))]), alpha,
                          gains.torso_weight))  # fmt: skip
        rise = float(jacp[2] @ qvel)
        climb = gains.height_stiffness * (self.height - point[2]) - gains.height_damping * rise
        height_row = np.zeros((1, size))
        height_row[0, :nv] = jacp[2]
        tasks.append(Task("height", height_row, np.array([climb - dotp[2] @ qvel]),
                          gains.height_weight))  # fmt: skip
        # Posture of every joint dof (after the free joint's six).
        joints = np.zeros((nv - 6, size))
        joints[:, 6:nv] = np.eye(nv - 6)
        angles = np.asarray(data.qpos[7:], dtype=float)
        target = gains.posture_stiffness * (self.posture - angles)
        target -= gains.posture_damping * qvel[6:]
        tasks.append(Task("posture", joints, target, gains.posture_weight))
        return tasks

    def compute(self, t: float, state: Any) -> FloatArray:
        """Return the motor commands ``ctrl`` [N m] for the state in ``state`` (an MjData).

        ``t`` [s] is the time since reset (unused: the laws are time-invariant). Never raises
        inside the loop: a tick DAQP cannot solve repeats the last command (``last.ok``).
        """
        if self.qp is None:
            raise InvalidParameterError("call reset(state) before compute(t, state)")
        self.last = self.qp.solve(state, self.tasks(state))
        return self.last.ctrl
