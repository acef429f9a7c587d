"""Compiled (numba, cached on disk) dual scales of the interior point.

The scales and feedback of its start (:func:`dual_scales`); the active set of an iterate read
in those scales is :func:`~pushrecovery.kernels.mpc.interior.identify_active`, beside the
iterations that call it. See :mod:`~pushrecovery.control.mpc.solvers.interior`. Apart from the
iterations' kernels (:mod:`~pushrecovery.kernels.mpc.interior`): it calls none of them.
"""

from __future__ import annotations

import numpy as np

from pushrecovery.kernels.jit import njit


@njit(cache=True, nogil=True, inline="always")
def _sandwich(b, s, m, r, c):  # type: ignore[no-untyped-def]
    """(Bᵀ S M)[r, c], summed over q then p as the recursion always has."""
    acc = 0.0
    for q in range(4):
        for p in range(4):
            acc += b[q, r] * s[q, p] * m[p, c]
    return acc


@njit(cache=True, nogil=True, error_model="numpy")
def dual_scales(a, b, wx, wu, bounds, scales, feedback):  # type: ignore[no-untyped-def]
    """Fill ``scales`` (N, 7) and ``feedback`` (N, 2, 4) from the unconstrained problem.

    ``scales``: the bounds' dual scales then the state rows' (see the wrapper); ``feedback``:
    the unconstrained problem's gains (u_i = K_i x_i).

    From the unconstrained problem's Riccati recursion, in Joseph's form (positive
    semidefinite whatever the rounding; the shortcut A^T S A − G^T H⁻¹ G is not, from
    N ≈ 150 on): H = 2 W^u_i + B^T S B, K = −H⁻¹ B^T S A, S ← A_K^T S A_K + K^T 2W^u_i K
    + 2 W^x_{i−1}, A_K = A + B K.
    """
    n = wx.shape[0]
    s = np.zeros((4, 4))
    for r in range(4):
        s[r, r] = 2.0 * wx[n - 1, r]
    h = np.empty((2, 2))
    g = np.empty((2, 4))
    gain = np.empty((2, 4))
    closed = np.empty((4, 4))
    sk = np.empty((4, 4))
    for i in range(n - 1, -1, -1):
        for r in range(2):
            for c in range(4):
                g[r, c] = _sandwich(b, s, a, r, c)
            for c in range(2):
                h[r, c] = _sandwich(b, s, b, r, c)
            h[r, r] += 2.0 * wu[i, r]
        det = h[0, 0] * h[1, 1] - h[0, 1] * h[1, 0]
        for c in range(4):
            gain[0, c] = -(h[1, 1] * g[0, c] - h[0, 1] * g[1, c]) / det
            gain[1, c] = -(h[0, 0] * g[1, c] - h[1, 0] * g[0, c]) / det
        for r in range(2):
            for c in range(4):
                feedback[i, r, c] = gain[r, c]
        for j in range(2):
            scales[i, j] = h[j, j] * (bounds[j, 1] - bounds[j, 0])
        scales[i, 2] = scales[i, 1] / abs(b[1, 1])
        for c in range(4):
            best = np.inf
            for j in range(2):
                if b[c, j] != 0.0:
                    best = min(best, scales[i, j] / abs(b[c, j]))
            scales[i, 3 + c] = best if best < np.inf else min(scales[i, 0], scales[i, 1])
        if i == 0:
            break
        for r in range(4):
            for c in range(4):
                closed[r, c] = a[r, c] + b[r, 0] * gain[0, c] + b[r, 1] * gain[1, c]
        for r in range(4):
            for c in range(4):
                acc = 0.0
                for q in range(4):
                    acc += s[r, q] * closed[q, c]
                sk[r, c] = acc
        for r in range(4):
            for c in range(4):
                acc = 2.0 * wu[i, 0] * gain[0, r] * gain[0, c]
                acc += 2.0 * wu[i, 1] * gain[1, r] * gain[1, c]
                for q in range(4):
                    acc += closed[q, r] * sk[q, c]
                s[r, c] = acc
            s[r, r] += 2.0 * wx[i - 1, r]
