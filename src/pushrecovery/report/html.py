"""One self-contained HTML page: the surfaces, the paper's figures and push campaigns.

:func:`write_report` computes every section for one body (:func:`~pushrecovery.report.build.
build_report`, data) and renders ``OUT/index.html`` through the jinja2 templates
(:func:`~pushrecovery.report.render.render_report`), with the figures embedded as base64 PNG
and plain CSS (no script, no external reference), next to the campaigns' own directories
(``OUT/campaign-*``: their Parquet pushes and summaries, reused by a rerun with the same grids)
and the figures' files.

Sections, in the page's order (key: content):

- ``bounds``: the parameters, bounds and thresholds (``pushrecovery bounds``);
- ``map``: the strategy map of the (x, ẋ) plane;
- ``plane``: the capture-point plane of the ground-plane model in double and single support,
  with the per-direction push thresholds;
- ``steps``: one- and two-step capture regions for a few pushes, the N-step strategy map and
  the N-step thresholds;
- ``figures``: every reproduced figure of the paper;
- ``analytic``: a campaign on the analytic ``stepping`` model with the ``recovery`` controller;
- ``sweep``: the critical push of ``flywheel`` + ``mpc`` against the hip torque limit;
- ``mujoco``: a campaign on the MuJoCo ``torso`` with ``mpc``;
- ``biped``: a campaign on the MuJoCo ``biped`` with ``recovery``;
- ``critical``: the MuJoCo critical-push table;
- ``filmstrips``: one rendered MuJoCo run per strategy;
- ``humanoid3d``: the 3-D humanoids (with MuJoCo and the ``robots`` extra; one line saying how
  to get it otherwise): the 3-D validation's polar plots and tables and filmstrips
  (:mod:`pushrecovery.report.humanoid3d`).

The grids come in two sizes: ``small`` (the default, about a minute on two cores) and ``full``;
any grid can be replaced (:class:`~pushrecovery.report.PushGrid`), any section left out (``skip``).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.errors import PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.report.build import build_report
from pushrecovery.report.render import render_report

__all__ = ["write_report"]


def write_report(
    params: BodyParams | None = None, out_dir: Path | str = Path("out/report"), **options: Any
) -> Path:
    """Compute every section of the report and write ``out_dir/index.html``.

    One self-contained page (figures as base64 PNG, plain CSS, no script or external
    reference): the parameters with the bounds and thresholds (Eq. 4, corrected Eq. 15,
    Eq. 12), the strategy map, the ground plane (the capture-point plane in double and single
    support, per-direction thresholds), the paper's figures, push campaigns on the analytic
    models and in MuJoCo with their accuracy, confusion matrix and outcome map, the MuJoCo
    critical-push table and one filmstrip per strategy (module docstring). The page's footer
    gives each section's wall time. The campaigns keep their files in
    ``out_dir/campaign-KEY`` (a rerun with the same grid and body reuses them; another grid
    replaces them). The data behind the page: :func:`~pushrecovery.report.build.build_report`.

    Parameters
    ----------
    params : BodyParams, optional
        The body; default the built-in preset (:func:`pushrecovery.load_params`).
    out_dir : path
        Output directory, created if missing.
    **options
        The keyword arguments of :func:`~pushrecovery.report.build.build_report`, all
        keyword-only: the other parameters below.

    Other Parameters
    ----------------
    size : {"small", "full"}
        Grid size (:data:`~pushrecovery.report.SIZES`): ``small`` (default) runs in about a
        minute on two cores, ``full`` is about ten times larger.
    full : bool
        Shorthand for ``size="full"``.
    analytic_grid, sweep_grid, mujoco_grid, biped_grid : PushGrid, optional
        Replace the grid of that campaign (``sweep_grid`` must sweep one parameter).
    mujoco : bool
        Include the MuJoCo sections (``mujoco``, ``biped``, ``critical``, ``filmstrips``,
        ``humanoid3d``).
    skip : collection of str
        Section keys to leave out (:data:`~pushrecovery.report.SECTIONS`).
    workers : int, optional
        Worker processes of the campaigns (1: this process; default all cores).
    scheduler : str, optional
        Address of a ``dask.distributed`` scheduler to run the campaigns on.
    progress : callable, optional
        Called with one line of text as each section starts and ends.
    robot : MjcfSource, optional
        The user's MJCF humanoid whose derived body ``params`` is: the "3-D humanoid" section
        validates it (ankle) beside the G1, and films it in place of the biped3d.

    Returns
    -------
    Path
        The HTML file.

    Raises
    ------
    InvalidParameterError
        On an unknown size or section key, or an invalid grid.
    """
    if params is not None:
        require_type("params", params, BodyParams)
    require_type("out_dir", out_dir, (str, os.PathLike))
    report = build_report(params, out_dir, **options)
    path = Path(out_dir) / "index.html"
    partial = path.with_suffix(".partial")
    try:
        partial.write_text(render_report(report), encoding="utf-8")
        partial.replace(path)
    except OSError as exc:
        raise PushRecoveryError(f"cannot write {path}: {exc.strerror or exc}") from None
    return path
