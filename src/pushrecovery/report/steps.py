"""The report's pieces about steps: the "Steps" section and a campaign's N-step counts."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pushrecovery.params import BodyParams
from pushrecovery.report.markup import esc, figure, num, paragraph, table

__all__ = ["step_counts", "steps_section"]


def steps_section(params: BodyParams, out: Path) -> str:
    """Return the report's "Steps" section: capture regions, the N-step map, thresholds."""
    from pushrecovery.plots.common import save_figure
    from pushrecovery.plots.steps import capture_regions_figure, n_step_map_figure
    from pushrecovery.surfaces.bounds import bounds_data

    (regions,) = save_figure(capture_regions_figure(params), out / "steps-regions", ["png"])
    (steps_map,) = save_figure(n_step_map_figure(params), out / "steps-map", ["png"])
    data = bounds_data(params)
    rows = [
        [n, num(-back, 3), num(forward, 3)]
        for n, (back, forward) in data["thresholds"]["steps"].items()
    ]
    sec4 = data["thresholds"]["step_sec4"]
    return (
        paragraph(
            "Beyond the hip region the body steps. With the CoP in the stance foot until the "
            "touchdown, the landing foot alone afterwards, footholds within max_step_length "
            f"({num(params.max_step_length, 3)} m) of the stance ankle and touchdowns at least "
            f"min_step_time ({num(params.min_step_time, 3)} s) apart, the capture points that N "
            "steps capture form a convex polygon, a Minkowski sum of the feet, the reach and the "
            "hip's box, each scaled by e^{−ω t} of its touchdown (docs/steps.md, checked against "
            "a linear program over CoP, foothold and flywheel torque sequences). A state needs "
            f"the smallest N; at most max_steps = {params.max_steps} (where one more step grows "
            "the region by less than 1 mm).",
            "lead",
        )
        + figure(
            regions,
            "Footholds of the first landing foot that capture four pushes from rest in double "
            "support with one step or two, and the recommended foothold (the region's "
            "Chebyshev centre). <code>steps-regions.png</code>",
        )
        + figure(steps_map, "Steps each sagittal state needs. <code>steps-map.png</code>")
        + "<h3>Largest push from rest with N steps</h3>\n"
        + paragraph(
            "From a CoM at rest over the ankle, sagittal model (<code>pushrecovery bounds "
            "--json</code>, <code>thresholds.steps</code>; ∞: Koolen et al.'s d_∞). Sec. IV's "
            f"instantaneous single step of the paper: {num(-sec4[0], 3)} m/s backward, "
            f"{num(sec4[1], 3)} m/s forward (what the recovery controller takes)."
        )
        + table(["steps", "backward [m/s]", "forward [m/s]"], rows, text_columns=1, ident="steps")
    )


def step_counts(summary: Mapping[str, Any]) -> str:
    """Describe the N-step predictions against the steps taken (summary ``steps``)."""
    steps = summary.get("steps") or {}
    if not steps.get("predicted"):
        return ""
    predicted = ", ".join(
        f"{n if n != '-1' else 'fall'}: {count}" for n, count in steps["predicted"].items()
    )
    taken = ", ".join(f"{n}: {count}" for n, count in steps["taken"].items())
    exact = steps.get("exact")
    share = (
        ""
        if exact is None
        else (
            f" Of the recovered pushes predicted to need steps, {num(100 * exact, 3)} % took "
            "exactly the predicted number."
        )
    )
    return paragraph(
        f"Steps predicted per push (N-step regions, docs/steps.md): {esc(predicted)}; steps "
        f"taken: {esc(taken)}.{share}"
    )
