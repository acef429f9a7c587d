"""A task of the whole-body QP: a weighted least-squares term W ‖A x − b‖² (mink's ``Task``).

x = (q̈, w_1, …) stacks the joint accelerations q̈ ∈ R^nv [m/s², rad/s²] and one contact
wrench w_i = (F_i, T_i) ∈ R^6 per foot [N, N m] (:mod:`~pushrecovery.control.wbc.qp`). A task
asks A x = b; the QP minimises Σ_k W_k ‖A_k x − b_k‖² under the dynamics and contact rows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = ["Task"]


@dataclass(frozen=True)
class Task:
    """One weighted task A x = b of the QP (module docstring).

    Attributes
    ----------
    name : str
        For reports.
    matrix, target : float arrays, shapes (k, m) and (k,)
        A over the first m ≤ nv + 6 n_feet unknowns of x = (q̈, w_1, …) (m = nv: a task on
        q̈ alone), and b [the task's units: m/s² or rad/s²].
    weight : float
        W > 0 [-].
    """

    name: str
    matrix: FloatArray
    target: FloatArray
    weight: float
