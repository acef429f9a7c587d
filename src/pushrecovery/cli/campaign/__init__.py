"""The ``campaign`` and ``report`` commands (registered on :mod:`pushrecovery.cli.app`'s group).

``campaign`` runs the planar models (analytic and sagittal MuJoCo); the 3-D humanoids' is
``pushrecovery humanoid campaign`` (:mod:`pushrecovery.cli.humanoid`), and a 3-D model or
option given here is refused in one line naming it (:mod:`pushrecovery.cli.families`).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.campaign.options import SCHEDULER, WORKERS, CampaignRun, run_options
from pushrecovery.cli.families import HUMANOID_MODELS, ModelChoice, humanoid_only
from pushrecovery.cli.options import (
    body_options,
    emit,
    mjcf_options,
    out_option,
    params_from,
    range_option,
)
from pushrecovery.sim.registry import MODELS, MUJOCO_MODELS

__all__ = ["campaign", "report"]


def _pair(flag: str, text: str | None) -> tuple[float, float] | None:
    """``A,B`` as two floats, or refuse naming the flag."""
    if text is None:
        return None
    from pushrecovery.errors import InvalidParameterError

    try:
        first, second = (float(part) for part in text.split(","))
    except ValueError:
        raise InvalidParameterError(f"{flag} must be two numbers A,B, got {text!r}") from None
    return first, second


def _refuse_wbc(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """Refuse the whole-body controller (``wbc-*``), naming ``humanoid campaign --strategy``."""
    if value is not None and value.startswith("wbc-"):
        from pushrecovery.errors import InvalidParameterError

        raise InvalidParameterError(
            f"--controller {value} is the 3-D humanoids' whole-body controller: use "
            f"'pushrecovery humanoid campaign --strategy {value.removeprefix('wbc-')}'"
        )
    return value


@click.command(
    short_help="Sweep pushes over starts, push sizes and parameters, at scale.",
    epilog=example(
        "pushrecovery campaign --x0 0 0.05 0.05 --xdot -1 2 0.25 --workers 1 --out out/campaign",
        "pushrecovery campaign --model flywheel --controller mpc --x0 0 0 1 --xdot 0 1 0.1 "
        "--param torque_max=50:150:50 --workers 1 --out out/sweep",
    ),
)
@click.option(
    "--backend",
    type=click.Choice(("analytic", "mujoco")),
    default="analytic",
    show_default=True,
    help="Physics: velocity jumps on the analytic models, real forces on MuJoCo.",
)
@click.option(
    "--model",
    type=ModelChoice(
        (*MODELS, *MUJOCO_MODELS),
        elsewhere={m: f"humanoid campaign --model {m}" for m in HUMANOID_MODELS},
        family="a 3-D humanoid",
    ),
    default=None,
    help="Plant (default: stepping on analytic, torso on mujoco; foot, torso and biped are "
    "MuJoCo's). The 3-D humanoids: pushrecovery humanoid campaign.",
)
@click.option(
    "--controller",
    default=None,
    callback=_refuse_wbc,
    help="Controller (default: recovery on analytic, mpc on mujoco).",
)
@humanoid_only(
    "campaign", "--azimuth", "--azimuths", "--strategy", "--fraction", nargs={"--fraction": 3}
)
@range_option("--x0", "x0", help_text="CoM positions before the push [m].")
@range_option("--xdot", help_text="Pushes as CoM velocities, forward positive [m/s].")
@range_option("--impulse", help_text="Pushes as impulses at the CoM, forward positive [N s].")
@run_options(
    param_help="Sweep a body parameter (SI units), repeatable: e.g. torque_max=50:150:25.",
    samples_help="Draw this many pushes uniformly from the ranges (with --seed) instead of the "
    "grid.",
    batch_size_help="Pushes per task (default about a second of work: 100 / 10 MuJoCo; up to "
    "10,000 / 1,000 for the compiled pendulum, lipm / stepping + recovery pairs).",
)
@click.option(
    "--state-sd",
    default=None,
    metavar="SX,SXDOT",
    help="Standard deviations of a state estimate's errors in x [m] and xdot [m/s]: each push "
    "gets a seeded estimate and p_recovers, P(its controller's strategy suffices); the "
    "summary scores them (calibration). docs/uncertainty.md.",
)
@click.option(
    "--latency",
    type=float,
    default=0.0,
    show_default=True,
    help="The controller reacts this late [s], in [0, 1], the CoP held at the foot's middle "
    "until then; the probabilities (--state-sd) take the same latency.",
)
@body_options
def campaign(
    backend: str,
    model: str | None,
    controller: str | None,
    x0: tuple[float, float, float] | None,
    xdot: tuple[float, float, float] | None,
    impulse: tuple[float, float, float] | None,
    state_sd: str | None,
    latency: float,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Simulate every push of a sweep and compare each with the surfaces' prediction.

    The grid is every --x0 [m, from the ankle] with every push (--xdot or --impulse, each
    START STOP STEP with STOP included) and every --param value, or --samples pushes drawn
    from those ranges. Prints the counts of outcomes, the accuracy and the confusion matrix,
    and the files written. Each push records its inputs, the predicted strategy and margins,
    the outcome, the peak torques and the CoP excursion (OUT/pushes.parquet, one row per
    push); OUT/summary.json has the counts, the accuracy of the prediction, the confusion
    matrix (predicted strategy vs the one used) and the empirical critical pushes against the
    analytic ones. Every finished batch is kept in OUT/batches: an interrupted campaign
    continues with --resume. The result does not depend on the number of workers. The 3-D
    humanoids are 'pushrecovery humanoid campaign'.
    """
    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.errors import InvalidParameterError

    run = CampaignRun.pop(kwargs)
    if run.resume and x0 is None and xdot is None and impulse is None:
        spec = run.stored("--x0", bool(model or controller), three_d=False)
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
            state_sd=_pair("--state-sd", state_sd),
            latency=latency,
            **run.spec_options(),
        )
    result = run.run(spec)
    files: dict[str, str] = {}
    if run.plot:
        from pushrecovery.plots.campaign import plot_critical_vs_parameter, plot_outcome_map

        directory = result.directory
        files["outcome_map"] = str(
            plot_outcome_map(result.table, spec, directory / "outcome_map.png")
        )
        if len(spec.sweeps) == 1 and result.summary["boundary"]:
            files["critical_vs_parameter"] = str(
                plot_critical_vs_parameter(result.summary, directory / "critical_vs_parameter.png")
            )
    run.show(result, files, as_json)


@click.command(
    short_help="The HTML report of a parameter set (the main job).",
    epilog=example("pushrecovery report --out out/report"),
)
@out_option("out/report", "Directory of the report (index.html and the campaigns).")
@click.option(
    "--full",
    is_flag=True,
    help="Larger campaigns (up to ten times the pushes) and finer critical pushes.",
)
@WORKERS
@SCHEDULER
@click.option(
    "--model",
    "robot",
    default=None,
    metavar="PATH.xml",
    help="Your own humanoid's MJCF file: the report's body is derived from it and its 3-D "
    "section validates and films it (name its feet and torso; docs/your_robot.md).",
)
@mjcf_options
@body_options
def report(
    out: str,
    full: bool,
    workers: int | None,
    scheduler: str | None,
    as_json: bool,
    robot: str | None,
    **kwargs: Any,
) -> None:
    """Write one self-contained HTML page about a parameter set.

    The body of the flags: its parameters, bounds and thresholds, the strategy map, the
    ground plane, capture regions, every paper figure, campaigns on the analytic models and in
    MuJoCo with their accuracy and confusion matrices, the MuJoCo critical pushes, a filmstrip
    per strategy and the 3-D humanoid; SI units throughout. Prints the page's path
    (OUT/index.html); the campaigns are kept in OUT and reused by a rerun with the same body
    and grids. With --model PATH.xml the body is your robot's, derived from its MJCF file
    (body flags refused), and the 3-D section validates and films it beside the G1.
    """
    from pushrecovery.cli.humanoid.bodies import mjcf_body, params_3d
    from pushrecovery.report import write_report

    source = None
    if robot is None:
        params = params_3d("biped3d", kwargs)  # refuses the MJCF options without --model
    else:
        params, source = mjcf_body(robot, kwargs)
    # Each section's start and end on a terminal only: a piped stderr keeps its one-line errors.
    progress = (lambda line: click.echo(line, err=True)) if sys.stderr.isatty() else None
    path = write_report(
        params, Path(out), full=full, workers=workers, scheduler=scheduler, progress=progress,
        robot=source,
    )  # fmt: skip
    emit({"report": str(path)}, as_json)
