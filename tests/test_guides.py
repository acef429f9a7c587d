"""The guides run as written (docs/guides/*.md): their code blocks are executed, in order.

Per guide, in one namespace and in a fresh working directory (so its ``out/`` files land in a
temporary folder):

- every ```python block runs; a ```text block right after it is its printed output;
- every ``$ pushrecovery ...`` line of a ```console block runs in this process
  (:func:`pushrecovery.cli.main`) and must exit 0; the lines under it, if any, are its output.

Outputs are compared as the README's are: the text exactly, the numbers up to the last digit
shown (integers exactly), and ``...`` stands for any text (a line of ``...``: any lines). A
```sh block is shown to the reader, not run (the full report takes minutes).
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

import pytest

GUIDES = Path(__file__).parent.parent / "docs" / "guides"
NAMES = ("robot-loop", "mujoco", "human-trials")
FENCE = re.compile(r"^```([\w-]*)[^\n]*\n(.*?)^```[ \t]*$", re.M | re.S)
NUMBER = r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
TOKEN = re.compile(rf"(\.\.\.|{NUMBER})")


@dataclass(frozen=True)
class Block:
    kind: str  # "python", "console", "text", ...
    body: str
    line: int  # of the block's first code line in the guide
    follows: bool  # only blank lines between the previous block's fence and this one


def blocks(text: str) -> list[Block]:
    found, end = [], None
    for match in FENCE.finditer(text):
        gap = text[end : match.start()] if end is not None else "x"
        line = text.count("\n", 0, match.start(2)) + 1
        found.append(Block(match.group(1), match.group(2), line, not gap.strip()))
        end = match.end()
    return found


def same_output(actual: str, expected: str) -> bool:
    """Whether ``actual`` is ``expected``: numbers to the digits shown, ``...`` any text."""
    actual = "\n".join(line.rstrip() for line in actual.strip().splitlines())
    expected = "\n".join(line.rstrip() for line in expected.strip().splitlines())
    pattern, numbers = "", []
    for i, part in enumerate(TOKEN.split(expected)):
        if i % 2 == 0:
            pattern += re.escape(part)
        elif part == "...":
            pattern += ".*?"
        else:
            pattern += rf"({NUMBER}|-?inf|nan)"
            numbers.append(part)
    match = re.fullmatch(pattern, actual, flags=re.S)
    if match is None:
        return False
    for shown, want in zip(match.groups(), numbers, strict=True):
        if re.fullmatch(r"-?\d+", want):  # counts, sizes: exactly
            if shown != want:
                return False
            continue
        try:
            got, value = float(shown), float(want)
        except ValueError:
            return False
        last_digit = float(Decimal(10) ** Decimal(want).as_tuple().exponent)
        if not abs(got - value) <= last_digit + 1e-9 * abs(value):
            return False
    return True


def run_python(source: str, namespace: dict[str, object], where: str, line: int) -> str:
    code = compile("\n" * (line - 1) + source, where, "exec")  # tracebacks name the guide line
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(code, namespace)
    return out.getvalue()


def console_commands(body: str) -> list[tuple[str, str]]:
    commands = []
    for chunk in re.split(r"^\$ ", body, flags=re.M)[1:]:
        lines = chunk.splitlines()
        command = lines.pop(0)
        while command.endswith("\\") and lines:
            command = command[:-1] + " " + lines.pop(0).strip()
        commands.append((command.strip(), "\n".join(lines)))
    return commands


def run_command(command: str) -> tuple[int, str]:
    from pushrecovery.cli import main

    args = shlex.split(command)
    assert args[0] == "pushrecovery", f"not a pushrecovery command: {command}"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main(args[1:])
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return code, out.getvalue() + err.getvalue()


def run_guide(text: str, name: str) -> int:
    """Run every block of a guide; return how many blocks and commands ran."""
    namespace: dict[str, object] = {"__name__": f"guide_{name.replace('-', '_')}"}
    ran, printed = 0, None
    where = f"docs/guides/{name}.md"
    for block in blocks(text):
        if block.kind == "python":
            printed = run_python(block.body, namespace, where, block.line)
            ran += 1
            continue
        if block.kind == "text" and block.follows and printed is not None:
            assert same_output(printed, block.body), (
                f"{where}:{block.line}: the block above printed\n{printed}"
            )
        elif block.kind == "console":
            for command, expected in console_commands(block.body):
                code, shown = run_command(command)
                assert code == 0, f"{where}:{block.line}: `{command}` exited {code}:\n{shown}"
                if expected.strip():
                    assert same_output(shown, expected), (
                        f"{where}:{block.line}: `{command}` printed\n{shown}"
                    )
                ran += 1
        printed = None
    return ran


@pytest.mark.parametrize("name", NAMES)
def test_guide_runs(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = (GUIDES / f"{name}.md").read_text()
    assert run_guide(text, name) > 0


@pytest.mark.parametrize("name", NAMES)
def test_guide_is_short(name):
    assert len((GUIDES / f"{name}.md").read_text().splitlines()) <= 400


GUIDE = """# A guide

```python
x = 3
print(f"x = {x * 0.5:.3f} m")
```

```text
x = 1.500 m
```
"""


def test_collector_checks_the_outputs_and_fails_on_a_raising_block():
    assert run_guide(GUIDE, "example") == 1
    with pytest.raises(AssertionError, match="printed"):
        run_guide(GUIDE.replace("1.500", "1.600"), "example")
    with pytest.raises(ZeroDivisionError):
        run_guide(GUIDE.replace("x * 0.5", "x / 0"), "example")


def test_outputs_compare_numbers_to_the_digits_shown():
    assert same_output("margin 0.12345 m\n", "margin 0.1235 m")
    assert not same_output("margin 0.12345 m", "margin 0.1250 m")
    assert not same_output("3 steps", "4 steps")
    assert same_output("a\nb 1\nc\nd", "a\n...\nd")
    assert same_output("median 5.5 µs", "median ... µs")
