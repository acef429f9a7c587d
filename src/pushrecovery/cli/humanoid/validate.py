"""``pushrecovery humanoid validate`` (biped3d, g1): the polar validation and confusion matrix.

``humanoid validate --model biped3d|g1``: each strategy's critical push per azimuth against the 2-D
prediction (:mod:`pushrecovery.experiments.validation3d`, and for the step
:mod:`pushrecovery.experiments.validation3d.step`: tables and one polar plot), then a 3-D
campaign over azimuths × fractions of the ankle's predicted critical push under the
whole-body controller with all its tasks, read as the confusion matrix of predicted against
used strategy (:mod:`pushrecovery.experiments.confusion3d`). Everything is written under
``--out``; the campaign (``OUT/confusion_<model>``) resumes if interrupted.
"""

from __future__ import annotations

import csv
import itertools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

if TYPE_CHECKING:
    from pushrecovery.params import BodyParams
    from pushrecovery.sim.mujoco.humanoid3d.mjcf import MjcfPlant

__all__ = ["QUICK", "Validate3DOptions", "validate_3d"]


@dataclass(frozen=True)
class Validate3DOptions:
    """What ``humanoid validate`` asks of a 3-D model (the command's options, parsed)."""

    model: str
    azimuths: tuple[float, ...]
    strategies: tuple[str, ...]
    rel_tolerance: float
    duration: float
    fractions: tuple[float, ...]
    confusion_duration: float
    confusion: bool
    out: Path
    workers: int | None


#: ``--quick``: two azimuths, the ankle, a coarse bisection, two push sizes.
QUICK = {
    "azimuths": (0.0, 90.0),
    "strategies": ("ankle",),
    "rel_tolerance": 0.03,
    "fractions": (0.5, 1.5),
}


def fraction_list(text: str | None, default: tuple[float, ...]) -> tuple[float, ...]:
    """Parse ``--fractions A,B,...``: 1 to 50 distinct numbers in (0, 20], increasing."""
    from pushrecovery.errors import InvalidParameterError

    if text is None:
        return default
    try:
        values = tuple(float(part) for part in text.split(","))
    except ValueError:
        raise InvalidParameterError(f"--fractions needs a list A,B,... [-], got {text!r}") from None
    if not (
        1 <= len(values) <= 50
        and all(math.isfinite(v) and 0.0 < v <= 20.0 for v in values)
        and all(a < b for a, b in itertools.pairwise(values))
    ):
        raise InvalidParameterError(
            f"--fractions must be 1 to 50 increasing numbers in (0, 20], got {text!r}"
        )
    return values


def validate_3d(
    options: Validate3DOptions, params: BodyParams, plant: MjcfPlant | None = None
) -> dict[str, Any]:
    """Run the 3-D validation and confusion matrix; write them under ``options.out``; JSON.

    ``plant``: an MJCF file's plant (its tables are named after the file's stem); default the
    built-in ``options.model``'s.
    """
    from pushrecovery.experiments.validation3d import run_validation3d
    from pushrecovery.plots.common import save_figure
    from pushrecovery.plots.validation3d import validation3d_figure

    out = options.out
    out.mkdir(parents=True, exist_ok=True)
    data: dict[str, Any] = {"backend": "mujoco", "model": options.model}
    result = step = None
    name = options.model if plant is None else plant.source.name
    stem = out / f"validation3d_{name}"
    files: dict[str, str] = {}
    balance = tuple(s for s in options.strategies if s != "step")
    if balance:
        result = run_validation3d(
            options.model,
            options.azimuths,
            balance,
            params=params,
            rel_tolerance=options.rel_tolerance,
            duration=options.duration,
            plant=plant,
        )
        stem.with_suffix(".md").write_text(result.to_table() + "\n")
        _write_csv(result, stem.with_suffix(".csv"))
        data["critical"] = [_row(row) for row in result.rows]
        files |= {"table": str(stem.with_suffix(".md")), "csv": str(stem.with_suffix(".csv"))}
    if "step" in options.strategies:
        from pushrecovery.experiments.validation3d.step import run_step_validation

        step = run_step_validation(
            options.azimuths,
            model=options.model,
            params=params,
            rel_tolerance=max(options.rel_tolerance, 0.02),
            duration=options.duration,
            plant=plant,
        )
        step_stem = out / f"validation3d_{name}_step"
        step_stem.with_suffix(".md").write_text(step.to_table() + "\n")
        data["step_critical"] = [_step_row(row, step) for row in step.rows]
        files["step_table"] = str(step_stem.with_suffix(".md"))
    if result is not None or step is not None:
        (figure,) = save_figure(validation3d_figure(result, step), stem, ["png"])
        data["files"] = files | {"polar": str(figure)}
    if options.confusion:
        data["confusion"] = _confusion(options, params, plant)
    return data


def _critical(row: Any) -> dict[str, Any]:
    """Return a row's predicted, corrected and measured critical push [N s], and the errors."""
    return {
        "predicted": row.predicted,
        "corrected": row.corrected,
        "measured": row.measured,
        "bracket": list(row.bracket),
        "relative_error": row.relative_error,
        "corrected_error": row.corrected_error,
    }


def _row(row: Any) -> dict[str, Any]:
    return {
        "azimuth": row.azimuth,
        "strategy": row.strategy,
        **_critical(row),
        "strategy_used": row.strategy_used,
        "foot_slip": _finite(row.foot_slip),
        "peak_force": _finite(row.peak_force),
    }


def _finite(value: float) -> float | None:
    """Return ``value``, or None where it is NaN (JSON has no NaN)."""
    return None if math.isnan(value) else value


def _step_row(row: Any, step: Any) -> dict[str, Any]:
    return {
        "azimuth": row.azimuth,
        **_critical(row),
        "steps": row.steps,
        "swing_time": row.swing_time,
        "step_length": row.step_length,
        "refit": None if math.isnan(row.refit) else row.refit,  # no step landed: JSON null
        "cause": row.cause(step.params),
        "foot_slip": _finite(row.foot_slip),
        "peak_force": _finite(row.peak_force),
    }


def _write_csv(result: Any, path: Path) -> None:
    rows = [_row(row) for row in result.rows]
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=[k for k in rows[0] if k != "bracket"]
                                + ["fell"])  # fmt: skip
        writer.writeheader()
        for row in rows:
            fell = row.pop("bracket")[1]
            writer.writerow({**row, "fell": fell})


def _confusion(
    options: Validate3DOptions, params: BodyParams, plant: MjcfPlant | None = None
) -> dict[str, Any]:
    """Run the confusion campaigns (resumable) and write the matrix; return its JSON.

    ``plant``: an MJCF file's plant, whose source the campaigns' workers build.
    """
    from pushrecovery.campaign import CampaignError, CampaignSpec, run_campaign
    from pushrecovery.cli.humanoid.campaign import write_confusion
    from pushrecovery.cli.progress import Progress

    # One campaign per push size (the sizes need not be evenly spaced: a campaign's range is),
    # each resumable in its own directory.
    source = None if plant is None else plant.source
    directory = options.out / f"confusion_{options.model if source is None else source.name}"
    specs = [
        CampaignSpec(
            backend="mujoco",
            model=options.model if source is None else "mjcf",
            mjcf=source,
            controller="wbc-step",
            params=params,
            x0=(0.0, 0.0, 1.0),
            fraction=(fraction, fraction, 1.0),
            azimuths=options.azimuths,
            duration=options.confusion_duration,
            batch_size=4,
        )
        for fraction in options.fractions
    ]
    tables = []
    bar = Progress(sum(s.size for s in specs), "confusion", "push")
    try:
        for spec in specs:
            fraction = spec.push_range[0]
            result = run_campaign(
                spec, directory / f"f{fraction:g}", workers=options.workers, resume=True,
                progress=bar.update,
            )  # fmt: skip
            assert result is not None
            tables.append(result.table)
    except CampaignError as exc:
        if "differs" not in str(exc):
            raise
        raise CampaignError(
            f"{exc}: validate completes the confusion campaigns it finds in {directory}; "
            "give another --out for another grid"
        ) from None
    finally:
        bar.close()
    import pyarrow as pa

    table = pa.concat_tables(tables)
    matrix, files = write_confusion(table, specs[0].model_name, directory)
    click.echo(f"confusion campaign in {directory}", err=True)
    return {
        "labels": ["ankle", "hip", "step", "fall"],
        "rows": "predicted",
        "columns": "used",
        "counts": matrix.counts.tolist(),
        "counts_corrected": matrix.counts_corrected.tolist(),
        "apart": matrix.apart(),
        "apart_corrected": matrix.apart(corrected=True),
        "judged": matrix.judged,
        # None when no push was judged (every run undecided): JSON has no NaN.
        "accuracy": matrix.accuracy if matrix.judged else None,
        "accuracy_corrected": matrix.accuracy_corrected if matrix.judged else None,
        "causes": matrix.causes(),
        "errors": matrix.errors,
        "files": files,
    }
