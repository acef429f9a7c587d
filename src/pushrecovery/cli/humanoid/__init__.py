"""The ``pushrecovery humanoid`` commands: the 3-D humanoids under the whole-body controller.

``humanoid simulate``, ``humanoid critical-push``, ``humanoid validate`` and ``humanoid
campaign`` run biped3d and g1 (MuJoCo, pushes at the torso from any azimuth;
docs/humanoid3d_pushes.md, "The commands") and list only the options that work for them
(issue 31); the planar commands of the same names refuse the humanoids in one line naming
these. The runs are in this package's modules: :mod:`~pushrecovery.cli.humanoid.simulate`,
:mod:`~pushrecovery.cli.humanoid.validate` and :mod:`~pushrecovery.cli.humanoid.campaign`,
and the bodies they run in :mod:`~pushrecovery.cli.humanoid.bodies`.

Over 400 lines on purpose: the four commands of one group, each mostly its options and
their help, which a reader compares side by side.
"""

from __future__ import annotations

from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.campaign.options import CampaignRun, run_options
from pushrecovery.cli.families import HUMANOID_MODELS, ModelChoice, planar_only
from pushrecovery.cli.options import (
    body_options_of,
    duration_option,
    echo_confusion,
    emit,
    mjcf_options,
    out_option,
    range_option,
)
from pushrecovery.sim.registry import MODELS, MUJOCO_MODELS

__all__ = ["humanoid"]

#: The planar models, refused by the humanoid commands with the planar command's name.
_PLANAR = (*MODELS, *MUJOCO_MODELS)
#: The planar commands' options that no humanoid command has, refused in one line.
_PLANAR_OPTIONS = ("--backend", "--controller", "--kp", "--kd", "--option", "--control-period")


def _model(command: str, files: bool = False) -> Any:
    """``--model biped3d|g1`` (``files``: or an MJCF file); a planar model is refused."""
    if command == "validate":  # the planar validate picks its models by --strategy
        elsewhere = dict.fromkeys(_PLANAR, "validate --strategy ankle|hip|step")
    else:
        elsewhere = {model: f"{command} --model {model}" for model in _PLANAR}
    mjcf = (
        ", or your own robot's MJCF file PATH.xml (its own body; name its feet and torso with "
        "--left-foot-body, --right-foot-body, --torso-body; docs/your_robot.md)"
        if files
        else ""
    )
    return click.option(
        "--model",
        type=ModelChoice(
            HUMANOID_MODELS, elsewhere=elsewhere, family="a planar model", files=files
        ),
        default="biped3d",
        show_default=True,
        help="The humanoid: biped3d (built from the body flags) or g1 (the Unitree G1, its own "
        f"body; the robots extra){mjcf}.",
    )


#: The push's direction of a single run (simulate, critical-push).
_azimuth = click.option(
    "--azimuth",
    type=float,
    default=0.0,
    show_default=True,
    help="The push's direction [deg], 0 forward (+x), 90 left (+y).",
)


#: The body flags of the humanoid commands: they build biped3d; g1 refuses them.
_body_options = body_options_of("biped3d")


@click.group(
    short_help="The 3-D humanoids (biped3d, g1) under the whole-body controller.",
    no_args_is_help=True,
    epilog=example("pushrecovery humanoid simulate --push 20 --duration 3"),
)
def humanoid() -> None:
    """Run the 3-D humanoids (biped3d, g1) under the whole-body controller.

    MuJoCo runs a pushed humanoid standing on both feet: the push is an impulse at the torso
    from any --azimuth (0 forward, 90 left) and the whole-body controller balances it with the
    ankles, the hips and, if allowed, a step. Azimuths are in degrees, impulses in N s, the
    rest SI. The body flags (--preset, --params, --mass, ...) build biped3d; g1, the Unitree G1
    (the robots extra), has its own body and refuses them. The planar models (lipm, pendulum,
    flywheel, stepping, foot, torso, biped) are the commands of the same names outside this
    group. The commands are described in docs/humanoid3d_pushes.md.
    """


@humanoid.command(
    short_help="Push a 3-D humanoid; report recovered or fell.",
    epilog=example("pushrecovery humanoid simulate --azimuth 90 --push 50 --stepping --duration 5"),
)
@_model("simulate", files=True)
@mjcf_options
@planar_only("simulate", *_PLANAR_OPTIONS, "--x", "--xdot", "--y", "--ydot", "--plot")
@_azimuth
@click.option(
    "--impulse",
    "--push",
    "impulse",
    type=float,
    default=0.0,
    show_default=True,
    help="The push: an impulse at the torso [N s], over 10 ms.",
)
@duration_option(10.0, "Longest simulated time [s].")
@click.option(
    "--stepping/--no-stepping",
    default=True,
    show_default=True,
    help="The whole-body controller may step when its ankles and hip cannot hold the push "
    "(docs/humanoid3d_stepping.md); --no-stepping measures the ankle or hip alone.",
)
@click.option(
    "--slip-limit",
    type=float,
    default=0.01,
    show_default=True,
    help="Largest slip of a loaded foot [m] of a run that counts as recovered; more is "
    "'slipped' (docs/physical_checks.md).",
)
@click.option(
    "--render",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write a filmstrip PNG of the run to this file and an animated GIF beside it (CoM, "
    "capture point, CoP and support polygon drawn, from a tracking camera).",
)
@click.option(
    "--view-azimuth",
    type=float,
    default=None,
    help="--render: where the camera stands [deg], 0 in front of the body, 90 on its left; "
    "default the push's azimuth - 90 (the push goes left to right).",
)
@click.option(
    "--view-elevation",
    type=float,
    default=None,
    help="--render: the camera's elevation above the horizon [deg], in [-30, 89]; default 25.",
)
@click.option(
    "--frame-times",
    default=None,
    metavar="T1,T2,...",
    help="--render: the filmstrip's frame times [s] after the start, increasing (default 6 "
    "evenly spaced).",
)
@_body_options
def simulate(
    model: str,
    azimuth: float,
    impulse: float,
    duration: float,
    stepping: bool,
    slip_limit: float,
    render: str | None,
    view_azimuth: float | None,
    view_elevation: float | None,
    frame_times: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Push a 3-D humanoid at the torso and run the whole-body controller; recovered or fell.

    The body starts standing still on both feet; the push is --impulse [N s] at the torso
    along --azimuth, and the run goes on for --duration (it stops early once the body falls or
    has stood still). Prints the outcome (recovered; slipped: at rest, but a loaded foot slid
    more than --slip-limit; fell; or undecided: not at rest yet), the strategy used (ankle,
    hip or step) and the steps, the ground plane's predicted strategy for the push, the peak
    torques [N m], the torso's largest tilt [rad] and the physical checks (foot slip, peak
    ground force, penetration, friction and torque use, joint limits). The body flags
    (--preset, --params, --mass, ...) build biped3d; g1 has the robot's own body and refuses
    them.
    """
    from pushrecovery.cli.humanoid.bodies import body_3d
    from pushrecovery.cli.humanoid.simulate import check_views, render_options, simulate_3d

    if not render:
        check_views(view_azimuth, view_elevation, frame_times)
    pictures = render_options(azimuth, view_azimuth, view_elevation, frame_times)
    body, plant = body_3d(model, kwargs)
    if render:
        from pushrecovery.sim.mujoco.render import require_offscreen_gl

        require_offscreen_gl()  # fail before the run, not after it
    run = simulate_3d(
        model, body, impulse, azimuth, duration, render, pictures, stepping, slip_limit, plant
    )
    emit(run, as_json)


@humanoid.command(
    "critical-push",
    short_help="Largest recoverable push at an azimuth.",
    epilog=example(
        "pushrecovery humanoid critical-push --azimuth 90 --duration 1 --tolerance 0.05"
    ),
)
@_model("critical-push", files=True)
@mjcf_options
@planar_only("critical-push", *_PLANAR_OPTIONS, "--x", "--direction")
@_azimuth
@click.option(
    "--tolerance",
    type=float,
    default=1e-4,
    show_default=True,
    help="Width of the final bracket, as a velocity [m/s] (times the mass: an impulse).",
)
@duration_option(
    10.0,
    "Longest simulated time per push [s]; keep it short (every push of the bisection runs the "
    "whole-body controller this long at most).",
)
@click.option(
    "--strategy",
    type=click.Choice(["ankle", "hip", "step"]),
    default=None,
    help="The controller measured: ankle (no hip task), hip (with it), step (stepping, "
    "reacting during the push); default the model's own without stepping (biped3d: hip, "
    "g1: ankle).",
)
@_body_options
def critical_push(
    model: str,
    azimuth: float,
    tolerance: float,
    duration: float,
    strategy: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Largest push at the torso along --azimuth that the whole-body controller recovers.

    The impulse is bisected between a run that stands and one that falls within --duration
    (keep it short: every push of the bisection is a run of the whole-body controller), to
    --tolerance times the mass. Prints the critical impulse [N s] and velocity [m/s], their
    bracket, the number of simulations, the strategy used just below it and that run's foot
    slip [m]; then the ground plane's predicted critical impulse of each strategy [N s] (ankle,
    hip, one step), plain and corrected for the push's height, and the measured push's error
    against the prediction of the strategy measured. The body flags (--preset, --params,
    --mass, ...) build biped3d; g1 has the robot's own body and refuses them.
    """
    from pushrecovery.cli.humanoid.bodies import body_3d
    from pushrecovery.cli.humanoid.simulate import critical_3d

    params, plant = body_3d(model, kwargs)
    emit(critical_3d(model, params, azimuth, tolerance, duration, strategy, plant), as_json)


@humanoid.command(
    short_help="Critical pushes per azimuth and a confusion matrix, vs 2-D.",
    epilog=example(
        "pushrecovery humanoid validate --azimuth 0 --strategy ankle --rel-tolerance 0.1 "
        "--duration 1 --no-confusion --out out/validate3d"
    ),
)
@_model("validate", files=True)
@mjcf_options
@planar_only("validate", "--backend", "--x0", "--tolerance", "--grid")
@click.option(
    "--strategy",
    "strategies",
    type=click.Choice(("ankle", "hip", "step")),
    multiple=True,
    help="Strategies whose critical push to measure (repeatable; default ankle, hip and step, "
    "on g1 ankle and step).",
)
@click.option("--azimuth", type=float, default=None, help="One push direction [deg].")
@click.option(
    "--azimuths",
    default=None,
    metavar="GRID",
    help="Push directions, START:STOP:STEP or A,B,... [deg] (default 0:360:30).",
)
@click.option(
    "--rel-tolerance",
    type=float,
    default=0.01,
    show_default=True,
    help="Each critical-push bracket's width, as a fraction of the prediction.",
)
@click.option(
    "--fractions",
    default=None,
    metavar="A,B,...",
    help="The confusion matrix's pushes, as fractions of the ankle's predicted critical push "
    "along each azimuth (default 0.5,0.9,1.1,1.5,2.0).",
)
@duration_option(
    None, "Longest run per push [s] (default 3 per critical-push run, 5 per confusion push)."
)
@click.option(
    "--quick",
    is_flag=True,
    help="Azimuths 0 and 90, the ankle, a 3 % bracket, push sizes 0.5 and 1.5.",
)
@click.option(
    "--critical/--no-critical",
    default=True,
    show_default=True,
    help="Measure the critical pushes (else only the confusion matrix).",
)
@click.option(
    "--confusion/--no-confusion",
    default=True,
    show_default=True,
    help="Also run the confusion campaign over azimuths x push sizes.",
)
@out_option(
    "out/validate3d", "Directory of the tables, plots and the confusion campaign (which resumes)."
)
@click.option("--workers", type=int, default=None, help="The confusion campaign's workers.")
@_body_options
def validate(
    model: str,
    strategies: tuple[str, ...],
    azimuth: float | None,
    azimuths: str | None,
    rel_tolerance: float,
    fractions: str | None,
    duration: float | None,
    quick: bool,
    critical: bool,
    confusion: bool,
    out: str,
    workers: int | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Measure critical pushes per azimuth against the 2-D prediction, and a confusion matrix.

    For each --strategy and azimuth the critical push at the torso is bisected and set beside
    the ground plane's prediction (and the prediction corrected for the push's height); then a
    campaign over azimuths x --fractions of the ankle's predicted critical push, under the
    whole-body controller with all its tasks, gives the confusion matrix of the predicted
    against the used strategy. Prints per strategy and azimuth the predicted, corrected and
    measured critical impulse [N s] with the errors, then the confusion matrices and the
    files: tables, CSV, the polar plot and the campaign, under --out (the campaign resumes if
    interrupted); --quick is a shorter first look. The body flags (--preset, --params, --mass,
    ...) build biped3d; g1 and an MJCF file (--model PATH.xml, its feet and torso named) have
    the robot's own body and refuse them.
    """
    from pathlib import Path

    from pushrecovery.cli.azimuths import azimuths_from
    from pushrecovery.cli.humanoid.bodies import body_3d, is_mjcf
    from pushrecovery.cli.humanoid.validate import (
        QUICK,
        Validate3DOptions,
        fraction_list,
        validate_3d,
    )
    from pushrecovery.experiments.confusion3d import DEFAULT_AZIMUTHS, DEFAULT_FRACTIONS

    quick_values: dict[str, Any] = QUICK if quick else {}
    directions = azimuths_from(azimuth, azimuths) or quick_values.get("azimuths", DEFAULT_AZIMUTHS)
    # The G1's hip task recovers nothing (docs/validation3d.md, "G1: no hip strategy"): its
    # ankle and step by default.
    usual = ("ankle", "step") if model == "g1" or is_mjcf(model) else ("ankle", "hip", "step")
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
    params, plant = body_3d(model, kwargs)
    data = validate_3d(options, params, plant)
    if as_json:
        emit(data, True)
        return
    _echo_validation(data)


@humanoid.command(
    short_help="Sweep pushes over azimuths, push sizes and parameters, at scale.",
    epilog=example(
        "pushrecovery humanoid campaign --azimuth 90 --fraction 0.5 1.5 1.0 --duration 2 "
        "--workers 1 --out out/c3d"
    ),
)
@_model("campaign", files=True)
@mjcf_options
@planar_only(
    "campaign", "--backend", "--controller", "--x0", "--xdot", nargs={"--x0": 3, "--xdot": 3}
)
@click.option(
    "--azimuth", type=float, default=None, help="One push direction [deg], 0 forward, 90 left."
)
@click.option(
    "--azimuths",
    default=None,
    metavar="GRID",
    help="Push directions [deg], START:STOP:STEP (a full turn's STOP, 360, is left out) or a "
    "list A,B,...; 0 forward, 90 left (default 0).",
)
@range_option("--impulse", help_text="Pushes as impulses at the torso [N s], along each azimuth.")
@range_option(
    "--fraction",
    help_text="Pushes as fractions of the ankle's predicted critical impulse along each "
    "azimuth [-].",
)
@click.option(
    "--strategy",
    type=click.Choice(("ankle", "hip", "step")),
    default=None,
    help="The whole-body controller's tasks: ankles only, + the hip task, + the hip and "
    "stepping tasks (default step).",
)
@run_options(
    param_help="Sweep a body parameter of biped3d (SI units), repeatable: e.g. mass=60:80:10.",
    samples_help="Draw this many pushes uniformly from the ranges (with --seed) instead of the "
    "grid; the azimuth between the smallest and the largest given.",
    batch_size_help="Pushes per task (default about a second of work).",
)
@_body_options
def campaign(
    model: str,
    azimuth: float | None,
    azimuths: str | None,
    impulse: tuple[float, float, float] | None,
    fraction: tuple[float, float, float] | None,
    strategy: str | None,
    as_json: bool,
    **kwargs: Any,
) -> None:
    """Push a 3-D humanoid from every azimuth with every push; compare with the prediction.

    The standing body is pushed at its torso from each of --azimuths with each push (--impulse,
    or --fraction of the ankle's predicted critical impulse along the azimuth) under the
    whole-body controller (--strategy), and each run is set beside the ground plane's
    predicted strategy: OUT/pushes.parquet has one row per push, OUT/summary.json the counts,
    the accuracy and the critical pushes per azimuth, OUT/confusion3d.* the confusion matrix of
    predicted against used strategy. Prints the counts of outcomes, the accuracy, the
    confusion matrix, where prediction and run differ, and the files. Finished batches are
    kept: an interrupted campaign continues with --resume. The body flags (--preset, --params,
    --mass, ...) build biped3d; g1 and an MJCF file (--model PATH.xml, its feet and torso
    named) have the robot's own body and refuse them and --param.
    """
    from pushrecovery.cli.azimuths import azimuths_from
    from pushrecovery.cli.humanoid.bodies import body_3d
    from pushrecovery.cli.humanoid.campaign import echo_causes, spec_3d, write_confusion
    from pushrecovery.errors import InvalidParameterError

    run = CampaignRun.pop(kwargs)
    directions = azimuths_from(azimuth, azimuths)
    if run.resume and impulse is None and fraction is None and directions is None:
        from click.core import ParameterSource

        given = click.get_current_context().get_parameter_source("model")
        asked = bool(strategy) or given is ParameterSource.COMMANDLINE
        spec = run.stored("--impulse or --fraction", asked, three_d=True)
    else:
        if (impulse is None) == (fraction is None):
            raise InvalidParameterError(
                "humanoid campaign needs one of --impulse, --fraction"
                if impulse is None
                else "give --impulse or --fraction, not both"
            )
        params, plant = body_3d(model, kwargs)
        spec = spec_3d(
            "mjcf" if plant is not None else model,
            params,
            strategy,
            impulse=impulse,
            fraction=fraction,
            azimuths=directions,
            mjcf=None if plant is None else plant.source,
            **run.spec_options(),
        )
    result = run.run(spec)
    confusion, files = write_confusion(result.table, spec.model_name, result.directory, run.plot)
    run.show(result, files, as_json, lambda: echo_causes(confusion))


def _echo_validation(data: dict[str, Any]) -> None:
    """Print the critical pushes, the confusion matrices and the files of a 3-D validation."""
    for row in data.get("critical", []):
        click.echo(
            f"{row['strategy']:<7}{row['azimuth']:>6g} deg  predicted {row['predicted']:6.1f}  "
            f"corrected {row['corrected']:6.1f}  measured {row['measured']:6.1f} N s  "
            f"({100 * row['relative_error']:+.1f} %, "
            f"corrected {100 * row['corrected_error']:+.1f} %)"
        )
    if "confusion" in data:
        found = data["confusion"]

        def agreement(value: float | None) -> str:
            return "n/a (every run undecided)" if value is None else f"{value:.3f}"

        echo_confusion(
            f"confusion (rows predicted, columns used), agreement {agreement(found['accuracy'])}",
            found["labels"],
            found["counts"],
            found.get("apart"),
        )
        echo_confusion(
            f"against the verdict corrected for the push's height, agreement "
            f"{agreement(found['accuracy_corrected'])}",
            found["labels"],
            found["counts_corrected"],
            found.get("apart_corrected"),
        )
        causes = ", ".join(f"{k} {v}" for k, v in found["causes"].items() if v and k != "agree")
        click.echo(f"where they differ: {causes or 'nowhere'}")
    files = {**data.get("files", {}), **data.get("confusion", {}).get("files", {})}
    for name, path in files.items():
        click.echo(f"{name:<18}{path}")
