"""The MPC's solvers behind one entry, :meth:`Route.solve <.route.Route.solve>`: a module each.

Each implements :class:`Solver` (``solve(x0, guess) -> Plan``) for one problem: :mod:`.riccati`
(the warm Riccati passes), :mod:`.interior` (the interior point), :mod:`.daqp` (the condensed
QP in a DAQP workspace), :mod:`.solve_qp` (through ``qpsolvers``); :mod:`.route` runs them in
order (docs/mpc.md, "How a tick is solved"). A route stays while the measured table of
docs/mpc.md, "The routes", shows it solving ticks.
"""

from pushrecovery.control.mpc.solvers.base import Guess, Solver
from pushrecovery.control.mpc.solvers.daqp import DaqpSolver
from pushrecovery.control.mpc.solvers.interior import InteriorPointSolver
from pushrecovery.control.mpc.solvers.riccati import RiccatiSolver
from pushrecovery.control.mpc.solvers.route import Route
from pushrecovery.control.mpc.solvers.solve_qp import SolveQpSolver

__all__ = [
    "DaqpSolver",
    "Guess",
    "InteriorPointSolver",
    "RiccatiSolver",
    "Route",
    "SolveQpSolver",
    "Solver",
]
