r"""Eq. (17) with the states kept, solved exactly by a warm-started active set and Riccati passes.

The sparse form of Eq. (17): variables u_0..u_{N−1} and x_1..x_N, the dynamics
x_{i+1} = A x_i + B u_i as equalities, and per stage three inequality rows: δ⁻ ≤ δ_i ≤ δ⁺,
abs(τ_i) ≤ τmax and abs(θ_{i+1}) ≤ θmax (θ_{i+1} = A_θ x_i + B_θ u_i, a row of stage i). For a fixed
set of rows held at their bounds, the minimiser is that of an equality-constrained LQ problem:
a backward Riccati recursion (per stage, the inputs are split into the part the active rows fix,
an affine function of x_i, and a free part minimised in closed form) and a forward pass give
it in O(N) with 2 × 2 and 4 × 4 algebra, without ever forming the N-sized Hessian. A backward
pass of the costates

.. math::

    λ_{i+1} = 2 W^x_i x_{i+1} + A^T λ_{i+2} + ν_{i+1} e_θ, \qquad
    2 W^u_i u_i + B^T λ_{i+1} + μ_i = 0

gives the multipliers μ (input rows) and ν (θ rows) of the active rows. The point is Eq. (17)'s
minimiser exactly when the KKT conditions hold: the inactive rows within their bounds (to
:data:`PRIMAL_TOL` of each range) and every multiplier of the right sign (to
:data:`DUAL_TOL` of the displacement it would cause, μ_j / H_jj against the range of input j,
with H the stage's input Hessian W^u_i + B^T S_{i+1} B). The QP is strictly convex, so that
point is unique.

The active set is found by primal–dual active-set passes (Hintermüller, Ito & Kunisch 2002):
each pass releases the rows whose multipliers have the wrong sign and adds the violated ones.
A receding horizon makes this cheap: the next tick's active set is nearly the previous one
shifted by a stage, which is where the passes start (two or three passes per tick in a pushed
run). There is no Hessian to condition: the Riccati recursion is the numerically stable way to
solve an LQ problem at any horizon, and its cost grows linearly with N.

A stage where τ_i and θ_{i+1} are both at a bound makes the θ row a pure state constraint:
it is carried back through the stages whose torques are held to the latest one whose torque is
free (the derivation is in the kernel's docstring). On the boundary of the flywheel's viable
set the caller may hold the first stages' torques at full braking (``forced``, the only plans
there) instead. When the passes do not verify an optimum (cycling, an infeasible QP, too many
passes) the caller solves the tick by the interior point
(:mod:`~pushrecovery.control.mpc.interior`), whose active set the passes then verify, or near
the viable set's boundary by DAQP on the condensed QP, and may :meth:`RiccatiSolver.seed` the
next tick with its active set. Everything here depends on the body (through A, B, the bounds)
and the settings only, and costs about 0.1 ms to set up.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.kernels.mpc.riccati import scratch, solve_from
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.params import BodyParams

__all__ = ["DUAL_TOL", "MAX_PASSES", "PRIMAL_TOL", "RiccatiSolver", "sparse_stages"]

FloatArray = NDArray[np.float64]

#: Largest violation of an inactive row, as a fraction of its range (δ⁺ − δ⁻, 2 τmax, 2 θmax).
PRIMAL_TOL = 1e-9
#: Largest wrong-sign multiplier, as the displacement it stands for over the input's range.
DUAL_TOL = 1e-9
#: Passes from the warm start before giving up on a tick (the caller then solves it by the
#: interior point). A pass costs 6-9 µs at N = 50 and a verified warm start takes one or two;
#: the others mostly need many more (a median of 25: the violated rows added at once overshoot
#: and the wrong-sign rows are released one per pass), a few cycle. Measured after the interior
#: point's iteration fell to 8 µs (quiet machine, best of 7): on the MuJoCo torso's 3 s run
#: (150 ticks) 6 passes gave 27 interior-point ticks and 5.7 ms of MPC, 10 gave 5.0 ms, 15
#: gave 4.7 ms (11 ticks), 20 gave 4.9 ms and 30 gave 5.2 ms; the flywheel benchmark's median,
#: p99 and largest tick at N = 50, 100 and 200 were the same within 5 % for 6 and 15.
MAX_PASSES = 15
#: At most this many from the empty set: its solves verify in one pass (the unconstrained
#: optimum) or need the whole active set built, which the passes rarely manage. MuJoCo torso
#: pushes of ±20-50 N s and flywheel pushes of −0.5 to 0.7 m/s at N = 50, 100, 200: of 1,612
#: solves from the empty set with 15 passes allowed, 1,566 verified in one pass, 3 in five and
#: 43 failed (each after 15 passes, ~60 µs, before the interior point).
EMPTY_PASSES = 5


def sparse_stages(
    params: BodyParams, settings: MPCSettings
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Return the sparse Eq. (17)'s stages: A, B, the weights and the bounds.

    A, B of x_{i+1} = A x_i + B u_i (:func:`~pushrecovery.models.flywheel.flywheel_discrete`);
    ``wx``, ``wu`` (N, 4) and (N, 2), stage i's weights γ^(N−1−i) Q of x_{i+1} and
    γ^(N−1−i) R of u_i; ``bounds`` (3, 2), the (lower, upper) bounds of δ [m], τ [N m] and
    θ [rad].

    Raises
    ------
    InvalidParameterError
        If ``params`` is not a BodyParams or ``settings`` not an MPCSettings.
    """
    require_type("params", params, BodyParams)
    require_type("settings", settings, MPCSettings)
    n = settings.horizon
    a, b = flywheel_discrete(params, settings.dt)
    stage = settings.gamma ** (n - 1 - np.arange(n))  # γ^(N−i) of x_i and u_{i−1}, i = 1..N
    wx = np.ascontiguousarray(stage[:, None] * np.asarray(settings.state_weights))
    wu = np.ascontiguousarray(stage[:, None] * np.asarray(settings.input_weights))
    theta_max = params.flywheel_angle_max
    bounds = np.array(
        [[params.heel, params.toe], [-params.torque_max, params.torque_max],
         [-theta_max, theta_max]]
    )  # fmt: skip
    return a, b, wx, wu, bounds


def check_structure(a: FloatArray, b: FloatArray) -> None:
    """Raise ValueError unless A, B have the zeros the sparse solvers' kernels skip.

    The flywheel's exact discretisation leaves (x, ẋ) and (θ, θ̇) decoupled in A and the CoP's
    column of B zero on θ, θ̇; the kernels (``kernels.mpc.riccati``, ``kernels.mpc.interior``) leave
    those products out. A model without these zeros is a bug here, not a user's input.
    """
    com, wheel = np.ix_([0, 2], [1, 3]), np.ix_([1, 3], [0, 2])
    if np.any(a[com]) or np.any(a[wheel]) or np.any(b[[1, 3], 0]):
        raise ValueError(
            "the sparse MPC solvers' kernels need A block-diagonal in (x, xdot), (theta, "
            "theta_dot) and B's CoP column zero on theta, theta_dot (the flywheel model's "
            f"discretisation); got A = {a.tolist()}, B = {b.tolist()}"
        )


class RiccatiSolver:
    """The sparse Eq. (17) of one body and settings, solved from a state each tick.

    Parameters
    ----------
    params : BodyParams
        Body parameters (bounds δ⁻ = heel, δ⁺ = toe, τmax, θmax).
    settings : MPCSettings
        dt, N, Q, R and γ.

    Raises
    ------
    ValueError
        If A, B lack the flywheel's zeros the kernels skip
        (:func:`check_structure`).

    Attributes
    ----------
    inputs : ndarray, shape (N, 2)
        (δ [m], τ [N m]) of the last verified solve.
    states : ndarray, shape (N + 1, 4)
        Its predicted states X_0..X_N, ``[x, θ, ẋ, θ̇]`` [m, rad, m/s, rad/s].
    active : ndarray of int8, shape (N, 3)
        Its active set: rows (δ_i, τ_i, θ_{i+1}), −1 at the lower bound, +1 at the upper.
    passes : int
        Passes of the last solve (−1: not verified).
    verified : bool
        Whether the last solve verified its optimum (``active`` is then its active set).
        After a failed solve ``active`` still holds the set the solve started from (shifted
        back): the last verified set or a seed, which the caller may hand to DAQP.
    """

    def __init__(self, params: BodyParams, settings: MPCSettings) -> None:
        self.a, self.b, self.wx, self.wu, self.bounds = sparse_stages(params, settings)  # checked
        check_structure(self.a, self.b)  # the zeros the kernels skip
        n = settings.horizon
        self.tols = PRIMAL_TOL * (self.bounds[:, 1] - self.bounds[:, 0])
        self.active = np.zeros((n, 3), dtype=np.int8)
        self._guess = np.zeros((n, 3), dtype=np.int8)
        self.inputs = np.zeros((n, 2))
        self.states = np.zeros((n + 1, 4))
        self.multipliers = np.zeros((n, 3))
        self._gains = np.zeros((n, 2, 4))
        self._offsets = np.zeros((n, 2))
        self._curvature = np.zeros((n, 2))
        self.passes = 0
        self.verified = False
        # The kernel's arguments, bound once (a tick makes one call).
        self._args = (
            self.active, self._guess, self.a, self.b, self.wx, self.wu, self.bounds, self.tols,
            DUAL_TOL, EMPTY_PASSES,
        )  # fmt: skip
        # The recursion's arrays, the passes' scratch and the record of which active set the
        # recursion was last run on (its numbers are reused while the set stays: a steady
        # state's empty set), kept from solve to solve.
        self._swept = np.zeros((n + 1, 3), dtype=np.int8)
        self._scratch = (self._gains, self._offsets, self._curvature, self.multipliers,
                         *scratch(n), self._swept)  # fmt: skip
        self._shapes = (self.inputs.shape, self.states.shape)
        # Load the compiled kernel now (from numba's disk cache), not on a control tick.
        self.solve(np.zeros(4), max_passes=0)
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

    def solve(
        self,
        x0: FloatArray,
        shift: bool = True,
        max_passes: int = MAX_PASSES,
        forced: tuple[int, int] = (0, 0),
    ) -> bool:
        """Solve from ``x0`` = [x, θ, ẋ, θ̇]; True if the KKT conditions were verified.

        The passes start from the last active set shifted by one stage (``shift``), the
        receding horizon's guess; the last stage keeps its rows. At most ``max_passes``.
        ``forced`` = (k, side): the torques of the first k stages are held at the bound of
        sign ``side`` and their θ rows left out (the flywheel on the edge of its viable set,
        :meth:`~.feasibility.FlywheelFeasibility.forced_braking`).
        On failure the attributes
        hold no solution, ``active`` is left as it was (the caller may hand it to DAQP) and
        the next solve starts from it again unless :meth:`seed` or :meth:`reset` is called.
        """
        # Fresh output arrays each solve: a verified solution is the caller's to keep (the
        # controller's plan holds them without copying).
        inputs_shape, states_shape = self._shapes
        inputs, states = np.empty(inputs_shape), np.empty(states_shape)
        self.passes = passes = solve_from(
            x0, shift, *self._args, max_passes, *forced, inputs, states, *self._scratch
        )
        if passes < 0:
            self.verified = False
            return False
        self.inputs, self.states = inputs, states
        self.verified = True
        return True
