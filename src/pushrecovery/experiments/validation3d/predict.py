"""The 2-D prediction of the critical push from any direction (issue 19, item 5).

The impulse J* = m ω d(ψ) that puts the capture point of the standing body on the boundary of
a region along the azimuth ψ: the support polygon P for the ankle strategy (Eq. 4 in the
plane), P grown by the hips' CMP offsets (the corrected Eq. 15, ``surfaces.plane.cmp_polygon``)
for the hip. Used by :mod:`pushrecovery.experiments.validation3d`.
"""

from __future__ import annotations

import math

from pushrecovery.arguments import bounded_float, finite_float, finite_vector, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.plane import cmp_polygon

__all__ = [
    "CriticalErrors",
    "critical_impulse_along",
    "predicted_critical_impulses",
]


class CriticalErrors:
    """The errors of a measured critical impulse against its predictions (a row's mixin).

    The row (a frozen dataclass) has the fields ``measured``, ``predicted`` and ``corrected``
    [N s].
    """

    measured: float
    predicted: float
    corrected: float

    @property
    def relative_error(self) -> float:
        """(measured − predicted)/predicted [-]."""
        return (self.measured - self.predicted) / self.predicted

    @property
    def corrected_error(self) -> float:
        """(measured − corrected)/corrected [-]."""
        return (self.measured - self.corrected) / self.corrected


def critical_impulse_along(
    region: ConvexPolygon, origin: tuple[float, float], azimuth: float, mass: float, omega: float
) -> float:
    """Return m ω ρ_R(r₀, ψ): the impulse that puts ξ on the region's boundary [N s].

    Parameters
    ----------
    region : ConvexPolygon
        The capture-point region R (world frame) [m].
    origin : (float, float)
        The standing CoM's ground point r₀, strictly inside R [m].
    azimuth : float
        The push's heading ψ, counter-clockwise from +x, in [−360, 360] deg.
    mass : float
        m > 0 [kg].
    omega : float
        ω = sqrt(g/L), in [0.1, 100] 1/s.

    Raises
    ------
    InvalidParameterError
        For an origin outside R, a non-finite or out-of-range azimuth, mass or omega.
    """
    require_type("region", region, ConvexPolygon)
    start = finite_vector("origin", origin, 2, unit="m")
    heading = bounded_float("azimuth", azimuth, -360.0, 360.0, "deg")
    mass = finite_float("mass", mass, "kg")
    if mass <= 0.0:
        raise InvalidParameterError(f"mass must be > 0 kg, got {mass:g}")
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    if not bool(region.contains(float(start[0]), float(start[1]))):
        raise InvalidParameterError(
            f"origin ({start[0]:g}, {start[1]:g}) m must lie strictly inside the region"
        )
    distance = region.ray_distance(float(start[0]), float(start[1]), math.radians(heading))
    return mass * omega * distance


def predicted_critical_impulses(
    params: BodyParams,
    azimuth: float,
    *,
    origin: tuple[float, float] | None = None,
    omega: float | None = None,
) -> dict[str, float]:
    """Return each strategy's predicted critical impulse at ``azimuth`` [N s] (module doc).

    Parameters
    ----------
    params : BodyParams
        The body: mass, feet and stance (double support, default foot poses), hip limits.
    azimuth : float
        ψ [deg], 0 forward, 90 left.
    origin : (float, float), optional
        The standing CoM's ground point r₀ [m]; default the ankles' midpoint.
    omega : float, optional
        ω [1/s]; default ``params.omega`` = sqrt(g/L).

    Returns
    -------
    dict
        ``{"ankle": m ω ρ_P, "hip": m ω ρ_(P ⊕ box)}``.
    """
    require_type("params", params, BodyParams)
    support = Support.from_params(params)
    start = support.ankle if origin is None else origin
    rate = params.omega if omega is None else omega
    regions = {"ankle": support.polygon, "hip": cmp_polygon(support, params)}
    return {
        name: critical_impulse_along(region, start, azimuth, params.mass, rate)
        for name, region in regions.items()
    }
