"""The ``campaign`` and ``report`` commands (registered on the group in :mod:`.app`)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.campaign3d import OPTIONS_3D
from pushrecovery.cli.options import body_options, echo_confusion, emit, params_from
from pushrecovery.cli.progress import Progress

__all__ = ["campaign", "report"]

_triple: dict[str, Any] = {"nargs": 3, "type": float, "metavar": "START STOP STEP", "default": None}


def _sweeps(pairs: tuple[str, ...]) -> dict[str, tuple[float, float, float]]:
    """``NAME=START:STOP:STEP`` options as {name: (start, stop, step)}."""
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


_workers = click.option(
    "--workers", type=int, default=None, help="Local worker processes (default: all cores)."
)
_scheduler = click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Run the batches on a running dask.distributed scheduler (tcp://host:port).",
)


@click.command(short_help="Sweep pushes over starts, push sizes and parameters, at scale.")
@click.option(
    "--backend",
    type=click.Choice(("analytic", "mujoco")),
    default="analytic",
    show_default=True,
    help="Physics: velocity jumps on the analytic models, real forces on MuJoCo.",
)
@click.option(
    "--model",
    default=None,
    help="Plant (default: stepping on analytic, torso on mujoco; 3-D: biped3d, g1).",
)
@click.option(
    "--controller",
    default=None,
    help="Controller (default: recovery / mpc; 3-D: wbc-ankle, wbc-hip, wbc-step).",
)
@click.option("--azimuth", type=float, default=None, help="3-D models: one push direction [deg].")
@OPTIONS_3D[2]
@OPTIONS_3D[0]
@click.option(
    "--x0", "x0", **_triple, help="CoM positions before the push [m] (3-D: 0, the default)."
)
@click.option("--xdot", **_triple, help="Pushes as CoM velocities [m/s].")
@click.option(
    "--impulse", **_triple, help="Pushes as impulses at the CoM [N s] (3-D: at the torso)."
)
@OPTIONS_3D[1]
@click.option(
    "--param",
    "sweep_pairs",
    multiple=True,
    metavar="NAME=START:STOP:STEP",
    help="Sweep a body parameter (SI units), repeatable: e.g. torque_max=50:150:25.",
)
@click.option(
    "--samples",
    type=int,
    default=None,
    help="Draw this many pushes uniformly from the ranges (with --seed) instead of the grid.",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of --samples.")
@click.option(
    "--duration", type=float, default=6.0, show_default=True, help="Longest time per push [s]."
)
@click.option(
    "--batch-size",
    type=int,
    default=None,
    help="Pushes per task (default about a second of work: 100 / 10 MuJoCo; up to 10,000 / "
    "1,000 for the compiled pendulum, lipm / stepping + recovery pairs).",
)
@click.option(
    "--push-timeout",
    type=float,
    default=120.0,
    show_default=True,
    help="Wall time a push may take [s]; a slower or hung push is an error row.",
)
@click.option(
    "--out", type=click.Path(file_okay=False), required=True, help="Directory of the campaign."
)
@click.option(
    "--workers",
    type=int,
    default=None,
    help="Local worker processes (default: all cores; 1: the pushes run in this process).",
)
@_scheduler
@click.option(
    "--resume",
    is_flag=True,
    help="Complete the campaign in --out, running only the missing batches.",
)
@click.option("--plot/--no-plot", default=True, show_default=True, help="Write the plots.")
@body_options
def campaign(
    backend: str,
    model: str | None,
    controller: str | None,
    azimuth: float | None,
    azimuths: str | None,
    strategy: str | None,
    x0: tuple[float, float, float] | None,
    xdot: tuple[float, float, float] | None,
    impulse: tuple[float, float, float] | None,
    fraction: tuple[float, float, float] | None,
    sweep_pairs: tuple[str, ...],
    samples: int | None,
    seed: int,
    duration: float,
    batch_size: int | None,
    push_timeout: float,
    out: str,
    workers: int | None,
    scheduler: str | None,
    resume: bool,
    plot: bool,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Simulate every push of a sweep and compare each with the surfaces' prediction.

    Each push records its inputs, the predicted strategy and margins, the outcome, the peak
    torques and the CoP excursion (OUT/pushes.parquet, one row per push); OUT/summary.json has
    the counts, the accuracy of the prediction, the confusion matrix (predicted strategy vs the
    one used) and the empirical critical pushes against the analytic ones. Every finished
    batch is kept in OUT/batches: an interrupted campaign continues with --resume. The
    result does not depend on the number of workers.

    The 3-D models (--backend mujoco --model biped3d|g1) push the standing body at its torso
    from each of --azimuths with each push (--impulse, or --fraction of the ankle's predicted
    critical impulse along the azimuth) under the whole-body controller (--strategy); OUT
    also gets the confusion matrix of predicted against used strategy (confusion3d.*).
    """
    from pushrecovery.campaign import CampaignSpec, read_spec, run_campaign
    from pushrecovery.cli.campaign3d import azimuths_from, spec_3d
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.sim.registry import MUJOCO_3D_MODELS

    directions = azimuths_from(azimuth, azimuths)
    three_d = model in MUJOCO_3D_MODELS
    if not three_d and (directions is not None or strategy or fraction):
        raise InvalidParameterError(
            "--azimuth(s), --strategy and --fraction need a 3-D model (--backend mujoco "
            f"--model biped3d or g1), got --model {model}"
        )
    directory = Path(out)
    pushes = (x0, xdot, impulse, fraction, directions)
    if resume and all(value is None for value in pushes):
        if sweep_pairs or samples is not None or model or controller or strategy:
            raise InvalidParameterError(
                "--resume without --x0 runs the stored campaign: give its whole spec or none"
            )
        spec = read_spec(directory)  # the stored campaign, as it was asked for
    elif three_d:
        if xdot is None and impulse is None and fraction is None:
            raise InvalidParameterError("campaign needs one of --impulse, --fraction, --xdot")
        options = {
            "backend": backend, "controller": controller, "strategy": strategy, "x0": x0,
            "xdot": xdot, "impulse": impulse, "fraction": fraction, "directions": directions,
            "sweeps": _sweeps(sweep_pairs), "samples": samples, "seed": seed,
            "duration": duration, "batch_size": batch_size, "push_timeout": push_timeout,
        }  # fmt: skip
        spec = spec_3d(str(model), options, kwargs)
    else:
        params = params_from(kwargs)
        if x0 is None or (xdot is None and impulse is None):
            raise InvalidParameterError("campaign needs --x0 and one of --xdot, --impulse")
        spec = CampaignSpec(
            backend=backend,
            model=model or ("stepping" if backend == "analytic" else "torso"),
            controller=controller or ("recovery" if backend == "analytic" else "mpc"),
            params=params,
            x0=x0,
            xdot=xdot,
            impulse=impulse,
            sweeps=_sweeps(sweep_pairs),
            samples=samples,
            seed=seed,
            duration=duration,
            batch_size=batch_size,
            push_timeout=push_timeout,
        )
    bar = Progress(spec.size, "campaign", "push")
    try:
        result = run_campaign(
            spec,
            directory,
            workers=workers,
            scheduler=scheduler,
            resume=resume,
            progress=bar.update,
            # --workers 1: in this process (no worker to start and import everything again;
            # a push that crashes the engine ends the campaign, its finished batches kept).
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
    files = {"pushes": str(result.pushes_file), "summary": str(directory / "summary.json")}
    confusion3d = None
    if spec.is_3d:
        from pushrecovery.cli.campaign3d import write_confusion

        confusion3d, written = write_confusion(result.table, spec.model, directory, plot)
        files.update(written)
    elif plot:
        from pushrecovery.plots.campaign import plot_critical_vs_parameter, plot_outcome_map

        files["outcome_map"] = str(
            plot_outcome_map(result.table, spec, directory / "outcome_map.png")
        )
        if len(spec.sweeps) == 1 and result.summary["boundary"]:
            files["critical_vs_parameter"] = str(
                plot_critical_vs_parameter(result.summary, directory / "critical_vs_parameter.png")
            )
    summary = {**result.summary, "files": files}
    if as_json:
        emit(summary, True)
        return
    outcomes = summary["outcomes"]
    click.echo(
        f"{summary['pushes']} pushes ({result.ran} of {spec.batches} batches run now): "
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
    if confusion3d is not None:
        from pushrecovery.cli.campaign3d import echo_causes

        echo_causes(confusion3d)
    for name, path in files.items():
        click.echo(f"{name:<22}{path}")


@click.command(short_help="The HTML report of a parameter set (the main job).")
@click.option(
    "--out",
    type=click.Path(file_okay=False),
    default="out/report",
    show_default=True,
    help="Directory of the report (index.html and the campaigns).",
)
@click.option(
    "--full",
    is_flag=True,
    help="Larger campaigns and finer critical pushes (about 3 minutes instead of half of one).",
)
@_workers
@_scheduler
@body_options
def report(
    out: str,
    full: bool,
    workers: int | None,
    scheduler: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Write one self-contained HTML page about a parameter set.

    Parameters, bounds, the strategy map, every paper figure, an analytic and a MuJoCo
    campaign, the MuJoCo critical pushes and a filmstrip per strategy.
    """
    from pushrecovery.report import write_report

    params = params_from(kwargs)
    # Each section's start and end on a terminal only: a piped stderr keeps its one-line errors.
    progress = (lambda line: click.echo(line, err=True)) if sys.stderr.isatty() else None
    path = write_report(
        params, Path(out), full=full, workers=workers, scheduler=scheduler, progress=progress
    )
    emit({"report": str(path)}, as_json)
