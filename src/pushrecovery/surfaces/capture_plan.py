"""Plans that capture a state with N steps: footholds, touchdown times, CoPs, the hip's share.

The plan decomposes the capture point in the Minkowski sum (S1) of
:mod:`pushrecovery.surfaces.n_step` (docs/steps.md, "Plans").
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from pushrecovery.ground.minkowski import decompose, minkowski_sum
from pushrecovery.ground.support import Stance
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.n_step import StepOption, check_touchdowns, hip_box, sum_terms

__all__ = ["CapturePlan", "capture_plan"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class CapturePlan:
    """A capturing sequence of steps for one state (:func:`capture_plan`).

    Attributes
    ----------
    steps : int
        Number of steps N (>= 1).
    swings : tuple of Stance
        The landing foot of each step.
    footholds : ndarray, shape (N, 2)
        Ankle positions of the landing feet [m], world frame.
    touchdowns : ndarray, shape (N,)
        Touchdown times from now [s].
    cops : ndarray, shape (N + 1, 2)
        The CoP to hold on each support, the current one first [m].
    hip : ndarray, shape (2,)
        The hip's share of the capture point, ω∫e^{−ωs} c ds [m] (0 without hip).
    margin : float
        Signed distance of the capture point to the region C_N of the plan's timing [m].
    ankle : ndarray, shape (2,)
        The stance ankle the first step leaves [m].
    """

    steps: int
    swings: tuple[Stance, ...]
    footholds: FloatArray
    touchdowns: FloatArray
    cops: FloatArray
    hip: FloatArray
    margin: float
    ankle: FloatArray = field(default_factory=lambda: np.zeros(2))

    def to_dict(self) -> dict[str, object]:
        """JSON form: footholds, touchdown times, landing feet and the CoPs [m, s]."""
        return {
            "steps": self.steps,
            "swing": [side.value for side in self.swings],
            "footholds": self.footholds.tolist(),
            "touchdowns": self.touchdowns.tolist(),
            "cops": self.cops.tolist(),
            "hip": self.hip.tolist(),
            "margin": self.margin,
            "ankle": self.ankle.tolist(),
        }


def capture_plan(
    xi: FloatArray,
    params: BodyParams,
    option: StepOption,
    steps: int,
    *,
    first_touchdown: float | None = None,
    hip: bool = True,
) -> CapturePlan:
    """Footholds, touchdowns and CoPs that capture the capture point ξ0 with ``steps`` steps.

    The decomposition of ξ0 in the Minkowski sum (S1) that keeps every term equally deep
    (:func:`~pushrecovery.ground.minkowski.decompose`): when ξ0 ∈ C_N the plan captures the
    LIPM exactly (hold each CoP until the next touchdown, then the last one); outside, it is
    the plan of the nearest boundary point along the ray from C_N's centre and ``margin`` < 0.
    Touchdowns every ``min_step_time`` from ``first_touchdown`` (default: min_step_time).
    """
    first = params.min_step_time if first_touchdown is None else first_touchdown
    times = tuple(first + params.min_step_time * k for k in range(steps))
    check_touchdowns(params, times)
    terms, offset, sides = sum_terms(params, option, times, hip)
    total = minkowski_sum(terms, offset)
    points, _ = decompose(xi, terms, offset, total)
    reach = np.cumsum(np.array(points[2 + steps :]), axis=0) + option.ankle
    feet = np.array(points[2 : 2 + steps]) + reach
    cops = np.vstack([points[1], feet])
    return CapturePlan(
        steps,
        tuple(sides),
        reach,
        np.array(times),
        cops,
        np.asarray(points[0]) if hip and hip_box(params, option.yaw) is not None else np.zeros(2),
        float(total.signed_distance(xi[0], xi[1])),
        np.array(option.ankle, dtype=np.float64),
    )
