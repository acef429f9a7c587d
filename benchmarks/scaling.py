"""The scaling curve of campaigns (issue 17): pushes against wall time on 1 and 2 workers and Dask.

Random pushes (``samples``) of the analytic ``pendulum`` + ``ankle-pd`` and ``stepping`` +
``recovery``, at several campaign sizes, each run in a fresh process (so that its peak memory
is its own) on a local pool of 1 and 2 workers and on a Dask ``LocalCluster`` of 2 one-thread
workers started beforehand (its start-up is not counted; a real cluster's is not either).

Printed per size: wall time and pushes/s for each, the speed-up of 2 local workers, the Dask
overhead (2 x the Dask wall time minus the 1-worker wall time, over the 1-worker wall time: the
share of the work spent on anything but simulating, start-up and join included), and the
parent process's peak memory. Writes the curve to ``out/scaling.png`` and the numbers to
``out/scaling.json``.

    .venv/bin/python benchmarks/scaling.py            # sizes up to 10**5 (about 10 minutes)
    .venv/bin/python benchmarks/scaling.py --million  # and 10**6 pendulum pushes (+5 minutes)
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

RUN = r"""
import json, resource, sys, time
from pathlib import Path
from pushrecovery import load_params
from pushrecovery.campaign import CampaignSpec, run_campaign

model, controller, size, batch, where, out = sys.argv[1:7]
spec = CampaignSpec("analytic", model, controller, load_params(), samples=int(size), seed=0,
                    x0=(-0.04, 0.11, 1.0),
                    xdot=(-0.9, 0.9, 1.0) if model == "pendulum" else (-3.5, 3.5, 1.0),
                    batch_size=int(batch))
kwargs = {"workers": int(where)} if where.isdigit() else {"scheduler": where}
start = time.perf_counter()
run_campaign(spec, Path(out), **kwargs)
wall = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"wall": wall, "peak_mb": peak}))
"""

#: (model, controller, sizes, largest batch): batches of at most about 2 s of work each.
CASES = (
    ("pendulum", "ankle-pd", (10**3, 10**4, 10**5), 10_000),
    ("stepping", "recovery", (10**3, 10**4), 1_000),
)


def _run(model: str, controller: str, size: int, batch: int, where: str, root: Path) -> dict:
    out = tempfile.mkdtemp(dir=root)
    args = [model, controller, str(size), str(batch), where, out]
    done = subprocess.run([sys.executable, "-c", RUN, *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{model} + {controller}, {size} pushes on {where}:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    from distributed import LocalCluster

    cases = list(CASES)
    if "--million" in sys.argv:
        cases[0] = ("pendulum", "ankle-pd", (10**3, 10**4, 10**5, 10**6), 10_000)
    results = []
    root = Path(tempfile.mkdtemp(prefix="pushrecovery-scaling-"))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        address = cluster.scheduler_address
        for model, controller, sizes, batch in cases:
            # Warm the machine's compiled caches and the Dask workers' imports.
            for where in ("1", address):
                _run(model, controller, 200, 100, where, root)
            for size in sizes:
                # At least 8 batches, so that 2 workers share the work; at most ``batch``.
                batch_size = max(min(batch, size // 8), 1)
                walls = {
                    label: _run(model, controller, size, batch_size, where, root)
                    for label, where in (("1", "1"), ("2", "2"), ("dask", address))
                }
                one, two, dask = (walls[k]["wall"] for k in ("1", "2", "dask"))
                entry = {
                    "model": model,
                    "controller": controller,
                    "pushes": size,
                    "batch_size": batch_size,
                    "wall_1": one,
                    "wall_2": two,
                    "wall_dask": dask,
                    "speedup_2": one / two,
                    "dask_overhead": (2 * dask - one) / one,
                    "peak_mb": max(w["peak_mb"] for w in walls.values()),
                }
                results.append(entry)
                print(
                    f"{model} + {controller}, {size:>9,} pushes (batches of "
                    f"{entry['batch_size']:,}): 1 worker {one:7.1f} s ({size / one:7.0f}/s), "
                    f"2 workers {two:7.1f} s ({size / two:7.0f}/s, {one / two:.2f}x), "
                    f"dask 2 {dask:7.1f} s ({size / dask:7.0f}/s, overhead "
                    f"{entry['dask_overhead']:+.1%}); parent peak {entry['peak_mb']:.0f} MB",
                    flush=True,
                )
    out = Path("out")
    out.mkdir(exist_ok=True)
    (out / "scaling.json").write_text(json.dumps(results, indent=2) + "\n")
    _plot(results, out / "scaling.png")
    return 0


def _plot(results: list[dict], path: Path) -> None:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 4.2), layout="constrained")
    axes = figure.subplots()
    styles = {"wall_1": ("1 worker", "o-"), "wall_2": ("2 workers", "s-"),
              "wall_dask": ("Dask, 2 workers", "^--")}  # fmt: skip
    for model in sorted({r["model"] for r in results}):
        rows = [r for r in results if r["model"] == model]
        for key, (label, style) in styles.items():
            axes.loglog([r["pushes"] for r in rows], [r[key] for r in rows], style,
                        label=f"{rows[0]['model']} + {rows[0]['controller']}, {label}")  # fmt: skip
    axes.set_xlabel("pushes in the campaign")
    axes.set_ylabel("wall time [s]")
    axes.set_title("Campaign scaling on the 2-core reference machine")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=7)
    figure.savefig(path, dpi=120)


if __name__ == "__main__":
    sys.exit(main())
