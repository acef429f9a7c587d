"""Every command's ``--help`` is documentation: a description, examples, and the examples run.

Issue 39: each command and subcommand of ``pushrecovery`` (the groups too) shows a summary line
and a paragraph saying what it does and prints, and at least one example command line; every
example line of every help page runs here as it is written (in this process, with click's
CliRunner, in a temporary directory so that ``out/...`` lands there) and exits 0; an example
with ``--json`` prints JSON. The CLI reference of the site (docs/cli.md) renders the same text.
"""

from __future__ import annotations

import json
import re
import shlex
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click
import pytest
from click.testing import CliRunner

from pushrecovery.cli.app import cli


def _commands(
    group: click.Group = cli, path: tuple[str, ...] = ()
) -> Iterator[tuple[tuple[str, ...], click.Command]]:
    """Yield (path, command) for the group and everything below it (lazy commands loaded)."""
    yield path, group
    ctx = click.Context(group, info_name=path[-1] if path else "pushrecovery")
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        assert command is not None, name
        if isinstance(command, click.Group):
            yield from _commands(command, (*path, name))
        else:
            yield (*path, name), command


def help_page(path: tuple[str, ...]) -> str:
    """Return ``pushrecovery PATH --help`` as a terminal of 80 columns shows it."""
    result = CliRunner().invoke(cli, [*path, "--help"], prog_name="pushrecovery", terminal_width=80)
    assert result.exit_code == 0, result.output
    return result.output


def description(page: str) -> list[str]:
    """Return the paragraphs between the usage line and the options, each on one line."""
    text = page.split("\nOptions:")[0].split("\n", 1)[1]
    return [" ".join(p.split()) for p in re.split(r"\n\s*\n", text) if p.strip()]


def examples(page: str) -> list[str]:
    """Return the command lines under ``Example:`` / ``Examples:``, continuations joined."""
    lines = page.splitlines()
    starts = [i for i, line in enumerate(lines) if re.fullmatch(r"\s*Examples?:", line)]
    found: list[str] = []
    for start in starts:
        for line in lines[start + 1 :]:
            if not line.strip():
                break
            if found and found[-1].endswith("\\"):
                found[-1] = found[-1][:-1].rstrip() + " " + line.strip()
            else:
                found.append(line.strip())
    return found


COMMANDS = list(_commands())
PAGES = {path: help_page(path) for path, _ in COMMANDS}
#: Every example line of every help page, once (the groups' repeat their commands').
EXAMPLES = list(dict.fromkeys(line for path, _ in COMMANDS for line in examples(PAGES[path])))


def _name(path: tuple[str, ...]) -> str:
    return " ".join(("pushrecovery", *path))


def test_every_command_is_covered() -> None:
    from pushrecovery.cli.app import COMMANDS as TABLE

    humanoid = ("simulate", "critical-push", "validate", "campaign")
    assert {_name(path) for path, _ in COMMANDS} == {
        "pushrecovery",
        *(f"pushrecovery {name}" for name in TABLE),
        *(f"pushrecovery humanoid {name}" for name in humanoid),
    }


@pytest.mark.parametrize("path", [path for path, _ in COMMANDS], ids=_name)
def test_every_help_page_has_a_description_and_an_example(path: tuple[str, ...]) -> None:
    page = PAGES[path]
    paragraphs = description(page)
    assert len(paragraphs) >= 2, f"{_name(path)}: a summary line and a paragraph\n{page}"
    summary, text = paragraphs[0], " ".join(paragraphs[1:])
    assert summary.endswith(".") and len(summary.split()) >= 4, summary
    sentences = [s for s in re.split(r"(?<=\.)\s+", text) if len(s.split()) >= 6]
    assert sentences and text.endswith("."), f"{_name(path)}: no sentence in {text!r}"
    lines = examples(page)
    assert lines, f"{_name(path)} --help has no example\n{page}"
    for line in lines:
        words = shlex.split(line)
        assert words[: len(path) + 1] == ["pushrecovery", *path], line
        if isinstance(dict(COMMANDS)[path], click.Group):  # a group's example runs a command
            assert len(words) > len(path) + 1 and not words[len(path) + 1].startswith("-"), line


@pytest.mark.parametrize("path", [path for path, _ in COMMANDS], ids=_name)
def test_every_listed_option_says_what_it_is(path: tuple[str, ...]) -> None:
    command = dict(COMMANDS)[path]
    for param in command.params:
        if isinstance(param, click.Option) and not param.hidden:
            assert param.help, f"{_name(path)} {param.opts[0]} has no help"


def _trial_csv(path: Path) -> None:
    """A LIPM push in mm, the CoP on a capture-point law (Euler at 1 ms, sampled at 100 Hz)."""
    omega, heel, toe = 9.81**0.5, -0.05, 0.15
    x, v, rows = 0.02, 0.0, ["time,com_ap,com_ml,cop_ap,cop_ml"]
    for k in range(2500):
        if k == 1000:
            v += 0.3
        cop = min(toe, max(heel, 2 * (x + v / omega) - 0.02))
        if k % 10 == 0:
            rows.append(f"{k / 1000:.3f},{x * 1000:.4f},3.0,{cop * 1000:.4f},2.0")
        x, v = x + v * 1e-3, v + omega**2 * (x - cop) * 1e-3
    path.write_text("\n".join(rows) + "\n")


#: The input files the examples name, made in the example's directory.
INPUTS = {"trial.csv": _trial_csv}


def _small_report(monkeypatch: pytest.MonkeyPatch) -> None:
    """Let ``report`` write its page with only the bounds section.

    The whole report takes minutes; its sections and grids are tests/test_report.py's. Here
    the command line, the body flags, the output directory and the printed path are checked.
    """
    import pushrecovery.report as report
    from pushrecovery.report import SECTIONS

    write_report = report.write_report

    def small(*args: Any, **kwargs: Any) -> Any:
        return write_report(*args, skip=[key for key in SECTIONS if key != "bounds"], **kwargs)

    monkeypatch.setattr(report, "write_report", small)


@pytest.mark.parametrize("line", EXAMPLES)
def test_every_example_runs(line: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    args = shlex.split(line)[1:]
    for arg in args:
        if arg in INPUTS:
            INPUTS[arg](tmp_path / arg)
    if args[0] == "report":
        _small_report(monkeypatch)
    result = CliRunner().invoke(cli, args, prog_name="pushrecovery")
    assert result.exit_code == 0, f"{line}\n{result.output}\n{result.exception!r}"
    if "--json" in args:
        json.loads(result.stdout)
    for arg in args:  # files are written under out/, here tmp_path/out
        assert not arg.startswith("/"), line
