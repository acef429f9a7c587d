"""Campaigns on a Dask cluster that lose a worker, or their client, and still give the same file.

A ``LocalCluster`` of worker processes stands for a real scheduler: a worker process is killed
(SIGKILL) while it holds batches, and, in the other test, the ``pushrecovery campaign`` client
is killed and the campaign resumed. Either way the ``pushes.parquet`` written must equal,
byte for byte, the file of an uninterrupted run: no push lost, none counted twice.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pushrecovery import load_params
from pushrecovery.campaign import CampaignSpec, run_campaign

distributed = pytest.importorskip("distributed")

P = load_params()
# One-push-loop pairs of a few tenths of a second per batch: the kill lands mid-campaign.
SPEC = CampaignSpec(
    "analytic", "flywheel", "bang-bang", P, x0=(0.0, 0.1, 0.05), xdot=(-0.6, 0.7, 0.1),
    batch_size=4,
)  # fmt: skip


def test_a_worker_killed_mid_campaign_changes_nothing(tmp_path: Path) -> None:
    reference = run_campaign(SPEC, tmp_path / "whole", workers=1)
    assert reference is not None and SPEC.batches >= 8
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        with distributed.Client(cluster, set_as_default=False) as client:
            pids = list(client.run(os.getpid).values())
        killed: list[int] = []

        def kill_one(pushes: int) -> None:
            if not killed and pushes < SPEC.size:  # after the first batch is back
                killed.append(pids[0])
                os.kill(pids[0], signal.SIGKILL)  # the nanny starts a new worker

        result = run_campaign(
            SPEC, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=kill_one
        )
    assert killed and result is not None
    whole = (tmp_path / "whole" / "pushes.parquet").read_bytes()
    assert (tmp_path / "dask" / "pushes.parquet").read_bytes() == whole
    assert result.summary == reference.summary


def test_a_killed_client_resumes_on_the_cluster(tmp_path: Path) -> None:
    exe = str(Path(sys.executable).with_name("pushrecovery"))
    args = (
        "--model stepping --controller recovery --x0 0 0.1 0.05 --xdot 2.6 3.0 0.1 "
        "--batch-size 1 --no-plot"
    ).split()
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        address = ["--scheduler", cluster.scheduler_address]
        out = tmp_path / "killed"
        proc = subprocess.Popen(
            [exe, "campaign", *args, *address, "--out", str(out)], stderr=subprocess.PIPE
        )
        batches, deadline = out / "batches", time.monotonic() + 120
        while not (batches.is_dir() and any(batches.glob("*.parquet"))):
            assert proc.poll() is None and time.monotonic() < deadline, proc.stderr
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)  # nothing can be saved at the last moment
        proc.wait()
        saved = len(list(batches.glob("batch-*.parquet")))
        assert 1 <= saved < 15  # killed part-way
        subprocess.run(
            [exe, "campaign", "--out", str(out), "--resume", "--no-plot", *address],
            capture_output=True,
            check=True,
        )
    whole = tmp_path / "whole"
    subprocess.run(
        [exe, "campaign", *args, "--workers", "1", "--out", str(whole)],
        capture_output=True,
        check=True,
    )
    assert (out / "pushes.parquet").read_bytes() == (whole / "pushes.parquet").read_bytes()
