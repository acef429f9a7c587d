"""The campaign sections: accuracy, the verdict table, the confusion matrix, the outcome map."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from pushrecovery.errors import InvalidParameterError
from pushrecovery.report.context import _campaign, _Context, _spec
from pushrecovery.report.markup import (
    esc,
    figure,
    num,
    paragraph,
    percent_within,
    table,
)
from pushrecovery.report.steps import step_counts


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
