"""The ``validate`` command: critical pushes and a confusion matrix, simulation vs surfaces."""

from __future__ import annotations

from typing import Any

import click

from pushrecovery.cli.options import (
    body_options,
    echo_confusion,
    emit,
    params_from,
    value_range_option,
)

__all__ = ["validate"]


@click.command(short_help="Critical pushes and a confusion matrix in simulation vs the surfaces.")
@click.option(
    "--backend",
    type=click.Choice(("analytic", "mujoco")),
    default="mujoco",
    show_default=True,
    help="Physics (MuJoCo pushes with real forces).",
)
@click.option(
    "--strategy",
    "strategies",
    type=click.Choice(("ankle", "hip", "step")),
    multiple=True,
    help="Strategies to validate (repeatable; default all the backend has models for).",
)
@click.option(
    "--model",
    "model3d",
    type=click.Choice(("biped3d", "g1")),
    default=None,
    help="3-D models (--backend mujoco): the critical push per azimuth and strategy against "
    "the 2-D prediction, and the confusion matrix over azimuths x push sizes.",
)
@click.option("--azimuth", type=float, default=None, help="3-D models: one push direction [deg].")
@click.option(
    "--azimuths",
    default=None,
    metavar="GRID",
    help="3-D models: push directions, START:STOP:STEP or A,B,... [deg] (default 0:360:30).",
)
@click.option(
    "--fractions",
    default=None,
    metavar="A,B,...",
    help="3-D models: the confusion matrix's pushes, as fractions of the ankle's predicted "
    "critical push along each azimuth (default 0.5,0.9,1.1,1.5,2.0).",
)
@click.option(
    "--rel-tolerance",
    type=float,
    default=0.01,
    show_default=True,
    help="3-D models: each critical-push bracket's width, as a fraction of the prediction.",
)
@click.option(
    "--quick",
    is_flag=True,
    help="3-D models: azimuths 0 and 90, the ankle, a 3 % bracket, push sizes 0.5 and 1.5.",
)
@click.option(
    "--out",
    type=click.Path(file_okay=False),
    default="out/validate3d",
    show_default=True,
    help="3-D models: directory of the tables, plots and the confusion campaign.",
)
@click.option("--workers", type=int, default=None, help="3-D models: campaign workers.")
@click.option(
    "--critical/--no-critical",
    default=True,
    show_default=True,
    help="3-D models: measure the critical pushes (else only the confusion matrix).",
)
@click.option(
    "--x0",
    "x0s",
    type=float,
    multiple=True,
    help="CoM positions before the push [m] (repeatable; default 0 and 0.05).",
)
@click.option(
    "--tolerance",
    type=float,
    default=2e-3,
    show_default=True,
    help="Width of each critical-push bracket [m/s].",
)
@click.option(
    "--duration",
    type=float,
    default=None,
    help="Longest run per push [s] (default 6; 3-D: 3 per critical-push run, 5 per "
    "confusion push).",
)
@click.option(
    "--grid",
    nargs=3,
    type=float,
    default=(-1.0, 2.0, 0.25),
    show_default=True,
    metavar="START STOP STEP",
    help="Push velocities of the confusion matrix [m/s], from each --x0.",
)
@click.option(
    "--confusion/--no-confusion",
    default=True,
    show_default=True,
    help="Also simulate the grid of pushes for the confusion matrix.",
)
@body_options
def validate(
    backend: str,
    strategies: tuple[str, ...],
    model3d: str | None,
    azimuth: float | None,
    azimuths: str | None,
    fractions: str | None,
    rel_tolerance: float,
    quick: bool,
    out: str,
    workers: int | None,
    critical: bool,
    x0s: tuple[float, ...],
    tolerance: float,
    duration: float | None,
    grid: tuple[float, float, float],
    confusion: bool,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Critical push of each strategy in simulation against its surface, and a confusion matrix.

    For each strategy (ankle: foot + ankle-pd; hip: torso + mpc; step: biped + recovery on
    MuJoCo, or the analytic models) the critical push by bisection, both directions, from each
    --x0, next to the surface's prediction (and, on MuJoCo, the prediction corrected for the CoP
    margin and the push's duration). The confusion matrix compares the strategy the surfaces
    predict for each push of the grid with the least strategy that recovers it in simulation.
    """
    import sys

    import numpy as np

    from pushrecovery.arguments import finite_array
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.sim.validation import (
        available_strategies,
        confusion_matrix,
        critical_table,
    )

    if model3d is not None:
        if backend != "mujoco":
            raise InvalidParameterError(
                f"--model {model3d} is a 3-D MuJoCo model: use --backend mujoco"
            )
        _validate_3d(model3d, strategies, critical, azimuth, azimuths, fractions, rel_tolerance,
                     quick, out, workers, duration, confusion, as_json, kwargs)  # fmt: skip
        return
    if (
        azimuth is not None
        or azimuths is not None
        or fractions is not None
        or quick
        or not critical
    ):
        raise InvalidParameterError(
            "--azimuth(s), --fractions, --quick and --no-critical need a 3-D model "
            "(--model biped3d or g1)"
        )
    duration = 6.0 if duration is None else duration
    params = params_from(kwargs)
    strategies = strategies or available_strategies(backend)
    missing = set(strategies) - set(available_strategies(backend))
    if missing:
        raise InvalidParameterError(
            f"--strategy {sorted(missing)[0]} has no {backend} model yet; "
            f"available: {list(available_strategies(backend))}"
        )
    x0s = tuple(finite_array("--x0", x0s)) if x0s else (0.0, 0.05)
    for x0 in x0s:
        if not params.heel < x0 < params.toe:
            raise InvalidParameterError(
                f"--x0 must lie on the foot, {params.heel:g} < x0 < {params.toe:g} m, got {x0:g}"
            )
    velocities = value_range_option("--grid", grid, limit=10_000)
    rows_total = len(strategies) * len(x0s) * 2
    total = rows_total + (len(x0s) * len(velocities) if confusion else 0)
    # On a terminal only: a piped stderr keeps its one-line errors.
    with click.progressbar(
        length=total, label="validating", file=sys.stderr, hidden=not sys.stderr.isatty()
    ) as bar:
        rows = critical_table(
            params,
            backend=backend,
            strategies=strategies,
            x0s=x0s,
            tolerance=tolerance,
            duration=duration,
            progress=bar.update,
        )
        matrix = (
            confusion_matrix(
                params,
                x0s,
                velocities.tolist(),
                backend=backend,
                strategies=strategies,
                duration=duration,
                progress=bar.update,
            )
            if confusion
            else None
        )
    data: dict[str, Any] = {
        "backend": backend,
        "params": params.to_dict(),
        "critical": [row.to_dict(params.mass) for row in rows],
    }
    if matrix is not None:
        data["confusion"] = matrix.to_dict()
    if as_json:
        emit(data, True)
        return
    click.echo(
        f"{'strategy':<9}{'dir':<9}{'x0':>7}{'predicted':>11}{'corrected':>11}"
        f"{'measured':>10}{'error':>9}{'corr.err':>10}"
    )
    for row in rows:
        corrected = "" if np.isnan(row.corrected) else f"{row.corrected:.4f}"
        error = "" if np.isnan(row.corrected) else f"{100 * row.corrected_error:+.1f}%"
        click.echo(
            f"{row.strategy:<9}{row.direction:<9}{row.x0:>7.3f}{row.predicted:>11.4f}"
            f"{corrected:>11}{row.measured:>10.4f}{100 * row.relative_error:>+8.1f}%{error:>10}"
        )
    if matrix is not None:
        from pushrecovery.sim.validation import LABELS

        echo_confusion(
            f"\nconfusion (rows predicted, columns needed), accuracy {matrix.accuracy:.3f}",
            LABELS,
            matrix.counts.tolist(),
        )


def _validate_3d(
    model: str,
    strategies: tuple[str, ...],
    critical: bool,
    azimuth: float | None,
    azimuths: str | None,
    fractions: str | None,
    rel_tolerance: float,
    quick: bool,
    out: str,
    workers: int | None,
    duration: float | None,
    confusion: bool,
    as_json: bool,
    kwargs: dict[str, Any],
) -> None:
    """``validate --model biped3d|g1`` (:mod:`pushrecovery.cli.validate3d`)."""
    from pathlib import Path

    from pushrecovery.cli.campaign3d import azimuths_from
    from pushrecovery.cli.simulation3d import _params_3d
    from pushrecovery.cli.validate3d import QUICK, Validate3DOptions, fraction_list, validate_3d
    from pushrecovery.experiments.confusion3d import DEFAULT_AZIMUTHS, DEFAULT_FRACTIONS

    quick_values: dict[str, Any] = QUICK if quick else {}
    directions = azimuths_from(azimuth, azimuths) or quick_values.get("azimuths", DEFAULT_AZIMUTHS)
    # The G1's hip task recovers nothing (docs/validation.md): its ankle and step by default.
    usual = ("ankle", "step") if model == "g1" else ("ankle", "hip", "step")
    chosen = strategies or quick_values.get("strategies", usual)
    chosen = chosen if critical else ()
    options = Validate3DOptions(
        model=model,
        azimuths=tuple(directions),
        strategies=tuple(chosen),
        rel_tolerance=quick_values.get("rel_tolerance", rel_tolerance),
        duration=3.0 if duration is None else duration,
        fractions=fraction_list(fractions, quick_values.get("fractions", DEFAULT_FRACTIONS)),
        confusion_duration=5.0 if duration is None else duration,
        confusion=confusion,
        out=Path(out),
        workers=workers,
    )
    data = validate_3d(options, _params_3d(model, kwargs))
    if as_json:
        emit(data, True)
        return
    for row in data.get("critical", []):
        click.echo(
            f"{row['strategy']:<7}{row['azimuth']:>6g} deg  predicted {row['predicted']:6.1f}  "
            f"corrected {row['corrected']:6.1f}  measured {row['measured']:6.1f} N s  "
            f"({100 * row['relative_error']:+.1f} %, "
            f"corrected {100 * row['corrected_error']:+.1f} %)"
        )
    if "confusion" in data:
        found = data["confusion"]
        echo_confusion(
            f"confusion (rows predicted, columns used), agreement {found['accuracy']:.3f}",
            found["labels"],
            found["counts"],
        )
        echo_confusion(
            f"against the verdict corrected for the push's height, agreement "
            f"{found['accuracy_corrected']:.3f}",
            found["labels"],
            found["counts_corrected"],
        )
        causes = ", ".join(f"{k} {v}" for k, v in found["causes"].items() if v and k != "agree")
        click.echo(f"where they differ: {causes or 'nowhere'}")
    files = {**data.get("files", {}), **data.get("confusion", {}).get("files", {})}
    for name, path in files.items():
        click.echo(f"{name:<18}{path}")
