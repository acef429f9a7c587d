"""The condensed QP through ``qpsolvers.solve_qp``, cold at every tick (any back-end).

The route of ``MPCSettings(solver=...)`` other than ``daqp`` (``quadprog``: the reference of the
tests and ``benchmarks/run.py``), and of ``daqp`` where its ``Model`` workspace cannot be built.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.mpc.plan import Plan
from pushrecovery.control.mpc.qp import CondensedQP
from pushrecovery.control.mpc.solvers.base import Guess
from pushrecovery.control.mpc.solvers.daqp import PRIMAL_TOL

__all__ = ["SolveQpSolver"]

FloatArray = NDArray[np.float64]

_COLD = Guess()


class SolveQpSolver:
    """One :class:`~pushrecovery.control.mpc.qp.CondensedQP` solved by ``qpsolvers.solve_qp``.

    Parameters
    ----------
    qp : CondensedQP
        The problem.
    backend : str
        The qpsolvers back-end (``quadprog``, ``daqp``, ...).

    """

    def __init__(self, qp: CondensedQP, backend: str) -> None:
        require_type("qp", qp, CondensedQP)
        require_type("backend", backend, str)
        self.qp = qp
        self.backend = backend
        # DAQP's tolerance of the workspace here too: its default (1e-6) is not exact.
        self._options: dict[str, Any] = {"primal_tol": PRIMAL_TOL} if backend == "daqp" else {}

    def reset(self) -> None:
        """Do nothing: every solve starts cold."""

    def solve(self, x0: FloatArray, guess: Guess = _COLD) -> Plan:
        """Solve the QP from state ``x0`` (cold, ``guess`` unused): SOLVED, or FAILED.

        Only the back-end's own failures (``ProblemError``, ``SolverError``, no solution, a
        solution that is not finite) are FAILED; any other exception is a bug and propagates.
        """
        from qpsolvers import solve_qp
        from qpsolvers.exceptions import ProblemError, SolverError

        qp = self.qp
        q, lower, upper = qp.vectors(x0)
        rows = qp.scaled_inequality
        try:
            solution: FloatArray | None = solve_qp(
                np.array(qp.scaled_hessian),  # writable: quadprog refuses read-only buffers
                q,
                np.vstack([rows, -rows]),
                np.concatenate([upper, -lower]),
                solver=self.backend,
                **self._options,
            )
        except (ProblemError, SolverError):
            return Plan.failed()
        if solution is None or not np.isfinite(solution).all():
            return Plan.failed()
        return qp.plan(x0, solution.copy())
