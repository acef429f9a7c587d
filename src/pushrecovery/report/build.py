"""Compute the report's sections for one body: :func:`build_report` returns them as data.

:func:`build_report` runs every section and returns a :class:`~pushrecovery.report.data.Report`
(frozen dataclasses of numbers, rows and figure paths); the figures and the campaigns' own
directories (``OUT/campaign-*``: their Parquet pushes and summaries, reused by a rerun with
the same grids) are written under ``OUT``; :func:`~pushrecovery.report.html.write_report`
renders the page.

The sections, their keys and the grids: :mod:`pushrecovery.report.html`.
"""

from __future__ import annotations

import functools
import os
import time
from collections.abc import Callable, Collection, Iterable, Mapping
from dataclasses import replace
from pathlib import Path

from pushrecovery.arguments import require_type, whole_number
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError
from pushrecovery.params import BodyParams
from pushrecovery.report.campaigns import CAMPAIGNS, _sweep, accuracy, campaign_section
from pushrecovery.report.config import (
    _RUN_ORDER,
    MUJOCO_SECTIONS,
    SECTIONS,
    SIZES,
    PushGrid,
)
from pushrecovery.report.context import _body_grids, _Context
from pushrecovery.report.data import FailedSection, Footer, Report, Section, Verdict
from pushrecovery.report.humanoid3d import humanoid3d_section
from pushrecovery.report.mujoco import _critical, _filmstrips
from pushrecovery.report.sections import _bounds, _figures, _map, _plane, _steps
from pushrecovery.sim.mjcf_source import MjcfSource
from pushrecovery.surfaces.bounds import bounds_data

__all__ = ["build_report"]


_BUILDERS: Mapping[str, Callable[[_Context], Section]] = {
    "bounds": _bounds,
    "map": _map,
    "plane": _plane,
    "steps": _steps,
    "figures": _figures,
    **{key: functools.partial(campaign_section, key=key) for key in CAMPAIGNS},
    "sweep": _sweep,
    "critical": _critical,
    "filmstrips": _filmstrips,
    "humanoid3d": humanoid3d_section,
}


def build_report(
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
    robot: MjcfSource | None = None,
) -> Report:
    """Compute every section of the report; return them as data.

    The parameters are those of :func:`~pushrecovery.report.html.write_report`, which renders
    what this returns. Figures and campaign files are written under ``out_dir``.

    Returns
    -------
    Report
        The sections in the page's order, the verdict paragraph's numbers, the notes and the
        wall time of each section.

    Raises
    ------
    InvalidParameterError
        On an unknown size or section key, or an invalid grid.
    """
    if params is not None:
        require_type("params", params, BodyParams)
    require_type("out_dir", out_dir, (str, os.PathLike))
    given = {"analytic_grid": analytic_grid, "sweep_grid": sweep_grid,
             "mujoco_grid": mujoco_grid, "biped_grid": biped_grid}  # fmt: skip
    for name, grid in given.items():
        if grid is not None:
            require_type(name, grid, PushGrid)
    if workers is not None:
        workers = whole_number("workers", workers, 1, 1024)
    if scheduler is not None:
        require_type("scheduler", scheduler, str)
    if progress is not None and not callable(progress):
        raise ParameterTypeError(f"progress must be callable, got {type(progress).__name__}")
    if robot is not None:
        require_type("robot", robot, MjcfSource)
    for name, flag in (("full", full), ("mujoco", mujoco)):
        require_type(name, flag, bool)
    require_type("size", size, str)
    if (
        isinstance(skip, str | bytes)
        or not isinstance(skip, Iterable)
        or not all(isinstance(s, str) for s in skip)
    ):
        raise ParameterTypeError("skip must be a list of section names")
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
    ctx = _Context(params, out, grids, workers, scheduler, robot=robot)
    sections: dict[str, Section] = {}
    times: dict[str, float] = {}
    start = time.perf_counter()
    for key in _RUN_ORDER:
        if key in skipped:
            continue
        if progress is not None:
            progress(f"{SECTIONS[key]} ...")
        began = time.perf_counter()
        try:
            sections[key] = _BUILDERS[key](ctx)
        except (PushRecoveryError, ImportError) as exc:
            # A missing optional dependency (MuJoCo) or an unusable setting: say so in place.
            sections[key] = FailedSection(type(exc).__name__, str(exc))
        times[key] = time.perf_counter() - began
        if progress is not None:
            progress(f"{SECTIONS[key]}: {times[key]:.1f} s")
    total = time.perf_counter() - start
    count = workers or os.cpu_count() or 1
    where = (
        f"the Dask scheduler {scheduler}"
        if scheduler
        else f"{count} local worker process{'es' if count > 1 else ''}"
    )
    return Report(
        size=size,
        verdict=replace(
            _verdict(params, ctx),
            missing=tuple(
                (key, SECTIONS[key], f"{section.error}: {section.message}")
                for key, section in sections.items()
                if isinstance(section, FailedSection)
            ),
        ),
        sections=tuple((key, SECTIONS[key], sections[key]) for key in SECTIONS if key in sections),
        notes={key: tuple(texts) for key, texts in ctx.notes.items()},
        footer=Footer(
            version=__version__,
            size=size,
            where=where,
            timings=tuple((SECTIONS[key], seconds) for key, seconds in times.items()),
            total=total,
        ),
    )


def _verdict(params: BodyParams, ctx: _Context) -> Verdict:
    """Return the body's forward thresholds and how well the surfaces predicted each campaign."""
    data = bounds_data(params)["thresholds"]
    return Verdict(
        ankle=float(data["ankle"][1]),
        hip=float(data["hip"][1]),
        step=float(data["step"][1]),
        scores=tuple(
            (SECTIONS[key], accuracy(summary), int(summary["pushes"]))
            for key, summary in ctx.summaries.items()
        ),
    )
