"""Fuzzing cases: random command lines of every command, mutated C3D, CSV, TOML and MJCF files,
and folders of good and bad trials.

Every draw comes from one ``random.Random(seed)``: a campaign is reproducible from its seed.
The options and their types are read from the commands themselves (click's parameters), so a
new option is fuzzed without touching this file.
"""

from __future__ import annotations

import importlib
import math
import os
import random
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click

from pushrecovery.cli.app import COMMANDS

FLOATS = [
    "0", "-0.0", "0.1", "-0.3", "1", "2.5", "-2.5", "9.81", "72", "0.05", "1e-3", "1e-9",
    "1e-300", "5e-324", "1e15", "1e300", "-1e300", "1.7976931348623157e308", "nan", "-nan",
    "inf", "-inf", "abc", "", "1e", "0x10", "1_0", "3000", "-1",
]  # fmt: skip
INTS = ["0", "1", "-1", "2", "5", "100", "3000", "1000000000", "99999999999999999999", "abc", ""]
STRINGS: dict[str, list[str]] = {
    "--option": [
        "horizon=30",
        "horizon=3000",
        "horizon=0",
        "dt=1e-9",
        "dt=0.01",
        "gamma=nan",
        "gamma=1",
        "switch_time=-1",
        "switch_time=0.2",
        "x",
        "=",
        "horizon=1e400",
        "solver=nope",
    ],
    "--param": [
        "torque_max=50:150:50",
        "mass=10:5",
        "mass=1:2:0",
        "x=1:2:3",
        "torque_max=0:1e9:1e-9",
        "gravity=nan:1:1",
        "mass",
        "mass=1:2:1:4",
    ],
    "--left-foot": [
        "[[0,0],[0.2,0],[0,0.1]]",
        "[[-0.05,-0.05],[0.15,-0.05],[0.15,0.05],[-0.05,0.05]]",
        "[[0,0]]",
        "junk",
        "[[nan,0],[1,1],[0,1]]",
        "[[0,0],[1e300,0],[0,1e300]]",
        "[]",
    ],
    "--scheduler": ["tcp://", "tcp://127.0.0.1:99999", "xyz", "tcp://:1"],
    "--preset": ["paper", "nope", ""],
    "--model": [
        "stepping",
        "pendulum",
        "flywheel",
        "torso",
        "biped",
        "foot",
        "biped3d",
        "g1",
        "nope",
        "",
    ],
    "--controller": ["recovery", "ankle-pd", "mpc", "bang-bang", "nope"],
    "--com-marker": ["CoM", "", "nope"],
    "--foot": ["left:LHEE,LTOE", "junk", ""],
}
STRINGS["--right-foot"] = STRINGS["--left-foot"]
#: Commands that may run for minutes on valid input: fuzzed with one invalid body value, so
#: that what is checked is that they refuse it before any work.
HEAVY = {
    "report",
    "figures",
    "validate",
    "campaign",
    "humanoid simulate",
    "humanoid critical-push",
    "humanoid validate",
    "humanoid campaign",
}
INVALID_BODY = [
    ["--mass", "nan"], ["--gravity", "1e15"], ["--com-height", "-1"], ["--toe", "inf"],
    ["--leg-length", "1e300"], ["--max-steps", "0.5"], ["--heel", "0.3"],
]  # fmt: skip
SKIP = {"--help", "--version"}
#: Number texts click reads as NaN or an infinity: no option of a number takes one.
NONFINITE = {"nan", "inf"}


@dataclass(frozen=True)
class Case:
    """One command line, and what it exercises (the input class of the summary).

    ``expect``: for a folder of trials, how many good ones the batch must keep. ``invalid``:
    the options given a value no documented input can be (NaN or an infinity for a number):
    the command must refuse it (exit 2), not end well.
    """

    kind: str
    args: list[str]
    expect: int | None = None
    invalid: tuple[str, ...] = ()


def _commands() -> dict[str, click.Command]:
    """Every command by its words: a group's (``humanoid``) as ``"humanoid simulate"``."""
    found = {}
    for name, (path, _) in COMMANDS.items():
        module, _, attribute = path.partition(":")
        command = getattr(importlib.import_module(module), attribute)
        if isinstance(command, click.Group):
            found |= {f"{name} {sub}": c for sub, c in command.commands.items()}
        else:
            found[name] = command
    return found


def _value(rng: random.Random, param: click.Parameter, name: str, folder: Path) -> list[str]:
    kind = param.type
    count = param.nargs if param.nargs > 1 else 1
    if name in STRINGS:
        return [rng.choice(STRINGS[name])]
    if isinstance(kind, click.Choice):
        return [rng.choice([*map(str, kind.choices), "nope"])]
    if isinstance(kind, click.types.IntParamType):
        return [rng.choice(INTS) for _ in range(count)]
    if isinstance(kind, click.types.FloatParamType):
        return [rng.choice(FLOATS) for _ in range(count)]
    if isinstance(kind, click.Path):
        inside = [str(folder / name) for name in ("out", "plot.png", "x.txt")]
        choices = [*inside, "/proc/version/x.png", "/dev/null", "/dev/zero", str(folder), "no.toml"]
        return [rng.choice(choices)]
    return [rng.choice(["", "x", "0", "nan"])]


def command_case(rng: random.Random, folder: Path) -> Case:
    """A random command line of a random command."""
    commands = _commands()
    name = rng.choice(sorted(commands))
    command = commands[name]
    args = name.split()
    params = [p for p in command.params if isinstance(p, click.Option) and p.opts[0] not in SKIP]
    invalid: list[str] = []
    for param in rng.sample(params, k=min(len(params), rng.choice([0, 1, 2, 3, 4, 6]))):
        option = max(param.opts, key=len)
        if param.is_flag:
            args.append(option)
            continue
        values = _value(rng, param, option, folder)
        args += [option, *values]
        number = isinstance(param.type, click.types.FloatParamType) and option not in STRINGS
        if number and any(v.lower().lstrip("+-") in NONFINITE for v in values):
            invalid.append(option)
    if name in ("analyze", "campaign", "humanoid campaign"):
        args += ["--out", str(folder / "out")]
    if name == "analyze":
        args.insert(1, rng.choice(["missing.c3d", str(folder), "/dev/null"]))
    if name in HEAVY or "mujoco" in args:
        args += rng.choice(INVALID_BODY)
    return Case(f"cli:{name}", args, invalid=tuple(invalid))


# --- files ------------------------------------------------------------------------------------
def mutate_bytes(rng: random.Random, data: bytes, head: int = 8192) -> bytes:
    """Flip, insert, delete or truncate a few bytes (most in the first ``head`` bytes)."""
    out = bytearray(data)
    for _ in range(rng.choice([1, 1, 2, 3, 5, 8])):
        if not out:
            break
        limit = min(len(out), head) if rng.random() < 0.8 else len(out)
        at = rng.randrange(limit)
        action = rng.random()
        if action < 0.6:
            out[at] = rng.randrange(256)
        elif action < 0.75:
            out[at] = rng.choice([0, 0xFF, 0x7F, 0x80])
        elif action < 0.85:
            out.insert(at, rng.randrange(256))
        elif action < 0.95:
            del out[at]
        else:
            del out[at:]
    return bytes(out)


def mutate_text(rng: random.Random, text: str) -> str:
    """Replace numbers, drop or repeat lines, rename a header, or flip bytes of a text file."""
    lines = text.splitlines()
    for _ in range(rng.choice([1, 2, 3])):
        if not lines:
            break
        i = rng.randrange(len(lines))
        action = rng.random()
        if action < 0.35:
            cells = lines[i].split(",")
            j = rng.randrange(len(cells))
            cells[j] = rng.choice(["nan", "inf", "-1e309", "1e300", "", "x", "0", "-0", "1e-320"])
            lines[i] = ",".join(cells)
        elif action < 0.5:
            del lines[i]
        elif action < 0.6:
            lines.insert(i, lines[i])
        elif action < 0.7:
            lines[i] = lines[i].replace(",", ";", 1)
        elif action < 0.8:
            lines = lines[: max(1, i)]
        else:
            raw = mutate_bytes(rng, "\n".join(lines).encode(), head=1 << 20)
            return raw.decode("latin-1")
    return "\n".join(lines) + "\n"


def toml_case(rng: random.Random, folder: Path, index: int) -> Case:
    """``bounds --params FILE`` with a mutated parameter file."""
    values = {"mass": "72.0", "com_height": "1.0", "gravity": "9.81", "heel": "-0.05",
              "toe": "0.15", "torque_max": "100.0", "min_step_time": "0.2"}  # fmt: skip
    choices = ["nan", "inf", "-1", "0", "1e15", "1e300", '"heavy"', "[1, 2]", "{a = 1}", "true",
               "1979-05-27", "1e-300", "-0.0"]  # fmt: skip
    lines = [f"{k} = {v}" for k, v in values.items()]
    for _ in range(rng.choice([1, 2])):
        i = rng.randrange(len(lines))
        lines[i] = lines[i].split("=")[0] + "= " + rng.choice(choices)
    text = "[body]\n" + "\n".join(lines) + "\n"
    if rng.random() < 0.4:
        text = mutate_bytes(rng, text.encode(), head=1 << 20).decode("latin-1")
    if rng.random() < 0.1:
        text = "a = " + "{b = " * rng.choice([10, 200, 2000]) + "1" + "}" * 2000 + "\n"
    path = folder / f"case{index}.toml"
    path.write_text(text, encoding="latin-1")
    command = rng.choice(
        [["bounds"], ["classify", "--x", "0", "--xdot", "0.5"], ["step", "--v0", "1"]]
    )
    return Case("file:toml", [*command, "--params", str(path), "--json"])


def csv_text(rng: random.Random) -> str:
    """A valid trial: the CoM of a pendulum swaying, with its CoP, at 100 Hz."""
    rows = ["time,com_ap,com_ml,cop_ap,cop_ml"]
    amplitude = rng.choice([0.01, 0.03])
    for i in range(rng.choice([30, 200])):
        t = i / 100.0
        rows.append(
            f"{t:.2f},{amplitude * math.sin(3 * t):.6f},0,{amplitude * math.sin(3 * t) * 1.1:.6f},0"
        )
    return "\n".join(rows) + "\n"


def csv_case(rng: random.Random, folder: Path, index: int) -> Case:
    """``analyze FILE`` with a mutated CSV trial."""
    path = folder / f"case{index}.csv"
    path.write_text(mutate_text(rng, csv_text(rng)), encoding="latin-1")
    return Case(
        "file:csv",
        ["analyze", str(path), "--mass", "70", "--out", str(folder / f"out{index}"), "--json"],
    )


def c3d_case(rng: random.Random, folder: Path, index: int, sources: list[Path]) -> Case:
    """``analyze FILE`` with a mutated C3D file (biomdp's and one written by the project)."""
    source = rng.choice(sources)
    path = folder / f"case{index}.c3d"
    path.write_bytes(mutate_bytes(rng, source.read_bytes()))
    extra: list[Any] = rng.choice([[], ["--json"], ["--units", "mm"]])
    return Case("file:c3d", ["analyze", str(path), "--out", str(folder / f"out{index}"), *extra])


# --- MJCF files and folders of trials ---------------------------------------------------------
_MJCF: list[str] = []


def _biped3d_xml() -> str:
    """The generated biped3d's MJCF (once per worker process: a mutation's source)."""
    if not _MJCF:
        from pushrecovery import load_params
        from pushrecovery.sim.mujoco.humanoid3d.biped3d import build_biped3d

        _MJCF.append(build_biped3d(load_params()).to_xml())
    return _MJCF[0]


def mjcf_case(rng: random.Random, folder: Path, index: int) -> Case:
    """``humanoid simulate --model FILE.xml`` with a mutated MJCF file (the generated biped3d).

    Numbers become NaN, huge or negative, elements and lines go, the file is cut or its bytes
    flipped: every file is refused in one line or simulated (for 0.05 s).
    """
    lines = _biped3d_xml().splitlines()
    for _ in range(rng.choice([1, 2, 3])):
        i = rng.randrange(len(lines))
        action = rng.random()
        if action < 0.4 and '"' in lines[i]:
            parts = lines[i].split('"')
            j = rng.randrange(1, len(parts), 2) if len(parts) > 2 else 0
            parts[j] = rng.choice(["nan", "inf", "-1", "0", "1e300", "", "x", "1 2", "-0"])
            lines[i] = '"'.join(parts)
        elif action < 0.6:
            del lines[i]
        elif action < 0.7:
            lines = lines[: max(1, i)]
        elif action < 0.8:
            lines.insert(i, rng.choice(["<include file='/dev/zero'/>", "<!--", "<body>", "&x;"]))
        else:
            raw = mutate_bytes(rng, "\n".join(lines).encode(), head=1 << 20)
            lines = raw.decode("latin-1").splitlines() or [""]
    path = folder / f"case{index}.xml"
    path.write_text("\n".join(lines) + "\n", encoding="latin-1")
    return Case(
        "file:mjcf",
        ["humanoid", "simulate", "--model", str(path), "--duration", "0.05", "--json"],
    )


def folder_case(rng: random.Random, folder: Path, index: int) -> Case:
    """``analyze FOLDER`` over a folder of good and bad trials: each bad one an error row.

    Good trials (quiet standing) beside a FIFO, a symlink loop, a link to ``/dev/zero``, an
    empty file, a folder named like a trial, a trial 60 folders deep, odd names and mutated
    trials; sometimes thousands of other files. ``expect`` is the number of good trials the
    batch must keep (its ``analysed`` count).
    """
    data = folder / "data"
    data.mkdir()
    good = rng.choice([1, 2, 5, 12])
    if rng.random() < 0.2:
        for k in range(3000):
            (data / f"notes{k}.txt").write_text("not a trial\n")
    for k in range(good):
        (data / f"good{k}.csv").write_text(csv_text(random.Random(k)))
    bad = rng.sample(["fifo", "loop", "zero", "empty", "dir", "deep", "name", "mutated"], 3)
    if "fifo" in bad:
        os.mkfifo(data / "fifo.csv")
    if "loop" in bad:
        (data / "loop.c3d").symlink_to(data / "loop.c3d")
    if "zero" in bad:
        (data / "zero.c3d").symlink_to("/dev/zero")
    if "empty" in bad:
        (data / "empty.csv").write_bytes(b"")
    if "dir" in bad:
        (data / "folder.csv").mkdir()
    if "deep" in bad:
        deep = data.joinpath(*(["n" * 40] * 60))
        deep.mkdir(parents=True)
        (deep / "deep.csv").write_text(csv_text(rng))
        good += 1
    if "name" in bad:
        (data / "new\nline é.csv").write_text(csv_text(rng))
        good += 1
    if "mutated" in bad:
        (data / "mutated.csv").write_text(mutate_text(rng, csv_text(rng)), encoding="latin-1")
    args = ["analyze", str(data), "--mass", "70", "--out", str(folder / "out"), "--json"]
    return Case("folder", args, expect=good)
