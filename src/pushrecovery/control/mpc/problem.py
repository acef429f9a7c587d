r"""The MPC problem of Sec. III-B: horizon, weights and solver (Eq. 17).

.. math:: J = \sum_{i=1}^{N} \gamma^{N-i} \left( X_i^T Q X_i + U_{i-1}^T R U_{i-1} \right)

with X_i the state predicted i steps ahead by the exact discretisation of Eq. (16) and U_{i−1}
the input applied over the step that leads to it. As printed, the weights γ^{N−i} *grow* toward
the end of the horizon (γ < 1); the text's "discount factor" is a misnomer (errata E13). Hard
constraints: δ⁻ ≤ δ ≤ δ⁺, abs(τ) ≤ τmax, abs(θ_i) ≤ θmax.
"""

from __future__ import annotations

from dataclasses import dataclass

from pushrecovery.arguments import finite_float, positive_float
from pushrecovery.errors import InvalidParameterError

__all__ = ["MPCSettings"]


#: Longest horizon [samples]: 4 s at the default 0.02 s; the condensed QP grows as N² (a
#: horizon of 3000 would take minutes to build and gigabytes to hold).
MAX_HORIZON = 200


@dataclass(frozen=True, slots=True)
class MPCSettings:
    """Settings of the receding-horizon controller; defaults are the paper's (Sec. III-B).

    Parameters
    ----------
    dt : float
        Step of the prediction and of the control loop [s] (paper: 0.02).
    horizon : int
        Number of steps N (paper: 50, a 1 s look-ahead).
    state_weights : tuple of 4 floats
        Diagonal of Q for (x, θ, ẋ, θ̇) in SI units (paper: 1e3, 1e3, 10, 10).
    input_weights : tuple of 2 floats
        Diagonal of R for (δ, τ) in SI units (paper: 1e-2, 1e-5).
    gamma : float
        γ of Eq. (17), in (0, 1] (paper: 0.9).
    solver : str
        qpsolvers back-end (default ``daqp``: a dual active-set method, exact to machine
        precision on these small dense problems and the fastest we measured).
    """

    dt: float = 0.02
    horizon: int = 50
    state_weights: tuple[float, float, float, float] = (1e3, 1e3, 10.0, 10.0)
    input_weights: tuple[float, float] = (1e-2, 1e-5)
    gamma: float = 0.9
    solver: str = "daqp"

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", positive_float("dt", self.dt, "s"))
        if (
            isinstance(self.horizon, bool)
            or not isinstance(self.horizon, int)
            or not 1 <= self.horizon <= MAX_HORIZON
        ):
            raise InvalidParameterError(
                f"horizon must be an integer in [1, {MAX_HORIZON}], got {self.horizon!r}"
            )
        for name, values, size in (
            ("state_weights", self.state_weights, 4),
            ("input_weights", self.input_weights, 2),
        ):
            if not isinstance(values, tuple | list) or len(values) != size:
                got = len(values) if isinstance(values, tuple | list) else repr(values)
                raise InvalidParameterError(f"{name} must have {size} entries, got {got}")
            checked = tuple(finite_float(name, v) for v in values)
            if min(checked) < 0.0 or (name == "input_weights" and min(checked) <= 0.0):
                bound = "> 0" if name == "input_weights" else ">= 0"
                raise InvalidParameterError(f"{name} must all be {bound}, got {checked}")
            object.__setattr__(self, name, checked)
        gamma = finite_float("gamma", self.gamma)
        if not 0.0 < gamma <= 1.0:
            raise InvalidParameterError(f"gamma must be in (0, 1], got {gamma:g}")
        object.__setattr__(self, "gamma", gamma)
