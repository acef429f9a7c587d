"""The ``pushrecovery`` command group: commands are imported only when they run.

As click's "lazily loaded subcommands": the group names each command by import string with
its one-line help, so ``pushrecovery --help`` imports no command module, no numpy and no model.
"""

from __future__ import annotations

import importlib

import click

from pushrecovery import __version__

__all__ = ["COMMANDS", "cli"]

#: Command name -> ("module:attribute", one-line help).
COMMANDS: dict[str, tuple[str, str]] = {
    "analyze": (
        "pushrecovery.cli.analyze:analyze",
        "Per-frame margins and strategies of measured trials (CSV, C3D).",
    ),
    "bounds": ("pushrecovery.cli.surfaces:bounds", "Capture-point bounds of each strategy."),
    "campaign": (
        "pushrecovery.cli.campaign:campaign",
        "Sweep pushes over starts, push sizes and parameters, at scale.",
    ),
    "capture-region": (
        "pushrecovery.cli.steps:capture_region_command",
        "Footholds that capture a state with N steps.",
    ),
    "classify": (
        "pushrecovery.cli.surfaces:classify",
        "Strategy a CoM state needs: ankle, hip, step or fall.",
    ),
    "critical-push": (
        "pushrecovery.cli.simulation:critical_push",
        "Largest recoverable push, vs Eq. 4.",
    ),
    "figures": (
        "pushrecovery.cli.figures:figures",
        "Reproduce the paper's figures and the ground-plane figure.",
    ),
    "humanoid": (
        "pushrecovery.cli.humanoid:humanoid",
        "The 3-D humanoids (biped3d, g1) under the whole-body controller.",
    ),
    "report": (
        "pushrecovery.cli.campaign:report",
        "The HTML report of a parameter set (the main job).",
    ),
    "simulate": (
        "pushrecovery.cli.simulation:simulate",
        "Simulate a push; report recovered or fell.",
    ),
    "step": ("pushrecovery.cli.surfaces:step", "Optimal step after a push (Sec. IV, Eq. 21)."),
    "validate": (
        "pushrecovery.cli.validate:validate",
        "Critical pushes and a confusion matrix in simulation vs the surfaces.",
    ),
}


class LazyGroup(click.Group):
    """A group whose commands are imported on first use (:data:`COMMANDS`)."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        """Return every command name, sorted."""
        return sorted({*super().list_commands(ctx), *COMMANDS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        """Import and return the command ``cmd_name`` (None if there is none)."""
        if cmd_name not in COMMANDS:
            return super().get_command(ctx, cmd_name)
        module, _, attribute = COMMANDS[cmd_name][0].partition(":")
        command = getattr(importlib.import_module(module), attribute)
        if not isinstance(command, click.Command):  # pragma: no cover - the table is ours
            raise TypeError(f"{COMMANDS[cmd_name][0]} is not a click command")
        return command

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """List the commands with their one-line help, importing none of them."""
        rows = [(name, COMMANDS[name][1]) for name in self.list_commands(ctx) if name in COMMANDS]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


@click.group(
    cls=LazyGroup,
    no_args_is_help=True,
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)
@click.version_option(__version__, prog_name="pushrecovery")
def cli() -> None:
    """Predict whether a pushed humanoid falls, and recover it (Stephens, Humanoid Push Recovery).

    SI units throughout; x is forward, y left, positions relative to the ankle (sagittal) or
    to the ankles' midpoint (ground plane). Every command takes the body-parameter flags and
    --json.
    """
