"""The ``analyze`` command: a measured trial (CSV or C3D) -> per-frame margins and strategies.

Over 400 lines on purpose: one command, its options, and its three paths (one trial, a batch,
a CoP-only trial) with what each prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.options import PARAM_FLAGS, body_options, emit, needs_plots

if TYPE_CHECKING:
    from pushrecovery.analysis.trial import TrialSummary

__all__ = ["analyze"]

# Literal so that --help imports nothing heavy; a test checks them against the readers.
_UNITS = ("m", "cm", "mm")
_AP_AXES = ("x", "-x", "y", "-y", "z", "-z")
_SEXES = ("female", "male")


#: The formats ``--figure-format`` writes (matplotlib's savefig).
FIGURE_FORMATS = ("png", "svg", "pdf")
#: (flag, default, help) of the AnalysisSettings fields named by the flags (SI units).
_SETTINGS: tuple[tuple[str, float | None, str], ...] = (
    ("--cutoff", 6.0, "Low-pass cutoff of the CoM and markers [Hz] (0: none)."),
    ("--force-cutoff", 10.0, "Low-pass cutoff of the force-plate signals [Hz] (0: none)."),
    ("--max-gap", 0.1, "Longest gap that is interpolated [s]; longer gaps are excluded."),
    (
        "--contact-height",
        0.02,
        "A foot supports while its lower marker is within this of its lowest [m].",
    ),
    (
        "--ankle-ap",
        None,
        "Lab position of the fixed feet along ap [m] (default: 0.05 m behind the mean CoP).",
    ),
    ("--ankle-ml", None, "Lab position of the fixed feet along ml [m] (default: the mean CoP)."),
)


def _settings_options(func: Any) -> Any:
    """Add one option per :data:`_SETTINGS` row."""
    for flag, default, text in reversed(_SETTINGS):
        shown = default is not None
        func = click.option(flag, type=float, default=default, show_default=shown, help=text)(func)
    return func


def _foot(text: str) -> tuple[str, str, str, str]:
    """``NAME=HEEL,TOE,ANKLE`` -> (name, heel, toe, ankle)."""
    from pushrecovery.errors import InvalidParameterError

    name, _, labels = text.partition("=")
    parts = [label.strip() for label in labels.split(",")]
    if not name or len(parts) != 3 or not all(parts):
        raise InvalidParameterError(
            "--foot needs NAME=HEEL,TOE,ANKLE marker labels (e.g. left=LHEE,LTOE,LANK), "
            f"got {text!r}"
        )
    return name, parts[0], parts[1], parts[2]


@click.command(
    short_help="Per-frame margins and strategies of measured trials (CSV, C3D).",
    epilog=example("pushrecovery analyze trial.csv --mass 72 --units mm --out out/trial"),
)
@click.argument("inputs", nargs=-1, required=True, metavar="FILE|FOLDER|GLOB...")
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False, path_type=Path),
    required=True,
    help="Directory for frames.parquet, frames.csv, summary.json and the plots (one file); "
    "for many, trials/<trial>/ per trial and trials, events, steps (Parquet, CSV) and "
    "summary.json.",
)
@click.option(
    "--subjects",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="CSV of subjects: pattern, subject, mass, leg_length, com_height, foot_length, "
    "foot_width, height, sex, condition (docs/analysis.md).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Local worker processes for many trials.",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Dask scheduler (tcp://HOST:PORT) to analyse many trials on.",
)
@click.option(
    "--resume",
    is_flag=True,
    help="Keep the trials already finished in --out.",
)
@click.option(
    "--units",
    type=click.Choice(_UNITS),
    default="m",
    show_default=True,
    help="Length unit of a CSV file.",
)
@click.option(
    "--ap-axis",
    type=click.Choice(_AP_AXES),
    default="x",
    show_default=True,
    help="C3D lab axis pointing forward (z up).",
)
@click.option(
    "--com-marker",
    "com_markers",
    multiple=True,
    metavar="LABEL",
    help="C3D marker(s) whose mean is the CoM (default CentreOfMass if present, "
    "else the CoM is integrated from the force plates).",
)
@click.option(
    "--foot",
    "feet",
    multiple=True,
    metavar="NAME=HEEL,TOE,ANKLE",
    help="C3D foot markers (default the Plug-in Gait LHEE,LTOE,LANK and RHEE,RTOE,RANK).",
)
@click.option(
    "--height",
    type=float,
    default=None,
    metavar="M",
    help="Stature [m], with --sex: the body's geometry and upper-body inertia from de Leva "
    "1996 Table 4 (docs/anthropometry.md).",
)
@click.option(
    "--sex",
    type=click.Choice(_SEXES),
    default=None,
    help="Column of de Leva's table, with --height.",
)
@_settings_options
@click.option(
    "--normalise",
    is_flag=True,
    help="Add Hof's dimensionless columns (named ..._norm): lengths / leg length l, "
    "velocities / sqrt(g l), times * sqrt(g/l).",
)
@click.option(
    "--xcom-length",
    type=click.Choice(("com_height", "leg_length")),
    default="com_height",
    show_default=True,
    help="Pendulum length l of Hof's XCoM in the 2-D margins (mos, mos_ap, ...): "
    "omega0 = sqrt(g/l); the per-axis margins of Eq. (4) and the verdicts keep the body's CoM "
    "height (docs/base_polygon.md).",
)
@click.option(
    "--com-noise",
    type=float,
    default=None,
    metavar="M",
    help="SD of the CoM signal's errors per sample [m]: adds <axis>_risk, P(the ankle does not "
    "suffice) per frame, through the analysis' own filter (docs/uncertainty.md).",
)
@click.option(
    "--com-height-sd",
    type=float,
    default=None,
    metavar="M",
    help="SD of the body's CoM height [m] (an anthropometric table's spread): the risk "
    "columns average over it.",
)
@click.option(
    "--plot/--no-plot",
    default=True,
    show_default=True,
    callback=needs_plots,
    help="Write time_series.png, phase_portrait.png and plane.png (a batch: also subjects.png "
    "and study.png).",
)
@click.option(
    "--figure-format",
    type=click.Choice(FIGURE_FORMATS),
    default="png",
    show_default=True,
    help="Format of the figures: png (150 dpi), or svg and pdf (vector, for a paper).",
)
@click.option(
    "--write-events",
    is_flag=True,
    help="Also write events.c3d: a copy of each C3D trial (never the input) with the onset and "
    "the foot events (Foot Strike, Foot Off) in its EVENT group (docs/events.md).",
)
@body_options
def analyze(inputs: tuple[str, ...], out: Path, as_json: bool, **kwargs: Any) -> None:
    """Analyse measured trials: capture point, margins, strategy and step per frame.

    Each input is a CSV (columns documented in docs/analysis.md) or C3D file (markers and
    force plates), a folder (every .csv and .c3d below it) or a glob pattern. Both directions
    are analysed, each with its own base of support; mass and CoM height come from the
    subjects table, the flags, the file, else (mass) the force plates. One file writes its
    outputs into OUT; many write one folder per trial and the tables of trials, events and
    steps. Positions are in the lab frame [m], ap forward and ml to the subject's left; margins are
    signed distances of the capture point to the base of support [m], positive inside. Prints
    the frames analysed, the body and where it came from, the most demanding strategy and the
    least CoP margin per direction, the step events and gaps, and the files; --json prints the
    whole summary (summary.json, with the files).
    """
    from pushrecovery.analysis.trial import AnalysisSettings

    feet = kwargs.pop("feet")
    reader: dict[str, dict[str, Any]] = {
        ".csv": {"units": kwargs.pop("units")},
        ".c3d": {
            "ap_axis": kwargs.pop("ap_axis"),
            "com_markers": list(kwargs.pop("com_markers")) or None,
            "feet": [_foot(text) for text in feet] if feet else None,
        },
    }
    fields = [flag[2:].replace("-", "_") for flag, _, _ in _SETTINGS]
    settings = AnalysisSettings(
        **{field: kwargs.pop(field) for field in fields},
        normalise=kwargs.pop("normalise"),
        xcom_length=kwargs.pop("xcom_length"),
        com_noise=kwargs.pop("com_noise"),
        com_height_sd=kwargs.pop("com_height_sd"),
    )
    single = len(inputs) == 1 and Path(inputs[0]).is_file()
    batch = {name: kwargs.pop(name) for name in ("subjects", "workers", "scheduler", "resume")}
    person = {name: kwargs.pop(name) for name in ("height", "sex")}
    if single and batch["subjects"] is None:
        _single(Path(inputs[0]), out, as_json, reader, settings, person, **kwargs)
    else:
        if any(value is not None for value in person.values()):
            from pushrecovery.errors import InvalidParameterError

            raise InvalidParameterError(
                "--height and --sex apply to one trial; a batch of trials is not scaled to "
                "people yet (give each trial's --mass and body flags, or analyse one file)"
            )
        _batch(inputs, out, as_json, reader, settings, batch, **kwargs)


def _single(
    file: Path,
    out: Path,
    as_json: bool,
    reader: dict[str, dict[str, Any]],
    settings: Any,
    person: dict[str, Any],
    **kwargs: Any,
) -> None:
    """One trial, its outputs straight into ``out`` (the first releases' contract)."""
    from pushrecovery.analysis.output import write_analysis
    from pushrecovery.analysis.readers import read_recording
    from pushrecovery.analysis.sway_recording import cop_only
    from pushrecovery.analysis.trial import analyze as analyze_trial
    from pushrecovery.analysis.trial import body_for
    from pushrecovery.analysis.trial.settings import PRESET_BODY
    from pushrecovery.errors import InvalidParameterError
    from pushrecovery.presets import load_params

    plot, figure_format = kwargs.pop("plot"), kwargs.pop("figure_format")
    write_events = kwargs.pop("write_events")
    if write_events and file.suffix.lower() != ".c3d":
        raise InvalidParameterError(
            f"--write-events writes the events into a C3D file's EVENT group: {file.name} is "
            "no .c3d file (the events are in summary.json and the events table)"
        )
    recording = read_recording(file, **reader.get(file.suffix.lower(), {}))
    if cop_only(recording):  # a posturography export: its sway measures, no body needed
        if write_events:
            raise InvalidParameterError(
                f"--write-events: {file.name} has only a CoP (posturography), no foot events"
            )
        _single_sway(recording, out, as_json, settings)
        return
    overrides = {field: kwargs.pop(field) for _, field, _ in PARAM_FLAGS}
    preset = load_params(kwargs["preset"], kwargs["params_file"], overrides)
    found, sources = body_for(
        recording,
        mass=overrides["mass"],
        com_height=overrides["com_height"],
        gravity=preset.gravity,
        height=person["height"],
        sex=person["sex"],
        keep={name for name, value in overrides.items() if value is not None},
    )
    params = load_params(kwargs["preset"], kwargs["params_file"], {**overrides, **found})
    result = analyze_trial(recording, params, settings, sources=sources)
    files = {name: str(path) for name, path in write_analysis(result, out).items()}
    if write_events:
        files["events_c3d"] = str(trial_c3d_events(file, result, out))
    if plot:
        files.update(plot_trial(result, out, figure_format))
    if as_json:
        emit({**result.summary.to_dict(), "files": files}, True)
        return
    emit(_brief(result.summary, files, sources.get("body", PRESET_BODY)), False)


def trial_c3d_events(file: Path, result: Any, out: Path) -> Path:
    """Write ``out/events.c3d``: ``file`` with the trial's events in its EVENT group."""
    from pushrecovery.analysis.c3d import write_events
    from pushrecovery.analysis.trial.events import c3d_events

    return write_events(file, out / "events.c3d", c3d_events(result.summary.events))


def plot_trial(result: Any, out: Path, figure_format: str = "png") -> dict[str, str]:
    """Draw a trial's time series, phase portrait and plane into ``out``; return the files.

    ``figure_format``: one of :data:`FIGURE_FORMATS` (the files' suffix).
    """
    from pushrecovery.plots.analysis import plot_phase_portrait, plot_time_series
    from pushrecovery.plots.plane.trial import plot_plane

    suffix = f".{figure_format}"
    return {
        "time_series": str(plot_time_series(result, (out / "time_series").with_suffix(suffix))),
        "phase_portrait": str(
            plot_phase_portrait(result, (out / "phase_portrait").with_suffix(suffix))
        ),
        "plane": str(plot_plane(result, result.base, (out / "plane").with_suffix(suffix))),
    }


def _batch(
    inputs: tuple[str, ...],
    out: Path,
    as_json: bool,
    reader: dict[str, dict[str, Any]],
    settings: Any,
    batch: dict[str, Any],
    **kwargs: Any,
) -> None:
    """Many trials: one folder each, the tables of trials and events, the summary."""
    import functools

    from pushrecovery.campaign.subjects import read_subjects
    from pushrecovery.campaign.trials import find_trials, run_trials, trial_jobs
    from pushrecovery.cli.progress import Progress

    plot, figure_format = kwargs.pop("plot"), kwargs.pop("figure_format")
    write_events = kwargs.pop("write_events")
    flags = {field: kwargs.pop(field) for _, field, _ in PARAM_FLAGS}
    subjects = read_subjects(batch["subjects"]) if batch["subjects"] is not None else ()
    trials, root = find_trials(inputs)
    if batch["subjects"] is not None:  # the table may sit among the trials it describes
        trials = [t for t in trials if t != batch["subjects"].resolve()]
    jobs = trial_jobs(
        trials, root, subjects, reader=reader, flags=flags, preset=kwargs["preset"],
        params_file=kwargs["params_file"], settings=settings, write_events=write_events,
    )  # fmt: skip
    bar = Progress(len(jobs), "analyze", "trial")
    try:
        result = run_trials(
            jobs,
            out,
            workers=batch["workers"],
            scheduler=batch["scheduler"],
            resume=batch["resume"],
            after=functools.partial(plot_trial, figure_format=figure_format) if plot else None,
            progress=bar.update,
        )
    finally:
        bar.close()
    files = {name: str(path) for name, path in result.files.items()}
    if plot:  # the trials' smallest margins by subject, and by condition
        from pushrecovery.plots.study import plot_study
        from pushrecovery.plots.subjects import plot_subjects

        subjects_figure = plot_subjects(result.trials, out / f"subjects.{figure_format}")
        files["subjects_figure"] = str(subjects_figure)
        files["study_figure"] = str(plot_study(result.trials, out / f"study.{figure_format}"))
    data = {**result.summary, "root": str(root), "analysed_now": result.ran, "files": files}
    if as_json:
        emit(data, True)
        return
    emit(
        {
            "trials": f"{result.summary['analysed']} of {result.summary['trials']} analysed "
            f"({result.summary['failed']} failed)",
            "subjects": len(result.summary["subjects"]),
            "files": files,
        },
        False,
    )


def _single_sway(recording: Any, out: Path, as_json: bool, settings: Any) -> None:
    """Write a CoP-only trial's sway measures to ``out/summary.json`` (docs/posturography.md)."""
    import json

    from pushrecovery.analysis.output import json_safe
    from pushrecovery.analysis.sway_recording import recording_sway

    measures, rate = recording_sway(recording, settings.force_cutoff)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "summary.json"
    summary = {
        "status": "posturography only",
        "source": recording.source,
        "frames": len(recording.force_time),
        "rate": rate,
        "posturography": {
            **measures.to_dict(), "cop_cutoff": settings.force_cutoff, "rate": rate,
        },
    }  # fmt: skip
    path.write_text(json.dumps(json_safe(summary), indent=2) + "\n")
    files = {"summary": str(path)}
    if as_json:
        emit({**summary, "files": files}, True)
        return
    brief = {
        "frames": f"{summary['frames']} ({rate:.6g} Hz, {measures.duration:.6g} s), CoP only: "
        "the sway measures, no margins",
        "path_length": measures.path_length.total,
        "mean_velocity": measures.mean_velocity.total,
        "rms_distance": measures.rms_distance.total,
        "ellipse_area": measures.ellipse.area,
        "files": files,
    }
    emit(brief, False)


def _brief(summary: TrialSummary, files: dict[str, str], body_source: str) -> dict[str, Any]:
    """Pick the lines a person reads first; everything else is in summary.json."""
    brief: dict[str, Any] = {
        "frames": f"{summary.valid_frames} of {summary.frames} analysed "
        f"({summary.rate:.6g} Hz, {summary.duration:.6g} s)",
        "mass": f"{summary.params.mass:.4g} kg ({summary.mass_source})",
        "com_height": f"{summary.params.com_height:.4g} m ({summary.com_height_source})",
        "body": body_source,
        "com": summary.com_source,
        "support": summary.support_source,
        "needs": summary.most_demanding,
    }
    for axis, data in summary.directions.items():
        brief[f"{axis}"] = {
            "needs": data.most_demanding,
            "min_cop_margin": data.min_cop_margin.value,
            "at": data.min_cop_margin.time,
            "time_in_strategy": data.time_in_strategy,
        }
    brief["step_events"] = len(summary.step_events)
    filled = sum(gap.filled for gap in summary.gaps)
    brief["gaps"] = f"{filled} interpolated, {len(summary.gaps) - filled} excluded"
    brief["files"] = files
    return brief
