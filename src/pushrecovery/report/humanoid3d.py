"""The "3-D humanoid" section: the 3-D validation's polar plots and tables, and filmstrips.

Computed only when MuJoCo and the ``robots`` extra are installed; otherwise the section is one
line saying how to get it (:data:`HINT`). For the biped3d of the report's body (ankle and hip)
and the G1 (ankle) (a report on the user's MJCF humanoid, ``robot``: that robot in place of the
biped3d, ankle), the critical push at each azimuth of the grids (``azimuths3d``,
``tolerance3d``, ``duration3d``) against the 2-D prediction
(:func:`~pushrecovery.experiments.validation3d.run_validation3d`, the azimuths shared over
the report's worker processes); then the filmstrips of :data:`~.config.HUMANOID3D_STRIPS`
(:mod:`pushrecovery.sim.mujoco.humanoid3d.render3d`).

Both are kept under ``OUT/humanoid3d`` with the settings they were computed with
(``*.json``): a rerun with the same settings, body and code (a digest of the package's
sources) reuses them.
"""

from __future__ import annotations

import functools
import json
import os
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from pushrecovery.arguments import require_type
from pushrecovery.errors import PushRecoveryError
from pushrecovery.experiments.filmstrip3d import STRIP_DURATION, filmstrip_run
from pushrecovery.report.config import HUMANOID3D_STRIPS
from pushrecovery.report.context import _Context
from pushrecovery.report.data import Filmstrip, Humanoid3DSection, Picture, Table
from pushrecovery.report.markup import num, percent_interval
from pushrecovery.sim.mjcf_source import MjcfSource

__all__ = ["HINT", "humanoid3d_section"]

#: The section's one line without the extra.
HINT = (
    "The 3-D humanoid section needs MuJoCo and the robots extra: pip install 'pushrecovery[robots]'"
)
#: The validations: model and strategies.
VALIDATIONS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("biped3d", ("ankle", "hip")),
    ("g1", ("ankle",)),
)
#: One filmstrip (:data:`~.config.HUMANOID3D_STRIPS`).
Strip = tuple[str, float, float, str, str, tuple[float, ...]]
#: A validated or filmed model: a built-in's name, or the user's MJCF humanoid.
Model = str | MjcfSource
#: Bumped when what a cached file holds changes meaning.
_CACHE_VERSION = 1


def _installed() -> bool:
    """Whether MuJoCo and the robots extra (the G1's model files) are installed."""
    import importlib.util

    if importlib.util.find_spec("mujoco") is None:
        return False
    from pushrecovery.sim.mujoco.humanoid3d import robots

    try:
        robots.robot_path("g1")
    except robots.RobotsExtraMissing:
        return False
    return True


def _read(path: Path, settings: dict[str, Any]) -> dict[str, Any] | None:
    """Return the cached ``result`` of ``path`` if it was computed with ``settings``."""
    try:
        stored = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(stored, dict) or stored.get("settings") != settings:
        return None
    result = stored.get("result")
    return result if isinstance(result, dict) else None


def _write(path: Path, settings: dict[str, Any], result: dict[str, Any]) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"settings": settings, "result": result}), encoding="utf-8")
    except OSError as exc:
        raise PushRecoveryError(f"cannot write {path}: {exc.strerror or exc}") from None


@functools.cache
def _code_fingerprint() -> str:
    """Return a digest of the package's source files: any change to the code recomputes.

    A development tree would otherwise show a cache computed before a controller change
    (the version number does not move between commits). About 10 ms, once per process.
    """
    import hashlib

    import pushrecovery

    root = Path(pushrecovery.__file__).parent
    digest = hashlib.sha256()
    for source in sorted(root.rglob("*.py")):
        digest.update(source.relative_to(root).as_posix().encode())
        digest.update(source.read_bytes())
    return digest.hexdigest()[:16]


def _name(model: Model) -> str:
    """Return the model's name in files and captions (an MJCF file's stem)."""
    return model if isinstance(model, str) else model.name


def _settings(ctx: _Context, model: Model, **extra: Any) -> dict[str, Any]:
    """Return the settings a cached file must match: the body, the grid, ``extra``, the code."""
    from pushrecovery import __version__

    body: Any = ctx.params.to_dict() if model == "biped3d" else "robot"
    if isinstance(model, MjcfSource):
        body = model.to_dict()
    return {"cache": _CACHE_VERSION, "version": __version__, "code": _code_fingerprint(),
            "model": _name(model), "body": body, **extra}  # fmt: skip


def _validate_one(model: Model, azimuth: float, strategies: tuple[str, ...], params: Any,
                  tolerance: float, duration: float) -> Any:  # fmt: skip
    """One azimuth of the validation (a worker process's job)."""
    from pushrecovery.experiments.validation3d import run_validation3d

    plant = None if isinstance(model, str) else model.plant()
    return run_validation3d(_name(model), [azimuth], strategies, params=params,
                            rel_tolerance=tolerance, duration=duration,
                            plant=plant)  # fmt: skip


def _run_validation(ctx: _Context, model: Model, strategies: tuple[str, ...]) -> Any:
    """Run the validation, one azimuth per job over the report's worker processes."""
    grids = ctx.grids
    params = ctx.params if model == "biped3d" else None
    jobs = [(model, a, strategies, params, grids.tolerance3d, grids.duration3d)
            for a in grids.azimuths3d]  # fmt: skip
    workers = min(ctx.workers or os.cpu_count() or 1, len(jobs))
    if workers <= 1:
        parts = [_validate_one(*job) for job in jobs]
    else:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        # Not fork: the parent may hold OpenMP threads (numba) or an OpenGL context.
        methods = multiprocessing.get_all_start_methods()
        start = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
        with ProcessPoolExecutor(max_workers=workers, mp_context=start) as pool:
            parts = list(pool.map(_validate_one, *zip(*jobs, strict=True)))
    return replace(parts[0], rows=tuple(row for part in parts for row in part.rows))


def _validation(ctx: _Context, model: Model, strategies: tuple[str, ...]) -> Any:
    """Return the validation of ``model``, from ``OUT/humanoid3d`` when computed alike."""
    from pushrecovery.experiments.validation3d import Validation3D, ValidationRow

    grids = ctx.grids
    settings = _settings(ctx, model, strategies=list(strategies),
                         azimuths=list(grids.azimuths3d), tolerance=grids.tolerance3d,
                         duration=grids.duration3d)  # fmt: skip
    path = ctx.out / "humanoid3d" / f"validation3d-{_name(model)}.json"
    cached = _read(path, settings)
    if cached is not None:
        try:
            rows = tuple(
                ValidationRow(**(row | {"bracket": tuple(row["bracket"])}))
                for row in cached["rows"]
            )
            curves = tuple((name, tuple(values)) for name, values in cached.get("curves", ()))
            fields = cached | {"rows": rows, "origin": tuple(cached["origin"]),
                               "strategies": tuple(cached["strategies"]),
                               "curves": curves}  # fmt: skip
            ctx.note("humanoid3d", f"Reused the {_name(model)} validation in {path.name}.")
            return Validation3D(**fields)
        except (KeyError, TypeError, ValueError):
            pass  # another layout: compute afresh
    result = _run_validation(ctx, model, strategies)
    _write(path, settings, asdict(result))
    return result


def _table(result: Any) -> Table:
    rows = tuple(
        (
            num(row.azimuth),
            row.strategy,
            num(row.predicted, 3),
            num(row.corrected, 3),
            num(row.measured, 3),
            f"[{num(row.bracket[0], 3)}, {num(row.bracket[1], 3)}]",
            percent_interval(row.bracket[0], row.bracket[1], row.predicted),
            percent_interval(row.bracket[0], row.bracket[1], row.corrected),
            row.strategy_used,
            num(1e3 * row.foot_slip, 2),
            num(row.peak_force, 3),
        )
        for row in result.rows
    )
    header = (
        *("azimuth [deg]", "strategy", "predicted [N s]", "corrected [N s]", "measured [N s]"),
        *("bracket [N s]", "vs predicted", "vs corrected", "used", "foot slip [mm]"),
        "peak ground force [m g]",
    )
    return Table(header, rows, text_columns=2, ident=f"validation3d-{result.model}")


def _polar(ctx: _Context, result: Any) -> Picture:
    from pushrecovery.plots.common import save_figure
    from pushrecovery.plots.validation3d import validation3d_figure

    stem = ctx.out / "humanoid3d" / f"validation3d-{result.model}"
    (path,) = save_figure(validation3d_figure(result), stem, ["png"])
    caption = (
        f"{result.model}: the critical push [N s] at each azimuth (0° forward, 90° left) under "
        "the whole-body controller (markers; bar: up to the push that fell) against the 2-D "
        f"prediction m ω ρ (solid, every 2°) and its push-height correction (dashed); bisected to "
        f"{100 * result.rel_tolerance:g} % of the prediction, {result.duration:g} s per run."
    )
    return Picture(path, caption, "experiments.validation3d.run_validation3d")


def _strip(ctx: _Context, key: str, spec: Strip) -> Filmstrip:
    """Render (or reuse) one filmstrip of :data:`HUMANOID3D_STRIPS`.

    A report on the user's robot films it in place of the biped3d.
    """
    import shutil

    from pushrecovery.sim.mujoco.humanoid3d.render3d import render_recording3d

    name, azimuth, fraction, controller, caption, times = spec
    model: Model = name
    if name == "biped3d" and ctx.robot is not None:
        model, caption = ctx.robot, caption.replace("biped3d", ctx.robot.name)
        key = key.replace("biped3d", ctx.robot.name)
    folder = ctx.out / "humanoid3d"
    png, stamp = folder / f"{key}.png", folder / f"{key}.json"
    settings = _settings(ctx, model, azimuth=azimuth, fraction=fraction, controller=controller,
                         times=list(times), duration=STRIP_DURATION)  # fmt: skip
    cached = _read(stamp, settings)
    if cached is not None and png.is_file():
        impulse, outcome = float(cached["impulse"]), str(cached["outcome"])
    else:
        recording, impulse, outcome = filmstrip_run(
            ctx.params, model, azimuth, fraction, controller, times[-1]
        )
        title = f"{caption}: {impulse:.1f} N s at {azimuth:g}°, {outcome}"
        shown = [t for t in times if t <= recording.time[-1]] or None  # a run that ended early
        render_recording3d(recording, png, title=title, times=shown, gif=False)
        _write(stamp, settings, {"impulse": impulse, "outcome": outcome})
    if model == "g1":  # a picture of the robot's meshes: its licence beside it
        from pushrecovery.sim.mujoco.humanoid3d.robots import robot_licence

        shutil.copyfile(robot_licence("g1"), folder / "g1-LICENSE")
    mass = ctx.params.mass if isinstance(model, MjcfSource) else _mass(ctx, model)
    text = (
        f"{caption}: {impulse:.1f} N s ({fraction:g} × the 2-D ankle limit at {azimuth:g}°), "
        f"{outcome}. Red: CoM and its ground point; blue: capture point; green: CoP measured "
        "from the contact forces; magenta: the support polygon of the soles in contact."
        + (" The G1 model: Unitree, BSD-3-Clause (g1-LICENSE)." if model == "g1" else "")
    )
    return Filmstrip(key, _name(model), caption, impulse, impulse / mass, outcome,
                     Picture(png, text, "sim.mujoco.humanoid3d.render3d"))  # fmt: skip


def _mass(ctx: _Context, model: str) -> float:
    if model == "g1":
        from pushrecovery.sim.mujoco.humanoid3d.robots import robot_params

        return robot_params("g1").mass
    return ctx.params.mass


def humanoid3d_section(ctx: _Context) -> Humanoid3DSection:
    """Return the "3-D humanoid" section (module docstring), or its one line without the extra."""
    require_type("ctx", ctx, _Context)
    if not _installed():
        return Humanoid3DSection(unavailable=HINT)
    from pushrecovery.sim.mujoco.render import require_offscreen_gl

    polar, tables = [], []
    validations: list[tuple[Model, tuple[str, ...]]] = list(VALIDATIONS)
    if ctx.robot is not None:  # the user's robot (its own body) in place of the biped3d
        validations[0] = (ctx.robot, ("ankle",))
    for model, strategies in validations:
        result = _validation(ctx, model, strategies)
        polar.append(_polar(ctx, result))
        tables.append(_table(result))
    try:
        require_offscreen_gl()
    except PushRecoveryError as exc:
        return Humanoid3DSection(tuple(polar), tuple(tables), rendering=str(exc))
    strips = tuple(_strip(ctx, key, spec) for key, spec in HUMANOID3D_STRIPS.items())
    return Humanoid3DSection(tuple(polar), tuple(tables), strips)
