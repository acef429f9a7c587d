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

import numpy as np
import pyarrow.parquet as pq

from pushrecovery import load_params

TRIALS = 200
RATE = 100.0
DURATION = 3.0


def _trial(push: float, azimuth: float, seed: int) -> str:
    params = load_params()
    omega, dt = params.omega, 1.0 / RATE
    rng = np.random.default_rng(seed)
    low = np.array([params.heel, -0.5 * params.foot_width])
    high = np.array([params.toe, 0.5 * params.foot_width])
    ch, sh = math.cosh(omega * dt), math.sinh(omega * dt)
    x, v = np.array([0.02, 0.0]), np.zeros(2)
    lines = ["time,com_ap,com_ml,cop_ap,cop_ml,base_ap_min,base_ap_max,base_ml_min,base_ml_max"]
    for k in range(int(DURATION * RATE)):
        if k == int(RATE):
            v = v + push * np.array([math.cos(azimuth), math.sin(azimuth)])
        cop = np.clip(x + 2.0 * v / omega, low, high)
        com = x + rng.normal(0.0, 1e-4, 2)
        lines.append(
            f"{k * dt:.4f},{com[0]:.6f},{com[1]:.6f},{cop[0]:.6f},{cop[1]:.6f},"
            f"{low[0]},{high[0]},{low[1]},{high[1]}"
        )
        offset = x - cop
        x, v = cop + offset * ch + v / omega * sh, omega * offset * sh + v * ch
        if np.any(np.abs(x) > 0.6):
            break
    return "\n".join(lines) + "\n"


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
            text = _trial(push, (k % 8) * math.pi / 4, seed=k)
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
