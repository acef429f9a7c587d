r"""The centroidal momentum task of the whole-body QP: L̇ as rows over the contact wrenches.

The floor's wrenches w_i = (F_i, T_i) (sole frames, orientation R_i, origin p_i) change the
whole body's angular momentum about its CoM c at the rate (Lee & Goswami 2012; Orin, Goswami
& Lee 2013)

.. math:: \dot{\mathbf L} = \sum_i (\mathbf p_i - \mathbf c) \times R_i \mathbf F_i
          + R_i \mathbf T_i ,

linear in w: :func:`momentum_rows` returns A with A x = L̇ (zeros on q̈). The hip law
(:mod:`~pushrecovery.control.wbc.hip`) asks L̇_{x,y} = m g (−δ_y, δ_x) for its CMP offset δ.
World frame, x forward, y left, z up, SI units.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.wbc.observation import HumanoidObservation

FloatArray = NDArray[np.float64]

__all__ = []


def momentum_rows(
    data: HumanoidObservation,
    bodies: NDArray[np.intp],
    size: int,
    nv: int,
    com: FloatArray,
    origins: FloatArray,
) -> FloatArray:
    """Return the 3 × size rows A with A x = L̇ (module docstring) [N m per unit of w].

    Parameters
    ----------
    data : HumanoidObservation
        After ``mj_kinematics``: the feet's orientations ``xmat`` and positions ``xpos``.
    bodies : int array
        The feet's body ids, in the QP's order.
    size, nv : int
        The QP's unknowns (nv accelerations then 6 per foot).
    com : float array, shape (3,)
        The CoM c [m].
    origins : float array, shape (n, 3)
        Each sole frame's origin in its body frame [m].
    """
    rows = np.zeros((3, size))
    rot = np.asarray(data.xmat)[bodies].reshape(-1, 3, 3)
    points = np.asarray(data.xpos)[bodies] + np.einsum("nij,nj->ni", rot, origins)
    for i, (r, lever) in enumerate(zip(rot, points - com, strict=True)):
        skew = np.array(
            [[0.0, -lever[2], lever[1]], [lever[2], 0.0, -lever[0]], [-lever[1], lever[0], 0.0]]
        )
        rows[:, nv + 6 * i : nv + 6 * i + 3] = skew @ r
        rows[:, nv + 6 * i + 3 : nv + 6 * i + 6] = r
    return rows
