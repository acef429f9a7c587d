"""The MuJoCo sections: the critical-push table and the filmstrips."""

from __future__ import annotations

from pushrecovery.errors import PushRecoveryError
from pushrecovery.report.config import FILMSTRIPS
from pushrecovery.report.context import _Context
from pushrecovery.report.data import CriticalSection, Filmstrip, FilmstripsSection, Picture, Table
from pushrecovery.report.markup import num, percent_interval


def _critical(ctx: _Context) -> CriticalSection:
    from pushrecovery.sim.validation import available_strategies, critical_table

    grids = ctx.grids
    rows = []
    for strategy in available_strategies("mujoco"):
        tolerance = grids.step_tolerance if strategy == "step" else grids.critical_tolerance
        for row in critical_table(
            ctx.params,
            backend="mujoco",
            strategies=(strategy,),
            x0s=tuple(x for x in grids.critical_x0s if ctx.params.heel < x < ctx.params.toe),
            tolerance=tolerance,
        ):
            rows.append(
                (
                    row.strategy,
                    f"{row.model} + {row.controller}",
                    row.direction,
                    num(row.x0),
                    num(row.predicted),
                    num(row.corrected),
                    num(row.measured),
                    f"[{num(row.bracket[0])}, {num(row.bracket[1])}]",
                    percent_interval(row.bracket[0], row.bracket[1], row.predicted),
                    percent_interval(row.bracket[0], row.bracket[1], row.corrected),
                    str(row.simulations),
                    num(1e3 * row.foot_slip, 2),
                    num(row.peak_force, 3),
                )
            )
    header = (
        "strategy",
        "model + controller",
        "direction",
        "x0 [m]",
        "predicted [m/s]",
        "corrected [m/s]",
        "MuJoCo [m/s]",
        "bracket [m/s]",
        "vs predicted",
        "vs corrected",
        "simulations",
        "foot slip [mm]",
        "peak ground force [m g]",
    )
    return CriticalSection(Table(header, tuple(rows), text_columns=3))


def _filmstrips(ctx: _Context) -> FilmstripsSection:
    from pushrecovery.control.base import make_controller
    from pushrecovery.experiments.pushes import strategy_pushes
    from pushrecovery.sim.backend import Recording
    from pushrecovery.sim.mujoco.render import (
        fit_view,
        render_frames,
        require_offscreen_gl,
        select_times,
        write_filmstrip,
    )
    from pushrecovery.sim.push import Push
    from pushrecovery.sim.registry import MUJOCO_MODELS, make_plant
    from pushrecovery.sim.simulate import simulate

    try:
        require_offscreen_gl()
    except PushRecoveryError as exc:
        return FilmstripsSection((), unavailable=str(exc))
    strips = []
    folder = ctx.out / "filmstrips"
    pushes = strategy_pushes(ctx.params)
    for strategy, (model, controller, name) in FILMSTRIPS.items():
        impulse = pushes.impulse(strategy, ctx.params.mass)
        caption = f"{name}, {impulse:g} N s"
        velocity = impulse / ctx.params.mass
        if model not in MUJOCO_MODELS:
            strips.append(Filmstrip(strategy, model, caption, impulse, velocity, None, None))
            continue
        plant = make_plant(model, ctx.params, "mujoco")
        if not isinstance(plant, Recording):  # pragma: no cover - every MuJoCo plant records
            raise TypeError(f"the MuJoCo model {model!r} records no frames")
        plant.record()
        plant.reset(0.0, 0.0)
        pushed = plant.apply_push(Push.from_impulse(impulse, ctx.params.mass))
        run = simulate(plant, make_controller(controller, ctx.params), pushed, duration=4.0)
        frames = plant.frames or []
        strip = select_times(frames, 7)
        images = render_frames(
            plant.model, strip, width=180, height=240, view=fit_view(plant.model, frames, 0.75)
        )
        path = write_filmstrip(
            images,
            [f.time for f in strip],
            folder / f"{strategy}.png",
            title=f"{caption}: {run.outcome.value}",
        )
        strips.append(
            Filmstrip(
                strategy,
                model,
                caption,
                impulse,
                velocity,
                run.outcome.value,
                Picture(
                    path, f"{caption} (ẋ = J/m = {num(velocity, 3)} m/s): {run.outcome.value}."
                ),
            )
        )
    return FilmstripsSection(tuple(strips))
