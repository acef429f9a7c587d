"""The balance strategies, in the order the paper escalates them, and their integer codes.

Vocabulary (stable, part of the JSON contract): ``ankle`` (CoP balancing, Eq. 4), ``hip`` (CMP
balancing, corrected Eq. 15), ``step`` (Sec. IV) and ``fall``.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["STRATEGY_CODES", "Strategy"]


class Strategy(StrEnum):
    """Balance strategies, in the order the paper escalates them (Sec. I-B)."""

    ANKLE = "ankle"
    HIP = "hip"
    STEP = "step"
    FALL = "fall"


#: Integer codes used by the vectorised classifier, index = code.
STRATEGY_CODES: tuple[Strategy, ...] = tuple(Strategy)
