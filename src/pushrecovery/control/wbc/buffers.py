"""The whole-body QP's per-tick arrays, allocated once, and MuJoCo's dense inertia (:mod:`.qp`)."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = ["Buffers", "full_inertia", "inertia_writer"]


def full_inertia(model: Any, data: Any, out: FloatArray) -> None:
    """Write the dense joint-space inertia M into ``out`` (MuJoCo 4's and 3's ``mj_fullM``)."""
    inertia_writer(model, data, out)()


def inertia_writer(model: Any, data: Any, out: FloatArray) -> Callable[[], None]:
    """Return a call that writes :func:`full_inertia` of ``data`` into ``out``, bound once.

    MuJoCo's arrays are views of ``data``'s fixed arena: a tick's call skips the version test
    and the lookups.
    """
    import mujoco

    if hasattr(data, "qM"):  # MuJoCo 3: mj_fullM(m, dst, qM)
        return partial(mujoco.mj_fullM, model, out, data.qM)
    return partial(mujoco.mj_fullM, model, data, out)  # MuJoCo 4: mj_fullM(m, d, dst)


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
