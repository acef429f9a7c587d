r"""N-step viability by linear programming: the ground truth of the capture regions.

With the touchdown times fixed on a grid of ``dt``, the LIPM with steps and an upper body
(:mod:`pushrecovery.surfaces.n_step`) is linear in everything the body chooses: the
CoP sequence p_i (piecewise constant, in the support of its phase: the stance polygon S, then
q_k + F_k after the k-th touchdown), the footholds q_k (q_k − q_{k−1} in the reach polygon
R_k), and the pitch and roll torques of the upper body (piecewise constant, abs(τ) ≤ τmax, the
flywheel angle abs(θ) ≤ θmax at the samples and three interior points of each step as in
:mod:`pushrecovery.surfaces.capture.lp.plane`, at rest at the end). The capture point follows
ξ_{i+1} = E ξ_i − (E − 1)(p_i + c_i), E = e^{ω dt}, c_i the CMP offset τ_i/(m g) along the
body's axes — exact for piecewise-constant inputs. Captured at the horizon: ξ in the last foot
and the flywheels at rest (the ankle then holds it, Eq. 4).

The LP maximises d · ξ0 (the support function of the N-step capturable set C_N) or, for a
given ξ0, d · q_1 (the support function of the region of first footholds). It assumes nothing
about the shape of the optimal inputs: the CoP may move within each phase, the flywheel turns
through the touchdowns. Without the hip, piecewise-constant CoPs lose nothing (each phase's
integral ranges over the same scaled polygon), so the LP is exact to the solver's tolerance;
with the hip its value is within the flywheel grid error of the continuous supremum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    finite_vector,
    require_type,
)
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError
from pushrecovery.ground.support import Stance
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.n_step import StepOption, landing_foot, reach_polygon

__all__ = ["StepLP", "step_lp"]

FloatArray = NDArray[np.float64]

_INTERIOR = (0.25, 0.5, 0.75)
_SOLVER_TOL = 1e-10
#: Largest grid (horizon / dt) accepted.
MAX_GRID = 4000


@dataclass(frozen=True, slots=True)
class StepLP:
    """Solution of :func:`step_lp`.

    Attributes
    ----------
    value : float
        The optimum of d · ξ0 (``target="capture_point"``) or d · q_1 (``"foothold"``) [m].
    capture_point : ndarray, shape (2,)
        ξ0 [m].
    footholds : ndarray, shape (N, 2)
        The landing ankles q_k [m].
    cops : ndarray, shape (M, 2)
        The CoP on the grid [m].
    torques : ndarray, shape (M, 2)
        Pitch and roll torques on the grid [N m].
    """

    value: float
    capture_point: FloatArray
    footholds: FloatArray
    cops: FloatArray
    torques: FloatArray


def step_lp(
    params: BodyParams,
    option: StepOption,
    touchdowns: tuple[float, ...],
    direction_angle: float,
    *,
    dt: float = 0.05,
    tail: float = 0.0,
    hip: bool = False,
    capture_point: tuple[float, float] | None = None,
) -> StepLP:
    """Maximise d · ξ0 over N-step capturable states, or d · q_1 for a given ξ0 (module doc).

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    option : StepOption
        The first landing foot and the stance it leaves.
    touchdowns : tuple of float
        Touchdown times [s], multiples of ``dt``.
    direction_angle : float
        Heading of d [rad].
    dt : float
        Input grid [s].
    tail : float
        Time after the last touchdown [s] (for the flywheel to come to rest).
    hip : bool
        Let the upper body torque.
    capture_point : (float, float), optional
        A fixed ξ0 [m]: then the objective is d · q_1 (first footholds).

    Raises
    ------
    ParameterTypeError
        If ``params`` or ``option`` has the wrong type.
    InvalidParameterError
        If ``touchdowns`` are not increasing positive multiples of ``dt`` (in [1 ms, 1 s]),
        ``tail`` is not in [0, 10] s, the grid is longer than ``MAX_GRID`` samples, or the
        heading or the fixed ξ0 is not finite.
    """
    from scipy.optimize import linprog

    require_type("params", params, BodyParams)
    require_type("option", option, StepOption)
    dt = bounded_float("dt", dt, 1e-3, 1.0, "s")
    tail = bounded_float("tail", tail, 0.0, 10.0, "s")
    direction_angle = finite_float("direction_angle", direction_angle, "rad")
    times = finite_array("touchdowns", touchdowns)
    if times.ndim != 1 or np.any(times <= 0.0) or np.any(np.diff(times) <= 0.0):
        raise InvalidParameterError(
            f"touchdowns must be increasing times > 0 [s], got {np.atleast_1d(times).tolist()[:8]}"
        )
    touchdowns = tuple(times.tolist())
    if capture_point is not None:
        capture_point = tuple(finite_vector("capture_point", capture_point, 2, unit="m"))
    if not isinstance(hip, bool | np.bool_):
        raise ParameterTypeError(f"hip must be True or False, got {type(hip).__name__}")
    n_steps = len(touchdowns)
    grid = [round(t / dt) for t in touchdowns]
    if any(abs(g * dt - t) > 1e-9 for g, t in zip(grid, touchdowns, strict=True)):
        raise InvalidParameterError(f"touchdowns must be multiples of dt = {dt:g} s")
    m = (grid[-1] if grid else 0) + round(tail / dt)
    if not 1 <= m <= MAX_GRID:
        raise InvalidParameterError(f"the grid must have 1 to {MAX_GRID} steps, got {m}")
    if capture_point is not None and n_steps == 0:
        raise InvalidParameterError("footholds need at least one step")
    e = math.exp(params.omega * dt)
    c, s = math.cos(option.yaw), math.sin(option.yaw)
    axes_world = np.array([[c, s], [-s, c]])  # rows: pitch and roll axes in the world
    limits = [
        (params.torque_max, params.flywheel_inertia, params.flywheel_angle_max),
        (params.torque_max_roll, params.flywheel_inertia_roll, params.flywheel_angle_max_roll),
    ]
    # Variables: ξ0 (2) | p_i (2M) | q_k (2N) | ũ_i (2M, torques in units of τmax).
    xi0, cop0, foot0, tau0 = 0, 2, 2 + 2 * m, 2 + 2 * m + 2 * n_steps
    size = tau0 + 2 * m
    rows: list[FloatArray] = []
    rhs: list[float] = []
    phase = np.searchsorted(np.array(grid), np.arange(m), side="right")  # touchdowns so far
    sides = []
    side = option.swing
    for _ in range(n_steps):
        sides.append(side)
        side = Stance.RIGHT if side is Stance.LEFT else Stance.LEFT
    feet = [landing_foot(params, sd, option.yaw) for sd in sides]

    for i in range(m):  # p_i in the support of its phase: n · (p_i − q_k) <= b
        k = int(phase[i])
        support = option.stance if k == 0 else feet[k - 1]
        for normal, offset in zip(support.normals, support.offsets, strict=True):
            row = np.zeros(size)
            row[cop0 + 2 * i : cop0 + 2 * i + 2] = normal
            if k > 0:
                row[foot0 + 2 * (k - 1) : foot0 + 2 * k] = -normal
            rows.append(row)
            rhs.append(float(offset))
    # Footholds within reach of the previous ankle.
    for k in range(n_steps):
        reach = reach_polygon(params, sides[k], option.yaw)
        for normal, offset in zip(reach.normals, reach.offsets, strict=True):
            row = np.zeros(size)
            row[foot0 + 2 * k : foot0 + 2 * k + 2] = normal
            bound = float(offset)
            if k == 0:
                bound += float(normal @ option.ankle)
            else:
                row[foot0 + 2 * (k - 1) : foot0 + 2 * k] = -normal
            rows.append(row)
            rhs.append(bound)
    # ξ_M = E^M ξ0 − Σ_i E^{M−1−i} (E − 1)(p_i + c_i) in the last support.
    weights = (e - 1.0) * e ** (m - 1 - np.arange(m))
    final = np.zeros((2, size))
    final[:, xi0 : xi0 + 2] = np.eye(2) * e**m
    for i in range(m):
        final[:, cop0 + 2 * i : cop0 + 2 * i + 2] -= np.eye(2) * weights[i]
        if hip:
            for j, (tau, _, _) in enumerate(limits):
                final[:, tau0 + 2 * i + j] -= weights[i] * axes_world[j] * tau / params.weight
    last = n_steps
    polygon = option.stance if last == 0 else feet[last - 1]
    for normal, offset in zip(polygon.normals, polygon.offsets, strict=True):
        row = normal @ final
        if last > 0:
            row[foot0 + 2 * (last - 1) : foot0 + 2 * last] -= normal
        rows.append(row)
        rhs.append(float(offset))
    bounds = [(None, None)] * tau0 + [(0.0, 0.0)] * (2 * m)
    equal_rows: list[FloatArray] = []
    if hip:
        for j, (tau, inertia, angle) in enumerate(limits):
            if tau <= 0.0:
                continue
            for i in range(m):
                bounds[tau0 + 2 * i + j] = (-1.0, 1.0)
            scale = tau / inertia  # θ̈ per unit ũ [rad/s²]
            for i in range(m):
                for h in (0.0, *(f * dt for f in _INTERIOR)):
                    # θ(i dt + h) = Σ_{l<i} [(i − l − ½) dt² + h dt] u_l + h²/2 u_i.
                    row = np.zeros(size)
                    lags = np.arange(i)
                    row[tau0 + 2 * lags + j] = scale * ((i - lags - 0.5) * dt * dt + h * dt)
                    row[tau0 + 2 * i + j] = scale * 0.5 * h * h
                    rows += [row, -row]
                    rhs += [angle, angle]
            rest = np.zeros(size)
            rest[tau0 + j : tau0 + 2 * m : 2] = 1.0  # θ̇_M = 0
            equal_rows.append(rest)
    cost = np.zeros(size)
    direction = np.array([math.cos(direction_angle), math.sin(direction_angle)])
    if capture_point is None:
        cost[xi0 : xi0 + 2] = -direction
    else:
        cost[foot0 : foot0 + 2] = -direction
        bounds[xi0] = (capture_point[0], capture_point[0])
        bounds[xi0 + 1] = (capture_point[1], capture_point[1])
    result = linprog(
        cost,
        A_ub=sp.csr_matrix(np.array(rows)),
        b_ub=np.array(rhs),
        A_eq=sp.csr_matrix(np.array(equal_rows)) if equal_rows else None,
        b_eq=np.zeros(len(equal_rows)) if equal_rows else None,
        bounds=bounds,
        method="highs",
        options={
            "primal_feasibility_tolerance": _SOLVER_TOL,
            "dual_feasibility_tolerance": _SOLVER_TOL,
        },
    )
    if result.status == 2:
        raise InvalidParameterError("no foothold captures this capture point (infeasible LP)")
    if result.status != 0:  # pragma: no cover
        raise PushRecoveryError(f"step LP failed: {result.message}")
    z = np.asarray(result.x, dtype=np.float64)
    torques = z[tau0:].reshape(m, 2) * np.array([lim[0] for lim in limits])
    return StepLP(
        value=float(-result.fun),
        capture_point=z[xi0 : xi0 + 2].copy(),
        footholds=z[foot0:tau0].reshape(n_steps, 2).copy(),
        cops=z[cop0:foot0].reshape(m, 2).copy(),
        torques=torques,
    )
