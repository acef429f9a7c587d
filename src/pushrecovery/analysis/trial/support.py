"""The base of support of a measured trial, per frame: from the feet, stated, or assumed."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.base_polygon import (
    BasePolygons,
    FootModel,
    base_from_feet,
    base_from_vertices,
)
from pushrecovery.analysis.recording import (
    AXES,
    LOADED,
    Foot,
    Recording,
    Support,
    fixed_feet,
    support_from_feet,
)
from pushrecovery.analysis.signals import (
    Gap,
    repair_gaps,
    resample,
)
from pushrecovery.analysis.trial.settings import COP_AHEAD_OF_ANKLE, AnalysisSettings
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams

FloatArray = NDArray[np.float64]


def _repair_loaded(
    time: FloatArray, cop: FloatArray, force: FloatArray | None, max_gap: float
) -> tuple[FloatArray, list[Gap]]:
    """Repair CoP gaps; while the plates are unloaded the CoP is undefined, not a gap."""
    repaired, gaps = repair_gaps(time, cop, max_gap, "cop")
    if force is not None:
        unloaded = ~(force[:, 2] > LOADED)
        repaired[unloaded] = np.nan
    return repaired, gaps


#: The foot markers the base of support is built from: their gaps are never filled.
BASE_MARKERS = ("heel", "toe")


def _support(
    recording: Recording,
    time: FloatArray,
    com: FloatArray,
    cop: FloatArray | None,
    params: BodyParams,
    settings: AnalysisSettings,
) -> tuple[Support, BasePolygons, str, list[Gap], dict[str, NDArray[np.bool_]]]:
    """Build the base of support from the feet, CSV columns, or two assumed fixed feet.

    Per axis (the intervals of :class:`Support`) and in the plane (the polygon of the
    supporting soles, :mod:`pushrecovery.analysis.base_polygon`, the foot model's width the
    settings' foot width). The last item: per base marker (``"<foot> heel"``, ``"<foot>
    toe"``), the frames it is missing in. Those markers are not gap-filled: a spline through a
    gap would invent the base's edge, so the frames a base marker misses have no known base
    (docs/analysis.md, "Data checks"); the ankle marker (the stepping model's stance ankle,
    not an edge of the base) is filled up to ``max_gap`` as before.
    """
    model = FootModel(width=settings.widths(params)[0])
    gaps: list[Gap] = []
    missing: dict[str, NDArray[np.bool_]] = {}
    if recording.feet:
        measured: list[Foot] = []
        for foot in recording.feet:
            parts = []
            for part in ("heel", "toe", "ankle"):
                name = f"{foot.name} {part}"
                values = resample(recording.time, getattr(foot, part), time)
                longest = 0.0 if part in BASE_MARKERS else settings.max_gap
                values, found = repair_gaps(time, values, longest, name)
                gaps += found
                if part in BASE_MARKERS:
                    missing[name] = np.asarray(~np.isfinite(values).all(axis=1), dtype=bool)
                parts.append(values)
            measured.append(Foot(foot.name, *parts))
        support = support_from_feet(
            tuple(measured),
            contact_height=settings.contact_height,
            foot_width=settings.widths(params)[0],
        )
        plane = base_from_feet(measured, model, contact_height=settings.contact_height)
        return support, plane, "foot markers", gaps, missing
    if recording.base_vertices is not None:
        plane = base_from_vertices(_resampled(recording.time, recording.base_vertices, time))
        low_ap, high_ap, low_ml, high_ml = plane.extents()
        edges = {"ap": np.column_stack([low_ap, high_ap]), "ml": np.column_stack([low_ml, high_ml])}
        support = _explicit_support(recording, time, params, settings, edges)
        return support, plane, "base polygon columns", gaps, missing
    if recording.base:
        support = _explicit_support(recording, time, params, settings)
        return support, _rectangles(support), "base columns", gaps, missing
    centre = cop if cop is not None and np.isfinite(cop).any() else com
    if not np.isfinite(centre).any():
        raise InvalidParameterError(
            "nothing locates the feet: the trial has no CoP and no CoM values; give "
            "--ankle-ap and --ankle-ml"
        )
    ankle_ap = settings.ankle_ap
    ankle_ml = settings.ankle_ml
    assumed = []
    if ankle_ap is None:
        ankle_ap = float(np.nanmean(centre[:, 0])) - COP_AHEAD_OF_ANKLE
        what = "CoP" if centre is cop else "CoM"
        assumed.append(f"ankles {COP_AHEAD_OF_ANKLE:g} m behind the mean {what}")
    if ankle_ml is None:
        ankle_ml = float(np.nanmean(centre[:, 1]))
        assumed.append("centred on it medio-laterally")
    foot_width, stance_width = settings.widths(params)
    feet = fixed_feet(len(time), ankle_ap, ankle_ml, params.heel, params.toe, stance_width)
    support = support_from_feet(feet, contact_height=settings.contact_height, foot_width=foot_width)
    plane = base_from_feet(feet, model, contact_height=settings.contact_height)
    source = "fixed feet (heel/toe flags, --stance-width)"
    if assumed:
        source += ": " + ", ".join(assumed)
    return support, plane, source, gaps, missing


def _rectangles(support: Support) -> BasePolygons:
    """Return the plane's base of CSV base columns: each frame's rectangle of intervals."""
    lo_ap, hi_ap = support.lower["ap"], support.upper["ap"]
    lo_ml, hi_ml = support.lower["ml"], support.upper["ml"]
    corners = [(lo_ap, lo_ml), (hi_ap, lo_ml), (hi_ap, hi_ml), (lo_ap, hi_ml)]
    return base_from_vertices(np.stack([np.column_stack(c) for c in corners], axis=1))


def _resampled(source: FloatArray, vertices: FloatArray, time: FloatArray) -> FloatArray:
    """Vertices (m, k, 2) at ``source`` times, at the frames' ``time`` (the same: as is)."""
    if len(source) == len(time) and np.array_equal(source, time):
        return vertices
    flat = resample(source, vertices.reshape(len(source), -1), time)
    return flat.reshape(len(time), *vertices.shape[1:])


def _explicit_support(
    recording: Recording,
    time: FloatArray,
    params: BodyParams,
    settings: AnalysisSettings,
    base: dict[str, FloatArray] | None = None,
) -> Support:
    """Support from CSV columns: base edges (or ``base``), optionally the stance ankle."""
    lower, upper, ankles = {}, {}, {}
    base = recording.base if base is None else base
    for axis in AXES:
        if axis not in base:
            raise InvalidParameterError(
                f"give the base of support along both axes: base_{axis}_min and base_{axis}_max "
                "columns are missing"
            )
        edges = base[axis]
        lower[axis], upper[axis] = edges[:, 0], edges[:, 1]
        if axis in recording.ankle:
            ankle = recording.ankle[axis]
        elif axis == "ap":
            ankle = lower[axis] - params.heel  # the ankle |heel| in front of the rear edge
        else:
            ankle = 0.5 * (lower[axis] + upper[axis])
        ankles[axis] = ankle[:, None]
    foot = {
        "ap": (params.heel, params.toe),
        "ml": (-settings.widths(params)[0] / 2, settings.widths(params)[0] / 2),
    }
    supporting = np.isfinite(lower["ap"])[:, None]
    return Support(lower, upper, ankles, foot, supporting)
