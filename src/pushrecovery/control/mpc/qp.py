r"""The condensed QP of the MPC, pre-stabilised: matrices built once, vectors updated each tick.

Eq. (17) over the exact discretisation x_{i+1} = A x_i + B u_i of Eq. (16) is condensed on the
inputs written as u_i = K x_i + v_i, with K a stabilising feedback (the infinite-horizon LQR
gain of the stage weights Q, R: ρ(A + B K) = 0.82 for the paper's settings). With A_K = A + B K
the predictions are

.. math:: X = Φ_K x_0 + Γ_K V, \qquad U = Ψ x_0 + Λ V,

with Φ_K the stacked A_K^i, Γ_K block (i, j) = A_K^{i−j} B (j ≤ i), Ψ block i = K A_K^i and Λ
lower block-triangular: I on the diagonal, K A_K^{i−1−j} B below. This is a change of
variables only (V ↔ U is one-to-one): the minimiser is Eq. (17)'s, exactly. It is the
conditioning that changes. Condensed on U itself, the unstable pendulum makes Γ grow as
e^{ω t} and P as e^{2 ω T}: after Jacobi scaling cond(P) was 1.5e8 at N = 50 and beyond 1e15 at
N = 100 (the solution at N = 200 was wrong). On V the predictions decay as 0.82^i and the scaled
P has a condition number of about 4 at every horizon (``tests/test_mpc.py``).

.. math::

    \min_V ½ V^T P V + q^T V, \quad P = 2 (Γ_K^T \bar Q Γ_K + Λ^T \bar R Λ),
    \quad q = 2 (Γ_K^T \bar Q Φ_K + Λ^T \bar R Ψ) x_0,

    \text{subject to } \underline u − Ψ x_0 ≤ Λ V ≤ \bar u − Ψ x_0, \quad
    −θ_{max} − S_θ Φ_K x_0 ≤ S_θ Γ_K V ≤ θ_{max} − S_θ Φ_K x_0,

with \bar Q, \bar R the stage weights γ^{N−i} Q, γ^{N−i} R. The variables are solved for in
scaled form V = D Ṽ, D = diag(P)^(−1/2) (Jacobi scaling), and every constraint row is scaled to
unit norm with its bounds. Building the matrices is vectorised
(block Toeplitz by index arithmetic): 1–2 ms at N = 50, once per body and settings.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.mpc.plan import Plan, Status
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.params import BodyParams

__all__ = ["CondensedQP", "shared_qp"]

FloatArray = NDArray[np.float64]


def _stabilising_gain(a: FloatArray, b: FloatArray, settings: MPCSettings) -> FloatArray:
    """LQR gain K (u = K x) of the stage weights: A + B K is stable.

    Any stabilising K gives the same minimiser; this one makes the predictions decay fastest
    in the cost's own metric. A weight of 0 on a state is lifted to 1e-9 of the largest so that
    the Riccati equation has its stabilising solution.
    """
    weights = np.asarray(settings.state_weights)
    q = np.diag(np.maximum(weights, 1e-9 * weights.max()))
    r = np.diag(settings.input_weights)
    cost_to_go = scipy.linalg.solve_discrete_are(a, b, q, r)
    gain: FloatArray = -np.linalg.solve(r + b.T @ cost_to_go @ b, b.T @ cost_to_go @ a)
    return gain


@functools.lru_cache(maxsize=256)
def _nearby_gain(body: BodyParams, settings: MPCSettings) -> FloatArray:
    """Return the LQR gain of ``body`` (one whose ω is rounded, see :func:`_gain`)."""
    return _stabilising_gain(*flywheel_discrete(body, settings.dt), settings)


def _gain(params: BodyParams, a: FloatArray, b: FloatArray, settings: MPCSettings) -> FloatArray:
    """Return a stabilising gain for (A, B): the gain of ω rounded to 2 digits, if it stabilises.

    Any stabilising gain gives the same minimiser. Solving the Riccati equation takes a few ms
    (scipy); the stance heights of a stepping run share the gain of their rounded ω instead.
    """
    # 2 digits: the stance heights of a campaign's steps (thousands) share a few gains; with 4
    # a batch of 1,410 stepping pushes solved 32 Riccati equations (0.5 s of its 2.5 s).
    omega = float(f"{params.omega:.2g}")
    nearby = dataclasses.replace(params, com_height=params.gravity / (omega * omega))
    gain = _nearby_gain(nearby, settings)
    if max(abs(np.linalg.eigvals(a + b @ gain))) < 0.95:
        return gain
    return _stabilising_gain(a, b, settings)  # pragma: no cover - ω far from its rounding


def _block_toeplitz(blocks: FloatArray) -> FloatArray:
    """Lower block-triangular matrix with block (i, j) = blocks[i − j] (0 above)."""
    n, rows, cols = blocks.shape
    lag = np.arange(n)[:, None] - np.arange(n)[None, :]
    full = np.where((lag >= 0)[:, :, None, None], blocks[np.clip(lag, 0, None)], 0.0)
    return np.ascontiguousarray(full.transpose(0, 2, 1, 3).reshape(n * rows, n * cols))


class CondensedQP:
    """Matrices of the pre-stabilised condensed MPC problem for one body and settings.

    Attributes
    ----------
    gain : ndarray, shape (2, 4)
        K of u = K x + v.
    phi : ndarray, shape (4N, 4)
        Free response Φ_K: stacked A_K^i, i = 1..N.
    gamma : ndarray, shape (4N, 2N)
        Forced response Γ_K: block (i, j) = A_K^(i−j) B for j ≤ i (X_{i+1} from v_j).
    psi, lam : ndarray, shapes (2N, 4) and (2N, 2N)
        The inputs U = Ψ x0 + Λ V.
    hessian : ndarray, shape (2N, 2N)
        P of the unscaled problem in V.
    scale : ndarray, shape (2N,)
        Diagonal of D (V = D Ṽ).
    scaled_inequality : ndarray, shape (3N, 2N)
        The constraint rows [Λ; S_θ Γ_K] D: inputs, then θ of X_1..X_N.
    """

    def __init__(self, params: BodyParams, settings: MPCSettings) -> None:
        require_type("params", params, BodyParams)
        require_type("settings", settings, MPCSettings)
        n = settings.horizon
        a, b = flywheel_discrete(params, settings.dt)
        self.params, self.settings = params, settings
        k = self.gain = _gain(params, a, b, settings)
        closed = a + b @ k
        powers = np.empty((n + 1, 4, 4))  # A_K^0..A_K^N
        powers[0] = np.eye(4)
        for i in range(n):
            powers[i + 1] = closed @ powers[i]
        forced = powers[:n] @ b  # A_K^i B, i = 0..N−1
        self.phi = np.ascontiguousarray(powers[1:].reshape(4 * n, 4))
        self.gamma = _block_toeplitz(forced)
        self.psi = np.ascontiguousarray((k @ powers[:n]).reshape(2 * n, 4))
        below = np.concatenate([np.eye(2)[None], k @ forced[: n - 1]])  # I, then K A_K^i B
        self.lam = _block_toeplitz(below)
        stage = settings.gamma ** (n - 1 - np.arange(n))  # γ^(N−i), i = 1..N
        q_bar = np.kron(stage, settings.state_weights)
        r_bar = np.kron(stage, settings.input_weights)
        self.hessian = 2.0 * (
            self.gamma.T @ (q_bar[:, None] * self.gamma) + self.lam.T @ (r_bar[:, None] * self.lam)
        )
        linear = 2.0 * (
            self.gamma.T @ (q_bar[:, None] * self.phi) + self.lam.T @ (r_bar[:, None] * self.psi)
        )
        self.scale = 1.0 / np.sqrt(np.diag(self.hessian))
        self._linear = np.ascontiguousarray(self.scale[:, None] * linear)  # q̃ = this @ x0
        scaled = self.scale[:, None] * self.hessian * self.scale[None, :]
        self.scaled_hessian = np.ascontiguousarray(0.5 * (scaled + scaled.T))  # exact symmetry
        rows = np.vstack([self.lam, self.gamma[1::4]]) * self.scale[None, :]
        # Each row at unit norm (its bounds with it): δ, τ and θ rows of Ṽ spanned 0.008-1500,
        # and near the edge of feasibility DAQP then missed feasible points.
        self.row_scale = 1.0 / np.linalg.norm(rows, axis=1)
        self.scaled_inequality = np.ascontiguousarray(self.row_scale[:, None] * rows)
        # The right-hand sides' state part, [Ψ; S_θ Φ_K] x0, and their constant bounds.
        free = np.vstack([self.psi, self.phi[1::4]])
        self._free = np.ascontiguousarray(self.row_scale[:, None] * free)
        theta_max = np.full(n, params.flywheel_angle_max)
        upper = np.concatenate([np.tile([params.toe, params.torque_max], n), theta_max])
        lower = np.concatenate([np.tile([params.heel, -params.torque_max], n), -theta_max])
        self._upper, self._lower = self.row_scale * upper, self.row_scale * lower

    @property
    def rows(self) -> int:
        """Number of constraint rows (3N)."""
        return self._upper.size

    def vectors(self, x0: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Scaled linear cost q̃ = D q and the rows' lower and upper bounds for state x0."""
        free = self._free @ x0
        return self._linear @ x0, self._lower - free, self._upper - free

    def vectors_into(
        self, x0: FloatArray, linear: FloatArray, lower: FloatArray, upper: FloatArray
    ) -> None:
        """Write :meth:`vectors` of x0 into preallocated contiguous float64 arrays.

        ``linear`` has shape (2N,), ``lower`` and ``upper`` (3N,); ``lower`` is also the
        scratch for the state part. The results are those of :meth:`vectors`, bit for bit.
        """
        np.dot(self._linear, x0, out=linear)
        np.dot(self._free, x0, out=lower)
        np.subtract(self._upper, lower, out=upper)
        np.subtract(self._lower, lower, out=lower)

    def inputs(self, x0: FloatArray, scaled: FloatArray) -> FloatArray:
        """Return the inputs U = Ψ x0 + Λ D Ṽ as an (N, 2) array of (δ [m], τ [N m])."""
        return (self.psi @ x0 + self.lam @ (self.scale * scaled)).reshape(-1, 2)

    def first_input(self, x0: FloatArray, scaled: FloatArray) -> FloatArray:
        """Return u_0 = K x0 + v_0 alone (δ [m], τ [N m]): Λ's first block row is [I 0 ...]."""
        return self.gain @ x0 + self.scale[:2] * scaled[:2]

    def predict(self, x0: FloatArray, scaled: FloatArray) -> FloatArray:
        """Predicted states X_0..X_N, shape (N + 1, 4), of the solution Ṽ: Φ_K x0 + Γ_K D Ṽ."""
        states = np.empty((self.settings.horizon + 1, 4))
        states[0] = x0
        states[1:] = (self.phi @ x0 + self.gamma @ (self.scale * scaled)).reshape(-1, 4)
        return states

    def plan(
        self,
        x0: FloatArray,
        scaled: FloatArray,
        active: NDArray[np.int8] | None = None,
        iterations: int = 0,
    ) -> Plan:
        """Return the SOLVED plan of the solution Ṽ from x0: the first input now, the rest later.

        ``scaled`` is kept (not copied); ``active`` and ``iterations`` are the solver's.
        """
        return Plan(
            Status.SOLVED,
            self.first_input(x0, scaled),
            lambda: self.inputs(x0, scaled),
            lambda: self.predict(x0, scaled),
            active,
            iterations,
        )


@functools.lru_cache(maxsize=8)
def shared_qp(params: BodyParams, settings: MPCSettings) -> CondensedQP:
    """Return the :class:`CondensedQP` of (params, settings), built once per process (8 kept).

    Its arrays are made read-only (solvers get copies), so the controllers of one body and
    settings (the recovery controller builds one per stance height and push) share it; each
    keeps its own DAQP workspace. A build costs 4-40 ms (N = 50-200), a hit ~1 µs; 8 QPs at
    N = 200 hold ~60 MB.
    """
    qp = CondensedQP(params, settings)
    for value in vars(qp).values():
        if isinstance(value, np.ndarray):
            value.setflags(write=False)
    return qp
