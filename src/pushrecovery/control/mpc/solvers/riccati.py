r"""Eq. (17) with the states kept, solved exactly by a warm-started active set and Riccati passes.

The sparse form of Eq. (17): variables u_0..u_{N−1} and x_1..x_N, the dynamics
x_{i+1} = A x_i + B u_i as equalities, and per stage three inequality rows: δ⁻ ≤ δ_i ≤ δ⁺,
abs(τ_i) ≤ τmax and abs(θ_{i+1}) ≤ θmax. For a fixed set of rows held at their bounds, the
minimiser is that of an equality-constrained LQ problem: a backward Riccati recursion and a
forward pass give it in O(N) with 2 × 2 and 4 × 4 algebra, and a backward pass of the costates

.. math::

    λ_{i+1} = 2 W^x_i x_{i+1} + A^T λ_{i+2} + ν_{i+1} e_θ, \qquad
    2 W^u_i u_i + B^T λ_{i+1} + μ_i = 0

gives the multipliers μ (input rows) and ν (θ rows) of the active rows. The point is Eq. (17)'s
(unique) minimiser exactly when the inactive rows hold (to :data:`PRIMAL_TOL` of each range)
and every multiplier has the right sign (to :data:`DUAL_TOL` of the displacement it would
cause, μ_j / H_jj against the range of input j, H = W^u_i + B^T S_{i+1} B).

The active set is found by primal–dual active-set passes (Hintermüller, Ito & Kunisch 2002),
started from the last tick's set shifted by a stage; docs/mpc.md, "How a tick is solved",
gives the pass budgets, the state rows carried back (derived in
:mod:`pushrecovery.kernels.mpc.riccati`), the braking held on the viable set's boundary and
what the route (:mod:`~pushrecovery.control.mpc.solvers.route`) does when the passes do not
verify an optimum. Everything here depends on the body (through A, B, the bounds) and the
settings only, and costs about 0.1 ms to set up.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.mpc.plan import Plan, Status
from pushrecovery.control.mpc.problem import SparseQP
from pushrecovery.control.mpc.solvers.base import Guess
from pushrecovery.kernels.mpc.riccati import scratch, solve_from
from pushrecovery.params import BodyParams

__all__ = [
    "DUAL_TOL", "EMPTY_PASSES", "MAX_PASSES", "POLISH_PASSES", "PRIMAL_TOL", "RiccatiSolver",
]  # fmt: skip

FloatArray = NDArray[np.float64]

#: Largest violation of an inactive row, as a fraction of its range (δ⁺ − δ⁻, 2 τmax, 2 θmax).
PRIMAL_TOL = 1e-9
#: Largest wrong-sign multiplier, as the displacement it stands for over the input's range.
DUAL_TOL = 1e-9
#: Passes from the warm start before giving up on a tick (the route then takes the interior
#: point); docs/mpc.md, "The route's constants".
MAX_PASSES = 15
#: At most this many from the empty set: its solves verify in one pass (the unconstrained
#: optimum) or almost never (docs/mpc.md, "The route's constants").
EMPTY_PASSES = 5
#: Passes allowed to verify a set another solver hands over: an interior-point iterate's, or
#: on the viable set's boundary the last tick's with full braking held.
POLISH_PASSES = 3

_WARM = Guess()
_VERIFIED = Status.VERIFIED  # a module global: an enum member through its class costs ~0.1 µs


class RiccatiSolver:
    """The sparse Eq. (17) of one body and settings, solved from a state each tick.

    Parameters
    ----------
    problem : SparseQP
        The stages, bounds δ⁻ = heel, δ⁺ = toe, τmax and θmax each with a range
        (:meth:`applies`).

    Attributes
    ----------
    problem : SparseQP
        The problem.
    active : ndarray of int8, shape (N, 3)
        The set the next solve starts from: rows (δ_i, τ_i, θ_{i+1}), −1 at the lower bound,
        +1 at the upper. After a verified solve its active set; after a failed one the set
        that solve started from (unshifted): the last verified set or a seed, which the route
        may hand to DAQP.
    verified : bool
        Whether the last solve verified its optimum (``active`` is then its active set).
    multipliers : ndarray, shape (N, 3)
        The multipliers of the rows of the last verified solve.
    """

    def __init__(self, problem: SparseQP) -> None:
        require_type("problem", problem, SparseQP)
        self.problem = problem
        n = problem.horizon
        bounds = problem.bounds
        self.tols = PRIMAL_TOL * (bounds[:, 1] - bounds[:, 0])
        self.active = np.zeros((n, 3), dtype=np.int8)
        self._guess = np.zeros((n, 3), dtype=np.int8)
        self.multipliers = np.zeros((n, 3))
        self.verified = False
        # The kernel's arguments, bound once (a tick makes one call).
        self._args = (
            self.active, self._guess, problem.a, problem.b, problem.wx, problem.wu, bounds,
            self.tols, DUAL_TOL, EMPTY_PASSES,
        )  # fmt: skip
        # The recursion's arrays, the passes' scratch and the record of which active set the
        # recursion was last run on (its numbers are reused while the set stays: a steady
        # state's empty set), kept from solve to solve.
        self._swept = np.zeros((n + 1, 3), dtype=np.int8)
        self._scratch = (np.zeros((n, 2, 4)), np.zeros((n, 2)), np.zeros((n, 2)),
                         self.multipliers, *scratch(n), self._swept)  # fmt: skip
        self._shapes = ((n, 2), (n + 1, 4))
        # Load the compiled kernel now (from numba's disk cache), not on a control tick.
        self.solve(np.zeros(4), Guess(budget=0))
        self.verified = False

    @staticmethod
    def applies(params: BodyParams) -> bool:
        """Tell whether every bound has a range (not τmax = 0): the multipliers' scale needs it."""
        return params.heel < params.toe and params.torque_max > 0 and params.flywheel_angle_max > 0

    def reset(self) -> None:
        """Start the next solve from the empty active set."""
        self.active.fill(0)
        self.verified = False

    def seed(self, active: NDArray[np.int8]) -> None:
        """Start the next solve from ``active`` (N, 3), e.g. the active set DAQP found."""
        self.active[...] = active
        self.verified = False

    def solve(self, x0: FloatArray, guess: Guess = _WARM) -> Plan:
        """Solve from ``x0`` = [x, θ, ẋ, θ̇]; VERIFIED if the KKT conditions hold, else FAILED.

        The passes start from ``guess.active`` (which becomes :attr:`active`, as by
        :meth:`seed`) or from :attr:`active`, shifted by one stage if ``guess.shift`` (the
        receding horizon's guess; the last stage keeps its rows); at most ``guess.budget``
        (default :data:`MAX_PASSES`). ``guess.forced`` = (k, side): the torques of the first k
        stages are held at the bound of sign ``side`` and their θ rows left out. The plan's
        ``iterations`` are the passes. On failure :attr:`active` is left as it was and the
        next solve starts from it again unless :meth:`seed` or :meth:`reset` is called.
        """
        if guess.active is not None:
            self.seed(guess.active)
        budget = MAX_PASSES if guess.budget is None else guess.budget
        # Fresh output arrays each solve: a verified plan keeps them as they are.
        inputs_shape, states_shape = self._shapes
        inputs, states = np.empty(inputs_shape), np.empty(states_shape)
        passes = solve_from(
            x0, guess.shift, *self._args, budget, *guess.forced, inputs, states, *self._scratch
        )
        if passes < 0:
            self.verified = False
            return Plan.failed()
        self.verified = True
        return Plan(_VERIFIED, inputs[0], inputs, states, self.active.copy(), passes)
