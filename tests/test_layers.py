"""The floors of docs/architecture.md hold: import contracts, and plots that leave no trace."""

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
