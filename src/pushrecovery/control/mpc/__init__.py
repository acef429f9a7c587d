"""Receding-horizon CMP balancing, Sec. III-B (Eqs. 16-17)."""

from pushrecovery.control.mpc.controller import MPCController
from pushrecovery.control.mpc.feasibility import FlywheelFeasibility
from pushrecovery.control.mpc.plan import Plan, Status
from pushrecovery.control.mpc.problem import MPCSettings, SparseQP
from pushrecovery.control.mpc.qp import CondensedQP

__all__ = [
    "CondensedQP",
    "FlywheelFeasibility",
    "MPCController",
    "MPCSettings",
    "Plan",
    "SparseQP",
    "Status",
]
