"""The campaign sections: accuracy, the verdict table, the confusion matrix, the outcome map."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from pushrecovery.errors import InvalidParameterError
from pushrecovery.report.context import _campaign, _Context, _spec
from pushrecovery.report.data import (
    CampaignSection,
    ConfusionMatrix,
    Disagreements,
    Picture,
    SweepSection,
    Table,
    VerdictCounts,
)
from pushrecovery.report.markup import num, percent_within
from pushrecovery.report.steps import step_counts

#: The files behind a campaign's tables, in its folder next to the page.
DATA_FILES = ("pushes.parquet", "summary.json", "spec.json")


def _confusion(summary: Mapping[str, Any], ident: str) -> ConfusionMatrix:
    """Predicted strategy (rows) against the strategy used (columns)."""
    confusion = summary["confusion"]
    return ConfusionMatrix(
        labels=tuple(confusion["labels"]),
        counts=tuple(tuple(int(c) for c in row) for row in confusion["counts"]),
        ident=ident,
        apart=tuple(
            (name, tuple(int(c) for c in column))
            for name, column in confusion.get("apart", {}).items()
        ),
    )


def _boundary_table(summary: Mapping[str, Any]) -> Table:
    sweeps = [name for name, _ in summary["spec"]["sweeps"]]
    rows = []
    for r in summary["boundary"]:
        low, high = r["bracket"]
        rows.append(
            (
                *(num(r[name]) for name in sweeps),
                num(r["x0"]),
                r["direction"],
                r["strategy"],
                num(r["analytic"]),
                num(r["empirical"]),
                f"[{num(low)}, {num(high)}]",
                percent_within(r["relative_error"], _resolution(r)),
                "yes" if r["monotone"] else "no",
            )
        )
    header = (
        *sweeps,
        "x0 [m]",
        "direction",
        "surface",
        "analytic [m/s]",
        "simulated [m/s]",
        "bracket [m/s]",
        "vs analytic",
        "monotone",
    )
    return Table(header, tuple(rows))


def _column(pushes: Any, name: str) -> np.ndarray:
    return np.asarray(pushes.column(name).to_numpy(zero_copy_only=False))


def _verdict_counts(pushes: Any, ident: str) -> VerdictCounts:
    """Count the surfaces' verdict (recovers or not) against the outcome, by push."""
    # As the accuracy: pushes with a decided outcome (neither an error nor undecided).
    decided = ~np.isin(_column(pushes, "outcome"), ("error", "undecided"))
    verdict = _column(pushes, "predicted_recovers").astype(bool)[decided]
    recovered = (_column(pushes, "outcome") == "recovered")[decided]
    return VerdictCounts(
        recovers_recovered=int(np.sum(verdict & recovered)),
        recovers_not_recovered=int(np.sum(verdict & ~recovered)),
        fails_recovered=int(np.sum(~verdict & recovered)),
        fails_not_recovered=int(np.sum(~verdict & ~recovered)),
        ident=ident,
    )


def _disagreements(pushes: Any) -> Disagreements:
    """Count the pushes whose outcome the surfaces got wrong, by kind."""
    decided = _column(pushes, "outcome") != "error"
    verdict = _column(pushes, "predicted_recovers").astype(bool) & decided
    recovered = _column(pushes, "outcome") == "recovered"
    verdict_fails = ~_column(pushes, "predicted_recovers").astype(bool) & decided
    unexpected = (_column(pushes, "predicted") == "fall") & recovered
    return Disagreements(
        fell_inside=int(np.sum(verdict & ~recovered)),
        recovered_beyond=int(np.sum(verdict_fails & recovered)),
        recovered_with_steps=int(np.sum(unexpected & (_column(pushes, "steps") >= 2))),
    )


#: The campaign sections: key -> (backend, model, controller, the grid (its field of
#: ``ReportGrids``), the lead paragraph; ``{froude}`` is √(g l) [m/s]).
CAMPAIGNS: Mapping[str, tuple[str, str, str, str, str]] = {
    "analytic": (
        "analytic",
        "stepping",
        "recovery",
        "analytic",
        "Every push of a grid over the start x0 and the push ẋ on Sec. IV's stepping model "
        "(rigid legs that land symmetrically, the impact of Eqs. 18–20) with the push-recovery "
        "controller (ankle, then hip, then Sec. IV's step, planned again at every touchdown), "
        "against the strategy the surfaces predict: Eq. (4), corrected Eq. (15) and N-step "
        "capturability. The locked swing leg cannot carry a CoM faster than √(g l) = "
        "{froude:.2f} m/s: the stance foot would leave the floor, which this model counts as a "
        "fall and the LIPM's verdict does not see (docs/steps.md). The next section runs the "
        "model of the N-step analysis.",
    ),
    "planar": (
        "analytic",
        "stepping-plane",
        "recovery-plane",
        "analytic",
        "The same pushes on the model of the N-step analysis: the planar LIPM with flywheels "
        "whose feet land where and when commanded, no sooner than min_step_time after the "
        "lift, within reach (stepping-plane), from double support. The plan-following "
        "controller (recovery-plane) takes the steps of the N-step plan and plans again at "
        "every touchdown; the verdict is classify's (Eq. 4, corrected Eq. 15, N-step "
        "capturability).",
    ),
    "mujoco": (
        "mujoco",
        "torso",
        "mpc",
        "mujoco",
        "The same comparison in real physics: the MuJoCo torso (foot, leg, upper body on a hip "
        "hinge) pushed by real forces and balanced by the receding-horizon controller (Eqs. "
        "16–17), against Eq. (4) and corrected Eq. (15).",
    ),
    "biped": (
        "mujoco",
        "biped",
        "recovery",
        "biped",
        "Pushes on the MuJoCo biped with the push-recovery controller, which steps when the "
        "capture point leaves the CMP region (corrected Eq. 15) and takes Sec. IV's step, "
        "planned again at every touchdown, against the strategy the surfaces predict "
        "(Eq. 4, corrected Eq. 15, N-step capturability).",
    ),
}


def accuracy(summary: Mapping[str, Any]) -> float | None:
    """Return a campaign summary's accuracy [-]; None when no push has an outcome (all errors)."""
    value = summary["accuracy"]
    return None if value is None else float(value)


def campaign_section(ctx: _Context, key: str) -> CampaignSection:
    """Run the campaign ``key`` of :data:`CAMPAIGNS`; return it as a section of the page.

    Its accuracy, confusion matrix, outcome map and boundary table (none for ``planar``).
    """
    from pushrecovery.plots.campaign import plot_outcome_map

    backend, model, controller, grid, lead = CAMPAIGNS[key]
    spec = _spec(ctx, backend, model, controller, getattr(ctx.grids, grid))
    froude = math.sqrt(ctx.params.gravity * ctx.params.leg_length)
    result = _campaign(ctx, key, spec)
    summary = result.summary
    outcomes = summary["outcomes"]
    picture = plot_outcome_map(result.table, spec, result.directory / "outcome-map.png")
    rows = summary["boundary"] if key != "planar" else []
    return CampaignSection(
        key=key,
        lead=lead.format(froude=froude),
        backend=spec.backend,
        model=spec.model,
        controller=spec.controller,
        pushes=int(summary["pushes"]),
        recovered=int(outcomes["recovered"]),
        fell=int(outcomes["fell"]),
        undecided=int(outcomes["undecided"]),
        slipped=int(outcomes.get("slipped", 0)),
        errors=int(outcomes.get("error", 0)),
        accuracy=accuracy(summary),
        verdicts=_verdict_counts(result.table, f"verdicts-{key}"),
        confusion=_confusion(summary, f"confusion-{key}"),
        disagreements=_disagreements(result.table),
        step_counts=step_counts(summary),
        outcome_map=Picture(
            picture,
            "Each push at (x0, ẋ), coloured by the strategy the run used (green ankle, orange "
            "hip, blue step; grey ×: fell; black ring: verdict ≠ outcome); dashed: the "
            "capture-point edges of Eq. (4), corrected Eq. (15) and of max_steps steps; "
            "dash-dotted: Sec. IV's single-step limit (the recovery controller's).",
        ),
        boundary=_boundary_table(summary) if rows else None,
        irregular=sum(1 for r in rows if not r["monotone"]),
        data_files=tuple(f"campaign-{key}/{name}" for name in DATA_FILES),
    )


def _resolution(row: Mapping[str, Any]) -> float | None:
    """Half the bracket relative to the analytic critical push: what the grid can resolve."""
    low, high = row["bracket"]
    if low is None or high is None or not row["analytic"]:
        return None
    return 0.5 * abs(high - low) / abs(row["analytic"])


def _sweep(ctx: _Context) -> SweepSection:
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
    return SweepSection(
        parameter=name,
        unit=UNITS.get(name, ""),
        pushes=int(result.summary["pushes"]),
        accuracy=accuracy(result.summary),
        picture=Picture(
            picture,
            "Critical push against the swept parameter: simulated (the grid's bracket as error "
            "bar) and analytic (dashed).",
        ),
        boundary=_boundary_table(result.summary),
    )
