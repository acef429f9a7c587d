"""The whole-body QP's per-tick arrays, allocated once (:mod:`~pushrecovery.control.wbc.qp`)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = []


class Buffers:
    """Every array of a tick, allocated once (``rows`` for all feet in contact)."""

    def __init__(self, nv: int, nf: int, rows: int, nu: int) -> None:
        size = nv + nf
        self.offset = np.zeros(nu)
        self.mass, self.jac, self.local = np.zeros((nv, nv)), np.zeros((nf, nv)), np.zeros((nf, nv))
        self.jac_dot, self.dots, self.points = (
            np.zeros(nf),
            np.zeros((nf, nv)),
            np.zeros((nf // 6, 3)),
        )
        self.hessian, self.linear, self.x = np.zeros((size, size)), np.zeros(size), np.zeros(size)
        self.factor, self.shift, self.first = (
            np.zeros((size, size)),
            np.zeros(size),
            np.zeros(size, np.int64),
        )
        self.rows, self.upper, self.lower = np.zeros((rows, size)), np.zeros(rows), np.zeros(rows)
        self.ldp_rows, self.ldp_upper, self.ldp_lower = (
            np.zeros((rows, size)),
            np.zeros(rows),
            np.zeros(rows),
        )
