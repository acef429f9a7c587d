"""The strategy a state needs: the complete strategy map of the paper, on a line or the plane.

Vocabulary (stable, part of the JSON contract), escalating as the paper proposes (Sec. I-B):
``ankle`` (CoP balancing, Eq. 4), ``hip`` (CMP balancing, corrected Eq. 15), ``step`` (a single
step within reach recovers, Sec. IV, :mod:`pushrecovery.surfaces.step`) and ``fall``.

On the ground plane (:func:`classify` with ``y``, ``ydot`` or a ``support``) the ankle and hip
regions are the support polygon and the CMP region of :mod:`pushrecovery.surfaces.plane`; the
step is Sec. IV's single step applied on the line through the stance ankle and the capture
point (the direction of its excursion), which issue 14's capture regions will replace
(``docs/plane.md``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from pushrecovery._validate import finite_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify_many import classify_states
from pushrecovery.surfaces.cmp import cmp_margin, cmp_region
from pushrecovery.surfaces.cop import CaptureInterval, capture_point, cop_margin, cop_region
from pushrecovery.surfaces.plane import cmp_polygon, plan_step_xy
from pushrecovery.surfaces.step import StepDecision, plan_step
from pushrecovery.surfaces.strategy import STRATEGY_CODES, Strategy

__all__ = [
    "STRATEGY_CODES",
    "Classification",
    "Strategy",
    "classify",
    "classify_states",
    "strategy_region",
]


_REGIONS: dict[str, Callable[[BodyParams], CaptureInterval]] = {
    Strategy.ANKLE: cop_region,
    Strategy.HIP: cmp_region,
}


def strategy_region(strategy: str, params: BodyParams) -> CaptureInterval:
    """Capture-point interval of a balancing strategy (``ankle`` or ``hip``) [m]."""
    try:
        return _REGIONS[strategy](params)
    except KeyError:
        raise InvalidParameterError(
            f"strategy must be one of {sorted(_REGIONS)}, got {strategy!r}"
        ) from None


@dataclass(frozen=True, slots=True)
class Classification:
    """Strategy needed by one state, with the capture point, the margins [m] and the step.

    ``margins``: ``cop`` and ``cmp`` are signed distances of the capture point to the regions'
    edges; ``step`` is the reach left beyond the shortest recovering step (max_step_length minus
    it), −inf when no single step recovers. ``step`` holds the recommended step for the ``step``
    strategy: ``step_length`` (foot to foot, signed like the step direction), ``com_to_foot``,
    ``theta`` (stance-leg angle at impact) and the admissible ``step_length_range``.

    On the ground plane also ``capture_point_xy`` (ξ in the world frame [m]), the ``support``
    and the CMP region's vertices (``cmp_region``); margins are then signed Euclidean
    distances in the plane, and ``step`` adds ``direction_xy`` (the unit vector of the step
    line, along which ``step_length`` is signed) and ``foothold_xy`` [m]: the landing ankle,
    ``step_length`` from the stance's reference ankle (in double support the ankles' midpoint,
    where the sagittal model puts its stance leg).
    """

    capture_point: float
    strategy: Strategy
    margins: dict[str, float] = field(default_factory=dict)
    step: dict[str, object] | None = None
    capture_point_xy: tuple[float, float] | None = None
    support: Support | None = None
    cmp_region: list[list[float]] | None = None

    def to_dict(self) -> dict[str, object]:
        """JSON form: ``{"capture_point", "strategy", "margins": {...}}`` (+ ``"step"``)."""
        margins = {k: (v if math.isfinite(v) else None) for k, v in self.margins.items()}
        data: dict[str, object] = {
            "capture_point": self.capture_point,
            "strategy": self.strategy.value,
            "margins": margins,
        }
        if self.step is not None:
            data["step"] = dict(self.step)
            data["step_length"] = self.step["step_length"]
        if self.capture_point_xy is not None:
            data["capture_point_xy"] = list(self.capture_point_xy)
        if self.support is not None:
            data["support"] = self.support.to_dict()
        if self.cmp_region is not None:
            data["cmp_region"] = self.cmp_region
        return data


def classify(
    x: float,
    xdot: float,
    params: BodyParams,
    *,
    y: float | None = None,
    ydot: float | None = None,
    support: Support | None = None,
) -> Classification:
    """Classify one CoM state (upper body upright and at rest, as the surfaces assume).

    Without ``y``, ``ydot`` and ``support`` this is the sagittal model of the paper (the foot
    the interval [heel, toe]); with any of them, the ground plane (module docstring), where
    ``support`` defaults to double support on the default feet
    (:meth:`~pushrecovery.ground.Support.from_params`). With y = ẏ = 0 and the default double
    support of a foot no longer than the stance is wide (the paper preset), both give the same
    verdict, capture point and margins.

    Parameters
    ----------
    x : float
        CoM position [m], x forward: relative to the ankle (sagittal), or in the world frame
        of the support (plane).
    xdot : float
        CoM velocity [m/s].
    params : BodyParams
        Body parameters.
    y : float, optional
        Lateral CoM position in the world frame [m], y left (default 0).
    ydot : float, optional
        Lateral CoM velocity [m/s] (default 0).
    support : Support, optional
        Stance and feet on the ground plane.

    Returns
    -------
    Classification
        ``ankle`` when the capture point is strictly inside the foot or support polygon
        (Eq. 4), ``hip`` when it is inside the CMP region (corrected Eq. 15, in the plane:
        the polygon grown by each axis's offset), ``step`` when a single step within reach
        recovers (with the recommended step), else ``fall``.
    """
    x = finite_float("x", x, "m")
    xdot = finite_float("xdot", xdot, "m/s")
    if y is not None or ydot is not None or support is not None:
        return _classify_plane(x, xdot, params, y, ydot, support)
    cop = float(cop_margin(x, xdot, params))
    cmp = float(cmp_margin(x, xdot, params))
    plan = plan_step(x, xdot, params) if abs(x) < params.leg_length else None
    capture = float(capture_point(x, xdot, params.omega))
    strategy, step = _escalate(cop, cmp, plan, params)
    margins = {"cop": cop, "cmp": cmp, "step": plan.margin if plan is not None else -math.inf}
    return Classification(capture, strategy, margins, step)


def _escalate(
    cop: float, cmp: float, plan: StepDecision | None, params: BodyParams
) -> tuple[Strategy, dict[str, object] | None]:
    """Return the first strategy whose margin is positive, and the step for ``step``."""
    if cop > 0.0:
        return Strategy.ANKLE, None
    if cmp > 0.0:
        return Strategy.HIP, None
    if plan is None or not plan.feasible:
        return Strategy.FALL, None
    return Strategy.STEP, {
        "step_length": plan.step_length,
        "com_to_foot": plan.direction * params.leg_length * math.sin(plan.theta),
        "theta": plan.theta,
        "step_length_range": [plan.shortest, plan.longest],
    }


def _classify_plane(
    x: float,
    xdot: float,
    params: BodyParams,
    y: float | None,
    ydot: float | None,
    support: Support | None,
) -> Classification:
    """:func:`classify` on the ground plane."""
    y = 0.0 if y is None else finite_float("y", y, "m")
    ydot = 0.0 if ydot is None else finite_float("ydot", ydot, "m/s")
    support = Support.from_params(params) if support is None else support
    inv = 1.0 / params.omega  # ξ as the monitor and the compiled margins compute it
    xi = (x + xdot * inv, y + ydot * inv)
    hip_region = cmp_polygon(support, params)
    cop = float(support.polygon.signed_distance(*xi))
    cmp = float(hip_region.signed_distance(*xi))
    if not (math.isfinite(cop) and math.isfinite(cmp)):
        raise InvalidParameterError("states are too large: the capture point overflows")
    line, plan = plan_step_xy(x, y, xdot, ydot, params, support)
    strategy, step = _escalate(cop, cmp, plan, params)
    if step is not None and plan is not None:
        ankle = support.ankle
        # + 0.0 turns the −0.0 of a zero component into 0.0 in the JSON.
        step["direction_xy"] = [line[0] + 0.0, line[1] + 0.0]
        step["foothold_xy"] = [
            ankle[0] + plan.step_length * line[0] + 0.0,
            ankle[1] + plan.step_length * line[1] + 0.0,
        ]
    margins = {"cop": cop, "cmp": cmp, "step": plan.margin if plan is not None else -math.inf}
    return Classification(xi[0], strategy, margins, step, xi, support, hip_region.to_list())
