"""Batch analysis of measured trials (issue 18): trials per second per core, time per trial-second.

200 generated 2-D LIPM trials (3 s at 100 Hz each: standing, a push from one of eight
directions at 1 s, the CoP at the capture point clipped to the foot; CoM, CoP and the base as
CSV columns) analysed in one batch on 1 and 2 local workers and on a Dask ``LocalCluster`` of
2 workers; the three tables must be equal. Baseline in the same run: reading the same files
alone (``read_recording``), per trial.
"""

from __future__ import annotations

import math
import shutil
import sys
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq

from pushrecovery import load_params
from pushrecovery.experiments.synthetic_trials import lipm_trial_csv

TRIALS = 200
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
        return 0 if same else 1
    finally:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
