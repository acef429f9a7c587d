r"""The MPC problem of Sec. III-B: horizon, weights and solver (Eq. 17), and its sparse form.

.. math:: J = \sum_{i=1}^{N} \gamma^{N-i} \left( X_i^T Q X_i + U_{i-1}^T R U_{i-1} \right)

with X_i the state predicted i steps ahead by the exact discretisation of Eq. (16) and U_{i−1}
the input applied over the step that leads to it. As printed, the weights γ^{N−i} *grow* toward
the end of the horizon (γ < 1); the text's "discount factor" is a misnomer (errata E13). Hard
constraints: δ⁻ ≤ δ ≤ δ⁺, abs(τ) ≤ τmax, abs(θ_i) ≤ θmax.

Two forms of it are solved (docs/mpc.md, "Exact at any horizon"): :class:`SparseQP` keeps the
states as variables (the Riccati passes, the interior point); the condensed QP
(:class:`~pushrecovery.control.mpc.qp.CondensedQP`) has the inputs only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import flywheel_discrete
from pushrecovery.params import BodyParams

__all__ = ["MPCSettings", "SparseQP"]

FloatArray = NDArray[np.float64]


#: Longest horizon [samples]: 4 s at the default 0.02 s; the condensed QP grows as N² (a
#: horizon of 3000 would take minutes to build and gigabytes to hold).
MAX_HORIZON = 200
#: Shortest prediction step and control period [s]: a 1 kHz loop.
MIN_DT = 1e-3


@dataclass(frozen=True, slots=True)
class MPCSettings:
    """Settings of the receding-horizon controller; defaults are the paper's (Sec. III-B).

    Parameters
    ----------
    dt : float
        Step of the prediction and of the control loop [s] (paper: 0.02), in
        [``MIN_DT``, 1]: a loop faster than 1 kHz multiplies a run's QPs without changing
        the plan (at 1e-6 s a 3 s run is 3 million QPs).
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
    realtime : bool
        Bound each tick's work by a fixed budget of Riccati passes and interior-point
        iterations (scaled by 1/N: docs/mpc.md, "The real-time mode"); when it runs out the tick
        applies the last verified plan shifted by one stage (``Status.SHIFTED``). Needs
        ``solver="daqp"`` (the sparse solvers' route); 1 and 0 are read as True and False (the
        CLI's ``--option realtime=1``). Default False: every tick solved exactly.
    """

    dt: float = 0.02
    horizon: int = 50
    state_weights: tuple[float, float, float, float] = (1e3, 1e3, 10.0, 10.0)
    input_weights: tuple[float, float] = (1e-2, 1e-5)
    gamma: float = 0.9
    solver: str = "daqp"
    realtime: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", bounded_float("dt", self.dt, MIN_DT, 1.0, "s"))
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
                got = len(values) if isinstance(values, tuple | list) else type(values).__name__
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
        # 0 and 1 too: the CLI's --option realtime=1 gives a number.
        if not isinstance(self.realtime, bool | np.bool_ | int) or self.realtime not in (0, 1):
            raise InvalidParameterError(
                f"realtime must be True or False (or 1, 0), got {self.realtime!r}"
            )
        object.__setattr__(self, "realtime", bool(self.realtime))
        require_type("solver", self.solver, str)
        if self.realtime and self.solver != "daqp":
            raise InvalidParameterError(
                f"realtime=True needs solver='daqp' (the sparse solvers' route), "
                f"got solver={self.solver!r}"
            )


class SparseQP:
    """Eq. (17) with the states kept as variables: its stages, for one body and settings.

    Variables u_0..u_{N−1} and x_1..x_N, the dynamics x_{i+1} = A x_i + B u_i as equalities
    (:func:`~pushrecovery.models.flywheel.flywheel_discrete`), and per stage three bounded
    components: δ_i, τ_i and θ_{i+1}. No N-sized matrix is formed.

    Parameters
    ----------
    params : BodyParams
        Body parameters (bounds δ⁻ = heel, δ⁺ = toe, τmax, θmax).
    settings : MPCSettings
        dt, N, Q, R and γ.

    Raises
    ------
    InvalidParameterError
        If ``params`` is not a BodyParams or ``settings`` not an MPCSettings.
    ValueError
        If A, B lack the flywheel's zeros the kernels skip: the flywheel's exact
        discretisation leaves (x, ẋ) and (θ, θ̇) decoupled in A and the CoP's column of B zero
        on θ, θ̇, and the kernels (``kernels.mpc.riccati``, ``kernels.mpc.interior``) leave
        those products out. A model without these zeros is a bug here, not a user's input.

    Attributes
    ----------
    a, b : ndarray, shapes (4, 4) and (4, 2)
        A and B of the exact discretisation.
    wx, wu : ndarray, shapes (N, 4) and (N, 2)
        Stage i's weights γ^(N−1−i) Q of x_{i+1} and γ^(N−1−i) R of u_i (SI units).
    bounds : ndarray, shape (3, 2)
        The (lower, upper) bounds of δ [m], τ [N m] and θ [rad].
    """

    __slots__ = ("a", "b", "bounds", "wu", "wx")

    def __init__(self, params: BodyParams, settings: MPCSettings) -> None:
        require_type("params", params, BodyParams)
        require_type("settings", settings, MPCSettings)
        n = settings.horizon
        a, b = self.a, self.b = flywheel_discrete(params, settings.dt)
        com, wheel = np.ix_([0, 2], [1, 3]), np.ix_([1, 3], [0, 2])
        if np.any(a[com]) or np.any(a[wheel]) or np.any(b[[1, 3], 0]):
            raise ValueError(
                "the sparse MPC solvers' kernels need A block-diagonal in (x, xdot), (theta, "
                "theta_dot) and B's CoP column zero on theta, theta_dot (the flywheel model's "
                f"discretisation); got A = {a.tolist()}, B = {b.tolist()}"
            )
        stage = settings.gamma ** (n - 1 - np.arange(n))  # γ^(N−i) of x_i and u_{i−1}, i = 1..N
        self.wx = np.ascontiguousarray(stage[:, None] * np.asarray(settings.state_weights))
        self.wu = np.ascontiguousarray(stage[:, None] * np.asarray(settings.input_weights))
        theta_max = params.flywheel_angle_max
        self.bounds = np.array(
            [[params.heel, params.toe], [-params.torque_max, params.torque_max],
             [-theta_max, theta_max]]
        )  # fmt: skip

    @property
    def horizon(self) -> int:
        """The number of stages N."""
        return int(self.wx.shape[0])

    def simulate(self, x0: FloatArray, inputs: FloatArray) -> FloatArray:
        """States X_0..X_N, shape (N + 1, 4), of inputs U of shape (N, 2) applied open loop."""
        states = np.empty((inputs.shape[0] + 1, 4))
        states[0] = x0
        for i, u in enumerate(inputs):
            states[i + 1] = self.a @ states[i] + self.b @ u
        return states
