r"""Compiled (numba, cached on disk) primal-dual active-set solve of Eq. (17) by Riccati recursion.

One file on purpose: numba's disk cache does not see changes in the files of the functions a
kernel calls, so the kernels that call each other live together. See
:mod:`~pushrecovery.control.mpc.riccati` for the method; here, the arithmetic.

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
"""

from __future__ import annotations

import numba
import numpy as np

# Outcomes of one pass of :func:`_pass`.
OPTIMAL, CHANGED, DEGENERATE = 0, 1, -1
#: Rows carried on one state (at most the state's dimension, and one more being reduced).
CARRIED = 5
#: Relative size under which a row is dependent on the pivots, or a pivot is missing.
RANK_TOL = 1e-10


@numba.njit(cache=True, nogil=True)
def _backward(a, b, wx, wu, active, bounds, gains, offsets, curvature):  # type: ignore[no-untyped-def]
    """Riccati recursion with the active rows as equalities; the number of rows left on x_0.

    −i − 2: the rows of stage i are over-determined (a carried row reduced to 0 = e).

    Writes u_i = gains[i] x_i + offsets[i] and the diagonal of the stage's input Hessian
    H = diag(wu_i) + B^T S_{i+1} B (the scale of its multipliers) into ``curvature[i]``; the
    rows carried to x_0 into ``rows_c`` (CARRIED, 4), ``rows_e``. Per stage, with
    S = P_{i+1} + diag(wx_i), s = p_{i+1} (cost-to-go x^T P x + 2 p^T x): u = T z + F x + f (the
    pivot rows fix F, f; T spans the free directions), z minimises T^T [H u + B^T S A x + B^T s]
    = 0, and P_i = A^T S A + G^T K + K^T G + K^T H K, p_i = A^T (S B k + s) + K^T (H k + B^T s)
    with G = B^T S A and u = K x + k.
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
    rc = np.empty((CARRIED + 2, 4))  # candidate rows c^T x_i + d^T u_i = e
    rd = np.empty((CARRIED + 2, 2))
    re = np.empty(CARRIED + 2)
    pc = np.empty((2, 4))
    pd = np.empty((2, 2))
    pe = np.empty(2)
    pend_c = np.empty((CARRIED, 4))  # rows on x_{i+1}
    pend_e = np.empty(CARRIED)
    pend_o = np.empty(CARRIED, dtype=np.int64)  # the stage of the θ row a carried row comes from
    ro = np.empty(CARRIED + 2, dtype=np.int64)
    po = np.empty(2, dtype=np.int64)
    npend = 0
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
        # The stage's rows: inputs first, then those on x_{i+1} through the dynamics.
        m = 0
        for j in range(2):
            side = active[i, j]
            if side != 0:
                rc[m, :] = 0.0
                rd[m, 0], rd[m, 1] = (1.0, 0.0) if j == 0 else (0.0, 1.0)
                re[m] = bounds[j, 1] if side > 0 else bounds[j, 0]
                ro[m] = -1
                m += 1
        if active[i, 2] != 0:
            if npend == CARRIED:
                return -i - 2
            pend_o[npend] = i
            pend_c[npend, :] = 0.0
            pend_c[npend, 1] = 1.0
            pend_e[npend] = bounds[2, 1] if active[i, 2] > 0 else bounds[2, 0]
            npend += 1
        for q in range(npend):
            for c in range(4):
                acc = 0.0
                for r in range(4):
                    acc += pend_c[q, r] * a[r, c]
                rc[m, c] = acc
            for c in range(2):
                acc = 0.0
                for r in range(4):
                    acc += pend_c[q, r] * b[r, c]
                rd[m, c] = acc
            re[m] = pend_e[q]
            ro[m] = pend_o[q]
            m += 1
        # Pivots (at most two independent d's); the others reduced to rows on x_i.
        rank = 0
        npend = 0
        for q in range(m):
            size = abs(rd[q, 0]) + abs(rd[q, 1])
            if rank == 0:
                residual = size
            elif rank == 1:
                residual = abs(pd[0, 0] * rd[q, 1] - pd[0, 1] * rd[q, 0]) / (
                    abs(pd[0, 0]) + abs(pd[0, 1])
                )
            else:
                residual = 0.0
            if residual > RANK_TOL * size:
                pc[rank, :] = rc[q, :]
                pd[rank, :] = rd[q, :]
                pe[rank] = re[q]
                po[rank] = ro[q]
                rank += 1
                continue
            al0, al1 = 0.0, 0.0  # d_q = al0 d_p0 + al1 d_p1
            if rank == 1:
                al0 = (pd[0, 0] * rd[q, 0] + pd[0, 1] * rd[q, 1]) / (
                    pd[0, 0] * pd[0, 0] + pd[0, 1] * pd[0, 1]
                )
            elif rank == 2:
                det = pd[0, 0] * pd[1, 1] - pd[0, 1] * pd[1, 0]
                al0 = (rd[q, 0] * pd[1, 1] - rd[q, 1] * pd[1, 0]) / det
                al1 = (pd[0, 0] * rd[q, 1] - pd[0, 1] * rd[q, 0]) / det
            origin = max(ro[q], po[0] if al0 != 0.0 else -1, po[1] if al1 != 0.0 else -1)
            if npend == CARRIED:
                return -origin - 2
            big, scale = 0.0, 0.0
            for c in range(4):
                v = rc[q, c] - al0 * pc[0, c] - al1 * pc[1, c]
                pend_c[npend, c] = v
                big = max(big, abs(v))
                scale = max(scale, abs(rc[q, c]))
            if big <= RANK_TOL * scale:
                return -origin - 2  # a row implied by (or at odds with) the others
            pend_e[npend] = re[q] - al0 * pe[0] - al1 * pe[1]
            pend_o[npend] = origin
            npend += 1
        feed[:, :] = 0.0
        ff[:] = 0.0
        if rank == 0:
            det = h[0, 0] * h[1, 1] - h[0, 1] * h[1, 0]
            for c in range(4):
                gains[i, 0, c] = -(h[1, 1] * g[0, c] - h[0, 1] * g[1, c]) / det
                gains[i, 1, c] = -(h[0, 0] * g[1, c] - h[1, 0] * g[0, c]) / det
            offsets[i, 0] = -(h[1, 1] * hs[0] - h[0, 1] * hs[1]) / det
            offsets[i, 1] = -(h[0, 0] * hs[1] - h[1, 0] * hs[0]) / det
        elif rank == 1:
            norm2 = pd[0, 0] * pd[0, 0] + pd[0, 1] * pd[0, 1]
            for r in range(2):
                ff[r] = pd[0, r] * pe[0] / norm2
                for c in range(4):
                    feed[r, c] = -pd[0, r] * pc[0, c] / norm2
            t[0], t[1] = -pd[0, 1], pd[0, 0]
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
        else:  # u = D^{-1} (e − C x)
            det = pd[0, 0] * pd[1, 1] - pd[0, 1] * pd[1, 0]
            for r in range(2):
                c0 = (pd[1, 1] if r == 0 else -pd[1, 0]) / det  # D^{-1}[r, 0]
                c1 = (-pd[0, 1] if r == 0 else pd[0, 0]) / det  # D^{-1}[r, 1]
                offsets[i, r] = c0 * pe[0] + c1 * pe[1]
                for c in range(4):
                    gains[i, r, c] = -(c0 * pc[0, c] + c1 * pc[1, c])
        # P_i and p_i of u = K x + k.
        k0, k1 = offsets[i, 0], offsets[i, 1]
        hk0 = h[0, 0] * k0 + h[0, 1] * k1 + hs[0]
        hk1 = h[1, 0] * k0 + h[1, 1] * k1 + hs[1]
        for r in range(4):
            sb[r, 0] = sb[r, 0] * k0 + sb[r, 1] * k1 + lin[r]  # S B k + s (sb done with)
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
    if npend:
        origin = 0
        for q in range(npend):
            origin = max(origin, pend_o[q])
        return -origin - 2
    return 0


@numba.njit(cache=True, nogil=True)
def _eliminate(p, e, jac, rhs, ids, live, k, ex_const, ex_ids, ex_coef, ex_n):  # type: ignore[no-untyped-def]
    """Record unknown ``p`` from equation ``e``: w_p = (rhs_e − Σ_{c ≠ p} jac_ec w_c) / jac_ep."""
    idx = ids[p]
    pivot = jac[e, p]
    ex_const[idx] = rhs[e] / pivot
    m = 0
    for c in range(k):
        if live[c] and c != p:
            ex_ids[idx, m] = c  # a column for now; turned into an id by the caller
            ex_coef[idx, m] = -jac[e, c] / pivot
            m += 1
    ex_n[idx] = m
    return idx


@numba.njit(cache=True, nogil=True)
def _multipliers(a, b, wx, wu, active, inputs, states, mult):  # type: ignore[no-untyped-def]
    """Multipliers of the active rows into ``mult`` (N, 3); False if they are not unique.

    Backward, λ_{i+1} = l + L w with w the θ rows' multipliers not fixed yet; stage i's
    stationarity 2 W^u u_i + B^T λ_{i+1} + μ_i = 0 fixes the active inputs' μ_i (their equation)
    and, by the other equations, up to two of w. The values follow forward by substitution.
    """
    n = wx.shape[0]
    width = CARRIED + 1
    after = np.zeros(4)
    lam = np.empty(4)
    lc = np.zeros((4, width))
    tmp = np.empty(4)
    ids = np.empty(width, dtype=np.int64)
    live = np.empty(width, dtype=np.bool_)
    total = 3 * n
    ex_const = np.zeros(total)
    ex_ids = np.empty((total, width), dtype=np.int64)
    ex_coef = np.empty((total, width))
    ex_n = np.zeros(total, dtype=np.int64)
    order = np.empty(total, dtype=np.int64)
    nord = 0
    jac = np.empty((2, width))
    rhs = np.empty(2)
    k = 0
    for i in range(n - 1, -1, -1):
        for r in range(4):
            acc = 2.0 * wx[i, r] * states[i + 1, r]
            for q in range(4):
                acc += a[q, r] * after[q]
            lam[r] = acc
        for col in range(k):
            for r in range(4):
                acc = 0.0
                for q in range(4):
                    acc += a[q, r] * lc[q, col]
                tmp[r] = acc
            lc[:, col] = tmp
        if active[i, 2] != 0:
            if k == width:
                return False
            ids[k] = 3 * i + 2
            lc[:, k] = 0.0
            lc[1, k] = 1.0
            k += 1
        scale = 0.0
        for e in range(2):
            acc = -2.0 * wu[i, e] * inputs[i, e]
            for q in range(4):
                acc -= b[q, e] * lam[q]
            rhs[e] = acc
            for col in range(k):
                acc = 0.0
                for q in range(4):
                    acc += b[q, e] * lc[q, col]
                jac[e, col] = acc
                if active[i, e] == 0:
                    scale = max(scale, abs(acc))
            live[e] = False
        for col in range(k):
            live[col] = True
        # The active inputs' μ = rhs_e − jac_e w: recorded first, so computed last.
        for e in range(2):
            if active[i, e] != 0:
                idx = 3 * i + e
                ex_const[idx] = rhs[e]
                for col in range(k):
                    ex_ids[idx, col] = ids[col]
                    ex_coef[idx, col] = -jac[e, col]
                ex_n[idx] = k
                order[nord] = idx
                nord += 1
        # The inactive inputs' equations fix up to two carried unknowns (full pivoting).
        used0, used1 = active[i, 0] != 0, active[i, 1] != 0
        for _ in range(2):
            best, pe, pp = RANK_TOL * scale, -1, -1
            for e in range(2):
                if used0 if e == 0 else used1:
                    continue
                for col in range(k):
                    if live[col] and abs(jac[e, col]) > best:
                        best, pe, pp = abs(jac[e, col]), e, col
            if pe < 0:
                break
            idx = _eliminate(pp, pe, jac, rhs, ids, live, k, ex_const, ex_ids, ex_coef, ex_n)
            for m in range(ex_n[idx]):  # columns into ids; λ's dependence substituted
                col = ex_ids[idx, m]
                for r in range(4):
                    lc[r, col] += lc[r, pp] * ex_coef[idx, m]
                ex_ids[idx, m] = ids[col]
            for r in range(4):
                lam[r] += lc[r, pp] * ex_const[idx]
            other = 1 - pe
            if not (used0 if other == 0 else used1):
                ratio = jac[other, pp] / jac[pe, pp]
                for col in range(k):
                    jac[other, col] -= ratio * jac[pe, col]
                rhs[other] -= ratio * rhs[pe]
            live[pp] = False
            order[nord] = idx
            nord += 1
            if pe == 0:
                used0 = True
            else:
                used1 = True
        kept = 0
        for col in range(k):
            if live[col]:
                ids[kept] = ids[col]
                lc[:, kept] = lc[:, col]
                kept += 1
        k = kept
        for r in range(4):
            after[r] = lam[r]
    if k:
        return False
    value = np.zeros(total)
    for m in range(nord - 1, -1, -1):
        idx = order[m]
        acc = ex_const[idx]
        for q in range(ex_n[idx]):
            acc += ex_coef[idx, q] * value[ex_ids[idx, q]]
        value[idx] = acc
    for i in range(n):
        for j in range(3):
            mult[i, j] = value[3 * i + j] if active[i, j] != 0 else 0.0
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
    forced,
):
    """Solve with ``active`` fixed, check the KKT conditions, update ``active`` if they fail.

    Returns OPTIMAL (``inputs``, ``states`` are the exact solution), CHANGED (``active`` now
    holds the next guess) or DEGENERATE (rows left on x_0, or multipliers not unique). The next
    guess adds the violated rows; only when none is violated does it release the row whose
    multiplier has the most wrong sign. The torques of the first ``forced`` stages are
    equalities (held, whatever their multipliers' signs) and those stages' θ rows are not
    checked: see :func:`solve_from`.
    """
    n = wx.shape[0]
    left = _backward(a, b, wx, wu, active, bounds, gains, offsets, curvature)
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
    added, angle = False, False
    for i in range(n):
        values = (inputs[i, 0], inputs[i, 1], states[i + 1, 1])
        for j in range(3):
            if active[i, j] == 0 and not (j == 2 and (angle or i < forced)):
                if values[j] > bounds[j, 1] + tols[j]:
                    active[i, j] = 1
                    added = True
                    angle |= j == 2
                elif values[j] < bounds[j, 0] - tols[j]:
                    active[i, j] = -1
                    added = True
                    angle |= j == 2
    if added:
        return CHANGED
    if not _multipliers(a, b, wx, wu, active, inputs, states, mult):
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
    forced,
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
                        offsets, curvature, mult, forced)  # fmt: skip
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
    forced,
    forced_side,
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

    The first ``forced`` stages' torques are held at the bound of sign ``forced_side`` and
    their θ rows left out: the flywheel on the edge of its viable set, where braking at full
    torque is the only way to keep θ within its bound (the caller's judgement), and those θ
    rows would be carried back to x_0, which cannot meet them otherwise.
    """
    n = active.shape[0]
    for i in range(n):
        src = i + 1 if shift and i < n - 1 else i
        for j in range(3):
            guess[i, j] = active[src, j]
        if i < forced:
            guess[i, 1] = forced_side
            guess[i, 2] = 0
    passes = solve_active_set(x0, a, b, wx, wu, guess, bounds, tols, dual_tol, max_passes,
                              forced, inputs, states, gains, offsets, curvature,
                              mult)  # fmt: skip
    if passes > 0:
        for i in range(n):
            for j in range(3):
                active[i, j] = guess[i, j]
    return passes
