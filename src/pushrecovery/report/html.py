"""One self-contained HTML page: the surfaces, the paper's figures and push campaigns.

:func:`write_report` computes every section for one body and writes ``OUT/index.html``, with
the figures embedded as base64 PNG and plain CSS (no script, no external reference), next to
the campaigns' own directories (``OUT/campaign-*``: their Parquet pushes and summaries, reused
by a rerun with the same grids) and the filmstrips (``OUT/filmstrips``).

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
- ``filmstrips``: one rendered MuJoCo run per strategy.

The grids come in two sizes: ``small`` (the default, about a minute on two cores) and ``full``;
any grid can be replaced (:class:`PushGrid`), any section left out (``skip``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Collection, Mapping
from dataclasses import replace
from pathlib import Path

from pushrecovery.errors import InvalidParameterError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.report.campaigns import _analytic, _biped, _mujoco, _sweep
from pushrecovery.report.config import (
    _RUN_ORDER,
    MUJOCO_SECTIONS,
    SECTIONS,
    SIZES,
    PushGrid,
    ReportGrids,
)
from pushrecovery.report.context import _body_grids, _Context
from pushrecovery.report.markup import (
    esc,
    num,
    page,
    paragraph,
    table,
)
from pushrecovery.report.mujoco import _critical, _filmstrips
from pushrecovery.report.sections import _bounds, _figures, _map, _plane, _steps
from pushrecovery.surfaces.bounds import bounds_data

__all__ = [
    "MUJOCO_SECTIONS",
    "SECTIONS",
    "SIZES",
    "PushGrid",
    "ReportGrids",
    "write_report",
]


_BUILDERS: Mapping[str, Callable[[_Context], str]] = {
    "bounds": _bounds,
    "map": _map,
    "plane": _plane,
    "steps": _steps,
    "figures": _figures,
    "analytic": _analytic,
    "sweep": _sweep,
    "mujoco": _mujoco,
    "biped": _biped,
    "critical": _critical,
    "filmstrips": _filmstrips,
}


# --- the page --------------------------------------------------------------------------------
def write_report(
    params: BodyParams | None = None,
    out_dir: Path | str = Path("out/report"),
    *,
    size: str = "small",
    full: bool = False,
    analytic_grid: PushGrid | None = None,
    sweep_grid: PushGrid | None = None,
    mujoco_grid: PushGrid | None = None,
    biped_grid: PushGrid | None = None,
    mujoco: bool = True,
    skip: Collection[str] = (),
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[str], None] | None = None,
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
    replaces them).

    Parameters
    ----------
    params : BodyParams, optional
        The body; default the built-in preset (:func:`pushrecovery.load_params`).
    out_dir : path
        Output directory, created if missing.
    size : {"small", "full"}
        Grid size (:data:`SIZES`): ``small`` (default) runs in about a minute on two cores,
        ``full`` is about ten times larger.
    full : bool
        Shorthand for ``size="full"``.
    analytic_grid, sweep_grid, mujoco_grid, biped_grid : PushGrid, optional
        Replace the grid of that campaign (``sweep_grid`` must sweep one parameter).
    mujoco : bool
        Include the MuJoCo sections (``mujoco``, ``biped``, ``critical``, ``filmstrips``).
    skip : collection of str
        Section keys to leave out (:data:`SECTIONS`).
    workers : int, optional
        Worker processes of the campaigns (1: this process; default all cores).
    scheduler : str, optional
        Address of a ``dask.distributed`` scheduler to run the campaigns on.
    progress : callable, optional
        Called with one line of text as each section starts and ends.

    Returns
    -------
    Path
        The HTML file.

    Raises
    ------
    InvalidParameterError
        On an unknown size or section key, or an invalid grid.
    """
    from pushrecovery import __version__, load_params

    if size not in SIZES:
        raise InvalidParameterError(f"size must be one of {list(SIZES)}, got {size!r}")
    unknown = sorted(set(skip) - set(SECTIONS))
    if unknown:
        raise InvalidParameterError(
            f"unknown section(s) {', '.join(map(repr, unknown))}; sections: {list(SECTIONS)}"
        )
    if workers is not None and workers < 1:
        raise InvalidParameterError(f"workers must be >= 1, got {workers}")
    params = load_params() if params is None else params
    size = "full" if full else size
    grids = _body_grids(SIZES[size], params)
    grids = replace(
        grids,
        analytic=analytic_grid or grids.analytic,
        sweep=sweep_grid or grids.sweep,
        mujoco=mujoco_grid or grids.mujoco,
        biped=biped_grid or grids.biped,
    )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    skipped = set(skip) | (set(MUJOCO_SECTIONS) if not mujoco else set())
    ctx = _Context(params, out, grids, workers, scheduler)
    bodies: dict[str, str] = {}
    times: dict[str, float] = {}
    start = time.perf_counter()
    for key in _RUN_ORDER:
        if key in skipped:
            continue
        if progress is not None:
            progress(f"{SECTIONS[key]} ...")
        began = time.perf_counter()
        try:
            bodies[key] = _BUILDERS[key](ctx)
        except (PushRecoveryError, ImportError) as exc:
            # A missing optional dependency (MuJoCo) or an unusable setting: say so in place.
            bodies[key] = paragraph(
                f"This section could not be computed: {esc(type(exc).__name__)}: {esc(exc)}",
                "note",
            )
        times[key] = time.perf_counter() - began
        if progress is not None:
            progress(f"{SECTIONS[key]}: {times[key]:.1f} s")
    total = time.perf_counter() - start
    html = page(
        "Push recovery report",
        _body(params, bodies, ctx, size),
        _footer(times, total, __version__, workers, scheduler, size),
    )
    path = out / "index.html"
    partial = path.with_suffix(".partial")
    try:
        partial.write_text(html, encoding="utf-8")
        partial.replace(path)
    except OSError as exc:
        raise PushRecoveryError(f"cannot write {path}: {exc.strerror or exc}") from None
    return path


def _body(params: BodyParams, bodies: Mapping[str, str], ctx: _Context, size: str) -> str:
    shown = [key for key in SECTIONS if key in bodies]
    parts = [
        "<h1>Push recovery report</h1>\n",
        paragraph(
            "Will a pushed humanoid fall, and what should it do about it? The decision "
            "surfaces of Stephens, <em>Humanoid Push Recovery</em> (Humanoids 2007) for one "
            "body, checked against simulation: CoP balancing (the ankle strategy, Eq. 4), CMP "
            f"balancing (the hip strategy, corrected Eq. 15) and stepping (Sec. IV). Grids: "
            f"<code>{esc(size)}</code>.",
            "lead",
        ),
        _verdict(params, ctx),
        "<nav><ul>\n"
        + "".join(f'<li><a href="#{key}">{esc(SECTIONS[key])}</a></li>\n' for key in shown)
        + "</ul></nav>\n",
    ]
    for key in shown:
        notes = "".join(paragraph(esc(text), "note") for text in ctx.notes.get(key, []))
        parts.append(
            f'<section id="{key}">\n<h2>{esc(SECTIONS[key])}</h2>\n{bodies[key]}{notes}</section>\n'
        )
    return "".join(parts)


def _verdict(params: BodyParams, ctx: _Context) -> str:
    """One paragraph at the top: the body's thresholds and how well the surfaces predicted."""
    data = bounds_data(params)["thresholds"]
    text = (
        "<strong>Verdict.</strong> From upright this body recovers pushes up to "
        f"{num(data['ankle'][1], 3)} m/s forward with the ankles (Eq. 4), "
        f"{num(data['hip'][1], 3)} m/s with the hip (corrected Eq. 15) and "
        f"{num(data['step'][1], 3)} m/s with steps (the N-step verdict)."
    )
    scores = [
        f"{esc(SECTIONS[key])}: accuracy {num(summary['accuracy'], 3)} over "
        f"{summary['pushes']} pushes"
        for key, summary in ctx.summaries.items()
    ]
    if scores:
        text += (
            " The surfaces' verdicts matched the simulated outcomes in " + "; ".join(scores) + "."
        )
    return paragraph(text, "verdict")


def _footer(
    times: Mapping[str, float],
    total: float,
    version: str,
    workers: int | None,
    scheduler: str | None,
    size: str,
) -> str:
    rows = [[SECTIONS[key], f"{seconds:.1f}"] for key, seconds in times.items()]
    rows.append(["total", f"{total:.1f}"])
    count = workers or os.cpu_count() or 1
    where = (
        f"the Dask scheduler {scheduler}"
        if scheduler
        else f"{count} local worker process{'es' if count > 1 else ''}"
    )
    return paragraph(
        f"Generated by pushrecovery {esc(version)} (grids <code>{esc(size)}</code>, "
        f"campaigns on {esc(where)}). Wall time of each section, in the order computed:"
    ) + table(["section", "wall time [s]"], rows, text_columns=1, ident="timings")
