"""A trial's data checked before its verdicts: flight phases, and a CoP outside the base.

Verdicts assume a body standing on the base of support the analysis computed. Two things in the
data contradict that, and the frames where they do get no verdict (issue 18, item 5):

- **flight**: the total vertical force is below :data:`~pushrecovery.analysis.recording.LOADED`
  (:func:`~pushrecovery.analysis.events.flight_phases`): no foot carries the body;
- **CoP outside the base**: the measured CoP lies beyond the computed base along an axis by more
  than :data:`COP_TOLERANCE` (marker placement and plate calibration put a correct CoP within
  about a centimetre of the sole's edge). The CoP can only be where a foot presses, so the base
  is wrong in that frame (a missing foot, a wrong foot model or an invented assumption).

When the CoP contradicts the base in more than :data:`MAX_CONTRADICTED` of the loaded frames,
the base as a whole is rejected and the trial is not classified: no frame gets a verdict.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.events import flight_phases
from pushrecovery.analysis.recording import AXES, LOADED

__all__ = ["COP_TOLERANCE", "MAX_CONTRADICTED", "DataChecks"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: How far the measured CoP may lie beyond the computed base before it contradicts it [m].
COP_TOLERANCE = 0.02
#: Share of the loaded frames beyond which a contradicted base is rejected for the trial.
MAX_CONTRADICTED = 0.2


@dataclass(frozen=True, slots=True, eq=False)
class DataChecks:
    """What the checks found, per frame of the analysis.

    Attributes
    ----------
    flights : tuple of (start, end)
        Flight phases [s] (at the force plates' rate).
    flight : ndarray of bool
        Frames inside a flight phase.
    cop_outside : dict of str to ndarray of bool
        Per axis, frames whose CoP lies beyond the base by more than ``tolerance``.
    loaded_frames : int
        Frames with a measured CoP (a loaded plate).
    tolerance : float
        :data:`COP_TOLERANCE` [m].
    base_rejected : bool
        The CoP contradicts the base in more than :data:`MAX_CONTRADICTED` of the loaded
        frames: the trial is not classified.
    marker_gaps : dict of str to ndarray of bool
        Per base marker (``"left heel"``, ...), the frames it is missing in: the base is
        unknown there (never filled: a spline through the gap would invent its edge).
    """

    flights: tuple[tuple[float, float], ...]
    flight: BoolArray
    cop_outside: dict[str, BoolArray]
    loaded_frames: int
    tolerance: float
    base_rejected: bool
    marker_gaps: dict[str, BoolArray] = field(default_factory=dict)

    @property
    def marker_gap(self) -> BoolArray:
        """Frames in which a base marker (a heel or toe marker) is missing."""
        missing = np.zeros_like(self.flight)
        for frames in self.marker_gaps.values():
            missing |= frames
        return missing

    @property
    def contradicted(self) -> BoolArray:
        """Frames whose CoP lies beyond the base along either axis."""
        return self.cop_outside[AXES[0]] | self.cop_outside[AXES[1]]

    @property
    def withheld(self) -> BoolArray:
        """Frames that get no verdict: all of them if the base is rejected."""
        if self.base_rejected:
            return np.ones_like(self.flight)
        return self.flight | self.contradicted | self.marker_gap

    def reasons(self) -> dict[str, int]:
        """Frames withheld, per reason (a frame may have both)."""
        reasons = {
            "flight (vertical force below 20 N)": int(self.flight.sum()),
            f"CoP beyond the computed base by more than {self.tolerance * 100:g} cm": int(
                self.contradicted.sum()
            ),
            "a heel or toe marker missing (base unknown)": int(self.marker_gap.sum()),
        }
        if self.base_rejected:
            reasons["base of support contradicted by the CoP: trial not classified"] = len(
                self.flight
            )
        return {key: value for key, value in reasons.items() if value}

    def to_dict(self) -> dict[str, Any]:
        """Return the summary's ``checks``."""
        return {
            "flight_phases": [{"start": a, "end": b, "duration": b - a} for a, b in self.flights],
            "flight_frames": int(self.flight.sum()),
            "cop_tolerance": self.tolerance,
            "loaded_frames": self.loaded_frames,
            "cop_outside_base_frames": {axis: int(v.sum()) for axis, v in self.cop_outside.items()},
            "base_rejected": self.base_rejected,
            "max_contradicted_share": MAX_CONTRADICTED,
            "excluded_frames_markers": int(self.marker_gap.sum()),
            "marker_gap_frames": {name: int(v.sum()) for name, v in self.marker_gaps.items()},
        }


def check_frames(
    time: FloatArray,
    force_time: FloatArray | None,
    force: FloatArray | None,
    cop: FloatArray | None,
    lower: dict[str, FloatArray],
    upper: dict[str, FloatArray],
    marker_gaps: dict[str, BoolArray] | None = None,
) -> DataChecks:
    """Check the frames at ``time`` [s] (module docstring); the pipeline's, unchecked.

    ``force`` is the ground reaction force (m, 3) [N] at ``force_time`` [s] (None without
    plates), ``cop`` the CoP (n, 2) [m] at the frames (NaN where unloaded), ``lower`` and
    ``upper`` the base per axis at the frames [m], ``marker_gaps`` per base marker the frames
    it is missing in.
    """
    n = len(time)
    flight = np.zeros(n, dtype=bool)
    flights: tuple[tuple[float, float], ...] = ()
    if force is not None and force_time is not None and np.isfinite(force[:, 2]).any():
        vertical = np.where(np.isfinite(force[:, 2]), force[:, 2], LOADED)  # gaps: not flight
        found = flight_phases(force_time, vertical)
        flights = found.intervals
        for start, end in flights:
            flight |= (time >= start - 1e-9) & (time <= end + 1e-9)
    outside = {axis: np.zeros(n, dtype=bool) for axis in AXES}
    loaded = 0
    if cop is not None:
        for i, axis in enumerate(AXES):
            with np.errstate(invalid="ignore"):
                outside[axis] = (cop[:, i] < lower[axis] - COP_TOLERANCE) | (
                    cop[:, i] > upper[axis] + COP_TOLERANCE
                )
        measured = np.isfinite(cop).all(axis=1) & ~flight
        loaded = int(measured.sum())
        for axis in AXES:
            outside[axis] &= measured
    contradicted = outside[AXES[0]] | outside[AXES[1]]
    rejected = loaded > 0 and contradicted.sum() > MAX_CONTRADICTED * loaded
    gaps = {name: frames for name, frames in (marker_gaps or {}).items() if frames.any()}
    return DataChecks(flights, flight, outside, loaded, COP_TOLERANCE, bool(rejected), gaps)
