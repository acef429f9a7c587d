"""The report's pieces about steps: the "Steps" section and a campaign's N-step counts."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.errors import ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.report.data import Picture, StepCounts, StepsSection, Table
from pushrecovery.report.markup import num

__all__ = ["step_counts", "steps_section"]


def steps_section(params: BodyParams, out: Path) -> StepsSection:
    """Return the report's "Steps" section: capture regions, the N-step map, thresholds."""
    require_type("params", params, BodyParams)
    require_type("out", out, Path)
    from pushrecovery.plots.common import save_figure
    from pushrecovery.plots.steps import capture_regions_figure, n_step_map_figure
    from pushrecovery.surfaces.bounds import bounds_data

    (regions,) = save_figure(capture_regions_figure(params), out / "steps-regions", ["png"])
    (steps_map,) = save_figure(n_step_map_figure(params), out / "steps-map", ["png"])
    data = bounds_data(params)
    rows = tuple(
        (str(n), num(-back, 3), num(forward, 3))
        for n, (back, forward) in data["thresholds"]["steps"].items()
    )
    sec4 = data["thresholds"]["step_sec4"]
    return StepsSection(
        regions=Picture(
            regions,
            "Footholds of the first landing foot that capture four pushes from rest in double "
            "support with one step or two, and the recommended foothold (the region's "
            "Chebyshev centre).",
            regions.name,
        ),
        steps_map=Picture(steps_map, "Steps each sagittal state needs.", steps_map.name),
        thresholds=Table(
            ("steps", "backward [m/s]", "forward [m/s]"), rows, text_columns=1, ident="steps"
        ),
        max_step_length=params.max_step_length,
        min_step_time=params.min_step_time,
        max_steps=params.max_steps,
        sec4_backward=-float(sec4[0]),
        sec4_forward=float(sec4[1]),
    )


def step_counts(summary: Mapping[str, Any]) -> StepCounts | None:
    """Return the N-step predictions against the steps taken (summary ``steps``), if any."""
    if not isinstance(summary, Mapping):
        raise ParameterTypeError(
            f"summary must be a campaign summary (a mapping), got {type(summary).__name__}"
        )
    steps = summary.get("steps") or {}
    if not steps.get("predicted"):
        return None
    return StepCounts(
        predicted=tuple(
            (n if n != "-1" else "fall", int(count)) for n, count in steps["predicted"].items()
        ),
        taken=tuple((n, int(count)) for n, count in steps["taken"].items()),
        exact=steps.get("exact"),
    )
