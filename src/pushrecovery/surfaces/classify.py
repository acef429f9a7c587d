"""The strategy a state needs, from the decision surfaces available so far.

Vocabulary (stable, part of the JSON contract): ``ankle`` (CoP balancing, Eq. 4), ``hip``
(CMP balancing, corrected Eq. 15), ``step`` (Sec. IV) and ``fall``. Until the stepping surface
lands, every state outside the CMP region is reported as ``step``: the paper's own fallback
("If the system is outside, however, it will have to take a step to avoid falling over").
"""

from __future__ import annotations

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
    """Strategy needed by one state, with the capture point and the margins [m]."""

    capture_point: float
    strategy: Strategy
    margins: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, object]:
        """JSON form: ``{"capture_point", "strategy", "margins": {"cop", "cmp"}}``."""
        return {
            "capture_point": self.capture_point,
            "strategy": self.strategy.value,
            "margins": dict(self.margins),
        }


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
        is inside the CMP region (corrected Eq. 15), else ``step``.
    """
    x = finite_float("x", x, "m")
    xdot = finite_float("xdot", xdot, "m/s")
    cop = float(cop_margin(x, xdot, params))
    cmp = float(cmp_margin(x, xdot, params))
    if cop > 0.0:
        strategy = Strategy.ANKLE
    elif cmp > 0.0:
        strategy = Strategy.HIP
    else:
        strategy = Strategy.STEP
    capture = float(capture_point(x, xdot, params.omega))
    return Classification(capture, strategy, {"cop": cop, "cmp": cmp})


def classify_states(x: ArrayLike, xdot: ArrayLike, params: BodyParams) -> NDArray[np.int8]:
    """Vectorised :func:`classify`: integer codes into :data:`STRATEGY_CODES`."""
    step = STRATEGY_CODES.index(Strategy.STEP)
    codes = np.full(np.broadcast_shapes(np.shape(x), np.shape(xdot)), step, dtype=np.int8)
    codes[cmp_margin(x, xdot, params) > 0.0] = STRATEGY_CODES.index(Strategy.HIP)
    codes[cop_margin(x, xdot, params) > 0.0] = STRATEGY_CODES.index(Strategy.ANKLE)
    return codes
