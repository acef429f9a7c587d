"""The ``pushrecovery`` command group: commands are imported only when they run.

As click's "lazily loaded subcommands": the group names each command by import string with
its one-line help, so ``pushrecovery --help`` imports no command module, no numpy and no model.
"""

from __future__ import annotations

import importlib

import click

from pushrecovery import __version__

__all__ = ["COMMANDS", "COMMAND_EXTRAS", "EXAMPLE_WIDTH", "cli", "example"]

#: Longest line of an example [characters]: with click's indent, an 80-column terminal.
EXAMPLE_WIDTH = 74

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
        "Largest recoverable push, against its surface's prediction.",
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

#: Command name -> the extras it needs (``pip install 'pushrecovery[EXTRA]'``); a command not
#: listed runs on the core install, some of its options needing one (``--plot``: ``plots``;
#: ``--backend mujoco``: ``sim``). A missing module is named with the first extra bringing it.
COMMAND_EXTRAS: dict[str, tuple[str, ...]] = {
    "analyze": ("analysis",),
    "campaign": ("campaign",),
    "figures": ("plots",),
    "humanoid": ("sim",),
    "report": ("report",),
}


def example(*lines: str) -> str:
    r"""Return a help page's epilog: its example command lines, each kept on its own line.

    Parameters
    ----------
    *lines : str
        Whole command lines, ``pushrecovery ...``; each one runs as it is written
        (``tests/test_cli_help.py`` runs them), files written under ``out/``. A line longer
        than :data:`EXAMPLE_WIDTH` is continued on the next with a shell's `` \``.

    Returns
    -------
    str
        ``Example:`` (or ``Examples:``) and the lines in a click ``\b`` paragraph, which click
        prints without rewrapping and sphinx-click renders as a line block.
    """
    heading = "Example:" if len(lines) == 1 else "Examples:"
    return "\b\n" + heading + "\n" + "\n".join(_wrapped(line) for line in lines)


def _wrapped(line: str) -> str:
    """Break ``line`` before options (each with its values) to lines of EXAMPLE_WIDTH at most."""
    chunks: list[str] = []
    for word in line.split():
        option = word.startswith("--") or (word.startswith("-") and word[1:2].isalpha())
        if option or not chunks:  # "--xdot -1 2 0.25" is one chunk
            chunks.append(word)
        else:
            chunks[-1] += " " + word
    rows = [chunks[0]]
    for chunk in chunks[1:]:
        if len(rows[-1]) + 1 + len(chunk) > EXAMPLE_WIDTH - (4 if len(rows) > 1 else 0):
            rows.append(chunk)
        else:
            rows[-1] += " " + chunk
    return " \\\n".join(f"  {row}" if i == 0 else f"      {row}" for i, row in enumerate(rows))


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
    epilog=example("pushrecovery classify --x 0.0 --xdot 0.7", "pushrecovery bounds --json"),
)
@click.version_option(__version__, prog_name="pushrecovery")
def cli() -> None:
    """Predict whether a pushed humanoid falls, and recover it (Stephens, Humanoid Push Recovery).

    SI units throughout (m, s, kg, N; angles in rad, push azimuths in degrees); x is forward,
    y left, positions relative to the ankle (sagittal commands) or to the ankles' midpoint
    (ground plane), velocities and pushes positive forward and left. The body is the paper's
    unless --preset, --params FILE or the body flags (--mass, --com-height, ...) change it
    (the Unitree G1 of 'pushrecovery humanoid' has its own). Every command prints a table, or
    with --json JSON whose keys are a stable contract (new keys are added, none
    renamed or dropped); bad input ends with one line on stderr and exit status 2.
    """
