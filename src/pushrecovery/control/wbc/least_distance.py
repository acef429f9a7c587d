r"""The whole-body QP's solve: DAQP on its least-distance form, motor rows last.

:class:`~.qp.WholeBodyQP` writes the QP min ½ xᵀ H x + fᵀ x s.t. l ≤ A x ≤ u into its
buffers (:mod:`.buffers`): the equality rows first, the wrench rows, then one row per
motor. :class:`LeastDistanceSolver` factors H on its envelope and hands DAQP the problem's
least-distance form (:func:`.kernels.wbc.least_distance`: H = I, M = A R⁻¹, bounds shifted),
first *without* the motor rows: a convex QP's optimum stays optimal under constraints it
satisfies, so when every command lands strictly inside its range that is the answer; else it
solves again with them, and keeps them while a motor stays on its limit. DAQP keeps one model
per number of rows handed over (without or with the motors'), warm-started tick to tick from
its last active set; the equality rows are immutable.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.buffers import Buffers
from pushrecovery.kernels.wbc import commands, least_distance, recover, transform_rows

FloatArray = NDArray[np.float64]

__all__ = []

#: DAQP's sense flags: an active, immutable row (an equality).
_EQUALITY = 5


class LeastDistanceSolver:
    """DAQP's workspaces for one QP's buffers, and the motor rows' screening (module docstring).

    Parameters
    ----------
    buf : Buffers
        The QP's arrays (:class:`~.buffers.Buffers`).
    equalities : int
        The number of equality rows at the top of ``buf.rows``.
    ctrl_low, ctrl_high : float arrays, shape (nu,)
        The motors' command ranges [N m] (±inf: unlimited).
    """

    def __init__(
        self, buf: Buffers, equalities: int, ctrl_low: FloatArray, ctrl_high: FloatArray
    ) -> None:
        self.buf, self.equalities = buf, equalities
        self.ctrl_low, self.ctrl_high = ctrl_low, ctrl_high
        size = buf.hessian.shape[0]
        self._identity, self._zeros = np.eye(size), np.zeros(size)
        self._models: dict[int, Any] = {}  # DAQP, by rows handed over: without/with the motors'
        self._views: dict[int, tuple[Any, ...]] = {}  # the buffers' rows, by count (no slicing)
        self._motor_rows = False  # whether the last tick needed the motor rows
        self._product = np.zeros(buf.offset.shape[0])  # A_a x of the motor rows
        self.last_ctrl = np.zeros(buf.offset.shape[0])  # the last good command

    def forget(self) -> None:
        """Drop the warm start: the next solve sets DAQP up afresh (other rows)."""
        self._models.clear()

    def _rows(self, count: int) -> tuple[Any, ...]:
        """Return the views a tick of ``count`` rows reads (made once per count)."""
        views = self._views.get(count)
        if views is None:
            buf, nu = self.buf, self.buf.offset.shape[0]
            views = self._views[count] = (
                buf.ldp_rows[:count], buf.ldp_upper[:count], buf.ldp_lower[:count],
                buf.rows[count - nu : count],
            )  # fmt: skip
        return views

    def _daqp(self, count: int) -> tuple[Any, int, int]:
        """Return DAQP's (u, flag, iterations) on the first ``count`` least-distance rows."""
        rows, high, low, _ = self._rows(count)
        model = self._models.get(count)
        if model is None:
            import daqp  # here: an import statement costs a tick ~60 ns

            sense = np.where(np.arange(count) < self.equalities, _EQUALITY, 0).astype(np.intc)
            model = daqp.Model()
            flag, _ = model.setup(self._identity, self._zeros, rows, high, low, sense)
            if flag < 0:
                raise RuntimeError(f"daqp could not set up the whole-body QP (exit flag {flag})")
            self._models[count] = model
        else:
            model.update(A=rows, bupper=high, blower=low)
        u, _, flag, info = model.solve()
        return u, int(flag), int(info["iterations"])

    def solve(self, count: int) -> tuple[FloatArray | None, FloatArray, float, int]:
        """Solve the QP of ``count`` rows in the buffers.

        Returns x (a new array; None when DAQP found no solution or H is not positive
        definite), the motor commands (new; clipped to their ranges, or a copy of the last good
        ones), the wall time of the factorisation and DAQP's update and solve [s], and DAQP's
        iterations.
        """
        buf, nu = self.buf, self._product.shape[0]
        start = time.perf_counter()  # the solve time includes the factorisation of H
        flag, steps, reduced = -1, 0, count - nu
        ctrl = np.empty(nu)
        if least_distance(buf.hessian, buf.linear, buf.rows, buf.upper, buf.lower, reduced,
                          buf.factor, buf.first, buf.shift, buf.ldp_rows, buf.ldp_upper,
                          buf.ldp_lower):  # fmt: skip
            # Without the (rarely active) motor rows first: a convex QP's optimum stays optimal
            # under constraints it satisfies; else again with them, and next tick at once.
            for rows in (count,) if self._motor_rows else (reduced, count):
                if rows == count:  # the motor rows, transformed only when needed
                    transform_rows(buf.factor, buf.first, buf.shift, buf.rows, buf.upper,
                                   buf.lower, reduced, count, buf.ldp_rows, buf.ldp_upper,
                                   buf.ldp_lower)  # fmt: skip
                u, flag, iterations = self._daqp(rows)
                steps += iterations
                if flag <= 0:
                    break
                recover(buf.factor, buf.first, buf.shift, u, buf.x)
                # NumPy's dot (BLAS's order of the sums), then the offset and the clip.
                product = np.dot(self._rows(count)[3], buf.x, out=self._product)
                inside = commands(product, buf.offset, self.ctrl_low, self.ctrl_high, ctrl)
                if rows == count:
                    self._motor_rows = not inside  # a motor on its limit: keep the rows
                    break
                if inside:
                    break
        elapsed = time.perf_counter() - start
        if flag <= 0:
            self.forget()  # the next tick starts cold, without the motor rows
            self._motor_rows = False
            return None, self.last_ctrl.copy(), elapsed, steps
        self.last_ctrl = ctrl
        return buf.x.copy(), ctrl, elapsed, steps
