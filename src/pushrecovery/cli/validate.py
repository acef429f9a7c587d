"""The ``validate`` command: critical pushes and a confusion matrix, simulation vs surfaces."""

from __future__ import annotations

from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.families import humanoid_only
from pushrecovery.cli.options import (
    body_options,
    duration_option,
    echo_confusion,
    emit,
    params_from,
    value_range_option,
)

__all__ = ["validate"]


@click.command(
    short_help="Critical pushes and a confusion matrix in simulation vs the surfaces.",
    epilog=example(
        "pushrecovery validate --backend analytic --strategy ankle --strategy hip",
        "pushrecovery validate --strategy ankle --x0 0 --no-confusion --json",
    ),
)
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
    default=None,
    hidden=True,
    expose_value=False,
    callback=lambda ctx, param, value: _refuse_model(value),
)
@humanoid_only(
    "validate",
    "--azimuth",
    "--azimuths",
    "--fractions",
    "--rel-tolerance",
    "--quick",
    "--out",
    "--workers",
    "--critical",
    "--no-critical",
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
@duration_option(6.0, "Longest run per push [s].")
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
    x0s: tuple[float, ...],
    tolerance: float,
    duration: float,
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
    Prints one row per strategy, direction and --x0 [m, from the ankle]: the predicted, the
    corrected and the measured critical push as CoM velocities [m/s] (backward negative) and
    the relative errors, then the confusion matrix (rows predicted, columns needed) and its
    accuracy. The 3-D humanoids are 'pushrecovery humanoid validate'.
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
    audited = any(not np.isnan(row.foot_slip) for row in rows)  # MuJoCo's physical checks
    click.echo(
        f"{'strategy':<9}{'dir':<9}{'x0':>7}{'predicted':>11}{'corrected':>11}"
        f"{'measured':>10}{'error':>9}{'corr.err':>10}"
        + (f"{'slip[mm]':>10}{'peak[mg]':>10}" if audited else "")
    )
    for row in rows:
        corrected = "" if np.isnan(row.corrected) else f"{row.corrected:.4f}"
        error = "" if np.isnan(row.corrected) else f"{100 * row.corrected_error:+.1f}%"
        checks = f"{1e3 * row.foot_slip:>10.1f}{row.peak_force:>10.2f}" if audited else ""
        click.echo(
            f"{row.strategy:<9}{row.direction:<9}{row.x0:>7.3f}{row.predicted:>11.4f}"
            f"{corrected:>11}{row.measured:>10.4f}{100 * row.relative_error:>+8.1f}%{error:>10}"
            + checks
        )
    if matrix is not None:
        from pushrecovery.sim.validation import LABELS

        echo_confusion(
            f"\nconfusion (rows predicted, columns needed), accuracy {matrix.accuracy:.3f}",
            LABELS,
            matrix.counts.tolist(),
        )


def _refuse_model(model: str | None) -> None:
    """Refuse ``--model``: a 3-D humanoid names its command; --strategy picks the planar models."""
    if model is None:
        return
    from pushrecovery.cli.families import refuse_humanoid_model
    from pushrecovery.errors import InvalidParameterError

    refuse_humanoid_model(model, "validate")
    raise InvalidParameterError(
        f"validate takes no --model (got {model!r}): --strategy picks the planar models; the "
        "3-D humanoids are 'pushrecovery humanoid validate --model biped3d|g1'"
    )
