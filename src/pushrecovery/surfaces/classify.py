"""The strategy a state needs, from the decision surfaces available so far.

Vocabulary (stable, part of the JSON contract): ``ankle`` (CoP balancing, Eq. 4), ``hip``
(CMP balancing, Sec. III), ``step`` (Sec. IV) and ``fall``. Until the hip and step surfaces
land, every state outside the CoP region is reported as ``step``: Sec. II's own fallback
("either a different balance strategy is needed or a step should be initiated").
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery._validate import finite_float
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cop import capture_point, cop_margin

__all__ = ["STRATEGY_CODES", "Classification", "Strategy", "classify", "classify_states"]


class Strategy(StrEnum):
    """Balance strategies, in the order the paper escalates them (Sec. I-B)."""

    ANKLE = "ankle"
    HIP = "hip"
    STEP = "step"
    FALL = "fall"


#: Integer codes used by the vectorised classifier, index = code.
STRATEGY_CODES: tuple[Strategy, ...] = tuple(Strategy)


@dataclass(frozen=True, slots=True)
class Classification:
    """Strategy needed by one state, with the capture point and the margins [m]."""

    capture_point: float
    strategy: Strategy
    margins: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, object]:
        """JSON form: ``{"capture_point", "strategy", "margins": {"cop", ...}}``."""
        return {
            "capture_point": self.capture_point,
            "strategy": self.strategy.value,
            "margins": dict(self.margins),
        }


def classify(x: float, xdot: float, params: BodyParams) -> Classification:
    """Classify one CoM state.

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
        ``ankle`` when the capture point is strictly inside the foot (Eq. 4), else ``step``.
    """
    x = finite_float("x", x, "m")
    xdot = finite_float("xdot", xdot, "m/s")
    margin = float(cop_margin(x, xdot, params))
    strategy = Strategy.ANKLE if margin > 0.0 else Strategy.STEP
    return Classification(float(capture_point(x, xdot, params.omega)), strategy, {"cop": margin})


def classify_states(x: ArrayLike, xdot: ArrayLike, params: BodyParams) -> NDArray[np.int8]:
    """Vectorised :func:`classify`: integer codes into :data:`STRATEGY_CODES`."""
    margin = cop_margin(x, xdot, params)
    ankle, step = STRATEGY_CODES.index(Strategy.ANKLE), STRATEGY_CODES.index(Strategy.STEP)
    return np.where(margin > 0.0, ankle, step).astype(np.int8)
