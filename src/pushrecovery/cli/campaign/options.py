"""The options and the run shared by ``campaign`` and ``humanoid campaign``.

Both sweep a grid of pushes (:class:`pushrecovery.campaign.CampaignSpec`) in batches on local
workers or a dask scheduler, resume an interrupted campaign and print the same summary; what
differs is the pushes (the planar models' --x0 and --xdot, the humanoids' azimuths and
fractions), which each command declares itself.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, TypeVar

import click

from pushrecovery.cli.options import (
    duration_option,
    echo_confusion,
    emit,
    needs_plots,
    out_option,
)
from pushrecovery.cli.progress import Progress

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["SCHEDULER", "WORKERS", "CampaignRun", "run_options"]

#: ``--workers`` of the campaigns (``campaign``, ``humanoid campaign``, ``report``).
WORKERS = click.option(
    "--workers",
    type=int,
    default=None,
    help="Local worker processes (default: all cores; 1: analytic pushes run in this process, "
    "MuJoCo pushes in one worker process).",
)
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
        duration_option(6.0, "Longest time per push [s]."),
        click.option("--batch-size", type=int, default=None, help=batch_size_help),
        click.option(
            "--push-timeout",
            type=float,
            default=120.0,
            show_default=True,
            help="Wall time a push may take [s]; a slower or hung push is an error row.",
        ),
        out_option(None, "Directory of the campaign."),
        WORKERS,
        SCHEDULER,
        click.option(
            "--resume",
            is_flag=True,
            help="Complete the campaign in --out, running only the missing batches.",
        ),
        click.option(
            "--plot/--no-plot",
            default=True,
            show_default=True,
            callback=needs_plots,
            help="Write the plots.",
        ),
    )

    def apply(func: F) -> F:
        for option in reversed(options):
            func = option(func)
        return func

    return apply


@dataclass(frozen=True)
class CampaignRun:
    """A campaign command's options of :func:`run_options`, as given; the run and its printout."""

    sweep_pairs: tuple[str, ...]
    samples: int | None
    seed: int
    duration: float
    batch_size: int | None
    push_timeout: float
    out: str
    workers: int | None
    scheduler: str | None
    resume: bool
    plot: bool

    @classmethod
    def pop(cls, kwargs: dict[str, Any]) -> CampaignRun:
        """Pop the run's options out of a command's keyword arguments."""
        return cls(**{option.name: kwargs.pop(option.name) for option in fields(cls)})

    def spec_options(self) -> dict[str, Any]:
        """Return the ``CampaignSpec`` keywords of the run: ``sweeps`` to ``push_timeout``.

        Raises
        ------
        InvalidParameterError
            If a ``--param`` is not ``NAME=START:STOP:STEP`` with numbers, or a name is given
            twice.
        """
        return {
            "sweeps": _sweeps(self.sweep_pairs),
            "samples": self.samples,
            "seed": self.seed,
            "duration": self.duration,
            "batch_size": self.batch_size,
            "push_timeout": self.push_timeout,
        }

    def stored(self, pushes: str, asked: bool, three_d: bool) -> Any:
        """Return the campaign stored in ``--out``: ``--resume`` given without pushes.

        Parameters
        ----------
        pushes : str
            The command's push options, for the message (``"--x0"``).
        asked : bool
            Whether another option of the spec was given on the command line (refused).
        three_d : bool
            Whether the command runs the 3-D humanoids (a campaign of the other family is
            refused, naming the command that runs it).

        Returns
        -------
        CampaignSpec
            The stored spec, as it was asked for.
        """
        from pushrecovery.campaign import read_spec
        from pushrecovery.errors import InvalidParameterError

        if self.sweep_pairs or self.samples is not None or asked:
            raise InvalidParameterError(
                f"--resume without {pushes} runs the stored campaign: give its whole spec or none"
            )
        directory = Path(self.out)
        spec = read_spec(directory)
        if spec.is_3d != three_d:
            family, command = (
                ("the 3-D humanoid", "humanoid campaign")
                if spec.is_3d
                else ("the planar model", "campaign")
            )
            raise InvalidParameterError(
                f"{directory} holds a campaign of {family} {spec.model}: use "
                f"'pushrecovery {command} --resume --out {directory}'"
            )
        return spec

    def run(self, spec: Any) -> Any:
        """Run ``spec`` into ``--out`` with a progress bar; Ctrl-C keeps the finished batches.

        ``--workers 1`` runs an analytic campaign's pushes in this process (no worker to start
        and import everything again: pure Python and the project's kernels, whose failures
        are exceptions, each an ``error`` row) and a MuJoCo campaign's in one worker process,
        isolated, as with more workers: a push that crashes the engine or hangs it outside the
        simulation's loop is one ``error`` row. An interrupted campaign exits with status 130.

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
                Path(self.out),
                workers=self.workers,
                scheduler=self.scheduler,
                resume=self.resume,
                progress=bar.update,
                isolated=self.workers != 1 or spec.backend == "mujoco",
            )
        except KeyboardInterrupt:
            bar.close()
            click.echo(
                f"pushrecovery: interrupted; the finished batches are in {Path(self.out)}; "
                "rerun with --resume to complete the campaign",
                err=True,
            )
            sys.exit(130)
        bar.close()
        assert result is not None  # no max_batches
        return result

    def show(
        self, result: Any, files: dict[str, str], as_json: bool, *more: Callable[[], None]
    ) -> None:
        """Print the summary with its files as JSON, or its counts, ``more`` and the files.

        Parameters
        ----------
        result : CampaignResult
            :meth:`run`'s.
        files : dict
            Name -> path of the files the command wrote beside the pushes and the summary.
        as_json : bool
            ``--json``.
        *more : callable
            Printers of further lines, after the confusion matrix.
        """
        summary = result.summary
        files = {
            "pushes": str(result.pushes_file),
            "summary": str(result.directory / "summary.json"),
            **files,
        }
        if as_json:
            emit({**summary, "files": files}, True)
            return
        outcomes = summary["outcomes"]
        click.echo(
            f"{summary['pushes']} pushes ({result.ran} of {result.spec.batches} batches run "
            f"now): {outcomes['recovered']} recovered, {outcomes['fell']} fell, "
            f"{outcomes['undecided']} undecided"
            + (f", {outcomes['slipped']} slipped" if outcomes.get("slipped") else "")
            + (f", {outcomes['error']} without an outcome" if outcomes.get("error") else "")
            + "; prediction accuracy "
            + ("n/a" if summary["accuracy"] is None else f"{summary['accuracy']:.3f}")
        )
        confusion = summary["confusion"]
        echo_confusion(
            "confusion (rows predicted, columns used):",
            confusion["labels"],
            confusion["counts"],
            confusion.get("apart"),
        )
        for echo in more:
            echo()
        for name, path in files.items():
            click.echo(f"{name:<22}{path}")


def _sweeps(pairs: tuple[str, ...]) -> dict[str, tuple[float, float, float]]:
    """Return the ``--param NAME=START:STOP:STEP`` options as {name: (start, stop, step)}."""
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
