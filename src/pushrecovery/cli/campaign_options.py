"""The options and the run shared by ``campaign`` and ``humanoid campaign``.

Both sweep a grid of pushes (:class:`pushrecovery.campaign.CampaignSpec`) in batches on local
workers or a dask scheduler, resume an interrupted campaign and print the same summary; what
differs is the pushes (the planar models' --x0 and --xdot, the humanoids' azimuths and
fractions), which each command declares itself.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import click

from pushrecovery.cli.options import echo_confusion
from pushrecovery.cli.progress import Progress

F = TypeVar("F", bound=Callable[..., Any])

__all__ = [
    "SCHEDULER",
    "echo_counts",
    "echo_files",
    "run_options",
    "run_spec",
    "sweeps_from",
]

#: ``--scheduler ADDRESS`` (``campaign``, ``humanoid campaign``, ``report``).
SCHEDULER = click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Run the batches on a running dask.distributed scheduler (tcp://host:port).",
)


def run_options(*, param_help: str, samples_help: str, batch_size_help: str) -> Callable[[F], F]:
    """Return the options of a campaign's run, after its pushes: --param to --plot.

    Parameters
    ----------
    param_help, samples_help, batch_size_help : str
        The help of ``--param``, ``--samples`` and ``--batch-size``, which name the command's
        models.

    Returns
    -------
    callable
        The click decorator adding ``--param`` (``sweep_pairs``), ``--samples``, ``--seed``,
        ``--duration``, ``--batch-size``, ``--push-timeout``, ``--out``, ``--workers``,
        ``--scheduler``, ``--resume`` and ``--plot/--no-plot``, in this order.
    """
    options = (
        click.option(
            "--param",
            "sweep_pairs",
            multiple=True,
            metavar="NAME=START:STOP:STEP",
            help=param_help,
        ),
        click.option("--samples", type=int, default=None, help=samples_help),
        click.option("--seed", type=int, default=0, show_default=True, help="Seed of --samples."),
        click.option(
            "--duration",
            type=float,
            default=6.0,
            show_default=True,
            help="Longest time per push [s].",
        ),
        click.option("--batch-size", type=int, default=None, help=batch_size_help),
        click.option(
            "--push-timeout",
            type=float,
            default=120.0,
            show_default=True,
            help="Wall time a push may take [s]; a slower or hung push is an error row.",
        ),
        click.option(
            "--out",
            type=click.Path(file_okay=False),
            required=True,
            help="Directory of the campaign.",
        ),
        click.option(
            "--workers",
            type=int,
            default=None,
            help="Local worker processes (default: all cores; 1: the pushes run in this process).",
        ),
        SCHEDULER,
        click.option(
            "--resume",
            is_flag=True,
            help="Complete the campaign in --out, running only the missing batches.",
        ),
        click.option("--plot/--no-plot", default=True, show_default=True, help="Write the plots."),
    )

    def apply(func: F) -> F:
        for option in reversed(options):
            func = option(func)
        return func

    return apply


def sweeps_from(pairs: tuple[str, ...]) -> dict[str, tuple[float, float, float]]:
    """Return the ``--param NAME=START:STOP:STEP`` options as {name: (start, stop, step)}.

    Parameters
    ----------
    pairs : tuple of str
        The ``--param`` values.

    Returns
    -------
    dict
        Parameter name -> (start, stop, step).

    Raises
    ------
    InvalidParameterError
        If one is not ``NAME=START:STOP:STEP`` with numbers, or a name is given twice.
    """
    from pushrecovery.errors import InvalidParameterError

    sweeps = {}
    for pair in pairs:
        name, _, text = pair.partition("=")
        parts = text.split(":")
        try:
            if not name or len(parts) != 3:
                raise ValueError
            values = tuple(float(p) for p in parts)
        except ValueError:
            raise InvalidParameterError(
                f"--param needs NAME=START:STOP:STEP (e.g. torque_max=50:150:25), got {pair!r}"
            ) from None
        if name in sweeps:
            raise InvalidParameterError(f"--param {name} given twice")
        sweeps[name] = values
    return sweeps  # type: ignore[return-value]


def run_spec(
    spec: Any, directory: Path, workers: int | None, scheduler: str | None, resume: bool
) -> Any:
    """Run a campaign with a progress bar; Ctrl-C keeps the finished batches and exits 130.

    Parameters
    ----------
    spec : CampaignSpec
        The campaign.
    directory : Path
        ``--out``.
    workers : int or None
        ``--workers``; 1 runs the pushes in this process (no worker to start and import
        everything again; a push that crashes the engine ends the campaign, its finished
        batches kept).
    scheduler : str or None
        ``--scheduler``.
    resume : bool
        ``--resume``.

    Returns
    -------
    CampaignResult
        The table, the summary and the number of batches run now.
    """
    from pushrecovery.campaign import run_campaign

    bar = Progress(spec.size, "campaign", "push")
    try:
        result = run_campaign(
            spec,
            directory,
            workers=workers,
            scheduler=scheduler,
            resume=resume,
            progress=bar.update,
            isolated=workers != 1,
        )
    except KeyboardInterrupt:
        bar.close()
        click.echo(
            f"pushrecovery: interrupted; the finished batches are in {directory}; "
            "rerun with --resume to complete the campaign",
            err=True,
        )
        sys.exit(130)
    bar.close()
    assert result is not None  # no max_batches
    return result


def echo_counts(summary: dict[str, Any], ran: int, batches: int) -> None:
    """Print a campaign's outcomes, its accuracy and its confusion matrix.

    Parameters
    ----------
    summary : dict
        The campaign's summary (``summary.json``).
    ran, batches : int
        The batches run now, and all of them.
    """
    outcomes = summary["outcomes"]
    click.echo(
        f"{summary['pushes']} pushes ({ran} of {batches} batches run now): "
        f"{outcomes['recovered']} recovered, {outcomes['fell']} fell, "
        f"{outcomes['undecided']} undecided"
        + (f", {outcomes['error']} without an outcome" if outcomes.get("error") else "")
        + "; prediction accuracy "
        + ("n/a" if summary["accuracy"] is None else f"{summary['accuracy']:.3f}")
    )
    confusion = summary["confusion"]
    echo_confusion(
        "confusion (rows predicted, columns used):", confusion["labels"], confusion["counts"]
    )


def echo_files(files: dict[str, str]) -> None:
    """Print the files a campaign wrote, one ``name path`` a line.

    Parameters
    ----------
    files : dict
        Name -> path.
    """
    for name, path in files.items():
        click.echo(f"{name:<22}{path}")
