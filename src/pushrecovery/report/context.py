"""The state shared by the report's sections, and the campaigns they run (reused on disk)."""

from __future__ import annotations

import shutil
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.report.config import PushGrid, Range, ReportGrids
from pushrecovery.sim.mjcf_source import MjcfSource


@dataclass
class _Context:
    params: BodyParams
    out: Path
    grids: ReportGrids
    workers: int | None
    scheduler: str | None
    notes: dict[str, list[str]] = field(default_factory=dict)
    summaries: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: The user's MJCF humanoid whose body ``params`` is (None: the body flags').
    robot: MjcfSource | None = None

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
    from pushrecovery.presets import load_params

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
    result = run_campaign(  # workers=1: this process, as write_report documents (and the CLI)
        spec,
        directory,
        workers=ctx.workers,
        scheduler=ctx.scheduler,
        resume=True,
        isolated=ctx.workers != 1,
    )
    assert result is not None  # no max_batches
    if result.ran < spec.batches:
        ctx.note(key, f"Reused {spec.batches - result.ran} of {spec.batches} batches on disk.")
    ctx.summaries[key] = result.summary
    return result


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
