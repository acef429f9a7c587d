"""The README works as written: its Python examples print what they say, its outputs are real.

Every ```python block runs (in a fresh namespace, in a scratch directory) and its output must be
its ``# prints: ...`` comments, in order. Every ```console block's ``$ pushrecovery ...`` command
runs in the same directory (the human-trials example analyses the file its Python block wrote)
and its output must be the one shown; a line ``...`` stands for lines left out. Numbers are
compared to 1e-6, relative.
"""

import contextlib
import io
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).parent.parent / "README.md"
TEXT = README.read_text()
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")
PYTHON_BLOCKS = re.findall(r"```python\n(.*?)```", TEXT, flags=re.S)
PRINTS = re.compile(r"^# prints: (.*)$", flags=re.M)


def console_examples():
    for block in re.findall(r"```console\n(.*?)```", TEXT, flags=re.S):
        for chunk in re.split(r"^\$ ", block, flags=re.M)[1:]:
            command, _, output = chunk.partition("\n")
            yield command.strip(), output.strip()


def same_text_and_numbers(actual, expected):
    """Equal up to the last printed digits of the numbers."""
    if NUMBER.sub("#", actual) != NUMBER.sub("#", expected):
        return False
    pairs = zip(NUMBER.findall(actual), NUMBER.findall(expected), strict=True)
    return all(abs(float(a) - float(b)) <= 1e-6 * (1 + abs(float(b))) for a, b in pairs)


def shown_as(actual, expected):
    """``actual`` is ``expected`` where the lines ``...`` of ``expected`` stand for any lines."""
    lines = actual.splitlines()
    parts = re.split(r"^\.\.\.$", expected, flags=re.M)
    segments = [part.strip("\n").splitlines() for part in parts]

    def at(start, segment):
        return start + len(segment) <= len(lines) and all(
            same_text_and_numbers(lines[start + i], line) for i, line in enumerate(segment)
        )

    position = 0
    for index, segment in enumerate(segments):
        if not segment:
            continue
        if index == 0:
            starts = [position]  # the first lines are shown
        elif index == len(segments) - 1:
            starts = [max(position, len(lines) - len(segment))]  # and the last
        else:
            starts = range(position, len(lines))
        found = next((start for start in starts if at(start, segment)), None)
        if found is None:
            return False
        position = found + len(segment)
    return not segments[-1] or position == len(lines)


@pytest.fixture(scope="module")
def readme_dir(tmp_path_factory):
    """A scratch directory in which the Python examples have run; their outputs by block."""
    from pushrecovery.control import CONTROLLERS

    where = tmp_path_factory.mktemp("readme")
    outputs = []
    before, registered = Path.cwd(), dict(CONTROLLERS)
    os.chdir(where)
    try:
        for block in PYTHON_BLOCKS:
            printed = io.StringIO()
            with contextlib.redirect_stdout(printed):
                exec(compile(block, "README.md", "exec"), {"__name__": "readme"})
            outputs.append(printed.getvalue().strip())
    finally:
        os.chdir(before)
        CONTROLLERS.clear()
        CONTROLLERS.update(registered)  # the example's policy leaves the registry as it was
    return where, outputs


def test_readme_has_an_example_per_user():
    assert len(PYTHON_BLOCKS) >= 3 and len(list(console_examples())) >= 3
    assert all(PRINTS.search(block) for block in PYTHON_BLOCKS)


@pytest.mark.parametrize("index", range(len(PYTHON_BLOCKS)))
def test_readme_python_block_prints_what_it_says(readme_dir, index):
    _, outputs = readme_dir
    expected = "\n".join(PRINTS.findall(PYTHON_BLOCKS[index]))
    assert same_text_and_numbers(outputs[index], expected), outputs[index]


@pytest.mark.parametrize(("command", "expected"), list(console_examples()))
def test_readme_console_output_is_real(readme_dir, command, expected):
    where, _ = readme_dir
    assert command.startswith("pushrecovery ")
    args = command.split()[1:]
    done = subprocess.run(
        [sys.executable, "-m", "pushrecovery", *args], capture_output=True, text=True, cwd=where
    )
    shown = (done.stdout + done.stderr).strip()
    assert shown_as(shown, expected), shown


def test_ellipsis_stands_for_lines_left_out():
    assert shown_as("a 1\nb 2\nc 3", "a 1\n...\nc 3")
    assert shown_as("a 1\nb 2\nc 3", "a 1\n...")
    assert shown_as("a 1\nb 2\nc 3", "a 1\nb 2\nc 3")
    assert not shown_as("a 1\nb 2\nc 3", "a 1\n...\nb 2")  # b is not the last line
    assert not shown_as("a 1\nb 2\nc 3", "b 2\n...")  # the first line is shown
    assert not shown_as("a 1\nb 2\nc 3", "a 1\n...\nc 4")


def test_readme_shows_the_two_commands():
    assert "make demo" in TEXT and "make test" in TEXT
