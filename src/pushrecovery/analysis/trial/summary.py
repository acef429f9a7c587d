"""The summary of a trial's analysis: extremes, time per strategy, steps, exclusions."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.margins import DirectionMargins
from pushrecovery.analysis.recording import (
    Recording,
    Support,
)
from pushrecovery.analysis.signals import (
    FILTER_ORDER,
    Gap,
    find_gaps,
)
from pushrecovery.analysis.trial.settings import AnalysisSettings
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy

FloatArray = NDArray[np.float64]


def _names(codes: NDArray[np.int8]) -> NDArray[np.object_]:
    """Strategy names of codes; None where invalid (−1)."""
    names = np.array([s.value for s in STRATEGY_CODES] + [None], dtype=object)
    return names[np.where(codes < 0, len(STRATEGY_CODES), codes)]


def _interpolated(time: FloatArray, gaps: list[Gap]) -> NDArray[np.bool_]:
    """Frames inside a filled gap of any signal."""
    flags = np.zeros(len(time), dtype=bool)
    for gap in gaps:
        if gap.filled:
            flags |= (time >= gap.start - 1e-9) & (time <= gap.end + 1e-9)
    return flags


def _exclusions(
    com: FloatArray, velocity: FloatArray, support: Support, invalid: NDArray[np.bool_]
) -> dict[str, int]:
    """Why frames were excluded (a frame may have several reasons)."""
    reasons = {
        "no CoM": int((~np.isfinite(com).all(axis=1)).sum()),
        "no CoM velocity (segment shorter than 3 frames)": int(
            (np.isfinite(com).all(axis=1) & ~np.isfinite(velocity).all(axis=1)).sum()
        ),
        "no supporting foot": int((~np.isfinite(support.lower["ap"] + support.lower["ml"])).sum()),
    }
    reasons = {k: v for k, v in reasons.items() if v}
    if invalid.any() and not reasons:  # pragma: no cover - every invalid frame has a reason
        reasons["other"] = int(invalid.sum())
    return reasons


def _extreme(values: FloatArray, time: FloatArray, *, lowest: bool = True) -> dict[str, Any]:
    """Return the smallest (largest) finite value and its time; None values if none."""
    finite = np.isfinite(values)
    if not finite.any():
        return {"value": None, "time": None}
    index = np.flatnonzero(finite)[
        np.argmin(values[finite]) if lowest else np.argmax(values[finite])
    ]
    return {"value": float(values[index]), "time": float(time[index])}


def _time_in(codes: NDArray[np.int8], period: float) -> dict[str, float]:
    return {
        s.value: float(np.count_nonzero(codes == i)) * period for i, s in enumerate(STRATEGY_CODES)
    }


def _most_demanding(codes: NDArray[np.int8]) -> str | None:
    valid = codes[codes >= 0]
    return STRATEGY_CODES[int(valid.max())].value if len(valid) else None


def _step_events(time: FloatArray, per_axis: dict[str, DirectionMargins]) -> list[dict[str, Any]]:
    """Every run of frames that needs a step, per axis, with the recommended step.

    The recommended step of an event is the median over its frames: along a fall the stance
    leg swings as a pendulum whose recovering step stays the same, while the first frames are
    marginal (and, after a short push, still inside the filter's transient).
    """
    step = STRATEGY_CODES.index(Strategy.STEP)
    events = []
    for axis, margins in per_axis.items():
        for start, stop in find_gaps(margins.strategy == step):
            span = slice(start, stop)
            events.append(
                {
                    "axis": axis,
                    "time": float(time[start]),
                    "end": float(time[stop - 1]),
                    "step_length": float(np.median(margins.step_length[span])),
                    "step_length_range": [
                        float(np.median(margins.step_shortest[span])),
                        float(np.median(margins.step_longest[span])),
                    ],
                    "step_length_onset": float(margins.step_length[start]),
                    "capture_point": float(margins.capture_point[start]),
                }
            )
    return sorted(events, key=lambda event: event["time"])


def _summary(
    recording: Recording,
    time: FloatArray,
    columns: dict[str, NDArray[Any]],
    codes: NDArray[np.int8],
    per_axis: dict[str, DirectionMargins],
    params: BodyParams,
    bodies: dict[str, BodyParams],
    settings: AnalysisSettings,
    gaps: list[Gap],
    *,
    sources: dict[str, str],
    com_source: str,
    support_source: str,
    reasons: dict[str, int],
    notes: list[str],
) -> dict[str, Any]:
    period = (time[-1] - time[0]) / max(len(time) - 1, 1)
    directions = {}
    for axis, margins in per_axis.items():
        directions[axis] = {
            "most_demanding": _most_demanding(margins.strategy),
            "time_in_strategy": _time_in(margins.strategy, period),
            "min_margin": {
                "cop": _extreme(margins.cop, time),
                "cmp": _extreme(margins.cmp, time),
            },
            "min_time_to_leave": {
                "cop": _extreme(margins.time_to_leave_cop, time),
                "cmp": _extreme(margins.time_to_leave_cmp, time),
            },
            "capture_point_range": [
                _extreme(margins.capture_point, time)["value"],
                _extreme(margins.capture_point, time, lowest=False)["value"],
            ],
            "foot": {"heel": bodies[axis].heel, "toe": bodies[axis].toe},
        }
    valid = int(np.count_nonzero(codes >= 0))
    return {
        "source": recording.source,
        "frames": len(time),
        "valid_frames": valid,
        "excluded_frames": len(time) - valid,
        "excluded": reasons,
        "rate": 1.0 / period if period > 0 else None,
        "duration": float(time[-1] - time[0]),
        "body": {
            "mass": params.mass,
            "mass_source": sources.get("mass", "given"),
            "com_height": params.com_height,
            "com_height_source": sources.get("com_height", "given"),
            "omega": params.omega,
        },
        "params": params.to_dict(),
        "com_source": com_source,
        "support_source": support_source,
        "filter": {
            "type": "Butterworth low-pass, forward-backward (zero lag)",
            "order": 2 * FILTER_ORDER,
            "cutoff": settings.cutoff,
            "force_cutoff": settings.force_cutoff,
        },
        "gaps": [gap.to_dict() for gap in gaps],
        "interpolated_frames": int(np.count_nonzero(columns["interpolated"])),
        "strategy": {
            "most_demanding": _most_demanding(codes),
            "time_in_strategy": _time_in(codes, period),
        },
        "directions": directions,
        "step_events": _step_events(time, per_axis),
        "notes": notes,
    }
