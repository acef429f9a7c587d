"""A push that kills its worker, or whose physics diverges, is one error row: the rest go on.

The crashing runners are module-level functions of this file: the quarantine's worker
processes import them by name (pytest put this folder on ``sys.path``).
"""

from __future__ import annotations

import os
import signal
from typing import Any

import pyarrow as pa
import pytest

from pushrecovery import load_params
from pushrecovery.campaign import CampaignSpec, run_campaign
from pushrecovery.campaign import pushes as pushes_module
from pushrecovery.campaign.execute import schema
from pushrecovery.campaign.isolation import quarantine
from pushrecovery.campaign.pushes import run_batch, run_push
from pushrecovery.campaign.summary import summarize
from pushrecovery.errors import SimulationDiverged

P = load_params()
SPEC = CampaignSpec(
    "analytic", "pendulum", "ankle-saturated", P, x0=(0.0, 0.05, 0.05), xdot=(-0.4, 0.6, 0.2),
    batch_size=4,
)  # fmt: skip
CRASH = 5  # the push that kills its process: in batch 1 of 3
HANG = 6  # the push that never returns (tests with a short push_timeout)


def crash_batch(spec: CampaignSpec, batch: int) -> tuple[int, list[dict[str, Any]]]:
    if any(push.index == CRASH for push in spec.pushes(batch)):
        os.kill(os.getpid(), signal.SIGSEGV)
    return run_batch(spec, batch)


def crash_push(spec: CampaignSpec, push: Any) -> dict[str, Any]:
    if push.index == CRASH:
        os.kill(os.getpid(), signal.SIGSEGV)
    return run_push(spec, push)


def crash_once_batch(spec: CampaignSpec, batch: int) -> tuple[int, list[dict[str, Any]]]:
    """Kill the first worker that runs batch 1 (a machine lost), then run as usual."""
    marker = os.environ["PUSHRECOVERY_TEST_CRASHED"]
    if batch == 1 and not os.path.exists(marker):
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return run_batch(spec, batch)


def hang_batch(spec: CampaignSpec, batch: int) -> tuple[int, list[dict[str, Any]]]:
    from pushrecovery.campaign import watchdog

    rows = []
    for push in spec.pushes(batch):
        watchdog.arm(spec.push_timeout)  # as run_batch does
        rows.append(hang_push(spec, push))
    watchdog.disarm()
    return batch, rows


def hang_push(spec: CampaignSpec, push: Any) -> dict[str, Any]:
    import time

    while push.index == HANG:
        time.sleep(1.0)  # outside the simulation: only the worker's watchdog ends it
    return run_push(spec, push)


def test_a_push_that_kills_its_worker_is_one_error_row() -> None:
    batches = list(range(SPEC.batches))
    assert len(batches) == 3
    found = dict(quarantine(SPEC, batches, batch_runner=crash_batch, push_runner=crash_push))
    assert sorted(found) == batches
    expected = dict(run_batch(SPEC, b) for b in batches)  # in this process, no crash
    for batch in batches:
        for row, reference in zip(found[batch], expected[batch], strict=True):
            if row["index"] == CRASH:
                assert row["outcome"] == "error" and row["used"] == "error"
                assert row["error"] == "its worker process died"
                assert row["predicted"] == reference["predicted"]
            else:
                assert row == reference


def test_diverged_physics_is_an_error_row_and_the_batch_goes_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _, reference = run_batch(SPEC, 0)
    import pushrecovery.sim.simulate as loop_module

    real = loop_module.simulate

    def diverging(plant: Any, controller: Any, state: Any, **kwargs: Any) -> Any:
        if abs(state[1] + 0.4) < 1e-9:  # the first push of the batch, ẋ = -0.4 m/s
            raise SimulationDiverged("MuJoCo: BADQACC at t = 0.1 s")
        return real(plant, controller, state, **kwargs)

    monkeypatch.setattr(loop_module, "simulate", diverging)  # the loop engine imports it per call
    _, rows = run_batch(SPEC, 0)
    assert rows[0]["outcome"] == "error" and rows[0]["xdot"] == pytest.approx(-0.4)
    assert rows[0]["error"].startswith("the physics diverged: MuJoCo: BADQACC")
    assert rows[1:] == reference[1:]  # the pushes after it, simulated as without it


def test_the_summary_leaves_errors_out_of_the_accuracy() -> None:
    rows = [row for batch in range(SPEC.batches) for row in run_batch(SPEC, batch)[1]]
    clean = summarize(SPEC, pa.Table.from_pylist(rows, schema=schema(SPEC)))
    rows[CRASH] = pushes_module.error_row(SPEC, next(
        p for b in range(SPEC.batches) for p in SPEC.pushes(b) if p.index == CRASH
    ), "its worker process died")  # fmt: skip
    summary = summarize(SPEC, pa.Table.from_pylist(rows, schema=schema(SPEC)))
    assert summary["outcomes"]["error"] == 1 and clean["outcomes"]["error"] == 0
    assert summary["pushes"] == clean["pushes"]
    assert sum(map(sum, summary["confusion"]["counts"])) == clean["pushes"] - 1
    right = clean["accuracy"] * clean["pushes"]
    assert summary["accuracy"] == pytest.approx((right - 1) / (clean["pushes"] - 1))


def test_run_campaign_records_the_new_column(tmp_path: Any) -> None:
    result = run_campaign(SPEC, tmp_path, workers=1)
    assert result is not None
    assert result.table.column("error").null_count == result.table.num_rows


def test_workers_start_ignoring_ctrl_c_and_the_campaign_does_not(tmp_path: Any) -> None:
    # A Ctrl-C while a pool started used to be ignored by the campaign itself (it ran to its
    # end). Now the workers inherit an ignored SIGINT from the fork server and this process
    # keeps its handler. In a process of its own: a fresh fork server, in the main thread.
    import subprocess
    import sys

    script = """
import multiprocessing, signal
from pushrecovery.campaign.isolation import quiet_worker_start

def probe(queue):
    queue.put(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)

if __name__ == "__main__":
    # As started from a terminal (here: not in the module's top level, which the fork server
    # runs again when it preloads the main module).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    context = multiprocessing.get_context("forkserver")
    queue = context.Queue()
    with quiet_worker_start():
        here = signal.getsignal(signal.SIGINT) is signal.default_int_handler
        worker = context.Process(target=probe, args=(queue,))  # no initializer
        worker.start()
    print(here, queue.get(timeout=30))
    worker.join()
"""
    path = tmp_path / "probe.py"  # a file: the workers import the probe from it
    path.write_text(script)
    done = subprocess.run([sys.executable, str(path)], capture_output=True, text=True)
    assert done.stdout.split() == ["True", "True"], done.stderr


def test_a_push_that_hangs_is_one_error_row() -> None:
    import dataclasses

    from pushrecovery.campaign.watchdog import hung_after

    spec = dataclasses.replace(SPEC, push_timeout=0.5)
    found = dict(quarantine(spec, [1], batch_runner=hang_batch, push_runner=hang_push))
    expected = run_batch(spec, 1)[1]
    for row, reference in zip(found[1], expected, strict=True):
        if row["index"] == HANG:
            assert row["outcome"] == "error"
            assert row["error"] == (
                f"it gave no answer for {hung_after(0.5):g} s of wall time; its worker process "
                "was stopped"
            )
        else:
            assert row == reference


def test_a_push_slower_than_its_limit_is_one_error_row() -> None:
    import dataclasses

    # 0.1 ms of wall time: every push of the pendulum takes longer (thousands of ticks).
    spec = dataclasses.replace(SPEC, push_timeout=1e-4)
    _, rows = run_batch(spec, 0)
    assert [row["outcome"] for row in rows] == ["error"] * len(rows)
    assert all(row["error"].startswith("too slow: the run took more than its wall-time limit")
               for row in rows)  # fmt: skip
    assert rows[0]["predicted"] == run_batch(SPEC, 0)[1][0]["predicted"]


def test_one_worker_still_runs_the_pushes_in_a_process_of_its_own(
    tmp_path: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from pushrecovery.campaign import execute

    def in_this_process(*args: Any) -> Any:
        raise AssertionError("workers=1 ran the pushes in the campaign's own process")

    monkeypatch.setattr(execute, "_serial", in_this_process)
    result = run_campaign(SPEC, tmp_path / "one", workers=1)
    assert result is not None and result.table.num_rows == SPEC.size
    with pytest.raises(AssertionError, match="own process"):
        run_campaign(SPEC, tmp_path / "here", workers=1, isolated=False)


def test_push_timeout_is_checked_and_stored(tmp_path: Any) -> None:
    import dataclasses

    from pushrecovery.errors import InvalidParameterError

    for bad in (0.0, -1.0, float("nan"), float("inf"), 3601.0, True, "60"):
        with pytest.raises(InvalidParameterError, match="push_timeout must be in"):
            dataclasses.replace(SPEC, push_timeout=bad)
    spec = dataclasses.replace(SPEC, push_timeout=30.0)
    assert CampaignSpec.from_dict(spec.to_dict()) == spec
    old = SPEC.to_dict()
    del old["push_timeout"]  # a campaign written before the limit existed
    assert CampaignSpec.from_dict(old).push_timeout == 120.0


def test_a_hung_worker_of_the_pool_ends_itself_and_the_campaign_goes_on(
    tmp_path: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    import dataclasses

    from pushrecovery.campaign import execute

    # The pool's batches hang at push HANG; the worker's watchdog ends it after
    # hung_after(0.5) = 1 s, the pool breaks, and the quarantine (the real runners) finishes.
    spec = dataclasses.replace(SPEC, push_timeout=0.5)
    monkeypatch.setattr(execute, "run_batch", hang_batch)
    result = run_campaign(spec, tmp_path / "c", workers=2)
    assert result is not None
    rows = result.table.to_pylist()
    reference = [row for b in range(spec.batches) for row in run_batch(spec, b)[1]]
    assert rows == reference


def test_a_push_that_kills_its_dask_worker_is_one_error_row() -> None:
    import dask
    from distributed import Client, LocalCluster

    from pushrecovery.campaign.cluster import on_cluster as _dask

    # The scheduler gives up on a task at once when its worker dies (the default retries on
    # 3 more workers, each a crash); the nanny restarts the worker.
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster:
            with Client(cluster, set_as_default=False) as client:
                found = dict(
                    _dask(SPEC, [0, 1], client, batch_runner=crash_batch, push_runner=crash_push)
                )
    assert sorted(found) == [0, 1]
    for batch in (0, 1):
        for row, reference in zip(found[batch], run_batch(SPEC, batch)[1], strict=True):
            if row["index"] == CRASH:
                assert row["outcome"] == "error" and row["error"] == "its worker process died"
            else:
                assert row == reference


def test_a_dead_dask_workers_batch_runs_on_another_and_the_campaign_finishes(
    tmp_path: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from distributed import Client, LocalCluster

    from pushrecovery.campaign.cluster import on_cluster as _dask

    # The scheduler's default: a task whose worker died runs again elsewhere (the other
    # worker, or the one its nanny restarts); the batch's rows are those of an unbroken run.
    marker = tmp_path / "crashed"
    monkeypatch.setenv("PUSHRECOVERY_TEST_CRASHED", str(marker))
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        with Client(cluster, set_as_default=False) as client:
            found = dict(_dask(SPEC, [0, 1, 2], client, batch_runner=crash_once_batch))
    assert marker.exists()  # a worker did die
    assert found == {b: run_batch(SPEC, b)[1] for b in (0, 1, 2)}


def test_a_worker_whose_campaign_was_killed_ends_itself() -> None:
    # A SIGKILL'ed campaign cannot stop its pool: its workers used to wait for work forever
    # (100 MB each). The watchdog ends a worker whose campaign process is gone.
    import subprocess
    import sys
    import time

    from pushrecovery.campaign.watchdog import ORPHAN_EXIT, PERIOD

    campaign = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    worker = subprocess.Popen([
        sys.executable, "-c",
        "import sys, time; from pushrecovery.campaign import watchdog; "
        f"watchdog.start({campaign.pid}); time.sleep(60)",
    ])  # fmt: skip
    time.sleep(4 * PERIOD)
    assert worker.poll() is None  # the campaign is alive: the worker waits
    campaign.kill()
    campaign.wait()
    assert worker.wait(timeout=10) == ORPHAN_EXIT
