"""The strategy a state needs: the complete strategy map of the paper.

Vocabulary (stable, part of the JSON contract), escalating as the paper proposes (Sec. I-B):
``ankle`` (CoP balancing, Eq. 4), ``hip`` (CMP balancing, corrected Eq. 15), ``step`` (a single
step within reach recovers, Sec. IV, :mod:`pushrecovery.surfaces.step`) and ``fall``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery._validate import finite_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_margin, cmp_region
from pushrecovery.surfaces.cop import CaptureInterval, capture_point, cop_margin, cop_region
from pushrecovery.surfaces.step import plan_steps

__all__ = [
    "STRATEGY_CODES",
    "Classification",
    "Strategy",
    "classify",
    "classify_states",
    "strategy_region",
]


class Strategy(StrEnum):
    """Balance strategies, in the order the paper escalates them (Sec. I-B)."""

    ANKLE = "ankle"
    HIP = "hip"
    STEP = "step"
    FALL = "fall"


#: Integer codes used by the vectorised classifier, index = code.
STRATEGY_CODES: tuple[Strategy, ...] = tuple(Strategy)

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
    """

    capture_point: float
    strategy: Strategy
    margins: dict[str, float] = field(default_factory=dict)
    step: dict[str, object] | None = None

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
        return data


def classify(x: float, xdot: float, params: BodyParams) -> Classification:
    """Classify one CoM state (CoM upright upper body at rest, as the surfaces assume).

    Parameters
    ----------
    x : float
        CoM position relative to the ankle [m], x forward.
    xdot : float
        CoM velocity [m/s].
    params : BodyParams
        Body parameters.

    Returns
    -------
    Classification
        ``ankle`` when the capture point is strictly inside the foot (Eq. 4), ``hip`` when it
        is inside the CMP region (corrected Eq. 15), ``step`` when a single step within reach
        recovers (with the recommended step), else ``fall``.
    """
    x = finite_float("x", x, "m")
    xdot = finite_float("xdot", xdot, "m/s")
    cop = float(cop_margin(x, xdot, params))
    cmp = float(cmp_margin(x, xdot, params))
    plan = plan_steps(x, xdot, params) if abs(x) < params.leg_length else None
    step_margin = float(plan.margin) if plan is not None else -math.inf
    step = None
    if cop > 0.0:
        strategy = Strategy.ANKLE
    elif cmp > 0.0:
        strategy = Strategy.HIP
    elif plan is not None and bool(plan.feasible):
        strategy = Strategy.STEP
        theta = float(plan.theta)
        step = {
            "step_length": float(plan.step_length),
            "com_to_foot": float(plan.direction) * params.leg_length * math.sin(theta),
            "theta": theta,
            "step_length_range": [float(plan.shortest), float(plan.longest)],
        }
    else:
        strategy = Strategy.FALL
    capture = float(capture_point(x, xdot, params.omega))
    margins = {"cop": cop, "cmp": cmp, "step": step_margin}
    return Classification(capture, strategy, margins, step)


def classify_states(x: ArrayLike, xdot: ArrayLike, params: BodyParams) -> NDArray[np.int8]:
    """Vectorised :func:`classify`: integer codes into :data:`STRATEGY_CODES`."""
    fall = STRATEGY_CODES.index(Strategy.FALL)
    codes = np.full(np.broadcast_shapes(np.shape(x), np.shape(xdot)), fall, dtype=np.int8)
    codes[plan_steps(x, xdot, params).feasible] = STRATEGY_CODES.index(Strategy.STEP)
    codes[cmp_margin(x, xdot, params) > 0.0] = STRATEGY_CODES.index(Strategy.HIP)
    codes[cop_margin(x, xdot, params) > 0.0] = STRATEGY_CODES.index(Strategy.ANKLE)
    return codes
