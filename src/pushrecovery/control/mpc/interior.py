r"""Eq. (17) with the states kept, solved by a primal-dual interior point with Riccati steps.

The sparse form of :mod:`~pushrecovery.control.mpc.riccati` (inputs u_i and states x_{i+1},
dynamics as equalities, three bounded components per stage: δ_i, τ_i, θ_{i+1}), solved by
Mehrotra's predictor-corrector method (Nocedal & Wright 2006, Alg. 16.4) from a cold start.
Every bound is a bound on one variable, so eliminating the slacks and the bounds' multipliers
leaves, at each Newton step, an equality-constrained LQ problem with diagonal weights
2W + Σ (Σ = z/s on the bounded components): a Riccati recursion solves it in O(N) with 4 × 4
and 2 × 2 algebra (Rao, Wright & Rawlings 1998), and the corrector reuses the predictor's
factors. A pure state bound (θ_{i+1} at its limit while τ_i is at its own), which the
active-set passes cannot represent, is for it a diagonal weight like any other.

Its place in the controller: the passes of :class:`~.riccati.RiccatiSolver` solve most ticks in
a few µs from the previous tick's active set; a tick they do not verify (a push's first tick,
an active set far from the last, a degenerate stage) goes here, 10-25 iterations of 8 µs
each at N = 50 whatever the start, no Hessian ever formed (its conditioning does not grow with
N, as the condensed QP's does). The solution's active set (a bound whose multiplier exceeds
its slack in the units below) then seeds the passes, which verify the KKT conditions exactly;
if they cannot (a degenerate stage), the interior point's own solution stands, converged to
:data:`TOL` of every scale.

Scales. A bound's multiplier z is measured against H_jj × range_j, the multiplier that would
move an unconstrained input by its whole range (H = 2 W^u_i + B^T S_{i+1} B, S the
unconstrained problem's cost-to-go); the θ bound's against the torque's divided by abs(B_θτ)
(θ moves by B_θτ τ), and a state's stationarity row against the inputs' scales divided by the
entries of B that carry it. Convergence: every bound's residual and complementarity product below
:data:`TOL` of its scale (× the range for products), every stationarity row below
:data:`DUAL_TOL` of its own. Measured against DAQP on the condensed QP
(``tests/test_mpc_interior.py``): first inputs equal to better than 1e-7 of their ranges.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import positive_float
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.control.mpc.riccati import check_structure, sparse_stages
from pushrecovery.errors import InvalidParameterError
from pushrecovery.kernels.mpc.interior import (
    COLD,
    CONVERGED,
    DIVERGED,
    EXHAUSTED,
    GUIDE_CENTRE,
    GUIDE_FLOOR,
    WARM,
    identify_active,
    solve_interior,
)
from pushrecovery.kernels.mpc.scales import dual_scales
from pushrecovery.params import BodyParams

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
#: Looser tolerance at which a verifier is first offered the active set (see solve()): the
#: benchmark's interior-point ticks took 12.3 iterations on average and 16 at most at 1e-6,
#: 11.2 and 15 at 1e-4; at 1e-3 some sets failed to verify and the worst took 20.
IDENTIFY_TOL = 1e-4
#: Before that, the set is offered once as soon as it has settled: within SETTLE_ROWS rows of
#: the previous iterate's, every complementarity product within SETTLE_TOL of its scale ×
#: range (a failed offer costs up to POLISH_PASSES passes, ~1.5 iterations). Iterations of the
#: interior-point ticks of the torso's 3 s run (MuJoCo, N = 50) and of the flywheel
#: benchmark's five pushes (N = 50 | N = 200), and the Riccati solves (offers included): only
#: at IDENTIFY_TOL 152, 1380 | 4439 (solves 765 at N = 50); 0 rows and 1e-2 141, 1309 | 4357;
#: 2 and 1e-2 139, 1266 | 4340; 2 and 1e-1 135, 1243 | 4314 (solves 778); 8 and 1e-1 133,
#: 1237 | 4302 (785); 4 and 1 135, 1235 | 4316 (793). The verified sets are the same: the
#: plans are bit for bit those verified at IDENTIFY_TOL.
SETTLE_ROWS = 2
SETTLE_TOL = 1e-1


class InteriorPointSolver:
    """The sparse Eq. (17) of one body and settings, solved by an interior point each call.

    Parameters
    ----------
    params : BodyParams
        Body parameters (bounds δ⁻ = heel, δ⁺ = toe, τmax, θmax; all with a range).
    settings : MPCSettings
        dt, N, Q, R and γ.
    guide_floor, guide_centre : float
        A warm start's rows in the last verified set (see :meth:`solve`) start with their slack
        at most ``guide_floor`` × the range, in (0, 1], and the product s z at
        ``guide_centre`` × dual scale × range, > 0.

    Raises
    ------
    InvalidParameterError
        If ``guide_floor`` or ``guide_centre`` is out of its range.

    Attributes
    ----------
    inputs : ndarray, shape (N, 2)
        (δ [m], τ [N m]) of the last converged solve (fresh arrays each solve).
    states : ndarray, shape (N + 1, 4)
        Its predicted states X_0..X_N, ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s].
    iterations : int
        Iterations of the last solve (−1: did not converge in :data:`MAX_ITERATIONS`).
    verified : bool
        Whether the last solve ended with the verifier's acceptance (see :meth:`solve`).
    """

    def __init__(
        self,
        params: BodyParams,
        settings: MPCSettings,
        *,
        guide_floor: float = GUIDE_FLOOR,
        guide_centre: float = GUIDE_CENTRE,
    ) -> None:
        self.a, self.b, self.wx, self.wu, self.bounds = sparse_stages(params, settings)  # checked
        self.guide_floor = positive_float("guide_floor", guide_floor)
        if self.guide_floor > 1.0:
            raise InvalidParameterError(f"guide_floor must be in (0, 1], got {guide_floor!r}")
        self.guide_centre = positive_float("guide_centre", guide_centre)
        check_structure(self.a, self.b)  # the zeros the kernels skip
        n = settings.horizon
        self.scales, self.feedback = np.empty((n, 7)), np.empty((n, 2, 4))
        dual_scales(self.a, self.b, self.wx, self.wu, self.bounds, self.scales, self.feedback)
        self.inputs = np.zeros((n, 2))
        self.states = np.zeros((n + 1, 4))
        self.iterations = 0
        self.verified = False
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
        identify_active(self.bounds, self.scales, *self._slacks, *self._bound_multipliers,
                        self._active)  # fmt: skip

    def _iterate(
        self, x0: FloatArray, iterations: int, start: int, loose: bool = False, settle: int = -1
    ) -> tuple[int, int]:
        """Run at most ``iterations`` of the kernel (``start``: COLD, WARM or 0).

        Returns its status and the iterations run. ``loose``: converged at :data:`IDENTIFY_TOL`
        (enough to identify the active set); ``settle`` >= 0: or stopped where the active set
        has settled (within ``settle`` rows and :data:`SETTLE_TOL`).
        """
        tol, dual_tol = (IDENTIFY_TOL, IDENTIFY_TOL) if loose else (TOL, DUAL_TOL)
        status, count = solve_interior(
            x0, self.a, self.b, self.wx, self.wu, self.bounds, self.scales, self.feedback,
            tol, dual_tol, iterations, start, self._guide, self._u, self._x, self._multipliers,
            *self._slacks, *self._bound_multipliers, self._work, *self._factors, self._active,
            SETTLE_TOL, settle, self.guide_floor, self.guide_centre,
        )  # fmt: skip
        return int(status), int(count)

    def solve(
        self,
        x0: FloatArray,
        verify: Callable[[NDArray[np.int8]], bool] | None = None,
        warm: FloatArray | None = None,
        guide: NDArray[np.int8] | None = None,
    ) -> bool:
        """Solve from ``x0`` = [x, θ, ẋ, θ̇]; True if solved (see the attributes).

        ``warm``: the last tick's plan, inputs (N, 2), to start from shifted by one stage
        (else the cold start), and ``guide`` (N, 3) the last verified active set (unshifted),
        whose rows it starts near their bounds. ``verify``, if given, is offered the iterate's
        active set (:meth:`active_set`) once it has settled (:data:`SETTLE_ROWS`), and if that
        one fails, once converged to :data:`IDENTIFY_TOL`: if it returns True (e.g. Riccati
        passes from that set verified the KKT conditions exactly), the solve stops there,
        ``verified`` is True and the solution is the verifier's; the attributes ``inputs`` and
        ``states`` are then not updated. Else it goes on to :data:`TOL`.
        """
        start = COLD
        if warm is not None:
            self._u[:-1] = warm[1:]
            self._u[-1] = warm[-1]
            start = WARM
        if guide is not None:
            self._guide[...] = guide
        else:
            self._guide.fill(0)
        self.verified = False
        done, settle = 0, SETTLE_ROWS
        while verify is not None and done < MAX_ITERATIONS:
            # The settled set first (one offer), then the loosely converged one: verified, the
            # solve ends there.
            status, count = self._iterate(x0, MAX_ITERATIONS - done, start, True, settle)
            start, done = 0, done + count
            if status == DIVERGED:
                self.iterations = -1
                return False
            if status == EXHAUSTED:
                break
            # Converged without an iteration since a settled set failed: the same set.
            repeated = status == CONVERGED and count == 0 and settle < 0
            if not repeated and verify(self._active):
                self.iterations, self.verified = done, True
                return True
            if status == CONVERGED:
                break
            settle = -1  # settled, not verified: on to IDENTIFY_TOL
        status, count = (
            (EXHAUSTED, 0)
            if done >= MAX_ITERATIONS
            else self._iterate(x0, MAX_ITERATIONS - done, start)
        )
        if status == CONVERGED:
            self.iterations = done + count
            self.inputs, self.states = self._u.copy(), self._x.copy()
            return True
        self.iterations = -1
        return False

    def active_set(self) -> NDArray[np.int8]:
        """Return the last iterate's active set, (N, 3) rows (δ_i, τ_i, θ_{i+1}), ±1 at a bound.

        A bound is active when its multiplier, in units of its dual scale, exceeds its slack
        in units of its range: at the interior point's solution the two are 1e-10 apart.
        """
        active = np.zeros_like(self._active)
        identify_active(self.bounds, self.scales, *self._slacks, *self._bound_multipliers,
                        active)  # fmt: skip
        return active
