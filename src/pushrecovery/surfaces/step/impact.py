r"""Sec. IV's impact at each touchdown of a plan: what the LIPM analysis leaves out.

The capture regions (:mod:`pushrecovery.surfaces.n_step`) keep the CoM at height L and
its velocity horizontal through every touchdown. Sec. IV's body has rigid legs: the CoM moves
on the stance leg's sphere, so at touchdown its velocity is perpendicular to the stance leg
(from the stance ankle a to the CoM) and has a vertical part, v_z = −v_h · (r − a)/L for a
horizontal part v_h (Eq. 18, at height L). The impact (Eqs. 19–20) is an impulse along the new
leg, from the landing ankle q to the CoM, that absorbs that vertical velocity, and so also
changes the horizontal one:

.. math:: \mathbf v_h^+ = \mathbf v_h - v_z \frac{\mathbf r - \mathbf q}{L}
          = \mathbf v_h + \frac{\mathbf v_h\cdot(\mathbf r - \mathbf a)}{L^2}
          (\mathbf r - \mathbf q).

With the legs at ±θ on the sagittal line (r − a = L tan θ = −(r − q)) this is Sec. IV's
v⁺ = L θ̇ cos 2θ / cos θ (with v_h = L θ̇ cos θ). The capture point after the impact is
ξ⁺ = r + v_h⁺/ω (the height regulated back to L). Here each touchdown of a plan reports both
capture points and their margins in what the rest of the plan needs (the landing foot and its
remaining steps, C_{N−k} of (S1) about the landing ankle): the impact slows the body along
the new leg, which helps when the capture point lies beyond the foot and hurts when the foot
was placed beyond it. Neither analysis is conservative in general. The CoM state at touchdown
follows the LIPM with the plan's CoPs held, the hip's share h of the capture point delivered
as a constant CMP offset h / (1 − e^{−ωt₁}) until the first touchdown (the same ξ₀ budget).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, finite_pair, require_type
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.plan import CapturePlan
from pushrecovery.surfaces.capture.region import MAX_POSITION, MAX_SPEED
from pushrecovery.surfaces.n_step import landing_viable

__all__ = ["TouchdownImpact", "plan_impacts"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class TouchdownImpact:
    """One touchdown of a plan, without and with Sec. IV's impact.

    Attributes
    ----------
    time : float
        Touchdown time [s].
    com, velocity : (float, float)
        CoM position [m] and velocity [m/s] at touchdown (LIPM, the plan's CoPs held).
    capture_point, capture_point_impact : (float, float)
        ξ without the impact and ξ⁺ after it [m].
    margin, margin_impact : float
        Their signed distances to what the rest of the plan captures [m], + inside.
    speed_ratio : float
        ‖v⁺_h‖ / ‖v_h‖ [-]: the share of the horizontal speed the impact leaves.
    """

    time: float
    com: tuple[float, float]
    velocity: tuple[float, float]
    capture_point: tuple[float, float]
    capture_point_impact: tuple[float, float]
    margin: float
    margin_impact: float
    speed_ratio: float

    def to_dict(self) -> dict[str, object]:
        """JSON form [s, m, m/s]."""
        return {
            "time": self.time,
            "com": list(self.com),
            "velocity": list(self.velocity),
            "capture_point": list(self.capture_point),
            "capture_point_impact": list(self.capture_point_impact),
            "margin": self.margin,
            "margin_impact": self.margin_impact,
            "speed_ratio": self.speed_ratio,
        }


def plan_impacts(
    plan: CapturePlan,
    position: tuple[float, float],
    velocity: tuple[float, float],
    params: BodyParams,
    yaw: float = 0.0,
) -> list[TouchdownImpact]:
    """Follow a plan's touchdowns from a CoM state, without and with the impact (module doc).

    Parameters
    ----------
    plan : CapturePlan
        The plan (footholds, touchdowns, CoPs).
    position, velocity : (float, float)
        CoM position [m] and velocity [m/s] now.
    params : BodyParams
        The body (L, ω, feet, reach, Δt_s).
    yaw : float
        The landing feet's yaw [rad]: a plan's ``landing_yaw`` (by default the stance's).

    Returns
    -------
    list of TouchdownImpact
        One per touchdown. The LIPM state is carried on without the impact.

    Raises
    ------
    ParameterTypeError
        If ``plan`` or ``params`` has the wrong type.
    InvalidParameterError
        A position or velocity that is not a finite (x, y) within the state ranges of
        :func:`~pushrecovery.surfaces.capture.region.capture_region` (±1000 m, ±100 m/s), or
        a non-finite ``yaw``.
    """
    from pushrecovery.kernels.single_margins import edge_rows, signed_distance

    require_type("plan", plan, CapturePlan)
    rx, ry = finite_pair("position", position, MAX_POSITION, "m")
    vx, vy = finite_pair("velocity", velocity, MAX_SPEED, "m/s")
    require_type("params", params, BodyParams)
    yaw = finite_float("yaw", yaw, "rad")
    omega, height = params.omega, params.com_height
    # Component by component on floats: the operations of the 2-vector form, the same bits
    # (the dot product stays numpy's, whose summation the floats need not match).
    ax, ay = (float(a) for a in plan.ankle)
    cops, footholds, touchdowns = plan.cops.tolist(), plan.footholds.tolist(), plan.touchdowns
    start = 0.0
    found = []
    first = math.exp(-omega * float(touchdowns[0]))
    hx, hy = (h / (1.0 - first) for h in plan.hip.tolist()) if first < 1.0 else (0.0, 0.0)
    inv = 1.0 / omega  # as capture_point
    for k in range(plan.steps):
        t = float(touchdowns[k])
        px, py = cops[k][0] + (hx if k == 0 else 0.0), cops[k][1] + (hy if k == 0 else 0.0)
        c, s = math.cosh(omega * (t - start)), math.sinh(omega * (t - start))
        rx, ry, vx, vy = (
            px + (rx - px) * c + vx / omega * s,
            py + (ry - py) * c + vy / omega * s,
            (rx - px) * omega * s + vx * c,
            (ry - py) * omega * s + vy * c,
        )
        start = t
        qx, qy = footholds[k]
        lean = float(np.array((vx, vy)) @ np.array((rx - ax, ry - ay))) / height**2
        after = (vx + lean * (rx - qx), vy + lean * (ry - qy))
        xi = (rx + vx * inv, ry + vy * inv)
        xi_impact = (rx + after[0] * inv, ry + after[1] * inv)
        remaining = landing_viable(params, plan.swings[k], yaw, plan.steps - 1 - k)
        region = remaining.transformed(qx, qy, 0.0)
        rows = edge_rows(region.vertices, region.normals, region.offsets)
        speed = float(np.hypot(vx, vy))
        found.append(
            TouchdownImpact(
                t,
                (rx, ry),
                (vx, vy),
                xi,
                xi_impact,
                signed_distance(rows, *xi),  # region.signed_distance's bits, compiled
                signed_distance(rows, *xi_impact),
                float(np.hypot(*after)) / speed if speed > 0.0 else 1.0,
            )
        )
        ax, ay = qx, qy
    return found
