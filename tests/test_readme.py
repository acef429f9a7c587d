"""The README works as written: its Python example runs and its console outputs are real."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).parent.parent / "README.md"
TEXT = README.read_text()
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


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


def test_readme_python_blocks_run(capsys):
    blocks = re.findall(r"```python\n(.*?)```", TEXT, flags=re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
    assert "recovered" in capsys.readouterr().out


@pytest.mark.parametrize(("command", "expected"), list(console_examples()))
def test_readme_console_output_is_real(command, expected):
    args = command.split()[1:]
    done = subprocess.run(
        [sys.executable, "-m", "pushrecovery", *args], capture_output=True, text=True
    )
    shown = (done.stdout + done.stderr).strip()
    assert same_text_and_numbers(shown, expected), shown


def test_readme_shows_the_two_commands():
    assert "make demo" in TEXT and "make test" in TEXT
