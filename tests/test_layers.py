"""The floors of docs/architecture.md hold: import contracts, and plots that leave no trace."""

import ast
import collections
import re
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib
import numpy as np
import pytest

from pushrecovery import load_params

ROOT = Path(__file__).resolve().parent.parent


def test_the_import_contracts_hold():
    lint = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    if lint is None:
        pytest.fail("lint-imports is missing: make test installs the dev extras")
    run = subprocess.run([lint], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-3000:]
    assert "0 broken" in run.stdout


def test_plots_do_not_switch_the_callers_backend(tmp_path):
    from pushrecovery.experiments.paper_figures import hip_runs
    from pushrecovery.plots.figures import fig5, fig9
    from pushrecovery.plots.runs import save_run

    before = matplotlib.get_backend()
    params = load_params()
    runs = hip_runs(params, "bang-bang", (0.5,))
    fig9(params, ("png",), tmp_path)
    fig5(params, runs, runs, ("png",), tmp_path)
    save_run(runs[0], params, tmp_path / "run.png")
    assert matplotlib.get_backend() == before
    assert {p.name for p in tmp_path.iterdir()} >= {"fig9.png", "fig5a.png", "fig5b.png", "run.png"}
    assert np.isfinite(runs[0].states).all()


def test_drawing_never_imports_pyplot():
    script = (
        "import sys, tempfile, pathlib\n"
        "from pushrecovery import load_params\n"
        "from pushrecovery.plots.figures import fig9, fig10\n"
        "out = pathlib.Path(tempfile.mkdtemp())\n"
        "fig9(load_params(), ('png',), out); fig10(load_params(), ('png',), out)\n"
        "print('matplotlib.pyplot' in sys.modules)\n"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "False"


# The contracts import-linter cannot state, read from the source with ast (issue 31).
SRC = ROOT / "src" / "pushrecovery"


def _modules(root=SRC):
    """(path, dotted parts, tree) of every module below ``root`` (a ``pushrecovery`` folder)."""
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root.parent).with_suffix("").parts
        yield path.relative_to(root), parts, ast.parse(path.read_text(encoding="utf-8"))


def _imports(tree):
    """(module, imported names) of every absolute import statement, at any depth."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, ()
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module, tuple(alias.name for alias in node.names)


def _private(name):
    return name.startswith("_") and not name.startswith("__")


def private_crossings(modules):
    """Imports of another subpackage's ``_name`` (module or name); a top-level module owns none."""
    found = []
    for path, parts, tree in modules:
        own = parts[1] if len(parts) > 2 else None
        for module, names in _imports(tree):
            words = module.split(".")
            if words[0] != "pushrecovery" or (len(words) > 1 and words[1] == own):
                continue
            if any(map(_private, words[1:])) or any(map(_private, names)):
                found.append(f"{path}: {module} {names}")
    return found


def numba_outside_kernels(modules):
    return [
        str(path)
        for path, parts, tree in modules
        if parts[1] != "kernels" and any(m.split(".")[0] == "numba" for m, _ in _imports(tree))
    ]


def kernels_importing_the_project(modules):
    return [
        f"{path}: {module}"
        for path, parts, tree in modules
        if parts[1] == "kernels"
        for module, _ in _imports(tree)
        if module.split(".")[0] == "pushrecovery" and module.split(".")[1:2] != ["kernels"]
    ]


def controllers_outside_control(modules):
    def named(base):
        return base.id if isinstance(base, ast.Name) else getattr(base, "attr", "")

    return [
        f"{path}: {node.name}"
        for path, parts, tree in modules
        if parts[1] != "control"
        for node in ast.walk(tree)
        if isinstance(node, ast.ClassDef)
        and any(named(base).endswith("Controller") for base in node.bases)
    ]


def long_modules_without_reason(modules):
    """Modules over 400 lines whose docstring does not say why (issue 31: split by concept)."""
    found = []
    for path, _, tree in modules:
        lines = max((getattr(node, "end_lineno", 0) or 0) for node in ast.walk(tree))
        if lines > 400 and "Over 400 lines" not in (ast.get_docstring(tree) or ""):
            found.append(f"{path}: {lines} lines")
    return found


def prefix_groups(modules):
    """Sibling modules or packages that share a prefix (the name before ``_`` or a digit).

    A group of files sharing a prefix is a package (issue 31): ``spec`` and ``spec3d``, or
    ``trial_rows`` and ``trial_steps``, are one concept's parts.
    """
    siblings = collections.defaultdict(set)
    for path, _, _ in modules:
        if path.name != "__init__.py":
            siblings[path.parent].add(path.stem)
        elif path.parent != Path("."):
            siblings[path.parent.parent].add(path.parent.name)
    found = []
    for folder, names in sorted(siblings.items()):
        groups = collections.defaultdict(list)
        for name in sorted(names):
            groups[re.split(r"[_\d]", name)[0]].append(name)
        found += [f"{folder}: {', '.join(group)}" for group in groups.values() if len(group) > 1]
    return found


CHECKS = (
    private_crossings,
    long_modules_without_reason,
    prefix_groups,
    numba_outside_kernels,
    kernels_importing_the_project,
    controllers_outside_control,
)


@pytest.mark.parametrize("check", CHECKS, ids=lambda c: c.__name__)
def test_the_source_keeps_the_contract(check):
    assert check(_modules()) == []


@pytest.mark.parametrize("check", CHECKS, ids=lambda c: c.__name__)
def test_each_contract_check_sees_its_violation(check, tmp_path):
    root = tmp_path / "pushrecovery"
    for folder in ("kernels", "sim", "control"):
        (root / folder).mkdir(parents=True)
    (root / "kernels" / "bad.py").write_text("from pushrecovery.models import stepping\n")
    (root / "sim" / "bad.py").write_text(
        "import numba\nfrom pushrecovery.control._x import y\n"
        "class Mine(base.Controller):\n    pass\n"
    )
    (root / "control" / "fine.py").write_text(
        "from pushrecovery.control._x import y\nclass Mine(Controller):\n    pass\n"
    )
    (root / "sim" / "long.py").write_text('"""A module."""\n' + "x = 1\n" * 410)
    (root / "control" / "fine3d.py").write_text('"""fine\'s 3-D twin, beside it."""\n')
    assert len(check(_modules(root))) == 1
