"""Compiled (numba, cached on disk) fused loops: the planar margin and the strategy codes.

Module-level functions, so numba's on-disk cache is keyed by this file and hits in every new
process; imported lazily, only for arrays large enough to repay loading numba.
"""

from __future__ import annotations

import math

import numpy as np

from pushrecovery.kernels.jit import njit, prange

#: Edge tables come padded to one of these row counts when they have no more (repeating a row
#: changes no maximum or minimum): the loop over edges then has a constant count, unrolls and
#: runs on SIMD lanes across states, 3-5x faster than a loop of run-time length.
EDGE_BLOCKS = (4, 8)


@njit(cache=True, nogil=True, inline="always")
def _point_margin(edges, count, px, py):  # type: ignore[no-untyped-def]
    """Signed distance of p to the convex polygon of the first ``count`` rows of ``edges``.

    Rows as :attr:`pushrecovery.ground.polygon.ConvexPolygon.edge_table`. Inside, the margin
    is −max_i e_i with e_i = n_i · p − b_i. Outside it is −sqrt(min_i (e_i² + d_i²)), d_i =
    max(−s_i, s_i − length_i, 0) with s_i = t_i · p − a_i the tangential coordinate: e_i² +
    d_i² is the squared distance to edge i's segment, and the nearest point of the polygon
    lies on one of them. No branches, so that the loop runs on SIMD lanes.
    """
    excess = -np.inf
    gap2 = np.inf
    for k in range(count):
        e = edges[k, 0] * px + edges[k, 1] * py - edges[k, 2]
        s = edges[k, 3] * px + edges[k, 4] * py - edges[k, 5]
        d = max(max(-s, s - edges[k, 6]), 0.0)
        c = e * e + d * d
        excess = e if e > excess else excess
        gap2 = c if c < gap2 else gap2
    return -excess if excess <= 0.0 else -math.sqrt(gap2)


def polygon_margin(x, y, xdot, ydot, inv_omega, edges, out):  # type: ignore[no-untyped-def]
    """Signed distance of ξ = r + ṙ/ω to a convex polygon (see :func:`_point_margin`) [m].

    ``edges`` from :func:`padded_edges`; flat float arrays. Returns the number of non-finite
    margins.
    """
    count = edges.shape[0]
    kernel = _MARGINS[count] if count in _MARGINS else _MARGINS[0]
    return kernel(x, y, xdot, ydot, inv_omega, edges, out)


# Each loop is built for one edge count (0: the table's own, at run time): a count frozen in
# the closure is a compile-time constant, which lets the loop over edges unroll. Each build is
# named after its count, so that it has a disk cache of its own (``_margins_4``, ...).
def _margins_loop(count):  # type: ignore[no-untyped-def]
    def margins(x, y, xdot, ydot, inv_omega, edges, out):  # type: ignore[no-untyped-def]
        bad = 0
        for i in prange(x.shape[0]):
            px, py = x[i] + xdot[i] * inv_omega, y[i] + ydot[i] * inv_omega
            margin = _point_margin(edges, count if count else edges.shape[0], px, py)
            out[i] = margin
            if not math.isfinite(margin):
                bad += 1
        return bad

    margins.__qualname__ = f"_margins_{count or 'any'}"
    return njit(parallel=True, cache=True, nogil=True)(margins)


_MARGINS = {count: _margins_loop(count) for count in (0, *EDGE_BLOCKS)}


@njit(parallel=True, cache=True, nogil=True)
def sagittal_codes(  # type: ignore[no-untyped-def]
    x, xdot, inv_omega, cop_centre, cop_half, cmp_centre, cmp_half, step_centre, step_half, out
):
    """Strategy codes on the line: 0 ankle (Eq. 4), 1 hip (Eq. 15), 2 step (S1), 3 fall.

    Each region an interval (centre, half-width); the margins are computed as
    :func:`pushrecovery.surfaces.cop.capture_margin` does, so the verdicts agree bit for bit.
    Returns the number of non-finite states.
    """
    bad = 0
    for i in prange(x.shape[0]):
        xi = x[i] + xdot[i] * inv_omega
        if cop_half - abs(xi - cop_centre) > 0.0:
            out[i] = 0
        elif cmp_half - abs(xi - cmp_centre) > 0.0:
            out[i] = 1
        elif step_half - abs(xi - step_centre) > 0.0:
            out[i] = 2
        else:
            out[i] = 3
            if not math.isfinite(xi):
                bad += 1
    return bad


def plane_codes(x, y, xdot, ydot, inv_omega, cop_edges, cmp_edges, out):  # type: ignore[no-untyped-def]
    """Strategy codes decided by the planar regions alone: 0 ankle, 1 hip, 3 beyond both.

    Inside a convex polygon means max_i(n_i · ξ − b_i) < 0 (``edges`` rows: n_x, n_y, b, ...),
    as the signed distance > 0 of :mod:`pushrecovery.ground.polygon`; tables of
    :func:`padded_edges` take an unrolled loop. Returns (states beyond the hip region,
    non-finite states).
    """
    args = (x, y, xdot, ydot, inv_omega, cop_edges, cmp_edges, out)
    if cop_edges.shape[0] == cmp_edges.shape[0] == EDGE_BLOCKS[0]:
        return _CODES[EDGE_BLOCKS[0]](*args)
    if cop_edges.shape[0] <= EDGE_BLOCKS[1] and cmp_edges.shape[0] <= EDGE_BLOCKS[1]:
        cop_edges, cmp_edges = padded_edges(cop_edges, 1), padded_edges(cmp_edges, 1)
        return _CODES[EDGE_BLOCKS[1]](*args[:5], cop_edges, cmp_edges, out)
    return _CODES[0](*args)


# As :func:`_margins_loop`: one build per edge count (a shared helper returning a tuple of
# both regions' excesses is 2-5x slower than these fused loops).
def _codes_loop(count):  # type: ignore[no-untyped-def]
    def codes(x, y, xdot, ydot, inv_omega, cop_edges, cmp_edges, out):  # type: ignore[no-untyped-def]
        beyond = 0
        bad = 0
        for i in prange(x.shape[0]):
            px, py = x[i] + xdot[i] * inv_omega, y[i] + ydot[i] * inv_omega
            cop = _max_excess(cop_edges, count if count else cop_edges.shape[0], px, py)
            hip = _max_excess(cmp_edges, count if count else cmp_edges.shape[0], px, py)
            code = 0 if cop < 0.0 else (1 if hip < 0.0 else 3)
            out[i] = code
            beyond += code == 3
            bad += not (abs(px) + abs(py) < np.inf)  # NaN or infinite
        return beyond, bad

    codes.__qualname__ = f"_codes_{count or 'any'}"
    return njit(parallel=True, cache=True, nogil=True)(codes)


@njit(cache=True, nogil=True, inline="always")
def _max_excess(edges, count, px, py):  # type: ignore[no-untyped-def]
    """max_i(n_i · p − b_i) over the first ``count`` rows of ``edges``."""
    excess = -np.inf
    for k in range(count):
        e = edges[k, 0] * px + edges[k, 1] * py - edges[k, 2]
        excess = e if e > excess else excess
    return excess


_CODES = {count: _codes_loop(count) for count in (0, *EDGE_BLOCKS)}


def padded_edges(table, smallest=0):  # type: ignore[no-untyped-def]
    """Return an edge table padded to the first of :data:`EDGE_BLOCKS` rows that holds it.

    Repeats its last row; tables longer than every block come back as they are. Blocks before
    index ``smallest`` are skipped.
    """
    rows = np.ascontiguousarray(table)
    fits = [block for block in EDGE_BLOCKS[smallest:] if block >= len(rows)]
    missing = fits[0] - len(rows) if fits else 0
    return np.ascontiguousarray(np.vstack([rows, np.repeat(rows[-1:], missing, axis=0)]))


@njit(cache=True, nogil=True)
def locate_steps(table, counts, steps, outer, px, py):  # type: ignore[no-untyped-def]
    """Return (steps of the first region holding p, 0 if none; largest signed distance [m]).

    ``table`` stacks the regions' edge tables (rows padded), ``counts`` their edge counts,
    ``steps`` the number of steps of each region (ascending); the distance is taken over the
    regions flagged in ``outer``, whose union is that of all.
    """
    best = -np.inf
    for r in range(table.shape[0]):
        if outer[r]:
            margin = _point_margin(table[r], counts[r], px, py)
            best = margin if margin > best else best
    if not best > 0.0:
        return 0, best
    for r in range(table.shape[0]):
        if _max_excess(table[r], counts[r], px, py) < 0.0:
            return steps[r], best
    return 0, best  # pragma: no cover - inside the union is inside one of them


@njit(parallel=True, cache=True, nogil=True)
def mark_regions(  # type: ignore[no-untyped-def]
    x, y, xdot, ydot, inv_omega, table, counts, discs, codes, pending, mark
):
    """Set ``codes[i] = mark`` where ``codes[i] == pending`` and ξ_i lies in some region.

    ``discs`` rows (c_x, c_y, r_in², r_out²): inside the inscribed disc is inside, outside the
    circumscribed one outside, so that most states skip the edges.
    """
    for i in prange(x.shape[0]):
        if codes[i] != pending:
            continue
        px, py = x[i] + xdot[i] * inv_omega, y[i] + ydot[i] * inv_omega
        for r in range(table.shape[0]):
            dx, dy = px - discs[r, 0], py - discs[r, 1]
            gap = dx * dx + dy * dy
            if gap < discs[r, 2]:
                inside = True
            elif gap >= discs[r, 3]:
                inside = False
            else:
                inside = _max_excess(table[r], counts[r], px, py) < 0.0
            if inside:
                codes[i] = mark
                break
