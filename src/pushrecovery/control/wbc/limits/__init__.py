"""The whole-body QP's limits: the joint-range guard (:mod:`.joint_guard`).

The motor limits, the contact wrenches' cones and the dynamics are the QP's own rows
(:mod:`pushrecovery.control.wbc.qp`).
"""
