"""The 3-D models of ``campaign`` (biped3d, g1): their spec, options and figure.

``campaign --backend mujoco --model biped3d|g1 --azimuths 0:360:30 --fraction 0.5 2 0.5
--strategy step``: the grid of azimuths × pushes under the whole-body controller
(:mod:`pushrecovery.campaign.spec3d`, :mod:`pushrecovery.campaign.pushes3d`); apart from
:mod:`pushrecovery.cli.campaign` so that each module holds one concept.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

__all__ = [
    "AZIMUTHS_HELP",
    "OPTIONS_3D",
    "azimuths_from",
    "echo_causes",
    "spec_3d",
    "write_confusion",
]

AZIMUTHS_HELP = (
    "3-D models: push directions [deg], START:STOP:STEP (a full turn's STOP, 360, is left "
    "out) or a list A,B,...; 0 forward, 90 left."
)

_strategy = click.option(
    "--strategy",
    type=click.Choice(("ankle", "hip", "step")),
    default=None,
    help="3-D models: the whole-body controller's tasks: ankles only, + the hip task, + the hip "
    "and stepping tasks (default step).",
)
_fraction = click.option(
    "--fraction",
    nargs=3,
    type=float,
    default=None,
    metavar="START STOP STEP",
    help="3-D models: pushes as fractions of the ankle's predicted critical impulse along each "
    "azimuth [-].",
)
_azimuths = click.option("--azimuths", default=None, metavar="GRID", help=AZIMUTHS_HELP)
#: The options ``campaign`` adds for the 3-D models.
OPTIONS_3D = (_strategy, _fraction, _azimuths)


def azimuths_from(azimuth: float | None, azimuths: str | None) -> tuple[float, ...] | None:
    """Return the directions of ``--azimuth DEG`` or ``--azimuths GRID`` (not both), or None."""
    from pushrecovery.campaign.spec3d import azimuth_grid, check_azimuths
    from pushrecovery.errors import InvalidParameterError

    if azimuth is not None and azimuths is not None:
        raise InvalidParameterError("give --azimuth DEG or --azimuths GRID, not both")
    if azimuths is not None:
        return azimuth_grid(azimuths)
    return None if azimuth is None else check_azimuths([azimuth], "--azimuth")


def spec_3d(
    model: str,
    options: dict[str, Any],
    body: dict[str, Any],
) -> Any:
    """Return the CampaignSpec of a 3-D campaign from the command's ``options``.

    ``options`` holds backend, controller, strategy, x0, xdot, impulse, fraction, directions
    (:func:`azimuths_from`), sweeps, samples, seed, duration, batch_size, push_timeout;
    ``body`` the body flags (``cli.simulation3d._params_3d``: the g1's own).
    """
    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.cli.simulation3d import _params_3d
    from pushrecovery.errors import InvalidParameterError

    if options["backend"] != "mujoco":
        raise InvalidParameterError(f"--model {model} is a 3-D MuJoCo model: use --backend mujoco")
    if options["controller"] is not None and options["strategy"] is not None:
        raise InvalidParameterError("give --strategy or --controller wbc-..., not both")
    return CampaignSpec(
        backend="mujoco",
        model=model,
        controller=options["controller"] or f"wbc-{options['strategy'] or 'step'}",
        params=_params_3d(model, body),
        x0=options["x0"] or (0.0, 0.0, 1.0),
        xdot=options["xdot"],
        impulse=options["impulse"],
        fraction=options["fraction"],
        azimuths=options["directions"],
        sweeps=options["sweeps"],
        samples=options["samples"],
        seed=options["seed"],
        duration=options["duration"],
        batch_size=options["batch_size"],
        push_timeout=options["push_timeout"],
    )


def write_confusion(
    table: Any, model: str, directory: Path, plot: bool = True
) -> tuple[Any, dict[str, str]]:
    """Write a 3-D campaign's confusion matrix (Parquet, CSV, figure); return it and the paths."""
    from pushrecovery.experiments.confusion3d import confusion_from_rows

    result = confusion_from_rows(table.to_pylist(), model)
    parquet, csv = result.write(directory / "confusion3d")
    files = {"confusion3d": str(parquet), "confusion3d_csv": str(csv)}
    if plot:
        from pushrecovery.plots.common import save_figure
        from pushrecovery.plots.confusion3d import confusion3d_figure

        (figure,) = save_figure(confusion3d_figure(result), directory / "confusion3d", ["png"])
        files["confusion3d_png"] = str(figure)
    return result, files


def echo_causes(result: Any) -> None:
    """Print the agreement of a confusion matrix and its pushes per cause."""
    from pushrecovery.cli.options import echo_confusion
    from pushrecovery.experiments.confusion3d import LABELS

    echo_confusion(
        f"corrected for the push's height (rows), agreement {result.accuracy_corrected:.3f}:",
        LABELS,
        result.counts_corrected.tolist(),
    )
    causes = {k: v for k, v in result.causes().items() if v and k != "agree"}
    click.echo(
        "where they differ: " + (", ".join(f"{k} {v}" for k, v in causes.items()) or "nowhere")
    )
