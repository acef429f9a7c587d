"""One self-contained HTML page: the surfaces, the paper's figures and push campaigns.

:func:`write_report` computes every section for one body and writes ``OUT/index.html``, with
the figures embedded as base64 PNG and plain CSS (no script, no external reference), next to
the campaigns' own directories (``OUT/campaign-*``: their Parquet pushes and summaries, reused
by a rerun with the same grids) and the filmstrips (``OUT/filmstrips``).

Sections, in the page's order (key: content):

- ``bounds``: the parameters, bounds and thresholds (``pushrecovery bounds``);
- ``map``: the strategy map of the (x, ẋ) plane;
- ``plane``: the capture-point plane of the ground-plane model in double and single support,
  with the per-direction push thresholds;
- ``steps``: one- and two-step capture regions for a few pushes, the N-step strategy map and
  the N-step thresholds;
- ``figures``: every reproduced figure of the paper;
- ``analytic``: a campaign on the analytic ``stepping`` model with the ``recovery`` controller;
- ``sweep``: the critical push of ``flywheel`` + ``mpc`` against the hip torque limit;
- ``mujoco``: a campaign on the MuJoCo ``torso`` with ``mpc``;
- ``biped``: a campaign on the MuJoCo ``biped`` with ``recovery``;
- ``critical``: the MuJoCo critical-push table;
- ``filmstrips``: one rendered MuJoCo run per strategy.

The grids come in two sizes: ``small`` (the default, about a minute on two cores) and ``full``;
any grid can be replaced (:class:`PushGrid`), any section left out (``skip``).
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.report.markup import (
    esc,
    figure,
    num,
    page,
    paragraph,
    percent,
    percent_within,
    table,
)
from pushrecovery.report.steps import step_counts
from pushrecovery.surfaces.bounds import bounds_data

__all__ = [
    "MUJOCO_SECTIONS",
    "SECTIONS",
    "SIZES",
    "PushGrid",
    "ReportGrids",
    "write_report",
]

Range = tuple[float, float, float]

#: Section keys and titles, in the page's order.
SECTIONS: Mapping[str, str] = {
    "bounds": "Parameters, bounds and thresholds",
    "map": "Strategy map",
    "plane": "Ground plane",
    "steps": "Steps: capture regions and N-step capturability",
    "figures": "The paper's figures",
    "analytic": "Push campaign on the analytic models",
    "sweep": "Critical push against the hip torque limit",
    "mujoco": "Push campaign in MuJoCo: the hip strategy",
    "biped": "Push campaign in MuJoCo: stepping",
    "critical": "Critical pushes in MuJoCo",
    "filmstrips": "Filmstrips",
}
#: The sections that need MuJoCo (left out with ``mujoco=False``).
MUJOCO_SECTIONS = ("mujoco", "biped", "critical", "filmstrips")
#: Order of computation: the campaigns first (the longest work, on the workers).
_RUN_ORDER = (
    "sweep",
    "analytic",
    "mujoco",
    "biped",
    "bounds",
    "map",
    "plane",
    "steps",
    "figures",
    "critical",
    "filmstrips",
)
#: Filmstrips: strategy -> (model, controller, caption), as docs/validation.md; the push is the
#: body's own (:func:`~pushrecovery.experiments.pushes.strategy_pushes`: 25, 40 and 80 N s for
#: the paper's body).
FILMSTRIPS: Mapping[str, tuple[str, str, str]] = {
    "ankle": ("foot", "ankle-pd", "ankle strategy: foot + ankle PD"),
    "hip": ("torso", "mpc", "hip strategy: torso + MPC"),
    "step": ("biped", "recovery", "stepping: biped + recovery controller"),
}
#: Captions of the paper's figures, by file stem.
FIGURE_CAPTIONS: Mapping[str, str] = {
    "fig3a": "Fig. 3(a): open-loop saturated ankle torque on the linear inverted pendulum, "
    "pushed from upright; green runs recover, red fall; the band is Eq. (4).",
    "fig3b": "Fig. 3(b): saturated PD ankle control of the nonlinear pendulum, pushes 15 % "
    "inside and outside Eq. (4).",
    "fig5a": "Fig. 5(a): bang-bang flywheel control (Eqs. 8–13), phase plot against corrected "
    "Eq. (15).",
    "fig5b": "Fig. 5(b): bang-bang flywheel control, flywheel angle and torque against time.",
    "fig6a": "Fig. 6(a): receding-horizon control (Eqs. 16–17), phase plot.",
    "fig6b": "Fig. 6(b): receding-horizon control (Eqs. 16–17), CoP, torque and flywheel "
    "against time.",
    "fig9": "Fig. 9: the stance pendulum, the coordinate jump to the new foot and the impact "
    "(Sec. IV).",
    "fig10": "Fig. 10: optimal step length against the initial CoM velocity (Eq. 21), with the "
    "range of steps that land the capture point on the new foot.",
    "plane": "The capture-point plane in double, left and right support: support polygon "
    "(ankle), CMP region (hip) and pushes from rest coloured by the strategy they need.",
}
#: Push directions of the ground-plane threshold table, in its column order.
PLANE_DIRECTIONS = ("forward", "backward", "left", "right")


@dataclass(frozen=True)
class PushGrid:
    """The pushes of one campaign: starts, pushes and swept body parameters.

    Parameters
    ----------
    x0 : (start, stop, step)
        CoM positions before the push [m]; values off the body's foot are dropped.
    xdot : (start, stop, step)
        Pushes, as the CoM velocity they give [m/s].
    sweeps : mapping of str to (start, stop, step)
        Body parameters to sweep, SI units (the ``sweep`` section needs exactly one).
    """

    x0: Range
    xdot: Range
    sweeps: Mapping[str, Range] = field(default_factory=dict)


@dataclass(frozen=True)
class ReportGrids:
    """Every grid of the report (see :data:`SIZES`).

    Parameters
    ----------
    analytic : PushGrid
        ``stepping`` + ``recovery`` on the analytic backend.
    sweep : PushGrid
        ``flywheel`` + ``mpc`` on the analytic backend, sweeping one parameter.
    mujoco : PushGrid
        ``torso`` + ``mpc`` in MuJoCo.
    biped : PushGrid
        ``biped`` + ``recovery`` in MuJoCo.
    critical_x0s : tuple of float
        Starts of the MuJoCo critical-push table [m].
    critical_tolerance : float
        Bracket of the ankle and hip critical pushes [m/s].
    step_tolerance : float
        Bracket of the stepping critical pushes [m/s].
    """

    analytic: PushGrid
    sweep: PushGrid
    mujoco: PushGrid
    biped: PushGrid
    critical_x0s: tuple[float, ...] = (0.0,)
    critical_tolerance: float = 2e-3
    step_tolerance: float = 1e-2


#: Grid sizes: ``small`` keeps the whole report near a minute on two cores.
SIZES: Mapping[str, ReportGrids] = {
    "small": ReportGrids(
        analytic=PushGrid((-0.03, 0.12, 0.05), (-3.4, 3.4, 0.2)),
        sweep=PushGrid((0.0, 0.0, 1.0), (-0.6, 1.0, 0.05), {"torque_max": (0.0, 200.0, 50.0)}),
        mujoco=PushGrid((0.0, 0.1, 0.05), (-0.8, 0.9, 0.05)),
        biped=PushGrid((0.0, 0.0, 1.0), (-3.0, 3.0, 0.25)),
    ),
    "full": ReportGrids(
        analytic=PushGrid((-0.04, 0.14, 0.02), (-3.5, 3.5, 0.05)),
        sweep=PushGrid((0.0, 0.1, 0.05), (-1.0, 1.2, 0.02), {"torque_max": (0.0, 300.0, 25.0)}),
        mujoco=PushGrid((-0.03, 0.12, 0.03), (-1.0, 1.0, 0.02)),
        biped=PushGrid((0.0, 0.05, 0.05), (-3.0, 3.0, 0.1)),
        critical_x0s=(-0.03, 0.0, 0.05, 0.1),
        critical_tolerance=1e-3,
        step_tolerance=5e-3,
    ),
}


@dataclass
class _Context:
    params: BodyParams
    out: Path
    grids: ReportGrids
    workers: int | None
    scheduler: str | None
    notes: dict[str, list[str]] = field(default_factory=dict)
    summaries: dict[str, dict[str, Any]] = field(default_factory=dict)

    def note(self, key: str, text: str) -> None:
        self.notes.setdefault(key, []).append(text)


# --- helpers ---------------------------------------------------------------------------------
def _body_grids(grids: ReportGrids, params: BodyParams) -> ReportGrids:
    """Return the built-in grids (drawn for the paper's body) scaled to ``params``' thresholds.

    Each campaign's pushes are multiplied by the ratio of the body's critical push to the
    paper body's for the strategy the campaign is about (one step for the stepping campaigns,
    the hip for the MPC's): the same part of the strategy map for any body.
    """
    from pushrecovery.experiments.pushes import push_scale, scaled_range
    from pushrecovery.params import load_params

    reference = load_params("paper")
    if params == reference:
        return grids
    step = push_scale(params, "step", reference)
    hip = push_scale(params, "hip", reference)
    return replace(
        grids,
        analytic=replace(grids.analytic, xdot=scaled_range(grids.analytic.xdot, step)),
        biped=replace(grids.biped, xdot=scaled_range(grids.biped.xdot, step)),
        mujoco=replace(grids.mujoco, xdot=scaled_range(grids.mujoco.xdot, hip)),
        sweep=replace(grids.sweep, xdot=scaled_range(grids.sweep.xdot, hip)),
    )


def _fit_x0(grid: PushGrid, params: BodyParams) -> Range:
    """``grid.x0`` restricted to the values strictly on the foot; the foot's middle if none."""
    from pushrecovery.campaign import value_range

    values = value_range("x0", grid.x0)
    kept = [float(v) for v in values if params.heel < v < params.toe]
    if not kept:
        centre = round(0.5 * (params.heel + params.toe), 6)
        return (centre, centre, 1.0)
    if len(kept) == len(values):
        return grid.x0
    return (kept[0], kept[-1], float(grid.x0[2]))


def _campaign(ctx: _Context, key: str, spec: Any) -> Any:
    """Run ``spec`` into ``OUT/campaign-KEY``, reusing finished batches of the same spec."""
    from pushrecovery.campaign import CampaignError, read_spec, run_campaign

    directory = ctx.out / f"campaign-{key}"
    if (directory / "spec.json").exists():
        try:
            same = read_spec(directory).to_dict() == spec.to_dict()
        except (CampaignError, InvalidParameterError):
            same = False
        if not same:  # another grid or body: start this campaign afresh
            shutil.rmtree(directory)
    result = run_campaign(
        spec, directory, workers=ctx.workers, scheduler=ctx.scheduler, resume=True
    )
    assert result is not None  # no max_batches
    if result.ran < spec.batches:
        ctx.note(key, f"Reused {spec.batches - result.ran} of {spec.batches} batches on disk.")
    ctx.summaries[key] = result.summary
    return result


def _confusion_table(summary: Mapping[str, Any], ident: str) -> str:
    """Predicted strategy (rows) against the strategy used (columns), with totals."""
    labels = summary["confusion"]["labels"]
    counts = [[int(c) for c in row] for row in summary["confusion"]["counts"]]
    head = "".join(f"<th>{esc(label)}</th>" for label in labels)
    lines = [
        f'<table class="confusion" id="{esc(ident)}">',
        f'<tr><th class="text">predicted \\ used</th>{head}<th>total</th></tr>',
    ]
    for i, (label, row) in enumerate(zip(labels, counts, strict=True)):
        cells = "".join(
            f'<td class="diagonal">{c}</td>' if i == j else f"<td>{c}</td>"
            for j, c in enumerate(row)
        )
        lines.append(f'<tr><th class="text">{esc(label)}</th>{cells}<td>{sum(row)}</td></tr>')
    totals = "".join(f"<td>{sum(col)}</td>" for col in zip(*counts, strict=True))
    grand = sum(map(sum, counts))
    lines.append(f'<tr><th class="text">total</th>{totals}<td>{grand}</td></tr>')
    lines.append("</table>")
    return "\n".join(lines) + "\n"


def _boundary_table(summary: Mapping[str, Any]) -> str:
    sweeps = [name for name, _ in summary["spec"]["sweeps"]]
    rows = []
    for r in summary["boundary"]:
        low, high = r["bracket"]
        rows.append(
            [
                *(num(r[name]) for name in sweeps),
                num(r["x0"]),
                r["direction"],
                r["strategy"],
                num(r["analytic"]),
                num(r["empirical"]),
                f"[{num(low)}, {num(high)}]",
                percent_within(r["relative_error"], _resolution(r)),
                "yes" if r["monotone"] else "no",
            ]
        )
    header = [
        *sweeps,
        "x0 [m]",
        "direction",
        "surface",
        "analytic [m/s]",
        "simulated [m/s]",
        "bracket [m/s]",
        "vs analytic",
        "monotone",
    ]
    return table(header, rows, text_columns=0)


def _verdict_table(pushes: Any, ident: str) -> str:
    """Return the accuracy's own table: the surfaces' verdict against the outcome, by push.

    Accuracy = (recovered where the verdict says the controller recovers + not recovered where
    it says it does not) / pushes: the diagonal of this table over its total.
    """
    verdict = np.asarray(pushes.column("predicted_recovers").to_numpy(zero_copy_only=False))
    outcome = np.asarray(pushes.column("outcome").to_numpy(zero_copy_only=False))
    recovered = outcome == "recovered"
    cells = [
        [int(np.sum(verdict & recovered)), int(np.sum(verdict & ~recovered))],
        [int(np.sum(~verdict & recovered)), int(np.sum(~verdict & ~recovered))],
    ]
    rows = [
        ["recovers (the controller's strategy or a lesser one)", *map(str, cells[0])],
        ["does not", *map(str, cells[1])],
    ]
    return paragraph(
        "Where the accuracy comes from: the surfaces' verdict (rows) against the outcome "
        f"(columns); accuracy = ({cells[0][0]} + {cells[1][1]}) / {sum(map(sum, cells))}."
    ) + table(
        ["verdict \\ outcome", "recovered", "fell or undecided"], rows, text_columns=1, ident=ident
    )


def _disagreements(table: Any) -> str:
    """One sentence on the pushes whose outcome the surfaces got wrong, by kind."""
    predicted = np.asarray(table.column("predicted").to_numpy(zero_copy_only=False))
    outcome = np.asarray(table.column("outcome").to_numpy(zero_copy_only=False))
    verdict = np.asarray(table.column("predicted_recovers").to_numpy(zero_copy_only=False))
    steps = np.asarray(table.column("steps").to_numpy(zero_copy_only=False))
    recovered = outcome == "recovered"
    wrong = int(np.sum(verdict != recovered))
    if not wrong:
        return paragraph("Every verdict of the surfaces matches the outcome.")
    unexpected = (predicted == "fall") & recovered
    several = int(np.sum(unexpected & (steps >= 2)))
    text = (
        f"{wrong} verdicts are wrong: {int(np.sum(verdict & ~recovered))} pushes the surfaces "
        f"put within the controller's strategy fell, {int(np.sum(~verdict & recovered))} "
        "pushes beyond it recovered"
    )
    if several:
        text += (
            f" ({several} of them predicted to fall recovered with two or more steps, beyond "
            "max_steps or the N-step regions)"
        )
    return paragraph(text + ".")


def _campaign_body(
    ctx: _Context, key: str, spec: Any, sentence: str, *, boundary: bool = True
) -> str:
    """Run a campaign; return its accuracy, confusion matrix, outcome map and boundary table."""
    from pushrecovery.plots.campaign import plot_outcome_map

    result = _campaign(ctx, key, spec)
    summary = result.summary
    parts = [paragraph(sentence, "lead")]
    accuracy = summary["accuracy"]
    outcomes = summary["outcomes"]
    parts.append(
        paragraph(
            f"<code>{esc(spec.model)}</code> + <code>{esc(spec.controller)}</code> on the "
            f"{esc(spec.backend)} backend, {summary['pushes']} pushes: "
            f"{outcomes['recovered']} recovered, {outcomes['fell']} fell, "
            f"{outcomes['undecided']} undecided. <strong>Accuracy "
            f"{num(accuracy, 3)}</strong>: the fraction of pushes where the surfaces' verdict "
            "(the controller's strategy or a lesser one recovers) matches the outcome."
        )
    )
    parts.append(_verdict_table(result.table, f"verdicts-{key}"))
    parts.append(
        "<h3>Confusion matrix</h3>\n"
        + paragraph(
            "Rows: the strategy the surfaces predict for the state after the push; columns: "
            "the strategy the run used (fall: it fell)."
        )
        + _confusion_table(summary, f"confusion-{key}")
        + _disagreements(result.table)
        + step_counts(summary)
    )
    picture = plot_outcome_map(result.table, spec, result.directory / "outcome-map.png")
    parts.append(
        "<h3>Outcome map</h3>\n"
        + figure(
            picture,
            "Each push at (x0, ẋ), coloured by the strategy the run used (green ankle, orange "
            "hip, blue step; grey ×: fell; black ring: verdict ≠ outcome); dashed: the "
            "capture-point edges of Eq. (4), corrected Eq. (15) and of max_steps steps; "
            "dash-dotted: Sec. IV's single-step limit (the recovery controller's).",
        )
    )
    if boundary and summary["boundary"]:
        irregular = [r for r in summary["boundary"] if not r["monotone"]]
        note = (
            f" {len(irregular)} row(s) are not monotone: a push beyond the first fall recovered."
            if irregular
            else " Every row is monotone: no push beyond the first fall recovered."
        )
        parts.append(
            "<h3>Critical pushes of the grid</h3>\n"
            + paragraph(
                "The empirical critical push is the middle of the bracket [largest push that "
                "recovered with every smaller one, next push of the grid]; analytic: the "
                "controller's surface; the error is given to the grid's resolution (± half the "
                "bracket)." + note
            )
            + _boundary_table(summary)
        )
    parts.append(_data_links(key))
    return "".join(parts)


def _resolution(row: Mapping[str, Any]) -> float | None:
    """Half the bracket relative to the analytic critical push: what the grid can resolve."""
    low, high = row["bracket"]
    if low is None or high is None or not row["analytic"]:
        return None
    return 0.5 * abs(high - low) / abs(row["analytic"])


def _data_links(key: str) -> str:
    """Links to the files behind a campaign's tables (next to the report)."""
    folder = f"campaign-{key}"
    return paragraph(
        "Data: "
        + ", ".join(
            f'<a href="{esc(folder)}/{esc(name)}">{esc(name)}</a>'
            for name in ("pushes.parquet", "summary.json", "spec.json")
        )
        + " (one row per push; the counts, confusion matrix and critical pushes; the grid).",
        "note",
    )


# --- sections --------------------------------------------------------------------------------
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


def _spec(ctx: _Context, backend: str, model: str, controller: str, grid: PushGrid) -> Any:
    from pushrecovery.campaign import CampaignSpec

    return CampaignSpec(
        backend,
        model,
        controller,
        ctx.params,
        x0=_fit_x0(grid, ctx.params),
        xdot=grid.xdot,
        sweeps=dict(grid.sweeps),
        # Batches of a few seconds: even over two workers, reused by a rerun.
        batch_size=10 if backend == "analytic" else 5,
    )


def _analytic(ctx: _Context) -> str:
    spec = _spec(ctx, "analytic", "stepping", "recovery", ctx.grids.analytic)
    return _campaign_body(
        ctx,
        "analytic",
        spec,
        "Every push of a grid over the start x0 and the push ẋ on the analytic stepping model "
        "with the push-recovery controller (ankle, then hip, then a step), against the "
        "strategy the surfaces predict: Eq. (4), corrected Eq. (15) and the single-step limit "
        "(Sec. IV).",
    )


def _sweep(ctx: _Context) -> str:
    from pushrecovery.plots.campaign import UNITS, plot_critical_vs_parameter

    grid = ctx.grids.sweep
    if len(grid.sweeps) != 1:
        raise InvalidParameterError(
            f"the sweep grid must sweep exactly one parameter, got {list(grid.sweeps)}"
        )
    name = next(iter(grid.sweeps))
    spec = _spec(ctx, "analytic", "flywheel", "mpc", grid)
    result = _campaign(ctx, "sweep", spec)
    picture = plot_critical_vs_parameter(result.summary, result.directory / "critical.png")
    return (
        paragraph(
            f"The critical push of the receding-horizon controller (Eqs. 16–17) on the flywheel "
            f"model as <code>{esc(name)}</code> [{esc(UNITS.get(name, ''))}] varies, against "
            "the hip surface, corrected Eq. (15), whose CMP margin τmax/(m g) (1 − "
            "e^(−ω T_max))² changes with the body.",
            "lead",
        )
        + paragraph(
            f"{result.summary['pushes']} pushes, accuracy {num(result.summary['accuracy'], 3)}."
        )
        + figure(
            picture,
            "Critical push against the swept parameter: simulated (the grid's bracket as error "
            "bar) and analytic (dashed).",
        )
        + _boundary_table(result.summary)
    )


def _mujoco(ctx: _Context) -> str:
    spec = _spec(ctx, "mujoco", "torso", "mpc", ctx.grids.mujoco)
    return _campaign_body(
        ctx,
        "mujoco",
        spec,
        "The same comparison in real physics: the MuJoCo torso (foot, leg, upper body on a hip "
        "hinge) pushed by real forces and balanced by the receding-horizon controller (Eqs. "
        "16–17), against Eq. (4) and corrected Eq. (15).",
    )


def _biped(ctx: _Context) -> str:
    spec = _spec(ctx, "mujoco", "biped", "recovery", ctx.grids.biped)
    return _campaign_body(
        ctx,
        "biped",
        spec,
        "Pushes on the MuJoCo biped with the push-recovery controller, which steps when the "
        "capture point leaves the CMP region (corrected Eq. 15), against the single-step limit "
        "of Sec. IV.",
    )


def _critical(ctx: _Context) -> str:
    from pushrecovery.sim.validation import available_strategies, critical_table

    grids = ctx.grids
    rows = []
    for strategy in available_strategies("mujoco"):
        tolerance = grids.step_tolerance if strategy == "step" else grids.critical_tolerance
        for row in critical_table(
            ctx.params,
            backend="mujoco",
            strategies=(strategy,),
            x0s=tuple(x for x in grids.critical_x0s if ctx.params.heel < x < ctx.params.toe),
            tolerance=tolerance,
        ):
            rows.append(
                [
                    row.strategy,
                    f"{row.model} + {row.controller}",
                    row.direction,
                    num(row.x0),
                    num(row.predicted),
                    num(row.corrected),
                    num(row.measured),
                    f"[{num(row.bracket[0])}, {num(row.bracket[1])}]",
                    percent(row.relative_error),
                    percent(row.corrected_error),
                    str(row.simulations),
                ]
            )
    header = [
        "strategy",
        "model + controller",
        "direction",
        "x0 [m]",
        "predicted [m/s]",
        "corrected [m/s]",
        "MuJoCo [m/s]",
        "bracket [m/s]",
        "vs predicted",
        "vs corrected",
        "simulations",
    ]
    return paragraph(
        "The largest push each strategy recovers in MuJoCo (bisection on a real force, shown "
        "as J/m), against the paper's surface (Eq. 4, corrected Eq. 15, the single-step limit "
        "of Sec. IV) and, for ankle and hip, the prediction corrected for the foot's usable "
        "length and the push's duration (docs/validation.md).",
        "lead",
    ) + table(header, rows, text_columns=3)


def _filmstrips(ctx: _Context) -> str:
    from pushrecovery.control.base import make_controller
    from pushrecovery.experiments.pushes import strategy_pushes
    from pushrecovery.sim.backend import Recording
    from pushrecovery.sim.mujoco.render import (
        fit_view,
        render_frames,
        require_offscreen_gl,
        select_times,
        write_filmstrip,
    )
    from pushrecovery.sim.push import Push
    from pushrecovery.sim.registry import MUJOCO_MODELS, make_plant
    from pushrecovery.sim.simulate import simulate

    lead = paragraph(
        "One MuJoCo run per strategy from upright, pushed by a real force: the ankle strategy "
        "inside Eq. (4), the hip strategy beyond it but inside corrected Eq. (15), and a step "
        "beyond both (Sec. IV). Red: CoM; blue: capture point; green: CoP.",
        "lead",
    )
    try:
        require_offscreen_gl()
    except PushRecoveryError as exc:
        return lead + paragraph(
            f"Rendering is not available on this machine, so there are no filmstrips: {esc(exc)}",
            "note",
        )
    parts = [lead]
    folder = ctx.out / "filmstrips"
    pushes = strategy_pushes(ctx.params)
    for strategy, (model, controller, name) in FILMSTRIPS.items():
        impulse = pushes.impulse(strategy, ctx.params.mass)
        caption = f"{name}, {impulse:g} N s"
        if model not in MUJOCO_MODELS:
            parts.append(paragraph(f"No MuJoCo model {esc(model)} for {esc(strategy)}.", "note"))
            continue
        plant = make_plant(model, ctx.params, "mujoco")
        if not isinstance(plant, Recording):  # pragma: no cover - every MuJoCo plant records
            raise TypeError(f"the MuJoCo model {model!r} records no frames")
        plant.record()
        plant.reset(0.0, 0.0)
        pushed = plant.apply_push(Push.from_impulse(impulse, ctx.params.mass))
        run = simulate(plant, make_controller(controller, ctx.params), pushed, duration=4.0)
        frames = plant.frames or []
        strip = select_times(frames, 7)
        images = render_frames(
            plant.model, strip, width=180, height=240, view=fit_view(plant.model, frames, 0.75)
        )
        path = write_filmstrip(
            images,
            [f.time for f in strip],
            folder / f"{strategy}.png",
            title=f"{caption}: {run.outcome.value}",
        )
        parts.append(
            f"<h3>{esc(strategy)}</h3>\n"
            + figure(
                path,
                f"{esc(caption)} (ẋ = J/m = {num(impulse / ctx.params.mass, 3)} m/s): "
                f"{esc(run.outcome.value)}.",
            )
        )
    return "".join(parts)


_BUILDERS: Mapping[str, Callable[[_Context], str]] = {
    "bounds": _bounds,
    "map": _map,
    "plane": _plane,
    "steps": _steps,
    "figures": _figures,
    "analytic": _analytic,
    "sweep": _sweep,
    "mujoco": _mujoco,
    "biped": _biped,
    "critical": _critical,
    "filmstrips": _filmstrips,
}


# --- the page --------------------------------------------------------------------------------
def write_report(
    params: BodyParams | None = None,
    out_dir: Path | str = Path("out/report"),
    *,
    size: str = "small",
    full: bool = False,
    analytic_grid: PushGrid | None = None,
    sweep_grid: PushGrid | None = None,
    mujoco_grid: PushGrid | None = None,
    biped_grid: PushGrid | None = None,
    mujoco: bool = True,
    skip: Collection[str] = (),
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[str], None] | None = None,
) -> Path:
    """Compute every section of the report and write ``out_dir/index.html``.

    One self-contained page (figures as base64 PNG, plain CSS, no script or external
    reference): the parameters with the bounds and thresholds (Eq. 4, corrected Eq. 15,
    Eq. 12), the strategy map, the ground plane (the capture-point plane in double and single
    support, per-direction thresholds), the paper's figures, push campaigns on the analytic
    models and in MuJoCo with their accuracy, confusion matrix and outcome map, the MuJoCo
    critical-push table and one filmstrip per strategy (module docstring). The page's footer
    gives each section's wall time. The campaigns keep their files in
    ``out_dir/campaign-KEY`` (a rerun with the same grid and body reuses them; another grid
    replaces them).

    Parameters
    ----------
    params : BodyParams, optional
        The body; default the built-in preset (:func:`pushrecovery.load_params`).
    out_dir : path
        Output directory, created if missing.
    size : {"small", "full"}
        Grid size (:data:`SIZES`): ``small`` (default) runs in about a minute on two cores,
        ``full`` is about ten times larger.
    full : bool
        Shorthand for ``size="full"``.
    analytic_grid, sweep_grid, mujoco_grid, biped_grid : PushGrid, optional
        Replace the grid of that campaign (``sweep_grid`` must sweep one parameter).
    mujoco : bool
        Include the MuJoCo sections (``mujoco``, ``biped``, ``critical``, ``filmstrips``).
    skip : collection of str
        Section keys to leave out (:data:`SECTIONS`).
    workers : int, optional
        Worker processes of the campaigns (1: this process; default all cores).
    scheduler : str, optional
        Address of a ``dask.distributed`` scheduler to run the campaigns on.
    progress : callable, optional
        Called with one line of text as each section starts and ends.

    Returns
    -------
    Path
        The HTML file.

    Raises
    ------
    InvalidParameterError
        On an unknown size or section key, or an invalid grid.
    """
    from pushrecovery import __version__, load_params

    if size not in SIZES:
        raise InvalidParameterError(f"size must be one of {list(SIZES)}, got {size!r}")
    unknown = sorted(set(skip) - set(SECTIONS))
    if unknown:
        raise InvalidParameterError(
            f"unknown section(s) {', '.join(map(repr, unknown))}; sections: {list(SECTIONS)}"
        )
    if workers is not None and workers < 1:
        raise InvalidParameterError(f"workers must be >= 1, got {workers}")
    params = load_params() if params is None else params
    size = "full" if full else size
    grids = _body_grids(SIZES[size], params)
    grids = replace(
        grids,
        analytic=analytic_grid or grids.analytic,
        sweep=sweep_grid or grids.sweep,
        mujoco=mujoco_grid or grids.mujoco,
        biped=biped_grid or grids.biped,
    )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    skipped = set(skip) | (set(MUJOCO_SECTIONS) if not mujoco else set())
    ctx = _Context(params, out, grids, workers, scheduler)
    bodies: dict[str, str] = {}
    times: dict[str, float] = {}
    start = time.perf_counter()
    for key in _RUN_ORDER:
        if key in skipped:
            continue
        if progress is not None:
            progress(f"{SECTIONS[key]} ...")
        began = time.perf_counter()
        try:
            bodies[key] = _BUILDERS[key](ctx)
        except (PushRecoveryError, ImportError) as exc:
            # A missing optional dependency (MuJoCo) or an unusable setting: say so in place.
            bodies[key] = paragraph(
                f"This section could not be computed: {esc(type(exc).__name__)}: {esc(exc)}",
                "note",
            )
        times[key] = time.perf_counter() - began
        if progress is not None:
            progress(f"{SECTIONS[key]}: {times[key]:.1f} s")
    total = time.perf_counter() - start
    html = page(
        "Push recovery report",
        _body(params, bodies, ctx, size),
        _footer(times, total, __version__, workers, scheduler, size),
    )
    path = out / "index.html"
    partial = path.with_suffix(".partial")
    try:
        partial.write_text(html, encoding="utf-8")
        partial.replace(path)
    except OSError as exc:
        raise PushRecoveryError(f"cannot write {path}: {exc.strerror or exc}") from None
    return path


def _body(params: BodyParams, bodies: Mapping[str, str], ctx: _Context, size: str) -> str:
    shown = [key for key in SECTIONS if key in bodies]
    parts = [
        "<h1>Push recovery report</h1>\n",
        paragraph(
            "Will a pushed humanoid fall, and what should it do about it? The decision "
            "surfaces of Stephens, <em>Humanoid Push Recovery</em> (Humanoids 2007) for one "
            "body, checked against simulation: CoP balancing (the ankle strategy, Eq. 4), CMP "
            f"balancing (the hip strategy, corrected Eq. 15) and stepping (Sec. IV). Grids: "
            f"<code>{esc(size)}</code>.",
            "lead",
        ),
        _verdict(params, ctx),
        "<nav><ul>\n"
        + "".join(f'<li><a href="#{key}">{esc(SECTIONS[key])}</a></li>\n' for key in shown)
        + "</ul></nav>\n",
    ]
    for key in shown:
        notes = "".join(paragraph(esc(text), "note") for text in ctx.notes.get(key, []))
        parts.append(
            f'<section id="{key}">\n<h2>{esc(SECTIONS[key])}</h2>\n{bodies[key]}{notes}</section>\n'
        )
    return "".join(parts)


def _verdict(params: BodyParams, ctx: _Context) -> str:
    """One paragraph at the top: the body's thresholds and how well the surfaces predicted."""
    data = bounds_data(params)["thresholds"]
    text = (
        "<strong>Verdict.</strong> From upright this body recovers pushes up to "
        f"{num(data['ankle'][1], 3)} m/s forward with the ankles (Eq. 4), "
        f"{num(data['hip'][1], 3)} m/s with the hip (corrected Eq. 15) and "
        f"{num(data['step'][1], 3)} m/s with steps (the N-step verdict)."
    )
    scores = [
        f"{esc(SECTIONS[key])}: {num(summary['accuracy'], 3)} of {summary['pushes']} pushes"
        for key, summary in ctx.summaries.items()
    ]
    if scores:
        text += (
            " The surfaces' verdicts matched the simulated outcomes in " + "; ".join(scores) + "."
        )
    return paragraph(text, "verdict")


def _footer(
    times: Mapping[str, float],
    total: float,
    version: str,
    workers: int | None,
    scheduler: str | None,
    size: str,
) -> str:
    rows = [[SECTIONS[key], f"{seconds:.1f}"] for key, seconds in times.items()]
    rows.append(["total", f"{total:.1f}"])
    count = workers or os.cpu_count() or 1
    where = (
        f"the Dask scheduler {scheduler}"
        if scheduler
        else f"{count} local worker process{'es' if count > 1 else ''}"
    )
    return paragraph(
        f"Generated by pushrecovery {esc(version)} (grids <code>{esc(size)}</code>, "
        f"campaigns on {esc(where)}). Wall time of each section, in the order computed:"
    ) + table(["section", "wall time [s]"], rows, text_columns=1, ident="timings")
