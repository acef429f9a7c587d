"""The sway measures of a recording whose CoP is all it holds (a posturography export).

A trial with a CoP and nothing to find the CoM from (no CoM, no ground reaction force) gives
its quiet-standing sway measures (:mod:`pushrecovery.analysis.posturography`) and no margins:
those need the CoM (docs/posturography.md, "A CoP-only file").
"""

from __future__ import annotations

import numpy as np

from pushrecovery.analysis.posturography import SwayMeasures, quiet_standing, sway_measures
from pushrecovery.analysis.recording import Recording
from pushrecovery.arguments import non_negative_float, require_type
from pushrecovery.errors import InvalidParameterError

__all__ = ["cop_only", "recording_sway"]


def cop_only(recording: Recording) -> bool:
    """Whether ``recording`` holds a CoP and nothing to find a CoM from (no CoM, no force).

    Such a trial (a posturography platform's export) gives its sway measures only
    (:func:`recording_sway`): margins need the CoM.

    Raises
    ------
    ParameterTypeError
        If ``recording`` is not a Recording.
    """
    require_type("recording", recording, Recording)
    return recording.cop is not None and recording.com is None and recording.force is None


def recording_sway(recording: Recording, cutoff: float) -> tuple[SwayMeasures, float]:
    """Return the sway measures of a quiet-standing recording's CoP and its rate [Hz].

    The CoP is low-passed at ``cutoff`` [Hz] (zero lag, as the analysis low-passes plate
    signals; 0: none), then :func:`sway_measures` on the whole trial.

    Raises
    ------
    ParameterTypeError
        If ``recording`` is not a Recording.
    InvalidParameterError
        If ``cutoff`` is not a finite number >= 0 [Hz], the recording has no CoP, a CoP frame
        is missing, the trace is no quiet standing
        (:func:`quiet_standing`, with the force when the recording has one), or it is too
        short for the spectra.
    """
    from pushrecovery.analysis.signals import smooth_and_differentiate

    require_type("recording", recording, Recording)
    cutoff = non_negative_float("cutoff", cutoff, "Hz")
    if recording.cop is None or recording.force_time is None or len(recording.force_time) < 2:
        raise InvalidParameterError("the recording has no CoP to measure the sway of")
    time = recording.force_time
    rate = 1.0 / float(np.median(np.diff(time)))
    if not np.isfinite(recording.cop).all():
        raise InvalidParameterError(
            f"the CoP misses {int((~np.isfinite(recording.cop).all(axis=1)).sum())} frame(s): "
            "the sway measures need every frame (analyse a window without gaps)"
        )
    cop, _ = smooth_and_differentiate(time, recording.cop, cutoff)
    if not quiet_standing(cop, rate, force=recording.force):
        raise InvalidParameterError(
            "the CoP trace is no quiet standing (docs/posturography.md: a step, a push or an "
            "unloaded plate): no sway measures"
        )
    return sway_measures(cop, rate), rate
