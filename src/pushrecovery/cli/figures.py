"""The ``figures`` command: the paper's figures reproduced into a folder."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.app import example
from pushrecovery.cli.options import body_options, emit, out_option, params_from

__all__ = ["figures"]


@click.command(
    short_help="Reproduce the paper's figures and the ground-plane figure.",
    epilog=example("pushrecovery figures --out out/figures --format png"),
)
@out_option("out/figures", "Directory for the figures.")
@click.option(
    "--format",
    "formats",
    multiple=True,
    default=("png", "svg"),
    show_default=True,
    type=click.Choice(("png", "svg", "pdf")),
    help="File formats (repeatable).",
)
@body_options
def figures(out: str, formats: tuple[str, ...], as_json: bool, **kwargs: Any) -> None:
    """Reproduce the paper's figures (Fig. 3, 5, 6, 9, 10) into a directory.

    The figures are drawn for the body of the flags (SI units on the axes), from simulations
    of the paper's pushes on the analytic models. Also plane.png/svg: the capture-point plane
    (x forward, y left [m]) with the support polygon (ankle), the CMP region (hip) and pushes
    coloured by the strategy they need, in double, left and right support. Prints the files
    written, one per figure and --format.
    """
    from pushrecovery.cli.progress import Progress
    from pushrecovery.experiments.paper_figures import paper_runs
    from pushrecovery.plots.figures import FIGURE_COUNT, write_figures

    params = params_from(kwargs)
    bar = Progress(FIGURE_COUNT + 1, "figures", "step")  # the runs, then each figure
    try:
        runs = paper_runs(params)
        bar.update(1)
        files = write_figures(params, runs, Path(out), formats, progress=bar.update)
    finally:
        bar.close()
    emit({"files": [str(f) for f in files]}, as_json)
