"""The sections of the surfaces: bounds, the strategy map, the ground plane, steps, figures."""

from __future__ import annotations

from pushrecovery.report.config import FIGURE_CAPTIONS, PLANE_DIRECTIONS
from pushrecovery.report.context import _Context
from pushrecovery.report.data import (
    BoundsSection,
    FiguresSection,
    MapSection,
    Picture,
    PlaneSection,
    StepsSection,
    Table,
)
from pushrecovery.report.markup import num
from pushrecovery.surfaces.bounds import bounds_data


def _bounds(ctx: _Context) -> BoundsSection:
    from pushrecovery.plots.campaign import UNITS

    data = bounds_data(ctx.params)
    params = tuple(
        (name, num(value, 6), UNITS.get(name, "")) for name, value in data["params"].items()
    )
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
            "one-step threshold",
            num(th["steps"]["1"][0], 6),
            num(th["steps"]["1"][1], 6),
            "m/s",
            "largest push from x = 0 one step recovers (the 1-step capture region)",
        ],
        [
            "Sec. IV single-step threshold",
            num(th["step_sec4"][0], 6),
            num(th["step_sec4"][1], 6),
            "m/s",
            "the same by the paper's single-step model, Sec. IV (Eq. 21)",
        ],
        [
            f"{ctx.params.max_steps}-step threshold",
            num(th["step"][0], 6),
            num(th["step"][1], 6),
            "m/s",
            f"largest push from x = 0 that {ctx.params.max_steps} steps recover "
            "(max_steps: the N-step capture regions)",
        ],
    ]
    return BoundsSection(
        parameters=Table(("parameter", "value", "unit"), params, text_columns=1),
        bounds=Table(
            ("quantity", "lower / backward", "upper / forward", "unit", "meaning"),
            tuple(map(tuple, rows)),
            text_columns=1,
        ),
    )


def _map(ctx: _Context) -> MapSection:
    from pushrecovery.plots.campaign import plot_strategy_map

    path = plot_strategy_map(ctx.params, ctx.out / "strategy-map.png")
    return MapSection(Picture(path, "Strategy map.", "surfaces.classify.classify_states"))


def _plane(ctx: _Context) -> PlaneSection:
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
            rows.append((stance.value, strategy, *(num(speeds[d], 3) for d in PLANE_DIRECTIONS)))
    (path,) = plane(params, ("png",), ctx.out)
    return PlaneSection(
        picture=Picture(
            path,
            f"Pushes of {HEADINGS} headings and {SPEEDS} speeds from a CoM at rest above the "
            "reference point (×: the ankles' midpoint in double support, the stance ankle in "
            "single support), drawn at their capture point and coloured by the strategy "
            "surfaces.classify.classify_states gives them; bottom row: close to the feet (the "
            "dotted frame above).",
            path.name,
        ),
        thresholds=Table(
            ("support", "strategy", *(f"{d} [m/s]" for d in PLANE_DIRECTIONS)),
            tuple(rows),
            text_columns=2,
            ident="plane-thresholds",
        ),
        pitch_offset=float(offsets["pitch"]),
        roll_offset=float(offsets["roll"]),
    )


def _steps(ctx: _Context) -> StepsSection:
    from pushrecovery.report.steps import steps_section

    return steps_section(ctx.params, ctx.out)


def _figures(ctx: _Context) -> FiguresSection:
    from pushrecovery.experiments.paper_figures import paper_runs
    from pushrecovery.plots.figures import write_figures

    # Written next to the page (the ground plane has its own section).
    folder = ctx.out / "figures"
    paths = write_figures(ctx.params, paper_runs(ctx.params), folder, ("png",), ground_plane=False)
    return FiguresSection(tuple(Picture(p, FIGURE_CAPTIONS.get(p.stem, ""), p.name) for p in paths))
