r"""Exact feasibility of Eq. (17): the flywheel's N-step viable set, a polygon in (θ, θ̇).

Only the θ rows can make Eq. (17) infeasible, and the exact discretisation of Eq. (16)
(:func:`~pushrecovery.models.flywheel.flywheel_discrete`) leaves the flywheel a double
integrator of its own, s_{i+1} = A s_i + b τ_i with s = (θ, θ̇), h = dt²/(2I), g = dt/I,

.. math:: A = \begin{bmatrix} 1 & dt \\ 0 & 1 \end{bmatrix},
          \quad b = \begin{bmatrix} h \\ g \end{bmatrix}.

So the QP is feasible exactly when s_0 lies in the N-step viable set S_N, built by
S_k = A^{−1}((C ∩ S_{k−1}) ⊕ W), C = {abs(θ) ≤ θmax}, W = {τ b : abs(τ) ≤ τmax}, and the test
is the gauge γ(s) = max(0, max_k n_k · s) of S_N = {s : n_k · s ≤ 1}: the QP is feasible
exactly when γ(s_0) ≤ 1. The controller skips DAQP only when γ(s_0) > 1 + :data:`BAND`
(DAQP's own tolerance). docs/mpc.md, "Exact feasibility: the flywheel's viable set", derives
the recursion, its starting box and the band.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.control.mpc.problem import MPCSettings
from pushrecovery.params import BodyParams

__all__ = ["BAND", "BOUNDARY", "FlywheelFeasibility", "viable_facets"]

FloatArray = NDArray[np.float64]

#: Relative margin beyond the exact boundary (γ > 1 + BAND) from which DAQP is not asked.
BAND = 1e-4
#: Relative margin inside the boundary within which a state is on it (γ ≥ 1 − BOUNDARY):
#: the feasible torques are then full braking to within rounding (forced_braking).
BOUNDARY = 1e-9


def _add_segment(poly: FloatArray, w: FloatArray) -> FloatArray:
    """Minkowski sum of a convex polygon (counter-clockwise vertices) and the segment [−w, w]."""
    edges = np.roll(poly, -1, axis=0) - poly
    # Edge i moves by +w when its outward normal (e_y, −e_x) points along w, else by −w.
    out = np.where(w[0] * edges[:, 1] - w[1] * edges[:, 0] >= 0.0, 1.0, -1.0)
    into = np.roll(out, 1)  # the sign of the edge ending at vertex i
    doubled = into != out
    counts = np.where(doubled, 2, 1)
    moves = np.repeat(out, counts)
    moves[(np.cumsum(counts) - counts)[doubled]] = into[doubled]  # first copy: the old side
    return _distinct(np.repeat(poly, counts, axis=0) + moves[:, None] * w)


def _clip(poly: FloatArray, limit: float) -> FloatArray:
    """Return the convex polygon ∩ {abs(θ) ≤ limit} (θ the first coordinate)."""
    for sign in (1.0, -1.0):
        value = sign * poly[:, 0] - limit  # ≤ 0 inside
        after = np.roll(value, -1)
        nxt = np.roll(poly, -1, axis=0)
        inside = value <= 0.0
        crossing = inside != (after <= 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(crossing, value / (value - after), 0.0)
        cut = poly + t[:, None] * (nxt - poly)
        cut[:, 0] = np.where(crossing, sign * limit, cut[:, 0])  # exactly on the line
        candidates = np.stack([poly, cut], axis=1).reshape(-1, 2)
        keep = np.stack([inside, crossing], axis=1).reshape(-1)
        poly = _distinct(candidates[keep])
    return poly


def _distinct(poly: FloatArray) -> FloatArray:
    """Drop vertices equal to their successor (to 1e−14 of the polygon's size)."""
    size = np.abs(poly).max()
    step = np.abs(np.roll(poly, -1, axis=0) - poly).max(axis=1)
    return poly[step > 1e-14 * size]


@functools.lru_cache(maxsize=64)
def viable_facets(
    inertia: float, torque_max: float, angle_max: float, dt: float, horizon: int
) -> FloatArray:
    """Facets of S_N as rows n_k, S_N = {s = (θ, θ̇) : n_k · s ≤ 1}; read-only, cached.

    Requires τmax > 0 and θmax > 0 (S_N then contains a neighbourhood of the origin).
    """
    h, g = 0.5 * dt * dt / inertia, dt / inertia
    if horizon == 1:
        facets = np.array([[1.0, dt], [-1.0, -dt]]) / (angle_max + h * torque_max)
    else:
        w = np.array([h, g]) * torque_max
        bound = 2.0 * ((2.0 * angle_max + h * torque_max) / dt + g * torque_max)
        poly = np.array(
            [[-angle_max, -bound], [angle_max, -bound], [angle_max, bound], [-angle_max, bound]]
        )
        previous = None
        for k in range(horizon):  # S_{k+1} from C ∩ S_k (C ∩ box for k = 0)
            poly = _add_segment(poly, w)
            poly[:, 0] -= dt * poly[:, 1]  # A^{-1}: θ − dt θ̇
            # S_{k+1} = S_k (as sets, bit for bit): a fixed point of the recursion, every
            # later S_j is the same (the paper's body: from k = 55; equal to 1e-14 from 34).
            ordered = poly[np.lexsort(poly.T[::-1])]
            if previous is not None and np.array_equal(ordered, previous):
                break
            previous = ordered
            if k < horizon - 1:
                poly = _clip(poly, angle_max)
        nxt = np.roll(poly, -1, axis=0)
        normals = np.stack([nxt[:, 1] - poly[:, 1], poly[:, 0] - nxt[:, 0]], axis=1)
        facets = normals / np.einsum("ij,ij->i", normals, poly)[:, None]
    facets.setflags(write=False)
    return facets


class FlywheelFeasibility:
    """Whether Eq. (17) is feasible from a state, exactly: the gauge of S_N (module docstring).

    Parameters
    ----------
    params : BodyParams
        I, τmax and θmax (τmax > 0, see :meth:`applies`).
    settings : MPCSettings
        dt and N.
    """

    __slots__ = ("_braking", "facets")

    def __init__(self, params: BodyParams, settings: MPCSettings) -> None:
        require_type("params", params, BodyParams)
        require_type("settings", settings, MPCSettings)
        self.facets = viable_facets(
            params.flywheel_inertia, params.torque_max, params.flywheel_angle_max,
            settings.dt, settings.horizon,
        )  # fmt: skip
        dt, inertia = settings.dt, params.flywheel_inertia
        self._braking = (
            0.5 * dt * dt / inertia, dt / inertia, dt, params.torque_max,
            params.flywheel_angle_max, settings.horizon,
        )  # fmt: skip

    def forced_braking(self, state: FloatArray) -> tuple[int, int]:
        """Return (k, side): full braking forced on the first k stages (k = 0: none).

        On the boundary of S_N (γ = 1) the only plans that keep abs(θ) ≤ θmax brake at full
        torque until the flywheel stops: from s_0, τ_i = side τmax with side = −sign θ̇_0
        brings θ to its peak θ_k, which is the bound ±θmax itself; any less braking at any of
        the first k stages would carry θ_k beyond it (θ_k increases with every τ_i, i < k,
        by h + (k − 1 − i) dt g > 0 per unit). k is that peak's stage if it lies within
        1e-9 of θmax (or beyond, by up to BAND), else 0.
        """
        h, g, dt, torque, limit, horizon = self._braking
        theta, rate = float(state[1]), float(state[3])
        if rate == 0.0:
            return 0, 0
        side = -1 if rate > 0.0 else 1
        direction = -side  # the sign of the threatened bound
        peak, peak_stage = -math.inf, 0
        for k in range(1, horizon + 1):
            theta, rate = theta + dt * rate + h * side * torque, rate + g * side * torque
            if direction * theta > peak:
                peak, peak_stage = direction * theta, k
            if direction * rate <= 0.0:
                break
        if limit * (1.0 - BOUNDARY) <= peak <= limit * (1.0 + BAND):
            return peak_stage, side
        return 0, 0

    @staticmethod
    def applies(params: BodyParams) -> bool:
        """Tell whether S_N has an interior (τmax > 0, finite θmax > 0)."""
        return params.torque_max > 0.0 and 0.0 < params.flywheel_angle_max < math.inf

    def gauge(self, state: FloatArray) -> float:
        """γ(θ_0, θ̇_0) of ``state`` = [x, θ, ẋ, θ̇]: feasible exactly when <= 1.

        The smallest t for which the QP with bounds t τmax and t θmax is feasible.
        """
        return max(0.0, float((self.facets @ state[1::2]).max()))
