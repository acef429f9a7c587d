"""Eq. (17) with the states kept, solved by a primal-dual interior point with Riccati steps.

The sparse form (:class:`~pushrecovery.control.mpc.problem.SparseQP`: inputs u_i and states
x_{i+1}, dynamics as equalities, three bounded components per stage: δ_i, τ_i, θ_{i+1}), solved
by Mehrotra's predictor-corrector method (Nocedal & Wright 2006, Alg. 16.4). Every bound is a
bound on one variable, so each Newton step is an equality-constrained LQ problem with diagonal
weights 2W + z/s: a Riccati recursion solves it in O(N) (Rao, Wright & Rawlings 1998), and the
corrector reuses the predictor's factors. A pure state bound (θ_{i+1} at its limit while τ_i is
at its own) is for it a diagonal weight like any other.

In the route (:mod:`~pushrecovery.control.mpc.solvers.route`; docs/mpc.md, "How a tick is
solved") it takes the ticks the warm Riccati passes do not verify, and offers its active set
to the passes (``polish``); if they cannot verify it, its own solution stands, converged to
:data:`TOL` of every scale. Scales: a bound's multiplier z is measured against H_jj × range_j
(H = 2 W^u_i + B^T S_{i+1} B, S the unconstrained problem's cost-to-go), the θ bound's against
the torque's divided by abs(B_θτ), and a state's stationarity row against the inputs' scales
divided by the entries of B that carry it; converged when every residual and complementarity
product is below :data:`TOL` of its scale and every stationarity row below :data:`DUAL_TOL`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import positive_float, require_type
from pushrecovery.control.mpc.plan import Plan, Status
from pushrecovery.control.mpc.problem import SparseQP
from pushrecovery.control.mpc.solvers.base import Guess, Solver
from pushrecovery.control.mpc.solvers.riccati import POLISH_PASSES
from pushrecovery.errors import ParameterTypeError
from pushrecovery.kernels.mpc.interior import (
    COLD,
    CONVERGED,
    DIVERGED,
    EXHAUSTED,
    GUIDE_CENTRE,
    WARM,
    identify_active,
    shift_iterate,
    solve_interior,
)
from pushrecovery.kernels.mpc.scales import dual_scales

__all__ = [
    "DUAL_TOL",
    "IDENTIFY_TOL",
    "MAX_ITERATIONS",
    "SETTLE_ROWS",
    "SETTLE_TOL",
    "TOL",
    "InteriorPointSolver",
]

FloatArray = NDArray[np.float64]

#: Convergence tolerance of the bounds and complementarity, relative to their scales.
TOL = 1e-10
#: Convergence tolerance of the stationarity rows, relative to their scales: their rounding
#: floor is a few 1e-10 (the costates grow backward along the horizon as e^{ω t}).
DUAL_TOL = 1e-8
#: Iterations before giving up (an infeasible problem; well-posed ones take 10-30).
MAX_ITERATIONS = 100
#: Looser tolerance at which the polish is offered the active set (see solve()); docs/mpc.md,
#: "The route's constants".
IDENTIFY_TOL = 1e-4
#: Before that, the set is offered once as soon as it has settled: within SETTLE_ROWS rows of
#: the previous iterate's, every complementarity product within SETTLE_TOL of its scale ×
#: range (docs/mpc.md, "The route's constants").
SETTLE_ROWS = 2
SETTLE_TOL = 1e-1

_COLD = Guess()


class InteriorPointSolver:
    """The sparse Eq. (17) of one body and settings, solved by an interior point each call.

    Parameters
    ----------
    problem : SparseQP
        The stages, bounds δ⁻ = heel, δ⁺ = toe, τmax and θmax each with a range.
    polish : Solver, optional
        Offered the iterate's active set (this tick's, unshifted, with the guess's ``forced``
        braking) once it has settled and once converged to :data:`IDENTIFY_TOL`, at most
        :data:`~pushrecovery.control.mpc.solvers.riccati.POLISH_PASSES` passes: the Riccati
        passes, whose VERIFIED plan then ends the solve. None: the interior point's own.
    guide_centre : float
        A warm start's rows in the guess's active set start with the product s z at this ×
        dual scale × range, > 0.

    Raises
    ------
    InvalidParameterError
        If ``guide_centre`` is not > 0.

    Attributes
    ----------
    problem : SparseQP
        The problem.
    scales : ndarray, shape (N, 7)
        Each stage's dual scales (see the module docstring).
    feedback : ndarray, shape (N, 2, 4)
        The unconstrained problem's time-varying gain (its cold start).
    iterations : int
        Iterations of the last solve (−1: did not converge in :data:`MAX_ITERATIONS`).
    resumable : bool
        Whether the last solve ran out of its budget with a finite iterate, which the next
        solve may continue (``Guess.resume``).
    """

    def __init__(
        self,
        problem: SparseQP,
        *,
        polish: Solver | None = None,
        guide_centre: float = GUIDE_CENTRE,
    ) -> None:
        require_type("problem", problem, SparseQP)
        if polish is not None and not callable(getattr(polish, "solve", None)):
            raise ParameterTypeError(f"polish must be a solver, got {type(polish).__name__}")
        self.problem = problem
        self.polish = polish
        self.guide_centre = positive_float("guide_centre", guide_centre)
        n = problem.horizon
        self.scales, self.feedback = np.empty((n, 7)), np.empty((n, 2, 4))
        dual_scales(problem.a, problem.b, problem.wx, problem.wu, problem.bounds, self.scales,
                    self.feedback)  # fmt: skip
        self.iterations = 0
        self.resumable = False
        self._u, self._x = np.zeros((n, 2)), np.zeros((n + 1, 4))  # the iterate
        # Iterates and scratch, allocated once.
        self._multipliers = np.zeros((n, 4))
        self._slacks = (np.zeros((n, 3)), np.zeros((n, 3)))
        self._bound_multipliers = (np.zeros((n, 3)), np.zeros((n, 3)))
        self._work = np.zeros((17, n + 1, 4))
        # The Newton steps' factors: S, K, H⁻¹, s, S B and A_K per stage.
        self._factors = (
            np.zeros((n + 1, 4, 4)), np.zeros((n, 2, 4)), np.zeros((n, 2, 2)),
            np.zeros((n + 1, 4)), np.zeros((n, 4, 2)), np.zeros((n, 4, 4)),
        )  # fmt: skip
        # Load the compiled kernel now (from numba's disk cache), not on a control tick.
        self._active = np.zeros((n, 3), dtype=np.int8)
        self._guide = np.zeros((n, 3), dtype=np.int8)
        self._iterate(np.zeros(4), 0, COLD)
        identify_active(problem.bounds, self.scales, *self._slacks, *self._bound_multipliers,
                        self._active)  # fmt: skip
        shift_iterate(np.zeros(4), problem.a, problem.b, self.feedback, self._u, self._x,
                      self._multipliers, *self._slacks, *self._bound_multipliers)  # fmt: skip

    def iterate_inputs(self) -> FloatArray:
        """Return a copy of the current iterate's inputs (δ [m], τ [N m]), shape (N, 2).

        After an unfinished solve (:attr:`resumable`) not a solution: within the bounds only
        to the iterate's slack residuals.
        """
        return self._u.copy()

    def reset(self) -> None:
        """Do nothing: each solve starts from its guess (the interior point keeps no start)."""

    def _iterate(
        self, x0: FloatArray, iterations: int, start: int, loose: bool = False, settle: int = -1
    ) -> tuple[int, int]:
        """Run at most ``iterations`` of the kernel (``start``: COLD, WARM or 0).

        Returns its status and the iterations run. ``loose``: converged at :data:`IDENTIFY_TOL`
        (enough to identify the active set); ``settle`` >= 0: or stopped where the active set
        has settled (within ``settle`` rows and :data:`SETTLE_TOL`).
        """
        p = self.problem
        tol, dual_tol = (IDENTIFY_TOL, IDENTIFY_TOL) if loose else (TOL, DUAL_TOL)
        status, count = solve_interior(
            x0, p.a, p.b, p.wx, p.wu, p.bounds, self.scales, self.feedback,
            tol, dual_tol, iterations, start, self._guide, self._u, self._x, self._multipliers,
            *self._slacks, *self._bound_multipliers, self._work, *self._factors, self._active,
            SETTLE_TOL, settle, self.guide_centre,
        )  # fmt: skip
        return int(status), int(count)

    def solve(self, x0: FloatArray, guess: Guess = _COLD) -> Plan:
        """Solve from ``x0`` = [x, θ, ẋ, θ̇]: a VERIFIED, CONVERGED or FAILED plan.

        ``guess.inputs``: the last tick's plan, to start from shifted by one stage (else the
        cold start), and ``guess.active`` the last verified active set (unshifted), whose rows
        that warm start puts near their bounds. With a ``polish`` solver, the iterate's active
        set is offered to it once it has settled (:data:`SETTLE_ROWS`), and if that one fails,
        once converged to :data:`IDENTIFY_TOL`: its VERIFIED plan ends the solve. Else the
        iterations go on to :data:`TOL` and the plan is the interior point's own (CONVERGED).
        ``guess.resume``: continue the last solve's iterate (if :attr:`resumable`) shifted by
        one stage, instead of a start from ``guess.inputs``. At most ``guess.budget``
        iterations in all (default :data:`MAX_ITERATIONS`), FAILED beyond; each offer costs
        at most :data:`~pushrecovery.control.mpc.solvers.riccati.POLISH_PASSES` passes.
        """
        start = COLD
        if guess.resume and self.resumable:
            shift_iterate(x0, self.problem.a, self.problem.b, self.feedback, self._u, self._x,
                          self._multipliers, *self._slacks, *self._bound_multipliers)  # fmt: skip
            start = 0
        elif guess.inputs is not None:
            self._u[:-1] = guess.inputs[1:]
            self._u[-1] = guess.inputs[-1]
            start = WARM
        if guess.active is not None:
            self._guide[...] = guess.active
        else:
            self._guide.fill(0)
        limit = MAX_ITERATIONS if guess.budget is None else min(guess.budget, MAX_ITERATIONS)
        self.resumable = False
        polish = self.polish
        done, settle = 0, SETTLE_ROWS
        while polish is not None and done < limit:
            # The settled set first (one offer), then the loosely converged one: verified, the
            # solve ends there.
            status, count = self._iterate(x0, limit - done, start, True, settle)
            start, done = 0, done + count
            if status == DIVERGED:
                self.iterations = -1
                return Plan.failed()
            if status == EXHAUSTED:
                break
            # Converged without an iteration since a settled set failed: the same set.
            repeated = status == CONVERGED and count == 0 and settle < 0
            if not repeated:
                offer = Guess(self._active, False, None, guess.forced, POLISH_PASSES)
                plan = polish.solve(x0, offer)
                if plan.status is Status.VERIFIED:
                    self.iterations = done
                    return plan
            if status == CONVERGED:
                break
            settle = -1  # settled, not verified: on to IDENTIFY_TOL
        status, count = (EXHAUSTED, 0) if done >= limit else self._iterate(x0, limit - done, start)
        if status == CONVERGED:
            self.iterations = done + count
            inputs, states = self._u.copy(), self._x.copy()
            active = self._active.copy()
            return Plan(Status.CONVERGED, inputs[0], inputs, states, active, self.iterations)
        self.iterations = -1
        self.resumable = status == EXHAUSTED
        return Plan.failed()
