r"""Compiled (numba, cached on disk) primal-dual active-set solve of Eq. (17) by Riccati recursion.

One file on purpose: numba's disk cache does not see changes in the files of the functions a
kernel calls, so the kernels that call each other live together. See
:mod:`~pushrecovery.control.mpc.riccati` for the method; here, the arithmetic.

Conventions. Stage i = 0..N−1 maps (x_i, u_i) to x_{i+1} = A x_i + B u_i at cost
x_{i+1}^T diag(wx_i) x_{i+1} + u_i^T diag(wu_i) u_i. Each stage has three constraint rows,
``active[i, j]`` ∈ {−1 (at its lower bound), 0 (inactive), +1 (at its upper bound)}:
j = 0 the CoP δ_i, j = 1 the torque τ_i, j = 2 the flywheel angle θ_{i+1} = A_θ x_i + B_θ u_i.
Multipliers enter the stationarity conditions with a + sign (``mult * side >= 0`` is optimal):

.. math::

    2\,\mathrm{diag}(wu_i)\,u_i + B^T λ_{i+1} + μ_i = 0, \qquad
    λ_{i+1} = 2\,\mathrm{diag}(wx_i)\,x_{i+1} + A^T λ_{i+2} + ν_{i+1} e_θ, \quad λ_{N+1} = 0.
"""

from __future__ import annotations

import numba
import numpy as np

# Outcomes of one pass of :func:`_pass`.
OPTIMAL, CHANGED, DEGENERATE = 0, 1, -1


@numba.njit(cache=True, nogil=True)
def _stage_rows(b, i, active, bounds, d, e, which):  # type: ignore[no-untyped-def]
    """Active rows of stage i as d^T u + [θ row: A_θ x] = e; their count (3: degenerate)."""
    m = 0
    for j in range(3):
        side = active[i, j]
        if side == 0:
            continue
        e[m] = bounds[j, 1] if side > 0 else bounds[j, 0]
        if j == 0:
            d[m, 0], d[m, 1] = 1.0, 0.0
        elif j == 1:
            d[m, 0], d[m, 1] = 0.0, 1.0
        else:
            d[m, 0], d[m, 1] = b[1, 0], b[1, 1]
        which[m] = j
        m += 1
    return m


@numba.njit(cache=True, nogil=True)
def _backward(a, b, wx, wu, active, bounds, gains, offsets, curvature):  # type: ignore[no-untyped-def]
    """Riccati recursion with the active rows as equalities; False if a stage is degenerate.

    Writes u_i = gains[i] x_i + offsets[i] and the diagonal of the stage's input Hessian
    H = diag(wu_i) + B^T S_{i+1} B (the scale of its multipliers) into ``curvature[i]``.
    Per stage, with S = P_{i+1} + diag(wx_i), s = p_{i+1} (cost-to-go x^T P x + 2 p^T x):
    u = T z + F x + f (the active rows fix F, f; T spans the free directions), z minimises
    T^T [H u + B^T S A x + B^T s] = 0, and P_i = A^T S A + G^T K + K^T G + K^T H K,
    p_i = A^T (S B k + s) + K^T (H k + B^T s) with G = B^T S A and u = K x + k.
    """
    n = wx.shape[0]
    cost = np.zeros((4, 4))
    lin = np.zeros(4)
    s = np.empty((4, 4))
    sb = np.empty((4, 2))
    sa = np.empty((4, 4))
    h = np.empty((2, 2))
    g = np.empty((2, 4))
    hs = np.empty(2)
    feed = np.empty((2, 4))
    ff = np.empty(2)
    t = np.empty(2)
    d = np.empty((3, 2))
    e = np.empty(3)
    which = np.empty(3, dtype=np.int64)
    for i in range(n - 1, -1, -1):
        for r in range(4):
            for c in range(4):
                s[r, c] = cost[r, c]
            s[r, r] += wx[i, r]
        for r in range(4):
            for c in range(2):
                acc = 0.0
                for q in range(4):
                    acc += s[r, q] * b[q, c]
                sb[r, c] = acc
            for c in range(4):
                acc = 0.0
                for q in range(4):
                    acc += s[r, q] * a[q, c]
                sa[r, c] = acc
        for r in range(2):
            for c in range(2):
                acc = 0.0
                for q in range(4):
                    acc += b[q, r] * sb[q, c]
                h[r, c] = acc
            h[r, r] += wu[i, r]
            for c in range(4):
                acc = 0.0
                for q in range(4):
                    acc += b[q, r] * sa[q, c]
                g[r, c] = acc
            acc = 0.0
            for q in range(4):
                acc += b[q, r] * lin[q]
            hs[r] = acc
        curvature[i, 0], curvature[i, 1] = h[0, 0], h[1, 1]
        m = _stage_rows(b, i, active, bounds, d, e, which)
        feed[:, :] = 0.0
        ff[:] = 0.0
        if m == 0:
            det = h[0, 0] * h[1, 1] - h[0, 1] * h[1, 0]
            for c in range(4):
                gains[i, 0, c] = -(h[1, 1] * g[0, c] - h[0, 1] * g[1, c]) / det
                gains[i, 1, c] = -(h[0, 0] * g[1, c] - h[1, 0] * g[0, c]) / det
            offsets[i, 0] = -(h[1, 1] * hs[0] - h[0, 1] * hs[1]) / det
            offsets[i, 1] = -(h[0, 0] * hs[1] - h[1, 0] * hs[0]) / det
        else:
            if m == 1:
                norm2 = d[0, 0] * d[0, 0] + d[0, 1] * d[0, 1]
                for r in range(2):
                    ff[r] = d[0, r] * e[0] / norm2
                    if which[0] == 2:
                        for c in range(4):
                            feed[r, c] = -d[0, r] * a[1, c] / norm2
                t[0], t[1] = -d[0, 1], d[0, 0]
            elif m == 2:
                det = d[0, 0] * d[1, 1] - d[0, 1] * d[1, 0]
                size = abs(d[0, 0] * d[1, 1]) + abs(d[0, 1] * d[1, 0])
                if abs(det) <= 1e-12 * size:
                    return False  # e.g. τ_i and θ_{i+1} both at a bound: a state constraint
                # u = D^{-1} (e − G x), G's rows A_θ for a θ row and 0 otherwise.
                for r in range(2):
                    c0 = (d[1, 1] if r == 0 else -d[1, 0]) / det  # D^{-1}[r, 0]
                    c1 = (-d[0, 1] if r == 0 else d[0, 0]) / det  # D^{-1}[r, 1]
                    ff[r] = c0 * e[0] + c1 * e[1]
                    for c in range(4):
                        gx = 0.0
                        if which[0] == 2:
                            gx += c0 * a[1, c]
                        if which[1] == 2:
                            gx += c1 * a[1, c]
                        feed[r, c] = -gx
            else:
                return False
            if m == 1:
                th0 = h[0, 0] * t[0] + h[0, 1] * t[1]
                th1 = h[1, 0] * t[0] + h[1, 1] * t[1]
                hz = t[0] * th0 + t[1] * th1
                hv = th0 * ff[0] + th1 * ff[1] + t[0] * hs[0] + t[1] * hs[1]
                for c in range(4):
                    gz = th0 * feed[0, c] + th1 * feed[1, c] + t[0] * g[0, c] + t[1] * g[1, c]
                    for r in range(2):
                        gains[i, r, c] = feed[r, c] - t[r] * gz / hz
                for r in range(2):
                    offsets[i, r] = ff[r] - t[r] * hv / hz
            else:
                for r in range(2):
                    offsets[i, r] = ff[r]
                    for c in range(4):
                        gains[i, r, c] = feed[r, c]
        # P_i and p_i of u = K x + k.
        k0, k1 = offsets[i, 0], offsets[i, 1]
        hk0 = h[0, 0] * k0 + h[0, 1] * k1 + hs[0]
        hk1 = h[1, 0] * k0 + h[1, 1] * k1 + hs[1]
        for r in range(4):
            v = sb[r, 0] * k0 + sb[r, 1] * k1 + lin[r]
            e3 = v  # S B k + s, row r
            sb[r, 0] = e3  # reuse: column 0 holds S B k + s now (sb no longer needed)
        for r in range(4):
            acc = gains[i, 0, r] * hk0 + gains[i, 1, r] * hk1
            for q in range(4):
                acc += a[q, r] * sb[q, 0]
            lin[r] = acc
        for r in range(4):
            kh0 = gains[i, 0, r] * h[0, 0] + gains[i, 1, r] * h[1, 0]
            kh1 = gains[i, 0, r] * h[0, 1] + gains[i, 1, r] * h[1, 1]
            for c in range(r, 4):
                acc = 0.0
                for q in range(4):
                    acc += a[q, r] * sa[q, c]
                acc += g[0, r] * gains[i, 0, c] + g[1, r] * gains[i, 1, c]
                acc += gains[i, 0, r] * g[0, c] + gains[i, 1, r] * g[1, c]
                acc += kh0 * gains[i, 0, c] + kh1 * gains[i, 1, c]
                cost[r, c] = acc
                cost[c, r] = acc
    return True


@numba.njit(cache=True, nogil=True)
def _pass(  # type: ignore[no-untyped-def]
    x0,
    a,
    b,
    wx,
    wu,
    active,
    bounds,
    tols,
    dual_tol,
    inputs,
    states,
    gains,
    offsets,
    curvature,
    mult,
):
    """Solve with ``active`` fixed, check the KKT conditions, update ``active`` if they fail.

    Returns OPTIMAL (``inputs``, ``states`` are the exact solution), CHANGED (``active`` now
    holds the next guess) or DEGENERATE. The next guess adds the violated rows; only when
    none is violated does it release the rows whose multipliers have the wrong sign.
    """
    n = wx.shape[0]
    if not _backward(a, b, wx, wu, active, bounds, gains, offsets, curvature):
        return DEGENERATE
    for c in range(4):
        states[0, c] = x0[c]
    for i in range(n):
        for r in range(2):
            acc = offsets[i, r]
            for c in range(4):
                acc += gains[i, r, c] * states[i, c]
            inputs[i, r] = acc
        for r in range(4):
            states[i + 1, r] = (
                a[r, 0] * states[i, 0] + a[r, 1] * states[i, 1] + a[r, 2] * states[i, 2]
                + a[r, 3] * states[i, 3] + b[r, 0] * inputs[i, 0] + b[r, 1] * inputs[i, 1]
            )  # fmt: skip
    added = False
    for i in range(n):
        values = (inputs[i, 0], inputs[i, 1], states[i + 1, 1])
        for j in range(3):
            if active[i, j] == 0:
                if values[j] > bounds[j, 1] + tols[j]:
                    active[i, j] = 1
                    added = True
                elif values[j] < bounds[j, 0] - tols[j]:
                    active[i, j] = -1
                    added = True
    if added:
        return CHANGED
    # Costates backward; multipliers of the active rows from the inputs' stationarity.
    d = np.empty((3, 2))
    e = np.empty(3)
    which = np.empty(3, dtype=np.int64)
    after = np.zeros(4)  # λ_{i+2}
    lam = np.empty(4)
    worst, worst_i, worst_j = 0.0, -1, -1
    for i in range(n - 1, -1, -1):
        for r in range(4):
            acc = 2.0 * wx[i, r] * states[i + 1, r]
            for q in range(4):
                acc += a[q, r] * after[q]
            lam[r] = acc
        r0 = -(2.0 * wu[i, 0] * inputs[i, 0])
        r1 = -(2.0 * wu[i, 1] * inputs[i, 1])
        for q in range(4):
            r0 -= b[q, 0] * lam[q]
            r1 -= b[q, 1] * lam[q]
        m = _stage_rows(b, i, active, bounds, d, e, which)
        mult[i, 0], mult[i, 1], mult[i, 2] = 0.0, 0.0, 0.0
        if m == 1:
            norm2 = d[0, 0] * d[0, 0] + d[0, 1] * d[0, 1]
            mult[i, which[0]] = (d[0, 0] * r0 + d[0, 1] * r1) / norm2
        elif m == 2:  # r = m0 d0 + m1 d1
            det = d[0, 0] * d[1, 1] - d[1, 0] * d[0, 1]
            mult[i, which[0]] = (r0 * d[1, 1] - r1 * d[1, 0]) / det
            mult[i, which[1]] = (d[0, 0] * r1 - d[0, 1] * r0) / det
        lam[1] += mult[i, 2]
        for r in range(4):
            after[r] = lam[r]
        for j in range(3):
            side = active[i, j]
            if side == 0:
                continue
            if j < 2:
                scale = curvature[i, j] * (bounds[j, 1] - bounds[j, 0])
            else:
                scale = curvature[i, 1] * (bounds[1, 1] - bounds[1, 0]) / abs(b[1, 1])
            wrong = -mult[i, j] * side / scale
            if wrong > dual_tol and wrong > worst:
                worst, worst_i, worst_j = wrong, i, j
    if worst_i < 0:
        return OPTIMAL
    active[worst_i, worst_j] = 0  # one at a time: releasing a whole block overshoots
    return CHANGED


@numba.njit(cache=True, nogil=True)
def solve_active_set(  # type: ignore[no-untyped-def]
    x0,
    a,
    b,
    wx,
    wu,
    active,
    bounds,
    tols,
    dual_tol,
    max_passes,
    inputs,
    states,
    gains,
    offsets,
    curvature,
    mult,
):
    """Primal-dual active-set iterations from ``active``; the number of passes, or −1.

    On success ``inputs`` (N, 2), ``states`` (N + 1, 4) and ``mult`` (N, 3) are the KKT point
    and ``active`` its active set. −1: degenerate, or no verified optimum within
    ``max_passes`` (cycling, or an infeasible problem).
    """
    for k in range(max_passes):
        outcome = _pass(x0, a, b, wx, wu, active, bounds, tols, dual_tol, inputs, states, gains,
                        offsets, curvature, mult)  # fmt: skip
        if outcome == OPTIMAL:
            return k + 1
        if outcome == DEGENERATE:
            return -1
    return -1


@numba.njit(cache=True, nogil=True)
def solve_from(  # type: ignore[no-untyped-def]
    x0,
    shift,
    active,
    guess,
    a,
    b,
    wx,
    wu,
    bounds,
    tols,
    dual_tol,
    max_passes,
    inputs,
    states,
    gains,
    offsets,
    curvature,
    mult,
):
    """:func:`solve_active_set` started from ``active`` (shifted one stage if ``shift``).

    The passes work on ``guess`` (the start is copied there: ``active[i + 1]`` to stage i,
    the last stage keeping its rows); on success the verified set is copied back into
    ``active``, on failure ``active`` is left as it was. One call per tick, so the Python
    side does no array work.
    """
    n = active.shape[0]
    for i in range(n):
        src = i + 1 if shift and i < n - 1 else i
        for j in range(3):
            guess[i, j] = active[src, j]
    passes = solve_active_set(x0, a, b, wx, wu, guess, bounds, tols, dual_tol, max_passes,
                              inputs, states, gains, offsets, curvature, mult)  # fmt: skip
    if passes > 0:
        for i in range(n):
            for j in range(3):
                active[i, j] = guess[i, j]
    return passes
