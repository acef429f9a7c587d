"""Compiled (numba, cached on disk) placement of regions built once in a stance foot's frame.

A single-support region of :mod:`pushrecovery.surfaces.n_step` is a rigid transform of the same
region built for the stance ankle at the origin with yaw 0: rotating every term of (S1) by the
stance yaw ψ and moving the ankle to q rotates and moves the sum. An edge table row
(n_x, n_y, b, t_x, t_y, a, length) (``ConvexPolygon.edge_table``) then becomes

    n' = R n,  t' = R t,  b' = b + n' · q,  a' = a + t' · q,  length' = length,

R the rotation by ψ: a handful of flops per edge instead of the Minkowski sums.
"""

from __future__ import annotations

from pushrecovery.kernels.jit import njit

__all__: list[str] = []


@njit(cache=True, nogil=True)
def place_tables(tables, counts, discs, poses, out, out_discs):  # type: ignore[no-untyped-def]
    """Rotate and move K stances' canonical tables into ``out``, levels interleaved.

    ``tables`` (K, M, E, 7) edge tables of M levels per stance, ``counts`` (K, M) their edge
    counts, ``discs`` (K, M, 4) rows (c_x, c_y, r_in², r_out²), ``poses`` (K, 4) rows
    (cos ψ, sin ψ, q_x, q_y). Row m K + k of ``out`` (rows of width W >= every count, padded
    by repeating the last edge) and of ``out_discs`` is level m of stance k.
    """
    stances, levels = tables.shape[0], tables.shape[1]
    width = out.shape[1]
    for m in range(levels):
        for k in range(stances):
            row = m * stances + k
            c, s, qx, qy = poses[k, 0], poses[k, 1], poses[k, 2], poses[k, 3]
            last = counts[k, m] - 1
            for e in range(width):
                src = tables[k, m, e if e < last else last]
                nx = c * src[0] - s * src[1]
                ny = s * src[0] + c * src[1]
                tx = c * src[3] - s * src[4]
                ty = s * src[3] + c * src[4]
                out[row, e, 0] = nx
                out[row, e, 1] = ny
                out[row, e, 2] = src[2] + (nx * qx + ny * qy)
                out[row, e, 3] = tx
                out[row, e, 4] = ty
                out[row, e, 5] = src[5] + (tx * qx + ty * qy)
                out[row, e, 6] = src[6]
            cx, cy = discs[k, m, 0], discs[k, m, 1]
            out_discs[row, 0] = c * cx - s * cy + qx
            out_discs[row, 1] = s * cx + c * cy + qy
            out_discs[row, 2] = discs[k, m, 2]
            out_discs[row, 3] = discs[k, m, 3]
