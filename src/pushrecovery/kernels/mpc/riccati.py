r"""Compiled (numba, cached on disk) primal-dual active-set solve of Eq. (17) by Riccati recursion.

One file on purpose: numba's disk cache does not see changes in the files of the functions a
kernel calls, so the kernels that call each other live together. See
:mod:`~pushrecovery.control.mpc.solvers.riccati` for the method; here, the arithmetic.

Conventions. Stage i = 0..N−1 maps (x_i, u_i) to x_{i+1} = A x_i + B u_i at cost
x_{i+1}^T diag(wx_i) x_{i+1} + u_i^T diag(wu_i) u_i. Each stage has three constraint rows,
``active[i, j]`` ∈ {−1 (at its lower bound), 0 (inactive), +1 (at its upper bound)}:
j = 0 the CoP δ_i, j = 1 the torque τ_i (rows on u_i), j = 2 the flywheel angle θ_{i+1} (a row
on x_{i+1}). Multipliers enter the stationarity conditions with a + sign (``mult * side >= 0``
is optimal):

.. math::

    2\,\mathrm{diag}(wu_i)\,u_i + B^T λ_{i+1} + μ_i = 0, \qquad
    λ_{i+1} = 2\,\mathrm{diag}(wx_i)\,x_{i+1} + A^T λ_{i+2} + ν_i e_θ, \quad λ_{N+1} = 0.

State rows carried back. The active rows on x_{i+1} (θ_{i+1}, and rows carried from later
stages) become rows on (x_i, u_i) through the dynamics, F (A x_i + B u_i) = f. With the input
rows they are reduced against u_i: at most two independent ones fix u_i's part in their span
(affine in x_i); each dependent one minus its combination of those is a pure row on x_i, carried
to stage i − 1 (τ_i and θ_{i+1} both at a bound: a row on θ_i, θ̇_i). Rows carried to x_0, which
is given, make the active set infeasible. The multipliers are the dual of this: the unknown ones
are carried back in λ (λ = l + L w) until a stage's stationarity fixes them.

Speed. A and B have the flywheel's structure
(checked by :class:`~pushrecovery.control.mpc.problem.SparseQP`): A block-diagonal in (x, ẋ) and
(θ, θ̇), B's CoP column zero on θ, θ̇. The products skip those zeros, and a stage's matrices
stay in scalars (numba reloads arrays, which may alias, after every store): term by term the
same sums in the same order as plain loops, so the same results (a skipped term is ±0, which
leaves a nonzero sum as it is; a sum the loops started from 0.0 keeps that start, ``0.0 + …``,
so that an all-zero one stays +0). A solve's scratch is allocated once (:func:`scratch`), not
per pass.

Over 400 lines on purpose: one kernel (the active-set passes), whose backward recursion,
elimination of the held θ rows and multiplier check share the per-stage scalars above; split,
they would pass a dozen arrays between modules for nothing.
"""

from __future__ import annotations

import numpy as np

from pushrecovery.kernels.jit import njit

# Outcomes of one pass of :func:`_pass`.
OPTIMAL, CHANGED, DEGENERATE = 0, 1, -1
#: Rows carried on one state (at most the state's dimension, and one more being reduced).
CARRIED = 5
#: Relative size under which a row is dependent on the pivots, or a pivot is missing.
RANK_TOL = 1e-10
# Unknown multipliers carried back in λ at once (_multipliers' columns).
_WIDTH = CARRIED + 1
# The scratch's float rows (see scratch): _backward's rows (c^T x_i + d^T u_i = e as
# c0..c3, d0, d1, e; a stage's candidates, then from _PENDING the rows carried to the stage
# before), then _multipliers' L (λ's columns), the Jacobian and right-hand side of a stage's
# inactive inputs' equations, and from _EX one row per multiplier (3 i + j): its recorded
# expression's coefficients, constant (_CONST) and value (_VALUE).
_PENDING = CARRIED + 2
_ROWS = _PENDING + CARRIED
_LC = _ROWS
_JAC = _LC + 4
_RHS = _JAC + 2
_EX = _RHS + 1
_CONST, _VALUE = _WIDTH, _WIDTH + 1
#: Columns of _backward's record of what enters a stage: P's upper triangle (10), p (4), the
#: number of rows carried, then per carried row its c0..c3, e and origin.
_SAVED = 15 + 6 * CARRIED
# The int rows: one per multiplier (its expression's unknowns' ids, their count (_COUNT), and
# in column _ORDER the order the expressions were recorded in); then the live unknowns' ids and
# flags.
_COUNT, _ORDER = _WIDTH, _WIDTH + 1


@njit(cache=True, nogil=True)
def scratch(n):  # type: ignore[no-untyped-def]
    """Return the passes' scratch at horizon ``n``: floats, ints, the rows' origins, the record.

    Three arrays rather than one per purpose, indexed as the constants above say: an
    allocation, or a view, costs tens of ns, a pass a few µs. Nothing is read before it is
    written in the same pass, so the contents need no initialisation.
    """
    total = 3 * n
    floats = np.empty((_EX + total, _WIDTH + 2))
    ints = np.empty((total + 2, _WIDTH + 2), dtype=np.int64)
    origins = np.empty(_ROWS, dtype=np.int64)  # the stage of the θ row a carried row comes from
    saved = np.empty((n, _SAVED))  # what enters each stage of the recursion (_backward)
    return floats, ints, origins, saved


@njit(cache=True, nogil=True)
def _entry(ata, g0r, g1r, er, fr, kh0r, kh1r, g0c, g1c, ec, fc):  # type: ignore[no-untyped-def]
    """P_i[r, c] = (A^T S A)[r, c] + (G^T K)[r, c] + (K^T G)[r, c] + (K^T H K)[r, c], as summed."""
    acc = ata + (g0r * ec + g1r * fc)
    acc += er * g0c + fr * g1c
    acc += kh0r * ec + kh1r * fc
    return acc


@njit(cache=True, nogil=True)
def _backward(a, b, wx, wu, active, bounds, gains, offsets, curvature, rows, origins, start, saved):  # type: ignore[no-untyped-def]
    """Riccati recursion with the active rows as equalities; the number of rows left on x_0.

    −i − 2: the rows of stage i are over-determined (a carried row reduced to 0 = e).

    From stage ``start`` down (N − 1: all of it): what the recursion carries into each stage
    (P, p and the rows carried back, :data:`_SAVED` columns) is saved in ``saved[i]`` as it
    enters stage i, and a recursion from ``start`` < N − 1 resumes from ``saved[start]``: the
    stages after ``start`` must have the rows they had when it was saved (their gains,
    offsets and curvature are then still in place), and it gives the same numbers as a whole
    recursion.

    Writes u_i = gains[i] x_i + offsets[i] and the diagonal of the stage's input Hessian
    H = diag(wu_i) + B^T S_{i+1} B (the scale of its multipliers) into ``curvature[i]``; the
    rows in ``rows`` (the scratch's floats) and ``origins`` (:func:`scratch`). Per stage, with
    S = P_{i+1} + diag(wx_i), s = p_{i+1} (cost-to-go x^T P x + 2 p^T x): u = T z + F x + f (the
    pivot rows fix F, f; T spans the free directions), z minimises T^T [H u + B^T S A x + B^T s]
    = 0, and P_i = A^T S A + G^T K + K^T G + K^T H K, p_i = A^T (S B k + s) + K^T (H k + B^T s)
    with G = B^T S A and u = K x + k. P (symmetric: its upper triangle), p and the stage's
    matrices are scalars; A's and B's zeros are skipped (see the module).
    """
    n = wx.shape[0]
    a00, a02, a20, a22 = a[0, 0], a[0, 2], a[2, 0], a[2, 2]  # A's (x, ẋ) block
    a11, a13, a31, a33 = a[1, 1], a[1, 3], a[3, 1], a[3, 3]  # its (θ, θ̇) block
    b00, b20, b01, b11, b21, b31 = b[0, 0], b[2, 0], b[0, 1], b[1, 1], b[2, 1], b[3, 1]
    # x_N's cost-to-go: none beyond its stage's weight.
    p00 = p01 = p02 = p03 = p11 = p12 = p13 = p22 = p23 = p33 = 0.0
    l0 = l1 = l2 = l3 = 0.0
    npend = 0
    if start < n - 1:  # resume: what entered stage `start` last time
        c = saved[start]
        p00, p01, p02, p03, p11 = c[0], c[1], c[2], c[3], c[4]
        p12, p13, p22, p23, p33 = c[5], c[6], c[7], c[8], c[9]
        l0, l1, l2, l3 = c[10], c[11], c[12], c[13]
        npend = int(c[14])
        for q in range(npend):
            o, k = _PENDING + q, 15 + 6 * q
            rows[o, 0], rows[o, 1], rows[o, 2], rows[o, 3] = c[k], c[k + 1], c[k + 2], c[k + 3]
            rows[o, 6], origins[o] = c[k + 4], int(c[k + 5])
    for i in range(start, -1, -1):
        c = saved[i]  # what enters stage i, for a later resumption
        c[0], c[1], c[2], c[3], c[4] = p00, p01, p02, p03, p11
        c[5], c[6], c[7], c[8], c[9] = p12, p13, p22, p23, p33
        c[10], c[11], c[12], c[13], c[14] = l0, l1, l2, l3, npend
        for q in range(npend):
            o, k = _PENDING + q, 15 + 6 * q
            c[k], c[k + 1], c[k + 2], c[k + 3] = rows[o, 0], rows[o, 1], rows[o, 2], rows[o, 3]
            c[k + 4], c[k + 5] = rows[o, 6], origins[o]
        # S = P + diag(wx_i) (off the diagonal, P's own entries).
        s00, s11, s22, s33 = p00 + wx[i, 0], p11 + wx[i, 1], p22 + wx[i, 2], p33 + wx[i, 3]
        # S B (B's CoP column: rows 0, 2) and S A (A's column c: rows c & 1, (c & 1) + 2).
        q00 = 0.0 + s00 * b00 + p02 * b20
        q01 = 0.0 + s00 * b01 + p01 * b11 + p02 * b21 + p03 * b31
        q10 = 0.0 + p01 * b00 + p12 * b20
        q11 = 0.0 + p01 * b01 + s11 * b11 + p12 * b21 + p13 * b31
        q20 = 0.0 + p02 * b00 + s22 * b20
        q21 = 0.0 + p02 * b01 + p12 * b11 + s22 * b21 + p23 * b31
        q30 = 0.0 + p03 * b00 + p23 * b20
        q31 = 0.0 + p03 * b01 + p13 * b11 + p23 * b21 + s33 * b31
        t00, t01 = 0.0 + s00 * a00 + p02 * a20, 0.0 + p01 * a11 + p03 * a31
        t02, t03 = 0.0 + s00 * a02 + p02 * a22, 0.0 + p01 * a13 + p03 * a33
        t10, t11 = 0.0 + p01 * a00 + p12 * a20, 0.0 + s11 * a11 + p13 * a31
        t12, t13 = 0.0 + p01 * a02 + p12 * a22, 0.0 + s11 * a13 + p13 * a33
        t20, t21 = 0.0 + p02 * a00 + s22 * a20, 0.0 + p12 * a11 + p23 * a31
        t22, t23 = 0.0 + p02 * a02 + s22 * a22, 0.0 + p12 * a13 + p23 * a33
        t30, t31 = 0.0 + p03 * a00 + p23 * a20, 0.0 + p13 * a11 + s33 * a31
        t32, t33 = 0.0 + p03 * a02 + p23 * a22, 0.0 + p13 * a13 + s33 * a33
        # H = B^T S B + diag(wu_i) (both off-diagonal sums, as computed), G = B^T S A, B^T s.
        h00 = 0.0 + b00 * q00 + b20 * q20 + wu[i, 0]
        h01 = 0.0 + b00 * q01 + b20 * q21
        h10 = 0.0 + b01 * q00 + b11 * q10 + b21 * q20 + b31 * q30
        h11 = 0.0 + b01 * q01 + b11 * q11 + b21 * q21 + b31 * q31 + wu[i, 1]
        g00 = 0.0 + b00 * t00 + b20 * t20
        g01 = 0.0 + b00 * t01 + b20 * t21
        g02 = 0.0 + b00 * t02 + b20 * t22
        g03 = 0.0 + b00 * t03 + b20 * t23
        g10 = 0.0 + b01 * t00 + b11 * t10 + b21 * t20 + b31 * t30
        g11 = 0.0 + b01 * t01 + b11 * t11 + b21 * t21 + b31 * t31
        g12 = 0.0 + b01 * t02 + b11 * t12 + b21 * t22 + b31 * t32
        g13 = 0.0 + b01 * t03 + b11 * t13 + b21 * t23 + b31 * t33
        hs0 = 0.0 + b00 * l0 + b20 * l2
        hs1 = 0.0 + b01 * l0 + b11 * l1 + b21 * l2 + b31 * l3
        curvature[i, 0], curvature[i, 1] = h00, h11
        # The stage's rows: inputs first, then those on x_{i+1} through the dynamics.
        m = 0
        for j in range(2):
            side = active[i, j]
            if side != 0:
                rows[m, 0] = rows[m, 1] = rows[m, 2] = rows[m, 3] = 0.0
                rows[m, 4], rows[m, 5] = (1.0, 0.0) if j == 0 else (0.0, 1.0)
                rows[m, 6] = bounds[j, 1] if side > 0 else bounds[j, 0]
                origins[m] = -1
                m += 1
        if active[i, 2] != 0:
            if npend == CARRIED:
                return -i - 2
            o = _PENDING + npend
            rows[o, 0], rows[o, 1], rows[o, 2], rows[o, 3] = 0.0, 1.0, 0.0, 0.0
            rows[o, 6] = bounds[2, 1] if active[i, 2] > 0 else bounds[2, 0]
            origins[o] = i
            npend += 1
        for q in range(_PENDING, _PENDING + npend):
            c0, c1, c2, c3 = rows[q, 0], rows[q, 1], rows[q, 2], rows[q, 3]
            rows[m, 0], rows[m, 1] = 0.0 + c0 * a00 + c2 * a20, 0.0 + c1 * a11 + c3 * a31
            rows[m, 2], rows[m, 3] = 0.0 + c0 * a02 + c2 * a22, 0.0 + c1 * a13 + c3 * a33
            rows[m, 4] = 0.0 + c0 * b00 + c2 * b20
            rows[m, 5] = 0.0 + c0 * b01 + c1 * b11 + c2 * b21 + c3 * b31
            rows[m, 6] = rows[q, 6]
            origins[m] = origins[q]
            m += 1
        # Pivots (at most two independent d's); the others reduced to rows on x_i.
        rank = 0
        npend = 0
        pc00 = pc01 = pc02 = pc03 = pd00 = pd01 = pe0 = 0.0
        pc10 = pc11 = pc12 = pc13 = pd10 = pd11 = pe1 = 0.0
        po0 = po1 = -1
        for q in range(m):
            rd0, rd1 = rows[q, 4], rows[q, 5]
            size = abs(rd0) + abs(rd1)
            if rank == 0:
                residual = size
            elif rank == 1:
                residual = abs(pd00 * rd1 - pd01 * rd0) / (abs(pd00) + abs(pd01))
            else:
                residual = 0.0
            if residual > RANK_TOL * size:
                if rank == 0:
                    pc00, pc01, pc02, pc03 = rows[q, 0], rows[q, 1], rows[q, 2], rows[q, 3]
                    pd00, pd01, pe0, po0 = rd0, rd1, rows[q, 6], origins[q]
                else:
                    pc10, pc11, pc12, pc13 = rows[q, 0], rows[q, 1], rows[q, 2], rows[q, 3]
                    pd10, pd11, pe1, po1 = rd0, rd1, rows[q, 6], origins[q]
                rank += 1
                continue
            al0, al1 = 0.0, 0.0  # d_q = al0 d_p0 + al1 d_p1
            if rank == 1:
                al0 = (pd00 * rd0 + pd01 * rd1) / (pd00 * pd00 + pd01 * pd01)
            elif rank == 2:
                det = pd00 * pd11 - pd01 * pd10
                al0 = (rd0 * pd11 - rd1 * pd10) / det
                al1 = (pd00 * rd1 - pd01 * rd0) / det
            origin = max(origins[q], po0 if al0 != 0.0 else -1, po1 if al1 != 0.0 else -1)
            if npend == CARRIED:
                return -origin - 2
            o = _PENDING + npend
            rc0, rc1, rc2, rc3 = rows[q, 0], rows[q, 1], rows[q, 2], rows[q, 3]
            v0, v1 = rc0 - al0 * pc00 - al1 * pc10, rc1 - al0 * pc01 - al1 * pc11
            v2, v3 = rc2 - al0 * pc02 - al1 * pc12, rc3 - al0 * pc03 - al1 * pc13
            big = max(max(max(max(0.0, abs(v0)), abs(v1)), abs(v2)), abs(v3))
            scale = max(max(max(max(0.0, abs(rc0)), abs(rc1)), abs(rc2)), abs(rc3))
            if big <= RANK_TOL * scale:
                return -origin - 2  # a row implied by (or at odds with) the others
            rows[o, 0], rows[o, 1], rows[o, 2], rows[o, 3] = v0, v1, v2, v3
            rows[o, 6] = rows[q, 6] - al0 * pe0 - al1 * pe1
            origins[o] = origin
            npend += 1
        # u = K x + k: the rows' F, f (K rows e, f; k = (k0, k1)) and the free part's optimum.
        if rank == 0:
            det = h00 * h11 - h01 * h10
            e0, f0 = -(h11 * g00 - h01 * g10) / det, -(h00 * g10 - h10 * g00) / det
            e1, f1 = -(h11 * g01 - h01 * g11) / det, -(h00 * g11 - h10 * g01) / det
            e2, f2 = -(h11 * g02 - h01 * g12) / det, -(h00 * g12 - h10 * g02) / det
            e3, f3 = -(h11 * g03 - h01 * g13) / det, -(h00 * g13 - h10 * g03) / det
            k0 = -(h11 * hs0 - h01 * hs1) / det
            k1 = -(h00 * hs1 - h10 * hs0) / det
        elif rank == 1:
            norm2 = pd00 * pd00 + pd01 * pd01
            ff0, ff1 = pd00 * pe0 / norm2, pd01 * pe0 / norm2
            t0, t1 = -pd01, pd00
            th0 = h00 * t0 + h01 * t1
            th1 = h10 * t0 + h11 * t1
            hz = t0 * th0 + t1 * th1
            hv = th0 * ff0 + th1 * ff1 + t0 * hs0 + t1 * hs1
            e0, f0 = _free(pd00, pd01, pc00, norm2, th0, th1, t0, t1, hz, g00, g10)
            e1, f1 = _free(pd00, pd01, pc01, norm2, th0, th1, t0, t1, hz, g01, g11)
            e2, f2 = _free(pd00, pd01, pc02, norm2, th0, th1, t0, t1, hz, g02, g12)
            e3, f3 = _free(pd00, pd01, pc03, norm2, th0, th1, t0, t1, hz, g03, g13)
            k0, k1 = ff0 - t0 * hv / hz, ff1 - t1 * hv / hz
        else:  # u = D^{-1} (e − C x)
            det = pd00 * pd11 - pd01 * pd10
            c0, c1 = pd11 / det, -pd01 / det  # D^{-1}'s first row
            k0 = c0 * pe0 + c1 * pe1
            e0, e1 = -(c0 * pc00 + c1 * pc10), -(c0 * pc01 + c1 * pc11)
            e2, e3 = -(c0 * pc02 + c1 * pc12), -(c0 * pc03 + c1 * pc13)
            c0, c1 = -pd10 / det, pd00 / det  # its second
            k1 = c0 * pe0 + c1 * pe1
            f0, f1 = -(c0 * pc00 + c1 * pc10), -(c0 * pc01 + c1 * pc11)
            f2, f3 = -(c0 * pc02 + c1 * pc12), -(c0 * pc03 + c1 * pc13)
        gains[i, 0, 0], gains[i, 0, 1], gains[i, 0, 2], gains[i, 0, 3] = e0, e1, e2, e3
        gains[i, 1, 0], gains[i, 1, 1], gains[i, 1, 2], gains[i, 1, 3] = f0, f1, f2, f3
        offsets[i, 0], offsets[i, 1] = k0, k1
        # P_i and p_i of u = K x + k.
        hk0 = h00 * k0 + h01 * k1 + hs0
        hk1 = h10 * k0 + h11 * k1 + hs1
        v0 = q00 * k0 + q01 * k1 + l0  # S B k + s
        v1 = q10 * k0 + q11 * k1 + l1
        v2 = q20 * k0 + q21 * k1 + l2
        v3 = q30 * k0 + q31 * k1 + l3
        l0 = e0 * hk0 + f0 * hk1 + a00 * v0 + a20 * v2
        l1 = e1 * hk0 + f1 * hk1 + a11 * v1 + a31 * v3
        l2 = e2 * hk0 + f2 * hk1 + a02 * v0 + a22 * v2
        l3 = e3 * hk0 + f3 * hk1 + a13 * v1 + a33 * v3
        x0, y0 = e0 * h00 + f0 * h10, e0 * h01 + f0 * h11  # (K^T H)[r], r = 0..3
        x1, y1 = e1 * h00 + f1 * h10, e1 * h01 + f1 * h11
        x2, y2 = e2 * h00 + f2 * h10, e2 * h01 + f2 * h11
        x3, y3 = e3 * h00 + f3 * h10, e3 * h01 + f3 * h11
        p00 = _entry(0.0 + a00 * t00 + a20 * t20, g00, g10, e0, f0, x0, y0, g00, g10, e0, f0)
        p01 = _entry(0.0 + a00 * t01 + a20 * t21, g00, g10, e0, f0, x0, y0, g01, g11, e1, f1)
        p02 = _entry(0.0 + a00 * t02 + a20 * t22, g00, g10, e0, f0, x0, y0, g02, g12, e2, f2)
        p03 = _entry(0.0 + a00 * t03 + a20 * t23, g00, g10, e0, f0, x0, y0, g03, g13, e3, f3)
        p11 = _entry(0.0 + a11 * t11 + a31 * t31, g01, g11, e1, f1, x1, y1, g01, g11, e1, f1)
        p12 = _entry(0.0 + a11 * t12 + a31 * t32, g01, g11, e1, f1, x1, y1, g02, g12, e2, f2)
        p13 = _entry(0.0 + a11 * t13 + a31 * t33, g01, g11, e1, f1, x1, y1, g03, g13, e3, f3)
        p22 = _entry(0.0 + a02 * t02 + a22 * t22, g02, g12, e2, f2, x2, y2, g02, g12, e2, f2)
        p23 = _entry(0.0 + a02 * t03 + a22 * t23, g02, g12, e2, f2, x2, y2, g03, g13, e3, f3)
        p33 = _entry(0.0 + a13 * t13 + a33 * t33, g03, g13, e3, f3, x3, y3, g03, g13, e3, f3)
    if npend:
        origin = 0
        for q in range(_PENDING, _PENDING + npend):
            origin = max(origin, origins[q])
        return -origin - 2
    return 0


@njit(cache=True, nogil=True)
def _free(pd0, pd1, pc, norm2, th0, th1, t0, t1, hz, g0, g1):  # type: ignore[no-untyped-def]
    """Column of K with one pivot row d^T u + c^T x = e: the row's part, then the free one's.

    F = −d c^T / |d|², moved along T = (−d_1, d_0) to the free optimum: K = F − T g_z / h_z
    with g_z = T^T (H F + G) (``th`` = H T, ``hz`` = T^T H T); one column of x.
    """
    fd0, fd1 = -pd0 * pc / norm2, -pd1 * pc / norm2
    gz = th0 * fd0 + th1 * fd1 + t0 * g0 + t1 * g1
    return fd0 - t0 * gz / hz, fd1 - t1 * gz / hz


@njit(cache=True, nogil=True)
def _eliminate(p, e, k, floats, ints, top):  # type: ignore[no-untyped-def]
    """Record unknown ``p`` from equation ``e``: w_p = (rhs_e − Σ_{c ≠ p} jac_ec w_c) / jac_ep.

    ``top``: the ints' row of the live unknowns' ids (their flags in the next).
    """
    idx = ints[top, p]
    row = _EX + idx
    pivot = floats[_JAC + e, p]
    floats[row, _CONST] = floats[_RHS, e] / pivot
    m = 0
    for c in range(k):
        if ints[top + 1, c] and c != p:
            ints[idx, m] = c  # a column for now; turned into an id by the caller
            floats[row, m] = -floats[_JAC + e, c] / pivot
            m += 1
    ints[idx, _COUNT] = m
    return idx


@njit(cache=True, nogil=True)
def _multipliers(a, b, wx, wu, active, inputs, states, mult, floats, ints):  # type: ignore[no-untyped-def]
    """Multipliers of the active rows into ``mult`` (N, 3); False if they are not unique.

    Backward, λ_{i+1} = l + L w with w the θ rows' multipliers not fixed yet; stage i's
    stationarity 2 W^u u_i + B^T λ_{i+1} + μ_i = 0 fixes the active inputs' μ_i (their equation)
    and, by the other equations, up to two of w. The values follow forward by substitution.
    ``floats``, ``ints``: scratch (:func:`scratch`). l is kept in scalars; A's and B's zeros
    are skipped (see the module).
    """
    n = wx.shape[0]
    width = _WIDTH
    top = 3 * n  # ints' rows of the live unknowns' ids and flags
    a00, a02, a20, a22 = a[0, 0], a[0, 2], a[2, 0], a[2, 2]
    a11, a13, a31, a33 = a[1, 1], a[1, 3], a[3, 1], a[3, 3]
    b00, b20, b01, b11, b21, b31 = b[0, 0], b[2, 0], b[0, 1], b[1, 1], b[2, 1], b[3, 1]
    f0 = f1 = f2 = f3 = 0.0  # l of λ_{i+2}
    nord = 0
    k = 0
    for i in range(n - 1, -1, -1):
        m0 = 2.0 * wx[i, 0] * states[i + 1, 0] + a00 * f0 + a20 * f2
        m1 = 2.0 * wx[i, 1] * states[i + 1, 1] + a11 * f1 + a31 * f3
        m2 = 2.0 * wx[i, 2] * states[i + 1, 2] + a02 * f0 + a22 * f2
        m3 = 2.0 * wx[i, 3] * states[i + 1, 3] + a13 * f1 + a33 * f3
        for col in range(k):  # L ← A^T L
            c0, c1 = floats[_LC, col], floats[_LC + 1, col]
            c2, c3 = floats[_LC + 2, col], floats[_LC + 3, col]
            floats[_LC, col] = 0.0 + a00 * c0 + a20 * c2
            floats[_LC + 1, col] = 0.0 + a11 * c1 + a31 * c3
            floats[_LC + 2, col] = 0.0 + a02 * c0 + a22 * c2
            floats[_LC + 3, col] = 0.0 + a13 * c1 + a33 * c3
        if active[i, 2] != 0:
            if k == width:
                return False
            ints[top, k] = 3 * i + 2
            floats[_LC, k], floats[_LC + 1, k] = 0.0, 1.0
            floats[_LC + 2, k], floats[_LC + 3, k] = 0.0, 0.0
            k += 1
        scale = 0.0
        free0, free1 = active[i, 0] == 0, active[i, 1] == 0
        floats[_RHS, 0] = -2.0 * wu[i, 0] * inputs[i, 0] - b00 * m0 - b20 * m2
        floats[_RHS, 1] = -2.0 * wu[i, 1] * inputs[i, 1] - b01 * m0 - b11 * m1 - b21 * m2 - b31 * m3
        for col in range(k):
            acc = 0.0 + b00 * floats[_LC, col] + b20 * floats[_LC + 2, col]
            floats[_JAC, col] = acc
            if free0:
                scale = max(scale, abs(acc))
        for col in range(k):
            acc = 0.0 + b01 * floats[_LC, col] + b11 * floats[_LC + 1, col]
            acc += b21 * floats[_LC + 2, col]
            acc += b31 * floats[_LC + 3, col]
            floats[_JAC + 1, col] = acc
            if free1:
                scale = max(scale, abs(acc))
        for col in range(k):
            ints[top + 1, col] = True
        # The active inputs' μ = rhs_e − jac_e w: recorded first, so computed last.
        for e in range(2):
            if active[i, e] != 0:
                idx = 3 * i + e
                floats[_EX + idx, _CONST] = floats[_RHS, e]
                for col in range(k):
                    ints[idx, col] = ints[top, col]
                    floats[_EX + idx, col] = -floats[_JAC + e, col]
                ints[idx, _COUNT] = k
                ints[nord, _ORDER] = idx
                nord += 1
        # The inactive inputs' equations fix up to two carried unknowns (full pivoting).
        used0, used1 = not free0, not free1
        for _ in range(2):
            best, pe, pp = RANK_TOL * scale, -1, -1
            for e in range(2):
                if used0 if e == 0 else used1:
                    continue
                for col in range(k):
                    if ints[top + 1, col] and abs(floats[_JAC + e, col]) > best:
                        best, pe, pp = abs(floats[_JAC + e, col]), e, col
            if pe < 0:
                break
            idx = _eliminate(pp, pe, k, floats, ints, top)
            for m in range(ints[idx, _COUNT]):  # columns into ids; λ's dependence substituted
                col = ints[idx, m]
                coef = floats[_EX + idx, m]
                for r in range(_LC, _LC + 4):
                    floats[r, col] += floats[r, pp] * coef
                ints[idx, m] = ints[top, col]
            w = floats[_EX + idx, _CONST]
            m0 += floats[_LC, pp] * w
            m1 += floats[_LC + 1, pp] * w
            m2 += floats[_LC + 2, pp] * w
            m3 += floats[_LC + 3, pp] * w
            other = 1 - pe
            if not (used0 if other == 0 else used1):
                ratio = floats[_JAC + other, pp] / floats[_JAC + pe, pp]
                for col in range(k):
                    floats[_JAC + other, col] -= ratio * floats[_JAC + pe, col]
                floats[_RHS, other] -= ratio * floats[_RHS, pe]
            ints[top + 1, pp] = False
            ints[nord, _ORDER] = idx
            nord += 1
            if pe == 0:
                used0 = True
            else:
                used1 = True
        kept = 0
        for col in range(k):
            if ints[top + 1, col]:
                ints[top, kept] = ints[top, col]
                for r in range(_LC, _LC + 4):
                    floats[r, kept] = floats[r, col]
                kept += 1
        k = kept
        f0, f1, f2, f3 = m0, m1, m2, m3
    if k:
        return False
    for m in range(nord - 1, -1, -1):
        idx = ints[m, _ORDER]
        acc = floats[_EX + idx, _CONST]
        for q in range(ints[idx, _COUNT]):
            acc += floats[_EX + idx, q] * floats[_EX + ints[idx, q], _VALUE]
        floats[_EX + idx, _VALUE] = acc
    for i in range(n):
        for j in range(3):
            mult[i, j] = floats[_EX + 3 * i + j, _VALUE] if active[i, j] != 0 else 0.0
    return True


@njit(cache=True, nogil=True)
def _pass(  # type: ignore[no-untyped-def]
    x0, a, b, wx, wu, active, bounds, tols, dual_tol, inputs, states, gains, offsets, curvature,
    mult, forced, work, swept,
):  # fmt: skip
    """Solve with ``active`` fixed, check the KKT conditions, update ``active`` if they fail.

    Returns OPTIMAL (``inputs``, ``states`` are the exact solution), CHANGED (``active`` now
    holds the next guess) or DEGENERATE (rows left on x_0, or multipliers not unique). The next
    guess adds the violated rows; only when none is violated does it release the row whose
    multiplier has the most wrong sign. The torques of the first ``forced`` stages are
    equalities (held, whatever their multipliers' signs) and those stages' θ rows are not
    checked: see :func:`solve_from`. ``work``: the scratch of :func:`scratch` (the passes of
    :func:`solve_active_set` share one).

    ``swept`` (N + 1, 3): rows 0..N−1 the active set whose recursion ``gains``, ``offsets`` and
    ``curvature`` hold, ``swept[N, 0]`` 1 if they hold one. The recursion depends on the set
    alone (A, B, the weights and bounds are the solver's own), so a pass on that set again (a
    steady state's empty set, tick after tick) skips it: the same numbers.
    """
    n = wx.shape[0]
    left = 0
    # The last stage whose rows differ from the recorded recursion's (all of it: none on record).
    start = n - 1 if swept[n, 0] != 1 else -1
    i = n - 1
    while start < 0 and i >= 0:
        if active[i, 0] != swept[i, 0] or active[i, 1] != swept[i, 1] or active[i, 2] != swept[
                i, 2]:  # fmt: skip
            start = i
        i -= 1
    if start >= 0:
        swept[n, 0] = 0  # the recursion below overwrites the arrays
        left = _backward(a, b, wx, wu, active, bounds, gains, offsets, curvature, work[0],
                         work[2], start, work[3])  # fmt: skip
        if left == 0:
            for i in range(start + 1):
                for j in range(3):
                    swept[i, j] = active[i, j]
            swept[n, 0] = 1
    if left != 0:
        # Too many rows: a θ row carried through saturated torques to a state that cannot meet
        # it. Release the chain's first torque row (else the θ row); the passes go on from there.
        origin = -left - 2
        for i in range(forced, origin + 1):
            if active[i, 1] != 0:
                active[i, 1] = 0
                return CHANGED
        if active[origin, 2] == 0:
            return DEGENERATE
        active[origin, 2] = 0
        return CHANGED
    # The rollout (the state in scalars; A's and B's zeros skipped), the inactive rows checked
    # on the way: the violated ones are added, no θ row after the first nor in the forced stages.
    a00, a02, a20, a22 = a[0, 0], a[0, 2], a[2, 0], a[2, 2]
    a11, a13, a31, a33 = a[1, 1], a[1, 3], a[3, 1], a[3, 3]
    b00, b20, b01, b11, b21, b31 = b[0, 0], b[2, 0], b[0, 1], b[1, 1], b[2, 1], b[3, 1]
    lo0, hi0 = bounds[0, 0] - tols[0], bounds[0, 1] + tols[0]
    lo1, hi1 = bounds[1, 0] - tols[1], bounds[1, 1] + tols[1]
    lo2, hi2 = bounds[2, 0] - tols[2], bounds[2, 1] + tols[2]
    s0, s1, s2, s3 = x0[0], x0[1], x0[2], x0[3]
    states[0, 0], states[0, 1], states[0, 2], states[0, 3] = s0, s1, s2, s3
    added, angle = False, False
    for i in range(n):
        u0 = offsets[i, 0] + gains[i, 0, 0] * s0 + gains[i, 0, 1] * s1 + gains[i, 0, 2] * s2
        u0 += gains[i, 0, 3] * s3
        u1 = offsets[i, 1] + gains[i, 1, 0] * s0 + gains[i, 1, 1] * s1 + gains[i, 1, 2] * s2
        u1 += gains[i, 1, 3] * s3
        s0, s1, s2, s3 = (
            a00 * s0 + a02 * s2 + b00 * u0 + b01 * u1, a11 * s1 + a13 * s3 + b11 * u1,
            a20 * s0 + a22 * s2 + b20 * u0 + b21 * u1, a31 * s1 + a33 * s3 + b31 * u1,
        )  # fmt: skip
        inputs[i, 0], inputs[i, 1] = u0, u1
        states[i + 1, 0], states[i + 1, 1], states[i + 1, 2], states[i + 1, 3] = s0, s1, s2, s3
        if active[i, 0] == 0:
            if u0 > hi0:
                active[i, 0] = 1
                added = True
            elif u0 < lo0:
                active[i, 0] = -1
                added = True
        if active[i, 1] == 0:
            if u1 > hi1:
                active[i, 1] = 1
                added = True
            elif u1 < lo1:
                active[i, 1] = -1
                added = True
        if active[i, 2] == 0 and not (angle or i < forced):
            if s1 > hi2:
                active[i, 2] = 1
                added = angle = True
            elif s1 < lo2:
                active[i, 2] = -1
                added = angle = True
    if added:
        return CHANGED
    empty = True
    for i in range(n):
        for j in range(3):
            if active[i, j] != 0:
                empty = False
    if empty:  # no multiplier to find or check: the unconstrained optimum
        for i in range(n):
            for j in range(3):
                mult[i, j] = 0.0
        return OPTIMAL
    if not _multipliers(a, b, wx, wu, active, inputs, states, mult, work[0], work[1]):
        return DEGENERATE
    worst, worst_i, worst_j = 0.0, -1, -1
    for i in range(n):
        for j in range(3):
            side = active[i, j]
            if side == 0 or (j == 1 and i < forced):
                continue
            if j < 2:
                scale = curvature[i, j] * (bounds[j, 1] - bounds[j, 0])
            else:
                scale = curvature[i, 1] * (bounds[1, 1] - bounds[1, 0]) / abs(b11)
            wrong = -mult[i, j] * side / scale
            if wrong > dual_tol and wrong > worst:
                worst, worst_i, worst_j = wrong, i, j
    if worst_i < 0:
        return OPTIMAL
    active[worst_i, worst_j] = 0  # one at a time: releasing a whole block overshoots
    return CHANGED


@njit(cache=True, nogil=True)
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
    forced,
    inputs,
    states,
    gains,
    offsets,
    curvature,
    mult,
    work,
    swept,
):
    """Primal-dual active-set iterations from ``active``; the number of passes, or −1.

    On success ``inputs`` (N, 2), ``states`` (N + 1, 4) and ``mult`` (N, 3) are the KKT point
    and ``active`` its active set. −1: degenerate, or no verified optimum within
    ``max_passes`` (cycling, or an infeasible problem). ``work``: the scratch of
    :func:`scratch`, the caller's (kept from solve to solve: an allocation per tick cost
    ~1 µs); ``swept``: the record of the last recursion (:func:`_pass`).
    """
    for k in range(max_passes):
        outcome = _pass(x0, a, b, wx, wu, active, bounds, tols, dual_tol, inputs, states,
                        gains, offsets, curvature, mult, forced, work, swept)  # fmt: skip
        if outcome == OPTIMAL:
            return k + 1
        if outcome == DEGENERATE:
            return -1
    return -1


@njit(cache=True, nogil=True)
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
    empty_passes,
    max_passes,
    forced,
    forced_side,
    inputs,
    states,
    gains,
    offsets,
    curvature,
    mult,
    floats,
    ints,
    origins,
    saved,
    swept,
):
    """:func:`solve_active_set` started from ``active`` (shifted one stage if ``shift``).

    The passes work on ``guess`` (the start is copied there: ``active[i + 1]`` to stage i,
    the last stage keeping its rows); on success the verified set is copied back into
    ``active``, on failure ``active`` is left as it was. One call per tick, so the Python
    side does no array work. ``floats``, ``ints``, ``origins``, ``saved``: the scratch of
    :func:`scratch`, and ``swept`` the recursion's record (:func:`_pass`); both the
    caller's, kept from solve to solve.

    From the empty set at most ``empty_passes`` passes
    (:data:`~pushrecovery.control.mpc.solvers.riccati.EMPTY_PASSES`).

    The first ``forced`` stages' torques are held at the bound of sign ``forced_side`` and
    their θ rows left out: the flywheel on the edge of its viable set, where braking at full
    torque is the only way to keep θ within its bound (the caller's judgement), and those θ
    rows would be carried back to x_0, which cannot meet them otherwise.
    """
    n = active.shape[0]
    rows = False
    for i in range(n):
        src = i + 1 if shift and i < n - 1 else i
        for j in range(3):
            guess[i, j] = active[src, j]
            rows = rows or guess[i, j] != 0
        if i < forced:
            guess[i, 1] = forced_side
            guess[i, 2] = 0
            rows = True
    if not rows:
        max_passes = min(max_passes, empty_passes)
    passes = solve_active_set(x0, a, b, wx, wu, guess, bounds, tols, dual_tol, max_passes,
                              forced, inputs, states, gains, offsets, curvature, mult,
                              (floats, ints, origins, saved), swept)  # fmt: skip
    if passes > 0:
        for i in range(n):
            for j in range(3):
                active[i, j] = guess[i, j]
    return passes
