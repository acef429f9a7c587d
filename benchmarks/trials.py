"""Batch analysis of measured trials (issue 18): trials per second per core, time per trial-second.

200 generated 2-D LIPM trials (3 s at 100 Hz each: standing, a push from one of eight
directions at 1 s, the CoP at the capture point clipped to the foot; CoM, CoP and the base as
CSV columns) analysed in one batch on 1 and 2 local workers and on a Dask ``LocalCluster`` of
2 workers; the three tables must be equal. Baseline in the same run: reading the same files
alone (``read_recording``), per trial.

Then the real Kistler quiet-standing trial (biomdp's ``kistler_COP.c3d``, 10 s at 1 kHz) in a
folder of 100 copies through ``pushrecovery analyze FOLDER --workers 1 --no-plot`` pinned to
one core (the whole command: start-up, the C3D reader's helper, the tables), against the same
trials analysed in this process (``run_trial``: read, analyse, write; median, p99 and largest
per trial) and reading the file alone. Targets (issue 34, item 6): >= 20 trials/s through the
CLI, and the CLI's cost per trial <= 0.5 s above the in-process one. With the plots on (the
default) on 10 copies, for comparison.
"""

from __future__ import annotations

import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq

from pushrecovery import load_params
from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

TRIALS = 200
#: Copies of the Kistler trial in the CLI's folder, and the targets of issue 34 item 6.
COPIES = 100
TARGET_RATE = 20.0  # trials/s through the CLI, one core
TARGET_OVERHEAD = 0.5  # s per trial above the in-process analysis
RATE = 100.0
DURATION = 3.0


def main() -> int:
    from distributed import LocalCluster

    from pushrecovery.analysis.readers import read_recording
    from pushrecovery.campaign.trials import find_trials, run_trials, trial_jobs

    root = Path(tempfile.mkdtemp(prefix="pushrecovery-trials-"))
    try:
        folder = root / "data"
        folder.mkdir()
        for k in range(TRIALS):
            push = 0.1 + 0.6 * (k % 25) / 24
            text = lipm_trial_csv(load_params(), push, (k % 8) * math.pi / 4, seed=k)
            (folder / f"trial{k:03d}.csv").write_text(text)
        trials, base = find_trials([folder])
        jobs = trial_jobs(trials, base)
        run_trials(jobs[:4], root / "warm", workers=1)  # imports, compiled kernels
        start = time.perf_counter()
        for path in trials:
            read_recording(path)
        read = (time.perf_counter() - start) / TRIALS
        walls, tables = {}, {}
        with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as cluster:
            run_trials(jobs[:4], root / "warm-dask", scheduler=cluster.scheduler_address)
            for label, kwargs in (
                ("1 worker", {"workers": 1}),
                ("2 workers", {"workers": 2}),
                ("dask 2 workers", {"scheduler": cluster.scheduler_address}),
            ):
                out = root / label.replace(" ", "-")
                start = time.perf_counter()
                run_trials(jobs, out, **kwargs)
                walls[label] = time.perf_counter() - start
                tables[label] = pq.read_table(out / "trials.parquet")
        same = all(t.equals(tables["1 worker"]) for t in tables.values())
        seconds = sum(len(path.read_text().splitlines()) - 1 for path in trials) / RATE
        one = walls["1 worker"]
        print(
            f"batch analysis, {TRIALS} trials ({seconds:.0f} trial-seconds): "
            + ", ".join(f"{k} {TRIALS / w:.1f} trials/s" for k, w in walls.items())
            + f"; one core {one / TRIALS * 1e3:.0f} ms per trial ({one / seconds * 1e3:.0f} ms "
            f"per trial-second, {one / TRIALS / read:.0f}x reading the file alone); "
            f"tables equal: {same}"
        )
        return (0 if same else 1) | kistler(root)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _cli(folder: Path, out: Path, *flags: str) -> float:
    """Wall time [s] of ``pushrecovery analyze folder --workers 1`` pinned to CPU 0."""
    exe = Path(sys.executable).with_name("pushrecovery")
    start = time.perf_counter()
    subprocess.run(
        [str(exe), "analyze", str(folder), "--out", str(out), "--workers", "1", *flags],
        check=True, capture_output=True, preexec_fn=lambda: os.sched_setaffinity(0, {0}),
    )  # fmt: skip
    return time.perf_counter() - start


def kistler(root: Path) -> int:
    """The Kistler trial in a folder of copies: CLI against in-process (module docstring)."""
    import biomdp

    from pushrecovery.analysis.readers import read_recording
    from pushrecovery.campaign.trials import find_trials, run_trial, trial_jobs

    source = Path(biomdp.__file__).parent / "tests" / "datasets" / "kistler_COP.c3d"
    folder = root / "kistler"
    folder.mkdir()
    for k in range(COPIES):
        shutil.copyfile(source, folder / f"trial{k:03d}.c3d")
    trials, base = find_trials([folder])
    jobs = trial_jobs(trials, base)
    run_trial(jobs[0], root / "kistler-warm")  # imports, compiled kernels, the reader's helper
    costs, reads = [], []
    for job in jobs[:30]:
        start = time.perf_counter()
        run_trial(job, root / "kistler-in-process")
        costs.append(time.perf_counter() - start)
        start = time.perf_counter()
        read_recording(job.path)
        reads.append(time.perf_counter() - start)
    median, read = statistics.median(costs), statistics.median(reads)
    p99 = sorted(costs)[min(len(costs) - 1, round(0.99 * (len(costs) - 1)))]
    cli = _cli(folder, root / "kistler-cli", "--no-plot")
    rate = COPIES / cli
    overhead = cli / COPIES - median
    ten = root / "kistler-ten"
    ten.mkdir()
    for path in trials[:10]:
        shutil.copyfile(path, ten / path.name)
    plotted = _cli(ten, root / "kistler-plots")
    missed = rate < TARGET_RATE or overhead > TARGET_OVERHEAD
    print(
        f"batch analysis, Kistler 10 s trial x {COPIES} through the CLI on one core, --no-plot: "
        f"{cli:.1f} s, {rate:.1f} trials/s (target >= {TARGET_RATE:g}"
        f"{': MISSED' if rate < TARGET_RATE else ''}); {cli / COPIES * 1e3:.0f} ms per trial, "
        f"{overhead * 1e3:.0f} ms above in-process (target <= {TARGET_OVERHEAD * 1e3:.0f}); in "
        f"process per trial median {median * 1e3:.0f} ms, p99 {p99 * 1e3:.0f} ms, max "
        f"{max(costs) * 1e3:.0f} ms, {median / read:.1f}x reading the file alone "
        f"({read * 1e3:.1f} ms); CLI/in-process {cli / COPIES / median:.2f}"
        f"; with the plots (10 copies) {10 / plotted:.2f} trials/s"
    )
    return int(missed)


if __name__ == "__main__":
    sys.exit(main())
