"""The risk of each frame: the probability that the ankle does not suffice, from CoM noise.

A CoM signal with independent errors of standard deviation σ at each sample gives, through the
analysis' low-pass and differentiation, a capture point ξ = x + ẋ/ω whose error has the
standard deviation σ_ξ = σ √(g₀² + g₁²/ω²), with the chain's noise gains g₀, g₁
(:func:`~pushrecovery.analysis.signals.noise_gains`; the two errors are uncorrelated for a
zero-phase filter). Along each axis the ankle suffices while ξ lies inside the base's interval
[lower, upper] (Eq. 4), so P(it does not) = 1 − [Φ((upper − ξ)/σ_ξ) − Φ((lower − ξ)/σ_ξ)]
(docs/uncertainty.md).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.special import ndtr

from pushrecovery.analysis.margins import DirectionMargins
from pushrecovery.analysis.signals import noise_gains
from pushrecovery.arguments import non_negative_float, require_type, sample_array
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams

__all__ = ["HERMITE_NODES", "frame_risk"]

FloatArray = NDArray[np.float64]

#: Gauss–Hermite nodes over the CoM height's spread.
HERMITE_NODES = 20


def frame_risk(
    time: FloatArray,
    per_axis: dict[str, DirectionMargins],
    support: Any,
    params: BodyParams,
    com_noise: float | None,
    cutoff: float,
    *,
    state: dict[str, tuple[FloatArray, FloatArray]] | None = None,
    com_height_sd: float | None = None,
) -> dict[str, FloatArray]:
    """Return per axis P(the ankle does not suffice) of every frame (module docstring).

    ``time`` [s] at a constant rate, ``per_axis`` the frames' margins (their capture points
    [m] and CoP margins: NaN where a frame has no verdict, and so is its risk), ``support`` the
    base's ``lower`` and ``upper`` per axis [m], ``com_noise`` σ [m] (None and no
    ``com_height_sd``: no risk, an empty dict), ``cutoff`` the analysis' low-pass [Hz].

    With ``com_height_sd`` σ_L [m] (and ``state``: per axis the frames' CoM and velocity
    [m, m/s]) the CoM height L is normal about the body's with that deviation (an
    anthropometric table's spread): ω = sqrt(g/L) moves ξ = x + ẋ/ω and σ_ξ, and the risk is
    averaged over L by :data:`HERMITE_NODES`-point Gauss–Hermite quadrature.
    """
    time = sample_array("time", time, (1,))
    require_type("params", params, BodyParams)
    require_type("per_axis", per_axis, dict)
    for axis, margins in per_axis.items():
        require_type(f"per_axis[{axis!r}]", margins, DirectionMargins)
        if not all(axis in getattr(support, side, {}) for side in ("lower", "upper")):
            raise ParameterTypeError(f"support must have lower and upper of axis {axis!r}")
    com_noise = None if com_noise is None else non_negative_float("com_noise", com_noise, "m")
    com_height_sd = (
        None if com_height_sd is None else non_negative_float("com_height_sd", com_height_sd, "m")
    )
    cutoff = non_negative_float("cutoff", cutoff, "Hz")
    if state is not None:
        require_type("state", state, dict)
    if (com_noise is None and not com_height_sd) or len(time) < 3:
        return {}
    rate = (len(time) - 1) / (time[-1] - time[0])
    position, slope = noise_gains(rate, cutoff)
    noise = 0.0 if com_noise is None else com_noise
    if com_height_sd and state is not None:
        nodes, weights = np.polynomial.hermite_e.hermegauss(HERMITE_NODES)
        heights = params.com_height + com_height_sd * nodes
        if np.any(heights <= 0.0):
            raise InvalidParameterError(
                f"com_height_sd must leave the CoM height > 0 over the quadrature (its nodes "
                f"reach {float(-nodes.min()):.1f} SD), got {com_height_sd:g} m"
            )
        omegas = np.sqrt(params.gravity / heights)
        weights = weights / weights.sum()
    else:
        omegas, weights = np.array([params.omega]), np.array([1.0])
    found = {}
    for axis, margins in per_axis.items():
        lower, upper = support.lower[axis], support.upper[axis]
        inside = np.zeros(len(time))
        for omega, weight in zip(omegas.tolist(), weights.tolist(), strict=True):
            if state is not None and len(omegas) > 1:
                com, velocity = state[axis]
                xi = com + velocity / omega
            else:
                xi = margins.capture_point
            sd = noise * math.hypot(position, slope / omega)
            if sd == 0.0:
                inside += weight * ((lower < xi) & (xi < upper))
            else:
                inside += weight * (ndtr((upper - xi) / sd) - ndtr((lower - xi) / sd))
        found[axis] = np.where(np.isfinite(margins.cop), 1.0 - inside, np.nan)
    return found
