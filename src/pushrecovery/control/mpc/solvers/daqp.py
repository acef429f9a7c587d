"""The condensed QP held in a DAQP workspace: set up once, warm-started every tick.

Going through ``qpsolvers.solve_qp`` rebuilds DAQP's whole problem each call: factorising the
Hessian and forming the constraint matrix of its dual (LDP) form costs ~0.3 ms, and a cold start
takes up to ~100 active-set iterations (~0.5 ms) when a push saturates the inputs. Here the
matrices are handed to a ``daqp.Model`` once; a tick only rewrites the state-dependent vectors
(q̃ and the rows' bounds) in preallocated buffers, and the solve starts from the previous tick's
active set, which in a receding horizon is nearly the new one (a few iterations).

The QP is strictly convex, so the warm-started solution is the cold one up to rounding (the
late-horizon torques are only defined to ~1e-7 N m: perturbing q̃ by a few ulps moves them
that much). DAQP stops once no constraint is violated by more than its primal tolerance, 1e-6 by
default, and which slightly violated constraint it leaves out depends on where it starts: up to
~0.1 N m on the flat, late-horizon torque directions. The tolerance is therefore tightened to
:data:`PRIMAL_TOL`, which makes the plan the exact QP solution whatever the start. Every bound
is a general row of the pre-stabilised QP (:mod:`~pushrecovery.control.mpc.qp`), at unit norm
in the scaled variables: over 3000 random states the plans keep their bounds to 1.1e-8 m
(CoP), 5e-8 N m (torque) and 1e-13 rad (θ); the applied input is clipped to its limits. A
tighter tolerance (1e-11) declared states at the edge of feasibility infeasible.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.mpc.plan import Plan
from pushrecovery.control.mpc.qp import CondensedQP
from pushrecovery.control.mpc.solvers.base import Guess

__all__ = ["ITER_BUDGET", "PRIMAL_TOL", "DaqpSolver"]

FloatArray = NDArray[np.float64]

#: Largest constraint violation DAQP accepts (scaled units; its default is 1e-6).
PRIMAL_TOL = 1e-9
#: Active-set iterations before DAQP gives up, times the horizon N (its default is 10,000
#: iterations): 200 at N = 50, 50 at N = 200 (docs/mpc.md, "The route's constants").
ITER_BUDGET = 10_000

# DAQP's ``sense`` flags (daqp constants.h): bit 0 active, bit 1 at the lower bound. Indexed by
# side + 1 of the active sets below: −1 (lower) → 3, 0 → 0, +1 (upper) → 1.
_SENSE_OF_SIDE = np.array([3, 0, 1], dtype=np.intc)

_WARM = Guess()


class DaqpSolver:
    """A ``daqp.Model`` of one :class:`~pushrecovery.control.mpc.qp.CondensedQP`, solved each tick.

    Parameters
    ----------
    qp : CondensedQP
        The problem; its matrices are copied into the workspace once.

    Raises
    ------
    ImportError
        If ``daqp`` is missing or too old for its ``Model`` workspace API as used here.
    RuntimeError
        If DAQP rejects the problem at setup (e.g. a Hessian it cannot factorise).

    Attributes
    ----------
    qp : CondensedQP
        The problem.
    """

    def __init__(self, qp: CondensedQP) -> None:
        import daqp

        require_type("qp", qp, CondensedQP)
        if not all(hasattr(getattr(daqp, "Model", None), a) for a in ("update", "settings")):
            raise ImportError("this daqp has no Model workspace with update() and settings")
        self.qp = qp
        n, rows = qp.scale.size, qp.rows
        # Every constraint is a general two-sided row (no simple bounds on Ṽ).
        self._linear = np.zeros(n)
        self._lower = np.zeros(rows)
        self._upper = np.zeros(rows)
        self._cold = np.zeros(rows, dtype=np.intc)  # no constraint active
        self._sense = np.zeros(rows, dtype=np.intc)  # a guess's start (see solve())
        model = daqp.Model()
        # The same contiguous buffers, rewritten in place, are handed to update() each tick.
        # The matrices are this workspace's own copies: daqp takes writable buffers only, and
        # the QP's are read-only (shared by the controllers of one body and settings).
        self._hessian = np.array(qp.scaled_hessian)
        self._rows = np.array(qp.scaled_inequality)
        flag, _ = model.setup(
            self._hessian, self._linear, self._rows, self._upper, self._lower, self._cold
        )
        if flag < 0:
            raise RuntimeError(f"daqp could not set up the MPC problem (exit flag {flag})")
        limit = max(1, ITER_BUDGET // qp.settings.horizon)
        model.settings = {"primal_tol": PRIMAL_TOL, "iter_limit": limit}
        if model.settings.get("primal_tol") != PRIMAL_TOL:
            raise ImportError("this daqp Model ignores its primal_tol setting")
        self._model: Any = model
        self._warm = False

    def __reduce__(self) -> tuple[Any, ...]:
        # The C workspace cannot be pickled: rebuild it (cold) from the problem instead.
        return (type(self), (self.qp,))

    def reset(self) -> None:
        """Start the next solve cold, from an empty active set."""
        self._warm = False

    def solve(self, x0: FloatArray, guess: Guess = _WARM) -> Plan:
        """Solve the QP from state ``x0``: a SOLVED plan, or FAILED if DAQP found no solution.

        The solve starts from the last solution's active set, or ``guess.active`` (N, 3)
        (condensed rows: δ_i at 2i, τ_i at 2i + 1, θ_{i+1} at 2N + i; unshifted), meant for the
        verified set of the Riccati passes' last tick: exactly the set DAQP would have ended
        with had it solved that tick, so the solve starts as warm as if DAQP ran every tick.
        Failures are reported as by qpsolvers (any exit flag <= 0), and only once a cold solve
        has failed too, so that feasibility never depends on the previous ticks. The solve
        after a failure starts cold: the active set it left behind is no guide. The plan's
        ``active`` is the set of the signs of DAQP's multipliers (+ at an upper bound); a plan
        that is not finite is FAILED, with that set.
        """
        model = self._model
        self.qp.vectors_into(x0, self._linear, self._lower, self._upper)
        warm = self._warm or guess.active is not None
        if guess.active is not None:
            n = guess.active.shape[0]
            sides = guess.active.astype(np.intp) + 1
            self._sense[: 2 * n] = _SENSE_OF_SIDE[sides[:, :2].ravel()]
            self._sense[2 * n :] = _SENSE_OF_SIDE[sides[:, 2]]
            model.update(f=self._linear, bupper=self._upper, blower=self._lower, sense=self._sense)
        elif self._warm:
            model.update(f=self._linear, bupper=self._upper, blower=self._lower)
        else:
            self._cold.fill(0)
            model.update(f=self._linear, bupper=self._upper, blower=self._lower, sense=self._cold)
        solution, _, flag, info = model.solve()
        iterations = int(info.get("iterations", 0))
        if flag <= 0 and warm:
            self._cold.fill(0)
            model.update(sense=self._cold)
            solution, _, flag, info = model.solve()
            iterations += int(info.get("iterations", 0))
        self._warm = flag > 0
        if flag <= 0:
            return Plan.failed()
        active = self._active_set(info["lam"])
        if not np.isfinite(solution).all():
            return Plan.failed(active)
        return self.qp.plan(x0, solution.copy(), active, iterations)

    @staticmethod
    def _active_set(lam: FloatArray) -> NDArray[np.int8]:
        """Return the rows' active set as (N, 3) rows (δ_i, τ_i, θ_{i+1}), ±1 at a bound."""
        n = lam.size // 3
        active = np.zeros((n, 3), dtype=np.int8)
        active[:, :2] = np.sign(lam[: 2 * n]).reshape(n, 2)
        active[:, 2] = np.sign(lam[2 * n :])
        return active
