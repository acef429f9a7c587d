r"""Compiled (numba, cached on disk) interior point for the sparse Eq. (17), Riccati steps.

One file on purpose (numba's disk cache does not see changes in the files of called kernels).
See :mod:`~pushrecovery.control.mpc.interior` for the method; here, the arithmetic.

Conventions as in :mod:`~pushrecovery.control.mpc._riccati_kernels`: stage i = 0..N−1 maps
(x_i, u_i) to x_{i+1} = A x_i + B u_i at cost x_{i+1}^T diag(wx_i) x_{i+1} + u_i^T diag(wu_i) u_i.
Three bounded components per stage, j = 0 the CoP δ_i = u_i[0], j = 1 the torque τ_i = u_i[1],
j = 2 the flywheel angle θ_{i+1} = x_{i+1}[1], each lo_j ≤ v ≤ hi_j. Slacks s⁻ = v − lo,
s⁺ = hi − v ≥ 0 with multipliers z⁻, z⁺ ≥ 0; ν_i is the multiplier of the dynamics row
x_{i+1} − A x_i − B u_i = 0. The Lagrangian's gradient (the dual residual r_d):

.. math::

    u_i:\; 2 W^u_i u_i − B^T ν_i − z^-_{i,0:2} + z^+_{i,0:2}, \qquad
    x_{i+1}:\; 2 W^x_i x_{i+1} + ν_i − A^T ν_{i+1} − e_θ (z^-_{i,2} − z^+_{i,2}),

with ν_N = 0. The iterate satisfies the dynamics exactly (it starts from a simulation and
every Newton step does), so there is no primal residual of the equalities.
"""

from __future__ import annotations

import numba
import numpy as np

# Step-to-boundary fraction of Mehrotra's method.
_FRACTION = 0.99
# A start's slacks are at least this fraction of their range, its products s z this fraction
# of dual scale × range: cold (the unconstrained solution) and warm (the last tick's plan
# shifted, near the solution: closer to the boundary, less centred; 13 iterations to a
# verified set instead of 20 in the benchmark's runs).
COLD, WARM = 1, 2
_FLOOR = (0.0, 0.1, 0.01)
_CENTRE = (0.0, 1.0, 0.01)
# A warm start's rows at a bound in the last verified active set (shifted): slack at most this
# fraction of the range, product s z this fraction of dual scale × range (the benchmark's
# interior-point ticks: 15.5 iterations on average and 22 at most to a verified set without,
# 12.4 and 15 with).
_GUIDE_FLOOR, _GUIDE_CENTRE = 0.003, 3.0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _value(u, x, i, j):  # type: ignore[no-untyped-def]
    """Return the bounded component j of stage i: δ_i, τ_i or θ_{i+1}."""
    if j < 2:
        return u[i, j]
    return x[i + 1, 1]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _advance(a, b, x, u, i):  # type: ignore[no-untyped-def]
    """Write x[i + 1] = A x[i] + B u[i] (the dynamics, Eq. 16 discretised)."""
    for r in range(4):
        acc = b[r, 0] * u[i, 0] + b[r, 1] * u[i, 1]
        for c in range(4):
            acc += a[r, c] * x[i, c]
        x[i + 1, r] = acc


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _residuals(  # type: ignore[no-untyped-def]
    a, b, wx, wu, bounds, u, x, nu, sl, su, zl, zu, rdu, rdx, rl, ru, mdu, mdx
):
    """Dual residual (rdu, rdx) and the slacks' residuals rl = v − lo − s⁻, ru = hi − v − s⁺.

    ``mdu``, ``mdx``: the sums of the absolute values of the dual residual's terms, its
    rounding scale (a falling state's early costates and multipliers are 1e11 times the
    stage's own dual scale, and their difference is known to no better than 1e-16 of them).
    """
    n = u.shape[0]
    for i in range(n):
        for c in range(2):
            term = 2.0 * wu[i, c] * u[i, c]
            acc = term - zl[i, c] + zu[i, c]
            size = abs(term) + zl[i, c] + zu[i, c]
            for r in range(4):
                acc -= b[r, c] * nu[i, r]
                size += abs(b[r, c] * nu[i, r])
            rdu[i, c] = acc
            mdu[i, c] = size
        for c in range(4):
            term = 2.0 * wx[i, c] * x[i + 1, c]
            acc = term + nu[i, c]
            size = abs(term) + abs(nu[i, c])
            if i + 1 < n:
                for r in range(4):
                    acc -= a[r, c] * nu[i + 1, r]
                    size += abs(a[r, c] * nu[i + 1, r])
            rdx[i, c] = acc
            mdx[i, c] = size
        rdx[i, 1] += zu[i, 2] - zl[i, 2]
        mdx[i, 1] += zu[i, 2] + zl[i, 2]
        for j in range(3):
            v = _value(u, x, i, j)
            rl[i, j] = v - bounds[j, 0] - sl[i, j]
            ru[i, j] = bounds[j, 1] - v - su[i, j]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _newton(  # type: ignore[no-untyped-def]
    a, b, wx, wu, sl, su, zl, zu, rdu, rdx, rl, ru, cl, cu, factor,
    big_s, gain, hinv, vec_s, sbs, closeds, off, rdiag, du, dx, dnu, dsl, dsu, dzl, dzu,
):  # fmt: skip
    r"""One Newton direction for the complementarity targets s⁻z⁻ + Δ = cl (and cu).

    Eliminating the slacks and bound multipliers leaves an equality-constrained LQ problem in
    (Δu, Δx) with the diagonal cost 2W + Σ (Σ = z⁻/s⁻ + z⁺/s⁺ on the bounded components) and
    the linear term r_d − [(cl − z⁻ rl)/s⁻ − (cu − z⁺ ru)/s⁺] (bounded components),
    Δx_0 = 0, solved by a Riccati recursion: S_{i+1}, s_{i+1} the cost-to-go of x_{i+1},
    H = R̃_i + B^T S B, Δu_i = K_i Δx_i + k_i with K = −H⁻¹ B^T S A and
    k = −H⁻¹ (g_u + B^T s), and S_i, s_i in Joseph's form (in the code). The dynamics'
    multipliers change by Δν_i = −(S_{i+1} Δx_{i+1} + s_{i+1}). With ``factor`` False the
    matrices (S, K, H⁻¹, S B, A_K) of the last call are reused: only the right-hand side
    changed (Mehrotra's corrector).
    """
    n = du.shape[0]
    sa = np.empty((4, 4))
    h = np.empty((2, 2))
    g = np.empty((2, 4))
    gu = np.empty(2)
    lin_u = np.empty(2)
    sbk = np.empty(4)
    # Cost-to-go of x_N: its own stage cost only.
    i = n - 1
    for r in range(4):
        vec_s[n, r] = rdx[i, r]
    vec_s[n, 1] -= (cl[i, 2] - zl[i, 2] * rl[i, 2]) / sl[i, 2] - (
        cu[i, 2] - zu[i, 2] * ru[i, 2]
    ) / su[i, 2]
    if factor:
        for r in range(4):
            for c in range(4):
                big_s[n, r, c] = 0.0
            big_s[n, r, r] = 2.0 * wx[i, r]
        big_s[n, 1, 1] += zl[i, 2] / sl[i, 2] + zu[i, 2] / su[i, 2]
    for i in range(n - 1, -1, -1):
        s = big_s[i + 1]
        sb = sbs[i]
        closed = closeds[i]
        if factor:
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
                rdiag[i, r] = 2.0 * wu[i, r] + zl[i, r] / sl[i, r] + zu[i, r] / su[i, r]
                h[r, r] += rdiag[i, r]
                for c in range(4):
                    acc = 0.0
                    for q in range(4):
                        acc += b[q, r] * sa[q, c]
                    g[r, c] = acc
            det = h[0, 0] * h[1, 1] - h[0, 1] * h[1, 0]
            hinv[i, 0, 0], hinv[i, 1, 1] = h[1, 1] / det, h[0, 0] / det
            hinv[i, 0, 1] = hinv[i, 1, 0] = -h[0, 1] / det
            for r in range(2):
                for c in range(4):
                    gain[i, r, c] = -(hinv[i, r, 0] * g[0, c] + hinv[i, r, 1] * g[1, c])
        # The linear term of u_i (without B^T s), the feed-forward k_i.
        for r in range(2):
            lin_u[r] = (
                rdu[i, r]
                - (cl[i, r] - zl[i, r] * rl[i, r]) / sl[i, r]
                + (cu[i, r] - zu[i, r] * ru[i, r]) / su[i, r]
            )
            acc = lin_u[r]
            for q in range(4):
                acc += b[q, r] * vec_s[i + 1, q]
            gu[r] = acc
        for r in range(2):
            off[i, r] = -(hinv[i, r, 0] * gu[0] + hinv[i, r, 1] * gu[1])
        if i == 0:
            break
        # x_i's cost-to-go under u = K x + k, in Joseph's form (a sum of positive semidefinite
        # terms: the shortcut A^T S A + G^T K loses definiteness to rounding at N = 200):
        # S_i = Q̃_{i−1} + A_K^T S A_K + K^T R̃ K, s_i = g_{x,i−1} + A_K^T (S B k + s) +
        # K^T (R̃ k + g_u), A_K = A + B K.
        if factor:
            for r in range(4):
                for c in range(4):
                    closed[r, c] = a[r, c] + b[r, 0] * gain[i, 0, c] + b[r, 1] * gain[i, 1, c]
        for r in range(4):
            sbk[r] = vec_s[i + 1, r] + sb[r, 0] * off[i, 0] + sb[r, 1] * off[i, 1]
        rk0 = rdiag[i, 0] * off[i, 0] + lin_u[0]
        rk1 = rdiag[i, 1] * off[i, 1] + lin_u[1]
        for r in range(4):
            acc = gain[i, 0, r] * rk0 + gain[i, 1, r] * rk1 + rdx[i - 1, r]
            for q in range(4):
                acc += closed[q, r] * sbk[q]
            vec_s[i, r] = acc
        vec_s[i, 1] -= (cl[i - 1, 2] - zl[i - 1, 2] * rl[i - 1, 2]) / sl[i - 1, 2] - (
            cu[i - 1, 2] - zu[i - 1, 2] * ru[i - 1, 2]
        ) / su[i - 1, 2]
        if factor:
            for r in range(4):
                for c in range(4):
                    sa[r, c] += sb[r, 0] * gain[i, 0, c] + sb[r, 1] * gain[i, 1, c]  # S A_K
            nxt = big_s[i]
            for r in range(4):
                for c in range(r, 4):
                    acc = (
                        rdiag[i, 0] * gain[i, 0, r] * gain[i, 0, c]
                        + rdiag[i, 1] * gain[i, 1, r] * gain[i, 1, c]
                    )
                    for q in range(4):
                        acc += closed[q, r] * sa[q, c]
                    nxt[r, c] = acc
                    nxt[c, r] = acc
                nxt[r, r] += 2.0 * wx[i - 1, r]
            nxt[1, 1] += zl[i - 1, 2] / sl[i - 1, 2] + zu[i - 1, 2] / su[i - 1, 2]
    # Forward: Δx_0 = 0.
    for c in range(4):
        dx[0, c] = 0.0
    for i in range(n):
        for r in range(2):
            acc = off[i, r]
            for c in range(4):
                acc += gain[i, r, c] * dx[i, c]
            du[i, r] = acc
        _advance(a, b, dx, du, i)
        for r in range(4):
            acc = vec_s[i + 1, r]
            for c in range(4):
                acc += big_s[i + 1, r, c] * dx[i + 1, c]
            dnu[i, r] = -acc
        for j in range(3):
            dv = du[i, j] if j < 2 else dx[i + 1, 1]
            dsl[i, j] = dv + rl[i, j]
            dsu[i, j] = -dv + ru[i, j]
            dzl[i, j] = (cl[i, j] - zl[i, j] * dsl[i, j]) / sl[i, j]
            dzu[i, j] = (cu[i, j] - zu[i, j] * dsu[i, j]) / su[i, j]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _max_step(values, steps):  # type: ignore[no-untyped-def]
    """Largest α ≤ 1 with values + α steps ≥ 0 (values > 0)."""
    alpha = 1.0
    n, m = values.shape
    for i in range(n):
        for j in range(m):
            if steps[i, j] < 0.0:
                alpha = min(alpha, -values[i, j] / steps[i, j])
    return alpha


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _start(x0, a, b, bounds, scale, feedback, u, x, nu, sl, su, zl, zu, start, guide):  # type: ignore[no-untyped-def]
    """Write a start from x0: ``start`` COLD or WARM (the inputs already in ``u``).

    COLD: the unconstrained problem's solution, whatever its bounds (inputs by its feedback,
    states simulated: bounded, where a saturated or open-loop guess lets a falling state grow
    as e^{ω t} and the iterations then stall). WARM: the inputs given, states simulated. Slacks
    at least a fraction of their range (an infeasible start), products s z a fraction of the
    bound's dual scale × range (``_FLOOR``, ``_CENTRE``). WARM also takes ``guide`` (N, 3),
    the last verified active set (unshifted; zeros: none): its rows start near their bounds
    with larger multipliers (``_GUIDE_FLOOR``, ``_GUIDE_CENTRE``).
    """
    floor, centre = _FLOOR[start], _CENTRE[start]
    n = u.shape[0]
    for c in range(4):
        x[0, c] = x0[c]
    for i in range(n):
        if start == COLD:
            for r in range(2):
                acc = 0.0
                for c in range(4):
                    acc += feedback[i, r, c] * x[i, c]
                u[i, r] = acc
        _advance(a, b, x, u, i)
        for r in range(4):
            nu[i, r] = 0.0
        for j in range(3):
            v = _value(u, x, i, j)
            span = bounds[j, 1] - bounds[j, 0]
            sl[i, j] = max(v - bounds[j, 0], floor * span)
            su[i, j] = max(bounds[j, 1] - v, floor * span)
            zl[i, j] = centre * scale[i, j] / sl[i, j] * span
            zu[i, j] = centre * scale[i, j] / su[i, j] * span
            if start == WARM:
                side = guide[i + 1, j] if i + 1 < n else guide[i, j]  # shifted by a stage
                if side < 0:
                    sl[i, j] = min(sl[i, j], _GUIDE_FLOOR * span)
                    zl[i, j] = _GUIDE_CENTRE * scale[i, j] / sl[i, j] * span
                elif side > 0:
                    su[i, j] = min(su[i, j], _GUIDE_FLOOR * span)
                    zu[i, j] = _GUIDE_CENTRE * scale[i, j] / su[i, j] * span


@numba.njit(cache=True, nogil=True, error_model="numpy")
def solve_interior(  # type: ignore[no-untyped-def]
    x0, a, b, wx, wu, bounds, scale, feedback, tol, dual_tol, max_iter, start, guide,
    u, x, nu, sl, su, zl, zu, work, big_s, gain, hinv, vec_s, sbs, closeds,
):  # fmt: skip
    """Mehrotra predictor-corrector iterations; their number if converged, else −1 or −2.

    ``feedback`` (N, 2, 4) is the unconstrained problem's time-varying gain (:func:`dual_scales`).
    ``start``: COLD or WARM from :func:`_start`'s point, 0: continue from the iterate in the arrays
    (u, x, ν, slacks and multipliers of a previous call). −2: not converged in ``max_iter``
    (the iterate is left to continue from); −1: the iterate is no longer finite (an
    infeasible problem diverges).

    ``scale`` (N, 7) holds each stage's dual scales: columns 0-2 those of the bounded
    components (the multiplier that would move it by its whole range, see the wrapper),
    3-6 those of the stationarity rows of x_{i+1}. Converged when every slack residual is
    within ``tol`` of its range, every stationarity residual within ``dual_tol`` of its scale
    or of its terms' size and every complementarity product within ``tol`` of scale × range.
    ``work`` is (17, N + 1, 4) scratch.
    """
    n = u.shape[0]
    rdu, rdx, rl, ru = work[0, :n, :2], work[1, :n], work[2, :n, :3], work[3, :n, :3]
    cl, cu = work[4, :n, :3], work[5, :n, :3]
    du, dx, dnu = work[6, :n, :2], work[7], work[8, :n]
    dsl, dsu, dzl, dzu = work[9, :n, :3], work[10, :n, :3], work[11, :n, :3], work[12, :n, :3]
    off, rdiag = work[13, :n, :2], work[14, :n, :2]
    mdu, mdx = work[15, :n, :2], work[16, :n]
    if start:
        _start(x0, a, b, bounds, scale, feedback, u, x, nu, sl, su, zl, zu, start, guide)
    for it in range(max_iter):
        _residuals(a, b, wx, wu, bounds, u, x, nu, sl, su, zl, zu, rdu, rdx, rl, ru, mdu, mdx)
        mu = 0.0
        done = True
        for i in range(n):
            for j in range(3):
                span = bounds[j, 1] - bounds[j, 0]
                mu += sl[i, j] * zl[i, j] + su[i, j] * zu[i, j]
                if max(abs(rl[i, j]), abs(ru[i, j])) > tol * span:
                    done = False
                if max(sl[i, j] * zl[i, j], su[i, j] * zu[i, j]) > tol * scale[i, j] * span:
                    done = False
                if j < 2 and abs(rdu[i, j]) > dual_tol * max(scale[i, j], mdu[i, j]):
                    done = False
            for c in range(4):
                if abs(rdx[i, c]) > dual_tol * max(scale[i, 3 + c], mdx[i, c]):
                    done = False
        if not np.isfinite(mu):
            return -1
        if done:
            return it
        mu /= 6 * n
        # Predictor (affine scaling).
        for i in range(n):
            for j in range(3):
                cl[i, j] = -sl[i, j] * zl[i, j]
                cu[i, j] = -su[i, j] * zu[i, j]
        _newton(a, b, wx, wu, sl, su, zl, zu, rdu, rdx, rl, ru, cl, cu, True,
                big_s, gain, hinv, vec_s, sbs, closeds, off, rdiag, du, dx, dnu, dsl, dsu, dzl,
                dzu)  # fmt: skip
        alpha = min(_max_step(sl, dsl), _max_step(su, dsu))
        alpha = min(alpha, _max_step(zl, dzl), _max_step(zu, dzu))
        mu_aff = 0.0
        for i in range(n):
            for j in range(3):
                mu_aff += (sl[i, j] + alpha * dsl[i, j]) * (zl[i, j] + alpha * dzl[i, j])
                mu_aff += (su[i, j] + alpha * dsu[i, j]) * (zu[i, j] + alpha * dzu[i, j])
        sigma = (mu_aff / (6 * n) / mu) ** 3
        # Corrector: centring and the second-order term, same matrices.
        for i in range(n):
            for j in range(3):
                cl[i, j] = sigma * mu - sl[i, j] * zl[i, j] - dsl[i, j] * dzl[i, j]
                cu[i, j] = sigma * mu - su[i, j] * zu[i, j] - dsu[i, j] * dzu[i, j]
        _newton(a, b, wx, wu, sl, su, zl, zu, rdu, rdx, rl, ru, cl, cu, False,
                big_s, gain, hinv, vec_s, sbs, closeds, off, rdiag, du, dx, dnu, dsl, dsu, dzl,
                dzu)  # fmt: skip
        primal = min(1.0, _FRACTION * min(_max_step(sl, dsl), _max_step(su, dsu)))
        dual = min(1.0, _FRACTION * min(_max_step(zl, dzl), _max_step(zu, dzu)))
        for i in range(n):
            for r in range(2):
                u[i, r] += primal * du[i, r]
            for r in range(4):
                x[i + 1, r] += primal * dx[i + 1, r]
                nu[i, r] += dual * dnu[i, r]
            for j in range(3):
                sl[i, j] += primal * dsl[i, j]
                su[i, j] += primal * dsu[i, j]
                zl[i, j] += dual * dzl[i, j]
                zu[i, j] += dual * dzu[i, j]
    return -2
