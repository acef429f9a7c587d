"""The condensed QP of the MPC: matrices built once, vectors updated each tick.

Stacking the predictions X = Φ x0 + Γ U over the horizon turns Eq. (17) into

    minimise ½ Uᵀ P U + qᵀ U,  P = 2 (Γᵀ Q̄ Γ + R̄),  q = 2 Γᵀ Q̄ Φ x0,
    subject to  lb ≤ U ≤ ub,  −θmax ≤ S_θ (Φ x0 + Γ U) ≤ θmax.

In SI units P is badly conditioned (the τ columns weigh ~1e-5, the δ columns ~1e3): condition
number ~1e11 for the paper's settings. The inputs are therefore solved for in scaled form
U = D Ũ with D = diag(P)^(-1/2) (Jacobi scaling), which brings it to ~1e3 without changing the
solution.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.params import BodyParams

__all__ = ["CondensedQP"]

FloatArray = NDArray[np.float64]


class CondensedQP:
    """Matrices of the condensed MPC problem for one body and one set of settings.

    Attributes
    ----------
    phi : ndarray, shape (4N, 4)
        Free response: stacked A^i, i = 1..N.
    gamma : ndarray, shape (4N, 2N)
        Forced response: block (i, j) = A^(i−j) B for j ≤ i.
    hessian : ndarray, shape (2N, 2N)
        P of the unscaled problem.
    scale : ndarray, shape (2N,)
        Diagonal of D (U = D Ũ).
    """

    def __init__(self, params: BodyParams, settings: MPCSettings) -> None:
        n = settings.horizon
        a, b = flywheel_discrete(params, settings.dt)
        self.params, self.settings = params, settings
        phi = np.zeros((4 * n, 4))
        gamma = np.zeros((4 * n, 2 * n))
        power = np.eye(4)
        for i in range(n):  # row block i predicts X_{i+1}
            power = a @ power
            phi[4 * i : 4 * i + 4] = power
        for j in range(n):  # input U_j first acts on X_{j+1}
            block = b
            for i in range(j, n):
                gamma[4 * i : 4 * i + 4, 2 * j : 2 * j + 2] = block
                block = a @ block
        stage = settings.gamma ** (n - 1 - np.arange(n))  # γ^(N−i), i = 1..N
        q_bar = np.kron(stage, settings.state_weights)
        r_bar = np.kron(stage, settings.input_weights)
        self.phi, self.gamma = phi, gamma
        self.hessian = 2.0 * (gamma.T @ (q_bar[:, None] * gamma) + np.diag(r_bar))
        self._linear = 2.0 * gamma.T @ (q_bar[:, None] * phi)  # q = linear @ x0
        self.scale = 1.0 / np.sqrt(np.diag(self.hessian))
        self.scaled_hessian = self.scale[:, None] * self.hessian * self.scale[None, :]
        # Symmetrise what rounding broke; the solvers check symmetry.
        self.scaled_hessian = 0.5 * (self.scaled_hessian + self.scaled_hessian.T)
        theta_rows = gamma[1::4]  # θ of X_1..X_N
        self._theta_free = phi[1::4]
        self.scaled_inequality = np.vstack([theta_rows, -theta_rows]) * self.scale[None, :]
        upper = np.tile([params.toe, params.torque_max], n)
        lower = np.tile([params.heel, -params.torque_max], n)
        self.scaled_lower, self.scaled_upper = lower / self.scale, upper / self.scale
        self._limit = np.full(n, params.flywheel_angle_max)

    def vectors(self, x0: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Scaled linear cost q̃ = D q and inequality right-hand side h for state x0."""
        theta_free = self._theta_free @ x0
        h = np.concatenate([self._limit - theta_free, self._limit + theta_free])
        return self.scale * (self._linear @ x0), h

    def vectors_into(self, x0: FloatArray, linear: FloatArray, rhs: FloatArray) -> None:
        """Write :meth:`vectors` of x0 into preallocated ``linear`` and ``rhs``.

        Both are contiguous float64 arrays of shape (2N,). The operations are those of
        :meth:`vectors` in the same order, so the results are bit for bit the same, without
        the temporaries.
        """
        horizon = self._limit.size
        np.dot(self._linear, x0, out=linear)
        np.multiply(self.scale, linear, out=linear)
        free = rhs[:horizon]
        np.dot(self._theta_free, x0, out=free)
        np.add(self._limit, free, out=rhs[horizon:])
        np.subtract(self._limit, free, out=free)

    def unscale(self, scaled_inputs: FloatArray) -> FloatArray:
        """Return the inputs U = D Ũ as an (N, 2) array of (δ [m], τ [N m])."""
        return (self.scale * scaled_inputs).reshape(-1, 2)

    def predict(self, x0: FloatArray, inputs: FloatArray) -> FloatArray:
        """Predicted states X_0..X_N, shape (N + 1, 4), for inputs of shape (N, 2)."""
        states = np.empty((self._limit.size + 1, 4))
        states[0] = x0
        future = states[1:].reshape(-1)  # a view: the rows are contiguous
        np.dot(self.gamma, inputs.reshape(-1), out=future)
        future += self.phi @ x0  # the same sum as Φ x0 + Γ U, without the temporaries
        return states
