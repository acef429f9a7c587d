r"""A loop's latency: the capture point moves on while the command waits.

With the CoP held at p during the latency τ, the LIPM (Eq. 23, ẍ = ω²(x − p)) gives
ξ̇ = ẋ + ẍ/ω = ω(ξ − p), so ξ(τ) = p + (ξ(0) − p) e^{ωτ}: the offset from the held CoP grows
by e^{ωτ}, mean and standard deviation alike (docs/uncertainty.md).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    finite_array,
    non_negative_float,
    positive_float,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError

__all__ = [
    "LATENCY_NODES",
    "MAX_LATENCY_GROWTH",
    "delayed_capture_point",
    "latency_growth",
    "latency_nodes",
]

FloatArray = NDArray[np.float64]

#: Gauss–Legendre nodes over a latency range.
LATENCY_NODES = 16
#: Largest e^{ωτ} a latency may give (beyond it the state is long gone: refused).
MAX_LATENCY_GROWTH = 1e6


def delayed_capture_point(
    mean: ArrayLike, cov: ArrayLike, omega: float, latency: float, cop: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Return the mean and covariance of ξ(τ) = p + (ξ − p) e^{ωτ} (module docstring).

    Parameters
    ----------
    mean : array_like, shape (d,)
        Mean of ξ when measured [m], d = 1 or 2.
    cov : array_like, shape (d, d)
        Its covariance [m²].
    omega : float
        sqrt(g / L) [1/s], > 0.
    latency : float
        τ [s], >= 0, with e^{ωτ} <= :data:`MAX_LATENCY_GROWTH`.
    cop : array_like, shape (d,)
        The CoP p held during the latency [m].
    """
    omega = positive_float("omega", omega, "1/s")
    growth = latency_growth(omega, non_negative_float("latency", latency, "s"))
    p, mu, sigma = finite_array("cop", cop), finite_array("mean", mean), finite_array("cov", cov)
    d = mu.shape[-1] if mu.ndim else 0
    try:  # one state (d,) or many (n, d), d = 1 or 2
        agree = d in (1, 2) and sigma.shape[-2:] == (d, d) and p.shape[-1:] in ((d,), ())
        agree = agree and len(np.broadcast_shapes(p.shape, mu.shape, sigma.shape[:-1])) > 0
    except ValueError:
        agree = False
    if not agree:
        raise InvalidParameterError(
            f"mean (..., d), cop (..., d) and cov (..., d, d) must agree, d = 1 or 2, got "
            f"shapes {mu.shape}, {p.shape} and {sigma.shape}"
        )
    return p + (mu - p) * growth, sigma * growth**2


def latency_growth(omega: float, tau: float) -> float:
    """Return e^{ωτ} for ω [1/s] and τ [s], refused beyond :data:`MAX_LATENCY_GROWTH`."""
    omega = positive_float("omega", omega, "1/s")
    tau = non_negative_float("latency", tau, "s")
    growth = math.exp(omega * tau) if omega * tau < 700.0 else math.inf
    if growth > MAX_LATENCY_GROWTH:
        raise InvalidParameterError(
            f"latency must keep e^(omega tau) <= {MAX_LATENCY_GROWTH:g} (tau <= "
            f"{math.log(MAX_LATENCY_GROWTH) / omega:.3g} s for omega = {omega:.3g} 1/s), "
            f"got {tau!r} s"
        )
    return growth


def latency_nodes(
    latency: float | tuple[float, float], nodes: int = LATENCY_NODES
) -> tuple[FloatArray, FloatArray]:
    """Return the nodes [s] and weights (sum 1) of a latency: one, or Gauss–Legendre on a range.

    ``nodes``: the Gauss–Legendre order on a range, in [1, 100] (an eigenvalue problem of that
    size: beyond 100 nodes the weights gain nothing and the work grows as its cube).
    """
    nodes = whole_number("nodes", nodes, 1, 100)
    if isinstance(latency, tuple | list):
        if len(latency) != 2:
            raise InvalidParameterError(
                f"latency must be a number or a range (low, high) [s], got {latency!r}"
            )
        low = non_negative_float("latency[0]", latency[0], "s")
        high = non_negative_float("latency[1]", latency[1], "s")
        if not low <= high:
            raise InvalidParameterError(
                f"latency range must have low <= high [s], got ({low}, {high})"
            )
        if low == high:
            return np.array([low]), np.array([1.0])
        x, w = np.polynomial.legendre.leggauss(nodes)
        return low + (x + 1.0) * 0.5 * (high - low), 0.5 * w
    return np.array([non_negative_float("latency", latency, "s")]), np.array([1.0])
