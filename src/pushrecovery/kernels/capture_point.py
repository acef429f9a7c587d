r"""The capture-point margin of Eq. (4) of [Stephens07] over many states, one fused pass.

margin_i = h − |x_i + ẋ_i/ω − c| [m], with c and h the centre and half width of the capture
interval; positive inside. Called by :func:`pushrecovery.surfaces.cop.capture_margin` for large
arrays (one multithreaded pass instead of five numpy passes).
"""

from __future__ import annotations

import math

from pushrecovery.kernels.jit import njit, prange

__all__ = ["capture_margins"]


@njit(parallel=True, cache=True, nogil=True)
def capture_margins(x, xdot, inv_omega, centre, half, out):  # type: ignore[no-untyped-def]
    """Write each state's margin into ``out``; return how many are not finite."""
    bad = 0
    for i in prange(x.shape[0]):
        margin = half - abs(x[i] + xdot[i] * inv_omega - centre)
        out[i] = margin
        if not math.isfinite(margin):
            bad += 1
    return bad
