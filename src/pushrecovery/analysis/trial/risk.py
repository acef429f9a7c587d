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
from pushrecovery.params import BodyParams

__all__ = ["frame_risk"]

FloatArray = NDArray[np.float64]


def frame_risk(
    time: FloatArray,
    per_axis: dict[str, DirectionMargins],
    support: Any,
    params: BodyParams,
    com_noise: float | None,
    cutoff: float,
) -> dict[str, FloatArray]:
    """Return per axis P(the ankle does not suffice) of every frame (module docstring).

    ``time`` [s] at a constant rate, ``per_axis`` the frames' margins (their capture points
    [m] and CoP margins: NaN where a frame has no verdict, and so is its risk), ``support`` the
    base's ``lower`` and ``upper`` per axis [m], ``com_noise`` σ [m] (None: no risk, an
    empty dict), ``cutoff`` the analysis' low-pass [Hz].
    """
    if com_noise is None or len(time) < 3:
        return {}
    rate = (len(time) - 1) / (time[-1] - time[0])
    position, slope = noise_gains(rate, cutoff)
    sd = com_noise * math.hypot(position, slope / params.omega)
    found = {}
    for axis, margins in per_axis.items():
        xi = margins.capture_point
        lower, upper = support.lower[axis], support.upper[axis]
        if sd == 0.0:
            inside = ((lower < xi) & (xi < upper)).astype(np.float64)
        else:
            inside = ndtr((upper - xi) / sd) - ndtr((lower - xi) / sd)
        found[axis] = np.where(np.isfinite(margins.cop), 1.0 - inside, np.nan)
    return found
