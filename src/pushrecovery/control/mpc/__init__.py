"""Receding-horizon CMP balancing, Sec. III-B (Eqs. 16-17)."""

from pushrecovery.control.mpc.controller import MPCController
from pushrecovery.control.mpc.feasibility import FlywheelFeasibility
from pushrecovery.control.mpc.plan import Plan
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.control.mpc.qp import CondensedQP
from pushrecovery.control.mpc.workspace import DaqpWorkspace

__all__ = [
    "CondensedQP",
    "DaqpWorkspace",
    "FlywheelFeasibility",
    "MPCController",
    "MPCSettings",
    "Plan",
]
