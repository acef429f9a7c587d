"""What the whole-body controller reads of a humanoid and what it commands (zero-copy).

:class:`HumanoidObservation` is the controller's view of the plant: the MuJoCo plant builds it
once (:func:`mujoco_observation`) from its own ``MjData``, and every field is a view of that
data's fixed arena or a MuJoCo call bound to it, so a tick copies nothing (the controller
reads the physics' own arrays, as it did when it read the ``MjData``). Field names are
MuJoCo's (world frame, x forward, y left, z up, SI units): the helpers that measure a pose
(:func:`~.bodies.sole_points`, :func:`~.foot_contact.foot_contact`) read an observation and an
``MjData`` alike.

:class:`HumanoidCommand` is the controller's output: a
:class:`~pushrecovery.control.base.Command` (the DCM law's CoP in ``cop``, ``cop_y``) with the
motor torques the plant holds and what the 3-D fall rule needs of the controller (the support
it stands on while it steps, and whether a foot swings).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command

if TYPE_CHECKING:
    from pushrecovery.ground.polygon import ConvexPolygon

FloatArray = NDArray[np.float64]

__all__ = ["HUMANOID_STATE", "HumanoidCommand", "HumanoidObservation", "mujoco_observation"]

#: The 3-D humanoids' state (the controller's ``state_labels``): the whole-body CoM [m] and
#: its velocity [m/s], world frame.
HUMANOID_STATE = ("x", "y", "z", "xdot", "ydot", "zdot")

#: A Jacobian call: (jacp, jacr, point, body) writes the 3 × nv translational and rotational
#: Jacobians (or their time derivatives) of the world point [m] on the body.
JacobianCall = Callable[[FloatArray, FloatArray, FloatArray, int], None]


@dataclass(frozen=True, slots=True)
class HumanoidObservation:
    """A floating-base humanoid's kinematics and dynamics at the current instant (views).

    Build it with :func:`mujoco_observation`; the plant's physics step rewrites the arrays
    in place (after MuJoCo's ``mj_step1`` or ``mj_forward``: positions, velocities and the
    quantities computed from them).

    Attributes
    ----------
    qpos, qvel : float arrays, shapes (nq,), (nv,)
        Generalised positions (the free root's position [m] and quaternion first, then the
        joints [rad or m]) and velocities (root linear [m/s] and angular [rad/s], joints).
    xpos, xmat : float arrays, shapes (nbody, 3), (nbody, 9)
        Each body frame's origin [m] and orientation (row-major rotation matrix).
    xipos, ximat : float arrays, shapes (nbody, 3), (nbody, 9)
        Each body's centre of mass [m] and principal inertia frame.
    xanchor, xaxis : float arrays, shape (njnt, 3)
        Each joint's anchor [m] and axis (unit).
    geom_xpos, geom_xmat : float arrays, shapes (ngeom, 3), (ngeom, 9)
        Each geom's centre [m] and orientation.
    subtree_com, subtree_linvel, subtree_angmom : float arrays, shape (nbody, 3)
        Each subtree's CoM [m], its velocity [m/s] and angular momentum about it [kg m²/s]
        (row 0: the whole body); the velocities are current after :attr:`subtree_vel`.
    qfrc_bias, qfrc_passive : float arrays, shape (nv,)
        Coriolis, centrifugal and gravity forces, and passive forces [N or N m].
    clock : callable () -> float
        The plant's time [s] (MuJoCo's, since the plant's reset).
    jac, jac_dot : callable (jacp, jacr, point, body) -> None
        Write the Jacobians J and J̇ of a world point on a body (``mj_jac``, ``mj_jacDot``).
    subtree_vel : callable () -> None
        Bring ``subtree_linvel`` and ``subtree_angmom`` up to date (``mj_subtreeVel``).
    inertia_writer : callable (out) -> (callable () -> None)
        Bind a call that writes the dense joint-space inertia M [kg, kg m²] into ``out``
        (nv × nv): bound once, called every tick.
    """

    qpos: FloatArray
    qvel: FloatArray
    xpos: FloatArray
    xmat: FloatArray
    xipos: FloatArray
    ximat: FloatArray
    xanchor: FloatArray
    xaxis: FloatArray
    geom_xpos: FloatArray
    geom_xmat: FloatArray
    subtree_com: FloatArray
    subtree_linvel: FloatArray
    subtree_angmom: FloatArray
    qfrc_bias: FloatArray
    qfrc_passive: FloatArray
    clock: Callable[[], float]
    jac: JacobianCall
    jac_dot: JacobianCall
    subtree_vel: Callable[[], None]
    inertia_writer: Callable[[FloatArray], Callable[[], None]]

    @property
    def time(self) -> float:
        """The plant's time [s] (:attr:`clock`, by MuJoCo's name)."""
        return self.clock()


def mujoco_observation(model: Any, data: Any) -> HumanoidObservation:
    """Return the :class:`HumanoidObservation` of MuJoCo's ``data`` (views of its arena).

    Built once per ``MjData`` (its arrays never move): the plants call it, as does a loop of
    one's own around ``mj_step``.

    Raises
    ------
    ParameterTypeError
        If ``model`` is not a ``mujoco.MjModel`` or ``data`` not a ``mujoco.MjData``.
    InvalidParameterError
        If ``data`` is not of ``model``'s size.
    """
    import mujoco

    from pushrecovery.control.wbc.bodies import check_data, check_model

    check_model(model)
    check_data(model, data)
    return HumanoidObservation(
        qpos=data.qpos, qvel=data.qvel, xpos=data.xpos, xmat=data.xmat, xipos=data.xipos,
        ximat=data.ximat, xanchor=data.xanchor, xaxis=data.xaxis, geom_xpos=data.geom_xpos,
        geom_xmat=data.geom_xmat, subtree_com=data.subtree_com,
        subtree_linvel=data.subtree_linvel, subtree_angmom=data.subtree_angmom,
        qfrc_bias=data.qfrc_bias, qfrc_passive=data.qfrc_passive,
        clock=partial(getattr, data, "time"), jac=partial(mujoco.mj_jac, model, data),
        jac_dot=partial(mujoco.mj_jacDot, model, data),
        subtree_vel=partial(mujoco.mj_subtreeVel, model, data),
        inertia_writer=partial(_inertia_writer, model, data),
    )  # fmt: skip


def _inertia_writer(model: Any, data: Any, out: FloatArray) -> Callable[[], None]:
    """Return a call writing M of ``data`` into ``out`` (MuJoCo 4's and 3's ``mj_fullM``)."""
    import mujoco

    if hasattr(data, "qM"):  # MuJoCo 3: mj_fullM(m, dst, qM)
        return partial(mujoco.mj_fullM, model, out, data.qM)
    return partial(mujoco.mj_fullM, model, data, out)  # MuJoCo 4: mj_fullM(m, d, dst)


@dataclass(frozen=True, slots=True)
class HumanoidCommand(Command):
    """A whole-body command: the motor torques, and the support the controller stands on.

    The :class:`~pushrecovery.control.base.Command` fields keep their meaning where they
    apply: ``cop`` and ``cop_y`` are the DCM law's CoP [m] (world x, y), ``saturated`` is
    False (the humanoids' rest rule is the plant's alone).

    Parameters
    ----------
    motors : float array, shape (nu,), or None
        The motor commands ``ctrl`` [N m] (torque / gear), in the model's actuator order;
        None holds the last ones.
    support : ConvexPolygon or None
        The support polygon of a controller that steps: the feet it keeps on the floor
        (world xy [m]); None when it does not step.
    stance : bool
        False while a foot swings toward a landing.
    """

    motors: FloatArray | None = None
    support: ConvexPolygon | None = None
    stance: bool = True
