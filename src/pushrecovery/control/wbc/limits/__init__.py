"""The whole-body QP's soft limits: the joint guard and the stepper's knee guard.

:mod:`.joint_guard` (:class:`~.joint_guard.JointGuard`, without stepping) and
:mod:`.knee_guard` (:func:`~.knee_guard.knee_guard_tasks`, the stepper's).

The motor limits, the contact wrenches' cones and the dynamics are the QP's own rows
(:mod:`pushrecovery.control.wbc.qp`).
"""
