"""Compiled (numba, cached on disk) fused loops: the planar margin and the strategy codes.

Module-level functions, so numba's on-disk cache is keyed by this file and hits in every new
process; imported lazily, only for arrays large enough to repay loading numba.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: States per block of the planar margin: the block's temporaries stay in the L1 cache.
_BLOCK = 4096


@numba.njit(parallel=True, cache=True, nogil=True)
def polygon_margin(  # type: ignore[no-untyped-def]
    x, y, xdot, ydot, inv_omega, edges, out
):
    """Signed distance of ξ = r + ṙ/ω to a convex polygon (see ground.polygon) [m].

    ``edges`` has one row per edge: normal (2), offset, start vertex (2), edge vector (2) and
    1/|edge|². Inside, the margin is −max_i e_i with e_i = n_i · ξ − b_i. Outside it is minus
    the square root of min_i c_i, with c_i = e_i² where ξ projects onto edge i's segment
    (0 <= t_i <= 1: the foot lies on the polygon) and |ξ − v_i|² elsewhere: every candidate
    is the distance to a point of the polygon, and the nearest point (an edge's interior or a
    vertex) is among them. Edge by edge over a block of states and without branches, so that
    the inner loop runs on SIMD lanes. Returns the number of non-finite margins.
    """
    size = x.shape[0]
    count = edges.shape[0]
    blocks = (size + _BLOCK - 1) // _BLOCK
    bad = 0
    for block in numba.prange(blocks):
        start = block * _BLOCK
        m = min(start + _BLOCK, size) - start
        px = np.empty(m)
        py = np.empty(m)
        excess = np.empty(m)
        gap2 = np.empty(m)
        for i in range(m):
            px[i] = x[start + i] + xdot[start + i] * inv_omega
            py[i] = y[start + i] + ydot[start + i] * inv_omega
            excess[i] = -np.inf
            gap2[i] = np.inf
        for k in range(count):
            nx, ny, b = edges[k, 0], edges[k, 1], edges[k, 2]
            vx, vy, ux, uy, inv = edges[k, 3], edges[k, 4], edges[k, 5], edges[k, 6], edges[k, 7]
            for i in range(m):
                e = nx * px[i] + ny * py[i] - b
                excess[i] = e if e > excess[i] else excess[i]
                dx = px[i] - vx
                dy = py[i] - vy
                t = (dx * ux + dy * uy) * inv
                c = e * e if (t >= 0.0) & (t <= 1.0) else dx * dx + dy * dy
                gap2[i] = c if c < gap2[i] else gap2[i]
        for i in range(m):
            margin = -excess[i] if excess[i] <= 0.0 else -math.sqrt(gap2[i])
            out[start + i] = margin
            if not math.isfinite(margin):
                bad += 1
    return bad


@numba.njit(parallel=True, cache=True, nogil=True)
def sagittal_codes(  # type: ignore[no-untyped-def]
    x, xdot, inv_omega, cop_centre, cop_half, cmp_centre, cmp_half, out
):
    """Strategy codes decided by the margins alone: 0 ankle (Eq. 4), 1 hip (Eq. 15), 3 else.

    The margins are computed as :func:`pushrecovery.surfaces.cop.capture_margin` does, so
    the verdicts agree bit for bit. Returns (states beyond the hip region, non-finite states).
    """
    beyond = 0
    bad = 0
    for i in numba.prange(x.shape[0]):
        xi = x[i] + xdot[i] * inv_omega
        if cop_half - abs(xi - cop_centre) > 0.0:
            out[i] = 0
        elif cmp_half - abs(xi - cmp_centre) > 0.0:
            out[i] = 1
        else:
            out[i] = 3
            if math.isfinite(xi):
                beyond += 1
            else:
                bad += 1
    return beyond, bad


#: Edge tables of :func:`plane_codes` come padded to exactly this many rows when they have no
#: more (repeating a row changes no maximum): the loop over edges then has a constant count,
#: unrolls and runs without branches, 4-5x faster than a loop of run-time length.
EDGE_BLOCK = 8


@numba.njit(parallel=True, cache=True, nogil=True)
def plane_codes(x, y, xdot, ydot, inv_omega, cop_edges, cmp_edges, out):  # type: ignore[no-untyped-def]
    """Strategy codes decided by the planar regions alone: 0 ankle, 1 hip, 3 beyond both.

    Inside a convex polygon means max_i(n_i · ξ − b_i) < 0 (``edges`` rows: n_x, n_y, b), as
    the signed distance > 0 of :mod:`pushrecovery.ground.polygon`; tables of
    :data:`EDGE_BLOCK` rows take the unrolled loop. Returns (states beyond the hip region,
    non-finite states).
    """
    beyond = 0
    bad = 0
    fixed = cop_edges.shape[0] == EDGE_BLOCK and cmp_edges.shape[0] == EDGE_BLOCK
    for i in numba.prange(x.shape[0]):
        px = x[i] + xdot[i] * inv_omega
        py = y[i] + ydot[i] * inv_omega
        if fixed:
            cop = _max_excess_fixed(cop_edges, px, py)
            hip = _max_excess_fixed(cmp_edges, px, py)
        else:
            cop = _max_excess(cop_edges, px, py)
            hip = _max_excess(cmp_edges, px, py)
        code = 0 if cop < 0.0 else (1 if hip < 0.0 else 3)
        out[i] = code
        beyond += code == 3
        bad += not (abs(px) + abs(py) < np.inf)  # NaN or infinite
    return beyond, bad


@numba.njit(cache=True, nogil=True, inline="always")
def _max_excess_fixed(edges, px, py):  # type: ignore[no-untyped-def]
    """max_i(n_i · p − b_i) over exactly EDGE_BLOCK rows (unrolled)."""
    excess = -np.inf
    for k in range(EDGE_BLOCK):
        e = edges[k, 0] * px + edges[k, 1] * py - edges[k, 2]
        excess = e if e > excess else excess
    return excess


@numba.njit(cache=True, nogil=True, inline="always")
def _max_excess(edges, px, py):  # type: ignore[no-untyped-def]
    """max_i(n_i · p − b_i) over the rows of ``edges``."""
    excess = -np.inf
    for k in range(edges.shape[0]):
        e = edges[k, 0] * px + edges[k, 1] * py - edges[k, 2]
        excess = e if e > excess else excess
    return excess


def padded_edges(table):  # type: ignore[no-untyped-def]
    """Return the (n_x, n_y, b) columns of an edge table, padded to EDGE_BLOCK rows if fewer."""
    rows = np.ascontiguousarray(table[:, :3])
    missing = max(0, EDGE_BLOCK - len(rows))
    return np.ascontiguousarray(np.vstack([rows, np.repeat(rows[-1:], missing, axis=0)]))
