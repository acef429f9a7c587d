"""The ``analyze`` command: a measured trial (CSV or C3D) -> per-frame margins and strategies."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.options import PARAM_FLAGS, body_options, emit

__all__ = ["analyze"]

# Literal so that --help imports nothing heavy; a test checks them against the readers.
_UNITS = ("m", "cm", "mm")
_AP_AXES = ("x", "-x", "y", "-y", "z", "-z")


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


@click.command(short_help="Per-frame margins and strategies of a measured trial (CSV, C3D).")
@click.argument("file", type=click.Path(dir_okay=True, path_type=Path))
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False, path_type=Path),
    required=True,
    help="Directory for frames.parquet, frames.csv, summary.json and the plots.",
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
    "--cutoff",
    type=float,
    default=6.0,
    show_default=True,
    help="Low-pass cutoff of the CoM and markers [Hz] (0: none).",
)
@click.option(
    "--force-cutoff",
    type=float,
    default=10.0,
    show_default=True,
    help="Low-pass cutoff of the force-plate signals [Hz] (0: none).",
)
@click.option(
    "--max-gap",
    type=float,
    default=0.1,
    show_default=True,
    help="Longest gap that is interpolated [s]; longer gaps are excluded.",
)
@click.option(
    "--contact-height",
    type=float,
    default=0.02,
    show_default=True,
    help="A foot supports while its lower marker is within this of its lowest [m].",
)
@click.option(
    "--ankle-ap",
    type=float,
    default=None,
    help="Lab position of the fixed feet along ap [m] (default: 0.05 m behind the mean CoP).",
)
@click.option(
    "--ankle-ml",
    type=float,
    default=None,
    help="Lab position of the fixed feet along ml [m] (default: the mean CoP).",
)
@click.option(
    "--plot/--no-plot",
    default=True,
    show_default=True,
    help="Write time_series.png and phase_portrait.png.",
)
@body_options
def analyze(file: Path, out: Path, as_json: bool, **kwargs: Any) -> None:
    """Analyse a measured trial: capture point, margins, strategy and step per frame.

    FILE is a CSV (columns documented in docs/analysis.md) or a C3D file (markers and force
    plates). Both directions are analysed, each with its own base of support; mass and CoM
    height come from the flags, else from the file, else (mass) from the force plates.
    """
    from pushrecovery.analysis.output import _json_safe, write_analysis
    from pushrecovery.analysis.readers import read_recording
    from pushrecovery.analysis.trial import AnalysisSettings, body_for
    from pushrecovery.analysis.trial import analyze as analyze_trial
    from pushrecovery.presets import load_params

    options: dict[str, Any] = {}
    suffix = file.suffix.lower()
    if suffix == ".csv":
        options["units"] = kwargs.pop("units")
    elif suffix == ".c3d":
        options["ap_axis"] = kwargs.pop("ap_axis")
        options["com_markers"] = list(kwargs.pop("com_markers")) or None
        feet = kwargs.pop("feet")
        options["feet"] = [_foot(text) for text in feet] if feet else None
    settings = AnalysisSettings(
        cutoff=kwargs.pop("cutoff"),
        force_cutoff=kwargs.pop("force_cutoff"),
        max_gap=kwargs.pop("max_gap"),
        contact_height=kwargs.pop("contact_height"),
        ankle_ap=kwargs.pop("ankle_ap"),
        ankle_ml=kwargs.pop("ankle_ml"),
    )
    plot = kwargs.pop("plot")
    recording = read_recording(file, **options)
    overrides = {field: kwargs.pop(field) for _, field, _ in PARAM_FLAGS}
    preset = load_params(kwargs["preset"], kwargs["params_file"], overrides)
    found, sources = body_for(
        recording,
        mass=overrides["mass"],
        com_height=overrides["com_height"],
        gravity=preset.gravity,
    )
    params = load_params(kwargs["preset"], kwargs["params_file"], {**overrides, **found})
    result = analyze_trial(recording, params, settings, sources=sources)
    files = {name: str(path) for name, path in write_analysis(result, out).items()}
    if plot:
        from pushrecovery.plots.analysis import plot_phase_portrait, plot_time_series

        files["time_series"] = str(plot_time_series(result, out / "time_series.png"))
        files["phase_portrait"] = str(plot_phase_portrait(result, out / "phase_portrait.png"))
    summary = _json_safe(result.summary)
    if as_json:
        emit({**summary, "files": files}, True)
        return
    emit(_brief(summary, files), False)


def _brief(summary: dict[str, Any], files: dict[str, str]) -> dict[str, Any]:
    """Pick the lines a person reads first; everything else is in summary.json."""
    brief: dict[str, Any] = {
        "frames": f"{summary['valid_frames']} of {summary['frames']} analysed "
        f"({summary['rate']:.6g} Hz, {summary['duration']:.6g} s)",
        "mass": f"{summary['body']['mass']:.4g} kg ({summary['body']['mass_source']})",
        "com_height": f"{summary['body']['com_height']:.4g} m "
        f"({summary['body']['com_height_source']})",
        "com": summary["com_source"],
        "support": summary["support_source"],
        "needs": summary["strategy"]["most_demanding"],
    }
    for axis, data in summary["directions"].items():
        margin = data["min_margin"]["cop"]
        brief[f"{axis}"] = {
            "needs": data["most_demanding"],
            "min_cop_margin": margin["value"],
            "at": margin["time"],
            "time_in_strategy": data["time_in_strategy"],
        }
    brief["step_events"] = len(summary["step_events"])
    brief["gaps"] = (
        f"{sum(g['filled'] for g in summary['gaps'])} interpolated, "
        f"{sum(not g['filled'] for g in summary['gaps'])} excluded"
    )
    brief["files"] = files
    return brief
