r"""The capture region of the planar flywheel model, by linear programming along directions.

The planar model (:mod:`pushrecovery.models.flywheel.plane`: the LIPM in x and y plus an
upper-body flywheel in pitch and one in roll, Eq. 16 per axis, exact zero-order hold) is linear
and so is every constraint: the CoP in the support polygon P (its half-planes n_i · p ≤ b_i),
abs(τ) ≤ τmax and abs(θ) ≤ θmax of each axis. So the support function of the set of capturable
initial capture points,

.. math:: h(\mathbf d) = \max\ \mathbf d \cdot \boldsymbol\xi_0
          \quad\text{over } \boldsymbol\xi_0 \text{ from which some admissible input sequence
          reaches a captured state,}

is a linear program; captured at the horizon means ξ_N ∈ P with both flywheels at rest within
their limits. Sweeping d traces the (convex) capturable set without assuming the shape of the
optimal input; it checks the closed form of :mod:`pushrecovery.surfaces.plane`, h_P(d) +
a_p abs(d · e_p) + a_r abs(d · e_r), derived, with when it is exact, in docs/plane.md ("The
CMP (hip) region: derivation"). The grid of ``dt`` and its error bound are those of the 1-D LP
(:mod:`pushrecovery.surfaces.capture.lp`). Starting the CoM at the origin (velocity ω ξ0) loses
no generality: only the capture point enters the constraints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, positive_float
from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.models.flywheel.plane import plane_discrete
from pushrecovery.params import BodyParams

__all__ = ["MAX_STEPS", "PlaneCaptureLP", "grid_steps", "support_function_lp"]

FloatArray = NDArray[np.float64]

#: Largest number of grid steps (horizon / dt) accepted: keeps one solve around a second.
MAX_STEPS = 2000

# Interior points of a step where |θ| ≤ θmax is checked (fractions of dt), as in the 1-D LP.
_INTERIOR = (0.25, 0.5, 0.75)
# HiGHS primal and dual feasibility tolerance (the default 1e-7 is looser than the grid error).
_SOLVER_TOL = 1e-9


@dataclass(frozen=True, slots=True)
class PlaneCaptureLP:
    """Solution of the planar capture LP along one direction.

    Attributes
    ----------
    value : float
        max d · ξ0 over the capturable initial capture points ξ0 [m] (d the unit direction).
    direction : ndarray, shape (2,)
        The unit direction d (world frame).
    capture_point : ndarray, shape (2,)
        An optimal ξ0 (world frame) [m].
    cops : ndarray, shape (N, 2)
        The optimal CoP sequence (world frame) [m].
    torques : ndarray, shape (N, 2)
        The optimal pitch and roll torques [N m].
    states : ndarray, shape (N + 1, 8)
        The optimal trajectory ``(x, y, θp, θr, ẋ, ẏ, θ̇p, θ̇r)`` from x = y = 0 [m, m, rad, rad,
        m/s, m/s, rad/s, rad/s].
    dt : float
        Grid step [s].
    """

    value: float
    direction: FloatArray
    capture_point: FloatArray
    cops: FloatArray
    torques: FloatArray
    states: FloatArray
    dt: float


def grid_steps(horizon: float, dt: float) -> int:
    """Return the steps of ``dt`` [s] in ``horizon`` [s], in [1, :data:`MAX_STEPS`].

    Compared before rounding: a subnormal ``dt`` gives an infinite ratio, refused.
    """
    horizon, dt = positive_float("horizon", horizon, "s"), positive_float("dt", dt, "s")
    ratio = horizon / dt
    if not ratio <= MAX_STEPS + 0.5:
        raise InvalidParameterError(
            f"horizon / dt must be at most {MAX_STEPS} steps, got horizon={horizon:g} s, "
            f"dt={dt:g} s ({ratio:g} steps)"
        )
    return max(1, round(ratio))


def support_function_lp(
    polygon: ConvexPolygon,
    params: BodyParams,
    direction_angle: float,
    *,
    dt: float = 0.01,
    horizon: float = 3.0,
    yaw: float = 0.0,
) -> PlaneCaptureLP:
    """Support function of the planar model's capturable set along one direction, by LP.

    Maximises d · ξ0, d = (cos ψ, sin ψ), over ξ0 and the CoP and torque sequences subject to
    the exact discrete dynamics (:func:`~pushrecovery.models.flywheel.plane.plane_discrete`),
    p_k ∈ ``polygon``, abs(τ_k) ≤ τmax and abs(θ) ≤ θmax of each axis (at the samples and three
    interior points of every step), and at the horizon ξ_N ∈ ``polygon`` and θ̇_N = 0 (module
    docstring for the grid error).

    Parameters
    ----------
    polygon : ConvexPolygon
        Support polygon P in the world frame [m].
    params : BodyParams
        Body parameters (pitch and roll axes of the upper body).
    direction_angle : float
        Heading ψ of d [rad], counter-clockwise from the world's x.
    dt : float
        Input grid step [s].
    horizon : float
        Time allowed to reach a captured state [s]; at most :data:`MAX_STEPS` steps of ``dt``.
    yaw : float
        Heading of the upper body's pitch axis [rad] (the stance's, ``Support.yaw``).

    Returns
    -------
    PlaneCaptureLP

    Raises
    ------
    InvalidParameterError
        A bad argument, named in the message.
    """
    from scipy.optimize import linprog

    if not isinstance(polygon, ConvexPolygon):
        raise InvalidParameterError(
            f"polygon must be a ConvexPolygon, got {type(polygon).__name__}"
        )
    if not isinstance(params, BodyParams):
        raise InvalidParameterError(f"params must be a BodyParams, got {type(params).__name__}")
    angle = finite_float("direction_angle", direction_angle, "rad")
    yaw = finite_float("yaw", yaw, "rad")
    dt = positive_float("dt", dt, "s")
    horizon = positive_float("horizon", horizon, "s")
    steps = grid_steps(horizon, dt)
    direction = np.array([math.cos(angle), math.sin(angle)])
    problem = _Problem(polygon, params, dt, steps, yaw)
    cost = np.zeros(problem.size)
    cost[0:2] = -direction
    result = linprog(
        cost,
        A_ub=problem.a_ub,
        b_ub=problem.b_ub,
        A_eq=problem.a_eq,
        b_eq=np.zeros(problem.a_eq.shape[0]),
        bounds=problem.bounds,
        method="highs",
        options={
            "primal_feasibility_tolerance": _SOLVER_TOL,
            "dual_feasibility_tolerance": _SOLVER_TOL,
        },
    )
    if result.status != 0:  # pragma: no cover - feasible (ξ0 = an interior point, no input)
        raise PushRecoveryError(f"planar capture LP failed: {result.message}")
    return problem.solution(np.asarray(result.x, dtype=np.float64), direction)


class _Problem:
    """The sparse LP in scaled variables z = (ξ0, X̃_1 ... X̃_N, Ũ_0 ... Ũ_{N-1}).

    X = Dx X̃ and U = Du Ũ: angles in units of θmax, rates of θmax / T_max, torques of τmax, so
    every variable is O(1) and HiGHS's tolerances mean the same thing for all of them.
    """

    def __init__(
        self, polygon: ConvexPolygon, params: BodyParams, dt: float, steps: int, yaw: float
    ) -> None:
        self.steps = steps
        self.dt = dt
        self.omega = params.omega
        a, b = plane_discrete(params, dt, yaw)
        axes = (
            (params.torque_max, params.flywheel_inertia, params.flywheel_angle_max),
            (params.torque_max_roll, params.flywheel_inertia_roll, params.flywheel_angle_max_roll),
        )
        torque_scale = [tau if tau > 0.0 else 1.0 for tau, _, _ in axes]
        rate_scale = [
            math.sqrt(tau * angle / inertia) if tau > 0.0 else 1.0 for tau, inertia, angle in axes
        ]
        self.dx = np.array([1.0, 1.0, axes[0][2], axes[1][2], 1.0, 1.0, *rate_scale])
        self.du = np.array([1.0, 1.0, *torque_scale])
        a_s = a * self.dx[None, :] / self.dx[:, None]
        b_s = b * self.du[None, :] / self.dx[:, None]
        n = steps
        self.x0 = 2
        self.u0 = 2 + 8 * n
        self.size = 2 + 12 * n

        # Dynamics: X̃_{k+1} − Ã X̃_k − B̃ Ũ_k = 0, with X̃_0 = (0, 0, 0, 0, ω ξ0, 0, 0).
        start = np.zeros((8, 2))
        start[4, 0] = start[5, 1] = self.omega
        first = sp.csr_matrix(-(a_s @ start))
        xi_block = sp.vstack([first, sp.csr_matrix((8 * (n - 1), 2))]) if n > 1 else first
        state_block = sp.identity(8 * n, format="csr") - sp.kron(
            sp.eye(n, k=-1, format="csr"), sp.csr_matrix(a_s), format="csr"
        )
        input_block = -sp.kron(sp.identity(n, format="csr"), sp.csr_matrix(b_s), format="csr")
        self.a_eq = sp.hstack([xi_block, state_block, input_block], format="csr")

        # Inequalities, as one-sided rows ≤ b.
        normals, offsets = polygon.normals, polygon.offsets
        edges = len(offsets)
        rows: list[sp.spmatrix] = []
        rhs: list[FloatArray] = []
        # CoP on the polygon at every step.
        cop_pick = np.zeros((edges, 4))
        cop_pick[:, 0:2] = normals
        cop = sp.kron(sp.identity(n, format="csr"), sp.csr_matrix(cop_pick), format="csr")
        rows.append(sp.hstack([sp.csr_matrix((edges * n, 2 + 8 * n)), cop], format="csr"))
        rhs.append(np.tile(offsets, n))
        # Capture point on the polygon at the horizon: n_i · (r_N + ṙ_N / ω) ≤ b_i.
        final = sp.lil_matrix((edges, self.size))
        base = self.x0 + 8 * (n - 1)
        for axis in (0, 1):
            final[:, base + axis] = normals[:, axis : axis + 1]
            final[:, base + 4 + axis] = normals[:, axis : axis + 1] / self.omega
        rows.append(final.tocsr())
        rhs.append(offsets.copy())
        # |θ| ≤ θmax inside every step: θ̃_k + h (ṡ/θmax) θ̃̇_k + h² τs / (2 I θmax) ũ_k.
        r_idx: list[int] = []
        c_idx: list[int] = []
        vals: list[float] = []
        row = 0
        for j, (_, inertia, angle) in enumerate(axes):
            for fraction in _INTERIOR:
                h = fraction * dt
                rate_coef = h * rate_scale[j] / angle
                input_coef = h * h * torque_scale[j] / (2.0 * inertia * angle)
                for k in range(n):
                    if k > 0:  # X̃_0 has the flywheels at rest at zero
                        state = self.x0 + 8 * (k - 1)
                        r_idx += [row, row]
                        c_idx += [state + 2 + j, state + 6 + j]
                        vals += [1.0, rate_coef]
                    r_idx.append(row)
                    c_idx.append(self.u0 + 4 * k + 2 + j)
                    vals.append(input_coef)
                    row += 1
        inside = sp.csr_matrix((vals, (r_idx, c_idx)), shape=(row, self.size))
        rows += [inside, -inside]
        rhs += [np.ones(row), np.ones(row)]
        self.a_ub = sp.vstack(rows, format="csr")
        self.b_ub = np.concatenate(rhs)

        # Bounds: sampled angles in [−1, 1] (units of θmax), torques in [−1, 1] (of τmax, or 0
        # for an axis without torque), flywheels at rest at the horizon, the rest free.
        lower = np.full(self.size, -np.inf)
        upper = np.full(self.size, np.inf)
        state_cols = self.x0 + 8 * np.arange(n)
        for j in (0, 1):
            lower[state_cols + 2 + j], upper[state_cols + 2 + j] = -1.0, 1.0
            limit = 1.0 if axes[j][0] > 0.0 else 0.0
            lower[self.u0 + 4 * np.arange(n) + 2 + j] = -limit
            upper[self.u0 + 4 * np.arange(n) + 2 + j] = limit
        last = self.x0 + 8 * (n - 1)
        lower[last + 6 : last + 8] = upper[last + 6 : last + 8] = 0.0
        self.bounds = np.column_stack([lower, upper])

    def solution(self, z: FloatArray, direction: FloatArray) -> PlaneCaptureLP:
        """Unscale the solution vector."""
        n = self.steps
        xi0 = z[0:2].copy()
        states = np.zeros((n + 1, 8))
        states[0, 4:6] = self.omega * xi0
        states[1:] = z[self.x0 : self.u0].reshape(n, 8) * self.dx
        inputs = z[self.u0 :].reshape(n, 4) * self.du
        return PlaneCaptureLP(
            value=float(direction @ xi0),
            direction=direction,
            capture_point=xi0,
            cops=inputs[:, 0:2].copy(),
            torques=inputs[:, 2:4].copy(),
            states=states,
            dt=self.dt,
        )
