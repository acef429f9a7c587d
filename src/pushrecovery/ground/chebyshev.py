"""The Chebyshev centre of a convex polygon: the centre of the largest disc inside it.

The capture regions recommend it as the foothold that leaves the most room in every direction
(:mod:`pushrecovery.surfaces.capture.region`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import require_type
from pushrecovery.ground.polygon import ConvexPolygon

__all__ = ["chebyshev_centre"]

FloatArray = NDArray[np.float64]


def chebyshev_centre(polygon: ConvexPolygon) -> FloatArray:
    """Return the centre of the largest disc in a convex polygon [m].

    The LP max r subject to n_i · q + r <= b_i, solved by a small compiled dual simplex
    (``kernels.polygons.chebyshev_centre``; scipy's HiGHS if it fails). When the largest disc
    can slide (two parallel edges hold it) the centres form a segment and its midpoint is
    returned: unique, and mirrored with the polygon.

    Raises
    ------
    ParameterTypeError
        If ``polygon`` is not a :class:`~pushrecovery.ground.polygon.ConvexPolygon`.
    """
    require_type("polygon", polygon, ConvexPolygon)
    return chebyshev_centre_unchecked(polygon)


def chebyshev_centre_unchecked(polygon: ConvexPolygon) -> FloatArray:
    """:func:`chebyshev_centre` of a polygon."""
    from pushrecovery.kernels.polygons import chebyshev_centre as solve

    normals, offsets = polygon.normals, polygon.offsets
    qx, qy, radius, ok = solve(normals, offsets)
    if not ok:  # pragma: no cover - the compiled simplex found no start or did not converge
        from scipy.optimize import linprog

        a_ub = np.column_stack([normals, np.ones(len(offsets))])
        bounds = [(None, None), (None, None), (0.0, None)]
        qx, qy, radius = linprog([0.0, 0.0, -1.0], A_ub=a_ub, b_ub=offsets, bounds=bounds).x
    centre = np.array([qx, qy])
    slack = offsets - normals @ centre - radius
    scale = max(1.0, float(np.abs(polygon.vertices).max()))
    touching = normals[slack < 1e-9 * scale]
    opposite = touching @ touching.T < -1.0 + 1e-9
    if not opposite.any():
        return centre
    # Held by two parallel edges: slide along them as far as the other edges allow.
    i = int(np.argwhere(opposite)[0, 0])
    along = np.array([-touching[i, 1], touching[i, 0]])
    rate = normals @ along
    room = offsets - normals @ centre - radius
    moving = np.abs(rate) > 1e-12
    ends = room[moving] / rate[moving]
    low = float(ends[rate[moving] < 0.0].max(initial=-np.inf))
    high = float(ends[rate[moving] > 0.0].min(initial=np.inf))
    return centre + 0.5 * (low + high) * along
