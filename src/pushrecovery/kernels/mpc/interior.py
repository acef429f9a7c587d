r"""Compiled (numba, cached on disk) interior point for the sparse Eq. (17), Riccati steps.

One file on purpose (numba's disk cache does not see changes in the files of called kernels).
See :mod:`~pushrecovery.control.mpc.solvers.interior` for the method; here, the arithmetic.

Conventions as in :mod:`~pushrecovery.kernels.mpc.riccati`: stage i = 0..N−1 maps
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

A and B have the flywheel's structure
(checked by :class:`~pushrecovery.control.mpc.problem.SparseQP`): the CoM (x, ẋ) and the flywheel
(θ, θ̇) evolve apart, A block-diagonal in that split, and the CoP moves the CoM only (B's δ
column zero on θ, θ̇). The products skip those zeros, term by term the same sums.

Over 400 lines on purpose: one kernel (the interior point), its start, Newton step, line search
and shift of an iterate sharing one iterate layout.
"""

from __future__ import annotations

import numpy as np

from pushrecovery.kernels.jit import njit

# Step-to-boundary fraction of Mehrotra's method.
_FRACTION = 0.99
# A start's slacks are at least this fraction of their range, its products s z this fraction
# of dual scale × range: cold (the unconstrained solution) and warm (the last tick's plan
# shifted, near the solution: closer to the boundary, less centred; docs/mpc.md, "The route's
# constants").
COLD, WARM = 1, 2
# solve_interior's outcomes.
CONVERGED, SETTLED, DIVERGED, EXHAUSTED = 0, 1, -1, -2
_FLOOR = (0.0, 0.1, 0.01)
_CENTRE = (0.0, 1.0, 0.01)
# A warm start's rows at a bound in the last verified active set (shifted): slack at most
# GUIDE_FLOOR of the range, product s z GUIDE_CENTRE (the default of solve_interior's
# ``guide_centre``) of dual scale × range (docs/mpc.md, "The route's constants").
GUIDE_FLOOR, GUIDE_CENTRE = 0.003, 3.0


@njit(cache=True, nogil=True, error_model="numpy")
def identify_active(bounds, scale, sl, su, zl, zu, active):  # type: ignore[no-untyped-def]
    """Write the iterate's active set into ``active`` (N, 3); the number of rows that changed.

    A bound is active when its multiplier, in units of its dual scale, exceeds its slack in
    units of its range (z / scale > s / range, compared without the quotients).
    """
    changed = 0
    for i in range(sl.shape[0]):
        for j in range(3):
            span = bounds[j, 1] - bounds[j, 0]
            side = 0
            if zl[i, j] * span > sl[i, j] * scale[i, j]:
                side = -1
            elif zu[i, j] * span > su[i, j] * scale[i, j]:
                side = 1
            if active[i, j] != side:
                active[i, j] = side
                changed += 1
    return changed


@njit(cache=True, nogil=True, error_model="numpy")
def _value(u, x, i, j):  # type: ignore[no-untyped-def]
    """Return the bounded component j of stage i: δ_i, τ_i or θ_{i+1}."""
    if j < 2:
        return u[i, j]
    return x[i + 1, 1]


@njit(cache=True, nogil=True, error_model="numpy")
def _advance(a, b, x, u, i):  # type: ignore[no-untyped-def]
    """Write x[i + 1] = A x[i] + B u[i] (the dynamics, Eq. 16 discretised; zeros skipped)."""
    for r in range(4):
        acc = b[r, 0] * u[i, 0] + b[r, 1] * u[i, 1] if r & 1 == 0 else b[r, 1] * u[i, 1]
        for c in range(r & 1, 4, 2):
            acc += a[r, c] * x[i, c]
        x[i + 1, r] = acc


@njit(cache=True, nogil=True, error_model="numpy")
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
            for r in range(0, 4, 2 - c):  # B's δ column is zero on rows 1, 3
                acc -= b[r, c] * nu[i, r]
                size += abs(b[r, c] * nu[i, r])
            rdu[i, c] = acc
            mdu[i, c] = size
        for c in range(4):
            term = 2.0 * wx[i, c] * x[i + 1, c]
            acc = term + nu[i, c]
            size = abs(term) + abs(nu[i, c])
            if i + 1 < n:
                for r in range(c & 1, 4, 2):  # A's column c: the rows of c's block
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


@njit(cache=True, nogil=True, error_model="numpy")
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

    The products skip A and B's zeros (see the module); the recursions keep a stage's
    matrices and vectors in scalars. Returns the largest steps α ≤ 1 that keep the slacks,
    and the multipliers, nonnegative (Mehrotra's step lengths).
    """
    n = du.shape[0]
    # A, B's entries (the kernels' zeros skipped in the products below).
    a00, a01, a02, a03 = a[0, 0], a[0, 1], a[0, 2], a[0, 3]
    a10, a11, a12, a13 = a[1, 0], a[1, 1], a[1, 2], a[1, 3]
    a20, a21, a22, a23 = a[2, 0], a[2, 1], a[2, 2], a[2, 3]
    a30, a31, a32, a33 = a[3, 0], a[3, 1], a[3, 2], a[3, 3]
    b00, b20, b01, b11, b21, b31 = b[0, 0], b[2, 0], b[0, 1], b[1, 1], b[2, 1], b[3, 1]
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
        k = gain[i]
        if factor:
            # Stage i's factors in scalars: between array stores, numba's arrays (which may alias)
            # would be reloaded. The same sums, in the same order, as the loops they unroll.
            s00, s01, s02, s03 = s[0, 0], s[0, 1], s[0, 2], s[0, 3]
            s10, s11, s12, s13 = s[1, 0], s[1, 1], s[1, 2], s[1, 3]
            s20, s21, s22, s23 = s[2, 0], s[2, 1], s[2, 2], s[2, 3]
            s30, s31, s32, s33 = s[3, 0], s[3, 1], s[3, 2], s[3, 3]
            # S B, S A (A's column c: rows c & 1 and (c & 1) + 2; B's δ column: rows 0, 2).
            q00, q01 = s00 * b00 + s02 * b20, s00 * b01 + s01 * b11 + s02 * b21 + s03 * b31
            q10, q11 = s10 * b00 + s12 * b20, s10 * b01 + s11 * b11 + s12 * b21 + s13 * b31
            q20, q21 = s20 * b00 + s22 * b20, s20 * b01 + s21 * b11 + s22 * b21 + s23 * b31
            q30, q31 = s30 * b00 + s32 * b20, s30 * b01 + s31 * b11 + s32 * b21 + s33 * b31
            t00, t01 = s00 * a00 + s02 * a20, s01 * a11 + s03 * a31
            t02, t03 = s00 * a02 + s02 * a22, s01 * a13 + s03 * a33
            t10, t11 = s10 * a00 + s12 * a20, s11 * a11 + s13 * a31
            t12, t13 = s10 * a02 + s12 * a22, s11 * a13 + s13 * a33
            t20, t21 = s20 * a00 + s22 * a20, s21 * a11 + s23 * a31
            t22, t23 = s20 * a02 + s22 * a22, s21 * a13 + s23 * a33
            t30, t31 = s30 * a00 + s32 * a20, s31 * a11 + s33 * a31
            t32, t33 = s30 * a02 + s32 * a22, s31 * a13 + s33 * a33
            # H = B^T S B + R̃ (its off-diagonal sums kept apart, as computed), K = −H⁻¹ B^T S A.
            d0 = 2.0 * wu[i, 0] + zl[i, 0] / sl[i, 0] + zu[i, 0] / su[i, 0]
            d1 = 2.0 * wu[i, 1] + zl[i, 1] / sl[i, 1] + zu[i, 1] / su[i, 1]
            rdiag[i, 0], rdiag[i, 1] = d0, d1
            h00 = b00 * q00 + b20 * q20 + d0
            h01 = b00 * q01 + b20 * q21
            h10 = b01 * q00 + b11 * q10 + b21 * q20 + b31 * q30
            h11 = b01 * q01 + b11 * q11 + b21 * q21 + b31 * q31 + d1
            det = h00 * h11 - h01 * h10
            i00, i11, i01 = h11 / det, h00 / det, -h01 / det
            hinv[i, 0, 0], hinv[i, 1, 1], hinv[i, 0, 1], hinv[i, 1, 0] = i00, i11, i01, i01
            g0, g1 = b00 * t00 + b20 * t20, b01 * t00 + b11 * t10 + b21 * t20 + b31 * t30
            e0, f0 = -(i00 * g0 + i01 * g1), -(i01 * g0 + i11 * g1)
            g0, g1 = b00 * t01 + b20 * t21, b01 * t01 + b11 * t11 + b21 * t21 + b31 * t31
            e1, f1 = -(i00 * g0 + i01 * g1), -(i01 * g0 + i11 * g1)
            g0, g1 = b00 * t02 + b20 * t22, b01 * t02 + b11 * t12 + b21 * t22 + b31 * t32
            e2, f2 = -(i00 * g0 + i01 * g1), -(i01 * g0 + i11 * g1)
            g0, g1 = b00 * t03 + b20 * t23, b01 * t03 + b11 * t13 + b21 * t23 + b31 * t33
            e3, f3 = -(i00 * g0 + i01 * g1), -(i01 * g0 + i11 * g1)
            sb[0, 0], sb[0, 1] = q00, q01
            sb[1, 0], sb[1, 1] = q10, q11
            sb[2, 0], sb[2, 1] = q20, q21
            sb[3, 0], sb[3, 1] = q30, q31
            k[0, 0], k[0, 1], k[0, 2], k[0, 3] = e0, e1, e2, e3
            k[1, 0], k[1, 1], k[1, 2], k[1, 3] = f0, f1, f2, f3
            if i > 0:
                # x_i's cost-to-go under u = K x + k, S_i in Joseph's form (a sum of positive
                # semidefinite terms: the shortcut A^T S A + G^T K loses definiteness to
                # rounding at N = 200): S_i = Q̃_{i−1} + A_K^T S A_K + K^T R̃ K, A_K = A + B K.
                c00, c01 = a00 + b00 * e0 + b01 * f0, a01 + b00 * e1 + b01 * f1
                c02, c03 = a02 + b00 * e2 + b01 * f2, a03 + b00 * e3 + b01 * f3
                closed[0, 0], closed[0, 1], closed[0, 2], closed[0, 3] = c00, c01, c02, c03
                c10, c11, c12, c13 = a10 + b11 * f0, a11 + b11 * f1, a12 + b11 * f2, a13 + b11 * f3
                closed[1, 0], closed[1, 1], closed[1, 2], closed[1, 3] = c10, c11, c12, c13
                c20, c21 = a20 + b20 * e0 + b21 * f0, a21 + b20 * e1 + b21 * f1
                c22, c23 = a22 + b20 * e2 + b21 * f2, a23 + b20 * e3 + b21 * f3
                closed[2, 0], closed[2, 1], closed[2, 2], closed[2, 3] = c20, c21, c22, c23
                c30, c31, c32, c33 = a30 + b31 * f0, a31 + b31 * f1, a32 + b31 * f2, a33 + b31 * f3
                closed[3, 0], closed[3, 1], closed[3, 2], closed[3, 3] = c30, c31, c32, c33
                p00, p01 = t00 + (q00 * e0 + q01 * f0), t01 + (q00 * e1 + q01 * f1)
                p02, p03 = t02 + (q00 * e2 + q01 * f2), t03 + (q00 * e3 + q01 * f3)
                p10, p11 = t10 + (q10 * e0 + q11 * f0), t11 + (q10 * e1 + q11 * f1)
                p12, p13 = t12 + (q10 * e2 + q11 * f2), t13 + (q10 * e3 + q11 * f3)
                p20, p21 = t20 + (q20 * e0 + q21 * f0), t21 + (q20 * e1 + q21 * f1)
                p22, p23 = t22 + (q20 * e2 + q21 * f2), t23 + (q20 * e3 + q21 * f3)
                p30, p31 = t30 + (q30 * e0 + q31 * f0), t31 + (q30 * e1 + q31 * f1)
                p32, p33 = t32 + (q30 * e2 + q31 * f2), t33 + (q30 * e3 + q31 * f3)
                nxt = big_s[i]
                m = d0 * e0 * e0 + d1 * f0 * f0 + c00 * p00 + c10 * p10 + c20 * p20
                m += c30 * p30
                nxt[0, 0] = m + 2.0 * wx[i - 1, 0]
                m = d0 * e0 * e1 + d1 * f0 * f1 + c00 * p01 + c10 * p11 + c20 * p21
                m += c30 * p31
                nxt[0, 1] = nxt[1, 0] = m
                m = d0 * e0 * e2 + d1 * f0 * f2 + c00 * p02 + c10 * p12 + c20 * p22
                m += c30 * p32
                nxt[0, 2] = nxt[2, 0] = m
                m = d0 * e0 * e3 + d1 * f0 * f3 + c00 * p03 + c10 * p13 + c20 * p23
                m += c30 * p33
                nxt[0, 3] = nxt[3, 0] = m
                m = d0 * e1 * e1 + d1 * f1 * f1 + c01 * p01 + c11 * p11 + c21 * p21
                m += c31 * p31
                nxt[1, 1] = m + 2.0 * wx[i - 1, 1]
                m = d0 * e1 * e2 + d1 * f1 * f2 + c01 * p02 + c11 * p12 + c21 * p22
                m += c31 * p32
                nxt[1, 2] = nxt[2, 1] = m
                m = d0 * e1 * e3 + d1 * f1 * f3 + c01 * p03 + c11 * p13 + c21 * p23
                m += c31 * p33
                nxt[1, 3] = nxt[3, 1] = m
                m = d0 * e2 * e2 + d1 * f2 * f2 + c02 * p02 + c12 * p12 + c22 * p22
                m += c32 * p32
                nxt[2, 2] = m + 2.0 * wx[i - 1, 2]
                m = d0 * e2 * e3 + d1 * f2 * f3 + c02 * p03 + c12 * p13 + c22 * p23
                m += c32 * p33
                nxt[2, 3] = nxt[3, 2] = m
                m = d0 * e3 * e3 + d1 * f3 * f3 + c03 * p03 + c13 * p13 + c23 * p23
                m += c33 * p33
                nxt[3, 3] = m + 2.0 * wx[i - 1, 3]
                nxt[1, 1] += zl[i - 1, 2] / sl[i - 1, 2] + zu[i - 1, 2] / su[i - 1, 2]
        # The linear term of u_i (without B^T s), the feed-forward k_i.
        d0, d1 = rdiag[i, 0], rdiag[i, 1]
        lin0 = rdu[i, 0] - (cl[i, 0] - zl[i, 0] * rl[i, 0]) / sl[i, 0]
        lin0 += (cu[i, 0] - zu[i, 0] * ru[i, 0]) / su[i, 0]
        lin1 = rdu[i, 1] - (cl[i, 1] - zl[i, 1] * rl[i, 1]) / sl[i, 1]
        lin1 += (cu[i, 1] - zu[i, 1] * ru[i, 1]) / su[i, 1]
        v = vec_s[i + 1]
        gu0 = lin0 + b[0, 0] * v[0] + b[2, 0] * v[2]
        gu1 = lin1 + b[0, 1] * v[0] + b[1, 1] * v[1] + b[2, 1] * v[2] + b[3, 1] * v[3]
        hi = hinv[i]
        k0 = -(hi[0, 0] * gu0 + hi[0, 1] * gu1)
        k1 = -(hi[1, 0] * gu0 + hi[1, 1] * gu1)
        off[i, 0], off[i, 1] = k0, k1
        if i == 0:
            break
        # s_i = g_{x,i−1} + A_K^T (S B k + s) + K^T (R̃ k + g_u), Joseph's form as S_i's.
        t0 = v[0] + sb[0, 0] * k0 + sb[0, 1] * k1
        t1 = v[1] + sb[1, 0] * k0 + sb[1, 1] * k1
        t2 = v[2] + sb[2, 0] * k0 + sb[2, 1] * k1
        t3 = v[3] + sb[3, 0] * k0 + sb[3, 1] * k1
        rk0 = d0 * k0 + lin0
        rk1 = d1 * k1 + lin1
        for r in range(4):
            vec_s[i, r] = (
                k[0, r] * rk0 + k[1, r] * rk1 + rdx[i - 1, r] + closed[0, r] * t0
                + closed[1, r] * t1 + closed[2, r] * t2 + closed[3, r] * t3
            )  # fmt: skip
        vec_s[i, 1] -= (cl[i - 1, 2] - zl[i - 1, 2] * rl[i - 1, 2]) / sl[i - 1, 2] - (
            cu[i - 1, 2] - zu[i - 1, 2] * ru[i - 1, 2]
        ) / su[i - 1, 2]
    # Forward: Δx_0 = 0, the step lengths on the way. Δx_i in scalars (not through memory).
    x0 = x1 = x2 = x3 = 0.0
    for c in range(4):
        dx[0, c] = 0.0
    primal = dual = 1.0
    for i in range(n):
        k = gain[i]
        u0 = off[i, 0] + k[0, 0] * x0 + k[0, 1] * x1 + k[0, 2] * x2 + k[0, 3] * x3
        u1 = off[i, 1] + k[1, 0] * x0 + k[1, 1] * x1 + k[1, 2] * x2 + k[1, 3] * x3
        # Δx_{i+1} = A Δx_i + B Δu_i, as in _advance.
        y0 = b00 * u0 + b01 * u1 + a00 * x0 + a02 * x2
        y1 = b11 * u1 + a11 * x1 + a13 * x3
        y2 = b20 * u0 + b21 * u1 + a20 * x0 + a22 * x2
        y3 = b31 * u1 + a31 * x1 + a33 * x3
        x0, x1, x2, x3 = y0, y1, y2, y3
        du[i, 0], du[i, 1] = u0, u1
        dx[i + 1, 0], dx[i + 1, 1], dx[i + 1, 2], dx[i + 1, 3] = x0, x1, x2, x3
        s = big_s[i + 1]
        for r in range(4):
            dnu[i, r] = -(
                vec_s[i + 1, r] + s[r, 0] * x0 + s[r, 1] * x1 + s[r, 2] * x2 + s[r, 3] * x3
            )
        for j in range(3):
            dv = u0 if j == 0 else (u1 if j == 1 else x1)
            dsl[i, j] = dl = dv + rl[i, j]
            dsu[i, j] = dh = -dv + ru[i, j]
            dzl[i, j] = el = (cl[i, j] - zl[i, j] * dl) / sl[i, j]
            dzu[i, j] = eh = (cu[i, j] - zu[i, j] * dh) / su[i, j]
            if dl < 0.0:
                primal = min(primal, -sl[i, j] / dl)
            if dh < 0.0:
                primal = min(primal, -su[i, j] / dh)
            if el < 0.0:
                dual = min(dual, -zl[i, j] / el)
            if eh < 0.0:
                dual = min(dual, -zu[i, j] / eh)
    return primal, dual


@njit(cache=True, nogil=True, error_model="numpy")
def _start(  # type: ignore[no-untyped-def]
    x0, a, b, bounds, scale, feedback, u, x, nu, sl, su, zl, zu, start, guide, guide_centre,
):  # fmt: skip
    """Write a start from x0: ``start`` COLD or WARM (the inputs already in ``u``).

    COLD: the unconstrained problem's solution, whatever its bounds (inputs by its feedback,
    states simulated: bounded, where a saturated or open-loop guess lets a falling state grow
    as e^{ω t} and the iterations then stall). WARM: the inputs given, states simulated. Slacks
    at least a fraction of their range (an infeasible start), products s z a fraction of the
    bound's dual scale × range (``_FLOOR``, ``_CENTRE``). WARM also takes ``guide`` (N, 3),
    the last verified active set (unshifted; zeros: none): its rows start near their bounds
    with larger multipliers (GUIDE_FLOOR, ``guide_centre``: as ``_FLOOR``, ``_CENTRE``).
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
                    sl[i, j] = min(sl[i, j], GUIDE_FLOOR * span)
                    zl[i, j] = guide_centre * scale[i, j] / sl[i, j] * span
                elif side > 0:
                    su[i, j] = min(su[i, j], GUIDE_FLOOR * span)
                    zu[i, j] = guide_centre * scale[i, j] / su[i, j] * span


@njit(cache=True, nogil=True, error_model="numpy")
def shift_iterate(x0, a, b, feedback, u, x, nu, sl, su, zl, zu):  # type: ignore[no-untyped-def]
    """Shift an unfinished iterate by one stage (the receding horizon) to continue it from x0.

    The inputs, costates, slacks and bound multipliers of stage i + 1 become stage i's (the
    last stage keeps its own). The states are simulated from x0, each shifted input corrected
    by the unconstrained problem's gain on the state's deviation from the shifted iterate's,
    u_i + K_i (x_i − x̄_{i+1}): open loop, a deviation of x0 would grow as e^{ω t} along the
    horizon (the reason of the cold start's feedback). The dynamics hold exactly, as the Newton
    steps need; the slacks' residuals, against the new states, are the iterations' to close.
    Continue with ``start`` 0.
    """
    n = u.shape[0]
    for i in range(n - 1):
        for r in range(2):
            u[i, r] = u[i + 1, r]
        for r in range(4):
            nu[i, r] = nu[i + 1, r]
        for j in range(3):
            sl[i, j] = sl[i + 1, j]
            su[i, j] = su[i + 1, j]
            zl[i, j] = zl[i + 1, j]
            zu[i, j] = zu[i + 1, j]
    dev = np.empty(4)
    for c in range(4):
        dev[c] = x0[c] - x[1, c]  # x̄_1: stage 0's reference, the old x[1]
        x[0, c] = x0[c]
    for i in range(n):
        for r in range(2):
            acc = 0.0
            for c in range(4):
                acc += feedback[i, r, c] * dev[c]
            u[i, r] += acc
        _advance(a, b, x, u, i)  # overwrites the old x[i + 1], read before as stage i's x̄
        if i + 2 <= n:
            for c in range(4):
                dev[c] = x[i + 1, c] - x[i + 2, c]  # the old x[i + 2]: stage i + 1's x̄


@njit(cache=True, nogil=True, error_model="numpy")
def solve_interior(  # type: ignore[no-untyped-def]
    x0, a, b, wx, wu, bounds, scale, feedback, tol, dual_tol, max_iter, start, guide,
    u, x, nu, sl, su, zl, zu, work, big_s, gain, hinv, vec_s, sbs, closeds, active,
    settle_tol, settle_rows, guide_centre,
):  # fmt: skip
    """Mehrotra predictor-corrector iterations: (status, their number).

    ``feedback`` (N, 2, 4) is the unconstrained problem's time-varying gain (:func:`dual_scales`).
    ``start``: COLD or WARM from :func:`_start`'s point, 0: continue from the iterate in the arrays
    (u, x, ν, slacks and multipliers of a previous call). Status CONVERGED: ``active`` (N, 3)
    holds the converged iterate's active set (:func:`identify_active`); EXHAUSTED: not
    converged in ``max_iter`` (the iterate is left to continue from); DIVERGED: the iterate
    is no longer finite (an infeasible problem diverges). SETTLED (only if ``settle_rows``
    >= 0): after an iteration of this call, the iterate's active set, in ``active``, differs
    from the previous iterate's in at most ``settle_rows`` rows and every complementarity
    product is within ``settle_tol`` of scale × range: a set worth verifying before the
    iterations converge (continue with ``start`` 0).

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
        _start(x0, a, b, bounds, scale, feedback, u, x, nu, sl, su, zl, zu, start, guide,
               guide_centre)  # fmt: skip
    for it in range(max_iter):
        _residuals(a, b, wx, wu, bounds, u, x, nu, sl, su, zl, zu, rdu, rdx, rl, ru, mdu, mdx)
        mu = 0.0
        done = near = True
        for i in range(n):
            for j in range(3):
                span = bounds[j, 1] - bounds[j, 0]
                mu += sl[i, j] * zl[i, j] + su[i, j] * zu[i, j]
                if max(abs(rl[i, j]), abs(ru[i, j])) > tol * span:
                    done = False
                product = max(sl[i, j] * zl[i, j], su[i, j] * zu[i, j])
                if product > tol * scale[i, j] * span:
                    done = False
                if product > settle_tol * scale[i, j] * span:
                    near = False
                if j < 2 and abs(rdu[i, j]) > dual_tol * max(scale[i, j], mdu[i, j]):
                    done = False
            for c in range(4):
                if abs(rdx[i, c]) > dual_tol * max(scale[i, 3 + c], mdx[i, c]):
                    done = False
        if not np.isfinite(mu):
            return DIVERGED, it
        if done:
            identify_active(bounds, scale, sl, su, zl, zu, active)
            return CONVERGED, it
        if settle_rows >= 0:
            changed = identify_active(bounds, scale, sl, su, zl, zu, active)
            if it > 0 and near and changed <= settle_rows:
                return SETTLED, it
        mu /= 6 * n
        # Predictor (affine scaling).
        for i in range(n):
            for j in range(3):
                cl[i, j] = -sl[i, j] * zl[i, j]
                cu[i, j] = -su[i, j] * zu[i, j]
        primal, dual = _newton(a, b, wx, wu, sl, su, zl, zu, rdu, rdx, rl, ru, cl, cu, True,
                               big_s, gain, hinv, vec_s, sbs, closeds, off, rdiag, du, dx, dnu,
                               dsl, dsu, dzl, dzu)  # fmt: skip
        alpha = min(primal, dual)
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
        primal, dual = _newton(a, b, wx, wu, sl, su, zl, zu, rdu, rdx, rl, ru, cl, cu, False,
                               big_s, gain, hinv, vec_s, sbs, closeds, off, rdiag, du, dx, dnu,
                               dsl, dsu, dzl, dzu)  # fmt: skip
        primal = min(1.0, _FRACTION * primal)
        dual = min(1.0, _FRACTION * dual)
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
    return EXHAUSTED, max_iter
