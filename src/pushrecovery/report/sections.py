"""The sections of the surfaces: bounds, the strategy map, the ground plane, steps, figures."""

from __future__ import annotations

import tempfile
from pathlib import Path

from pushrecovery.report.config import FIGURE_CAPTIONS, PLANE_DIRECTIONS
from pushrecovery.report.context import _Context
from pushrecovery.report.markup import (
    esc,
    figure,
    num,
    paragraph,
    table,
)
from pushrecovery.surfaces.bounds import bounds_data


def _bounds(ctx: _Context) -> str:
    from pushrecovery.plots.campaign import UNITS

    data = bounds_data(ctx.params)
    params = [[name, num(value, 6), UNITS.get(name, "")] for name, value in data["params"].items()]
    cop, cmp, th = data["cop"], data["cmp"], data["thresholds"]
    rows = [
        ["ω = sqrt(g/L)", num(data["omega"], 6), "", "1/s", "LIPM natural frequency, Eq. (4)"],
        [
            "CoP region",
            num(cop["lower"], 6),
            num(cop["upper"], 6),
            "m",
            "capture-point interval of ankle balancing, Eq. (4)",
        ],
        [
            "CMP region",
            num(cmp["lower"], 6),
            num(cmp["upper"], 6),
            "m",
            "capture-point interval of hip balancing, corrected Eq. (15)",
        ],
        [
            "CMP margin",
            num(cmp["margin"], 6),
            "",
            "m",
            "what the hip adds beyond each foot edge, corrected Eq. (15)",
        ],
        ["T_max", num(cmp["t_max"], 6), "", "s", "longest bang-bang half period, Eq. (12)"],
        [
            "ankle threshold",
            num(th["ankle"][0], 6),
            num(th["ankle"][1], 6),
            "m/s",
            "largest push from x = 0, ω δ±, Eq. (4)",
        ],
        [
            "hip threshold",
            num(th["hip"][0], 6),
            num(th["hip"][1], 6),
            "m/s",
            "largest push from x = 0, corrected Eq. (15)",
        ],
        [
            "step threshold",
            num(th["step"][0], 6),
            num(th["step"][1], 6),
            "m/s",
            "largest push from x = 0 one step recovers, Sec. IV",
        ],
    ]
    return (
        paragraph(
            "The body and the capture-point bounds of each strategy: CoP balancing (Eq. 4), "
            "CMP balancing (corrected Eq. 15, errata E11) with the spin-up time of Eq. (12), "
            "and the largest push from upright each strategy recovers (the numbers of "
            "<code>pushrecovery bounds --json</code>).",
            "lead",
        )
        + "<h3>Parameters</h3>\n"
        + table(["parameter", "value", "unit"], params, text_columns=1)
        + "<h3>Bounds and thresholds</h3>\n"
        + table(
            ["quantity", "lower / backward", "upper / forward", "unit", "meaning"],
            rows,
            text_columns=1,
        )
    )


def _map(ctx: _Context) -> str:
    from pushrecovery.plots.campaign import plot_strategy_map

    picture = plot_strategy_map(ctx.params, ctx.out / "strategy-map.png")
    return paragraph(
        "The strategy each CoM state (x, ẋ) needs according to the decision surfaces: ankle "
        "where the capture point x + ẋ/ω lies in the CoP region (Eq. 4), hip in the CMP region "
        "(corrected Eq. 15), step where at most max_steps steps capture it (the N-step capture "
        "regions of the LIPM with a step time, docs/steps.md), otherwise fall.",
        "lead",
    ) + figure(picture, "Strategy map (<code>surfaces.classify.classify_states</code>).")


def _plane(ctx: _Context) -> str:
    from pushrecovery.ground.support import Stance, Support
    from pushrecovery.plots.figures import plane
    from pushrecovery.plots.plane import HEADINGS, SPEEDS
    from pushrecovery.surfaces.bounds import plane_bounds

    params = ctx.params
    rows = []
    offsets: dict[str, float] = {}
    for stance in Stance:
        bounds = plane_bounds(params, Support.from_params(params, stance))
        offsets = bounds["cmp_offset"]
        for strategy in ("ankle", "hip", "step"):
            speeds = bounds["thresholds"][strategy]
            rows.append([stance.value, strategy, *(num(speeds[d], 3) for d in PLANE_DIRECTIONS)])
    (picture,) = plane(params, ("png",), ctx.out)
    return (
        paragraph(
            "The model on the ground plane (x forward, y left, in m): the capture point ξ = r + "
            "ṙ/ω of each axis against the regions of the strategies. The support polygon (one "
            "foot in single support, the convex hull of both feet in double support) is the "
            "ankle strategy's region: a CoP anywhere in it captures every ξ strictly inside "
            "(Eq. 4 in the plane). Grown by the pitch and roll flywheels' offsets (corrected "
            f"Eq. 15: {num(offsets['pitch'], 3)} m along x and {num(offsets['roll'], 3)} m "
            "along y of the stance) it is the hip strategy's CMP region. Beyond it the body "
            "must step: the N-step capture regions of the next section; beyond the dashed "
            "curve no plan of at most max_steps steps captures the push.",
            "lead",
        )
        + figure(
            picture,
            f"Pushes of {HEADINGS} headings and {SPEEDS} speeds from a CoM at rest above the "
            "reference point "
            "(×: the ankles' midpoint in double support, the stance ankle in single support), "
            "drawn at their capture point and coloured by "
            "<code>surfaces.classify.classify_states</code>; bottom row: close to the feet "
            "(the dotted frame above). <code>plane.png</code>",
        )
        + "<h3>Largest push from rest by direction</h3>\n"
        + paragraph(
            "The largest push [m/s] each strategy recovers from a CoM at rest above the "
            "reference point, by direction (<code>pushrecovery bounds --json</code>, "
            "<code>plane</code>): ω times the distance to the region's edge for ankle, hip "
            "and step (the farthest N-step region)."
        )
        + table(
            ["support", "strategy", *(f"{d} [m/s]" for d in PLANE_DIRECTIONS)],
            rows,
            text_columns=2,
            ident="plane-thresholds",
        )
    )


def _steps(ctx: _Context) -> str:
    from pushrecovery.report.steps import steps_section

    return steps_section(ctx.params, ctx.out)


def _figures(ctx: _Context) -> str:
    from pushrecovery.experiments.paper_figures import paper_runs
    from pushrecovery.plots.figures import write_figures

    parts = [
        paragraph(
            "The paper's figures recomputed for this body: Fig. 3 (CoP balancing, Eq. 4), "
            "Figs. 5 and 6 (CMP balancing: bang-bang, Eqs. 8–13, and receding horizon, Eqs. "
            "16–17) and Figs. 9 and 10 (stepping, Sec. IV, Eq. 21).",
            "lead",
        )
    ]
    with tempfile.TemporaryDirectory(prefix="pushrecovery-figures-") as tmp:
        # The ground plane has its own section.
        for path in write_figures(
            ctx.params, paper_runs(ctx.params), Path(tmp), ("png",), ground_plane=False
        ):
            caption = FIGURE_CAPTIONS.get(path.stem, "")
            parts.append(figure(path, f"{esc(caption)} <code>{esc(path.name)}</code>"))
    return "".join(parts)
