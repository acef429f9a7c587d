"""kernels.jit: a one-state command runs the kernels as plain Python, with the compiled numbers.

``pushrecovery classify`` and ``capture-region`` run from a command line of their own load no
numba (their kernels run as the Python they are written in). The plain run must print what
the compiled library prints, to the last digit: random states, stances, foot poses, landing
yaws, N-step regions and state uncertainty, each compared as JSON text (``repr`` of a float
round-trips, so equal text is equal bits).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from pushrecovery.cli import main

# A fresh process, switched to plain Python before anything computes, runs the commands with
# this module's _run.
PLAIN_RUNNER = f"""
import json, sys
from pushrecovery.kernels.jit import run_as_python
run_as_python()
sys.path.insert(0, {str(Path(__file__).parent)!r})
from test_plain_kernels import _run
outputs = [_run(argv) for argv in json.load(sys.stdin)]
json.dump({{"outputs": outputs, "numba": "numba" in sys.modules}}, sys.stdout)
"""


# Commands whose plain run once printed another last digit: the interpreter's own math.hypot
# (the first), numba's unstable argsort in the Minkowski sum (the others).
FOUND = [
    "classify --x 0.0540 --xdot 1.996 --y -0.0200 --ydot 0.487 "
    "--cov 0.0001,0,0,0,0,0.0001,0,0,0,0,0.004,0,0,0,0,0.004 --json",
    "capture-region --x 0.0 --xdot 1.0 --steps 3 --json",
    "capture-region --x 0.02 --xdot 1.4 --ydot -0.7 --steps 2 --stance left "
    "--left-foot 0.05,0.1,0.3 --json",
    "classify --x 0.01 --xdot 1.1 --ydot -0.9 --stance right --right-foot 0.1,-0.1,-0.4 "
    "--landing-yaw 0.2 --json",
    "classify --x 0.0 --xdot 0.9 --y 0.02 --latency 0.02 --json",
]


def _python(script: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    """Run ``script`` in a fresh interpreter (numba's settings from the environment left out)."""
    done = subprocess.run(
        [sys.executable, "-c", script],
        input=stdin,
        capture_output=True,
        text=True,
        env={k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")},
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    return done


def _commands(seed: int, count: int) -> list[list[str]]:
    """Random one-state commands: sagittal and planar verdicts, plans and regions."""
    rng = np.random.default_rng(seed)
    commands = []
    for i in range(count):
        x, y = rng.uniform(-0.04, 0.1), rng.uniform(-0.05, 0.05)
        scale = rng.choice([0.7, 2.5, 7.0])  # near the ankle and hip bounds, steps, falls
        xdot, ydot = scale * rng.uniform(-0.5, 1.0), scale * rng.uniform(-0.4, 0.4)
        state = ["--x", f"{x:.4f}", "--xdot", f"{xdot:.3f}"]
        plane = ["--y", f"{y:.4f}", "--ydot", f"{ydot:.3f}"]
        stance = str(rng.choice(["double", "left", "right"]))
        yaw = rng.uniform(-0.5, 0.5)
        feet = ["--stance", stance, "--left-foot", f"0.02,0.1,{yaw:.3f}"]
        kind = i % 5
        if kind == 0:
            commands.append(["classify", *state, "--json"])
        elif kind == 1:
            landing = ["--landing-yaw", f"{rng.uniform(-0.4, 0.4):.3f}"]
            commands.append(["classify", *state, *plane, *feet, *landing, "--json"])
        elif kind == 2:
            cov = ",".join(f"{v:g}" for v in np.diag([1e-4, 1e-4, 4e-3, 4e-3]).ravel())
            commands.append(["classify", *state, *plane, "--cov", cov, "--json"])
        elif kind == 3:
            steps = ["--steps", str(rng.integers(1, 4))]
            commands.append(["capture-region", *state, *plane, *steps, *feet, "--json"])
        else:
            timing = ["--timing", "after", "--steps", "2"]
            commands.append(["capture-region", *state, *plane, *timing, "--json"])
    return commands


def _run(argv: list[str]) -> str:
    """The command's output and exit status, run in this process."""
    out, code = io.StringIO(), None
    with contextlib.redirect_stdout(out):
        try:
            main(argv)
        except SystemExit as exc:
            code = exc.code
    return f"{out.getvalue()}|exit {code}"


def test_plain_kernels_print_the_compiled_numbers():
    commands = [line.split() for line in FOUND] + _commands(seed=7, count=80)
    plain = json.loads(_python(PLAIN_RUNNER, json.dumps(commands)).stdout)
    assert plain["numba"] is False
    verdicts, refused = set(), 0
    for argv, text in zip(commands, plain["outputs"], strict=True):
        assert text == _run(argv), argv  # this process: compiled
        body, _, code = text.rpartition("|exit ")
        refused += code == "2"
        if argv[0] == "classify" and code in ("None", "0"):
            verdicts.add(json.loads(body)["strategy"])
    assert verdicts == {"ankle", "hip", "step", "fall"}  # every branch ran
    assert refused <= 4


def test_a_one_state_command_line_loads_no_numba():
    script = (
        "import sys\n"
        "sys.argv = ['pushrecovery', 'classify', '--x', '0', '--xdot', '1.4', '--y', '0.02',"
        " '--json']\n"
        "from pushrecovery.cli import main\n"
        "try:\n    main()\nfinally:\n    print('numba' in sys.modules, file=sys.stderr)\n"
    )
    done = _python(script)
    assert done.stderr.strip() == "False"
    assert json.loads(done.stdout)["strategy"] == "step"


def test_main_with_arguments_keeps_the_compiled_kernels():
    """A process that calls ``main(argv)`` (a test, a script) is not switched to plain Python."""
    script = (
        "import contextlib, io, sys\n"
        "from pushrecovery.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    main(['classify', '--x', '0', '--xdot', '1.4', '--y', '0.02', '--json'])\n"
        "from pushrecovery.kernels.placement import place_tables\n"
        "print(type(place_tables).__name__)\n"
    )
    assert _python(script).stdout.split() == ["CPUDispatcher"]
