"""Push campaigns: same results on any number of workers and on Dask, resume, bad specs."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from conftest import AS_FROM_A_TERMINAL
from pushrecovery import InvalidParameterError, load_params
from pushrecovery.campaign import CampaignError, CampaignSpec, missing_batches, run_campaign
from pushrecovery.sim.critical import predicted_critical_velocity

P = load_params()
# 2 starts x 13 pushes in batches of 5: 6 batches, the last one short.
TINY = {"x0": (0.0, 0.05, 0.05), "xdot": (-0.4, 0.8, 0.1), "batch_size": 5}


def tiny(**changes):
    return CampaignSpec("analytic", "pendulum", "ankle-pd", P, **{**TINY, **changes})


def test_grid_order_and_size():
    spec = tiny()
    assert spec.size == 26 and spec.batches == 6
    assert [len(spec.pushes(b)) for b in range(6)] == [5, 5, 5, 5, 5, 1]
    first, last = spec.push(0), spec.push(25)
    assert (first.x0, first.xdot) == (0.0, pytest.approx(-0.4))
    assert (last.x0, last.xdot) == (0.05, pytest.approx(0.8))
    swept = CampaignSpec(
        "analytic", "flywheel", "mpc", P, x0=(0.0, 0.0, 1.0), xdot=(0.5, 0.6, 0.1),
        sweeps={"torque_max": (50.0, 150.0, 50.0)},
    )  # fmt: skip
    assert swept.size == 6
    assert swept.push(5).params.torque_max == 150.0 and swept.push(5).xdot == pytest.approx(0.6)


def test_default_batches_are_about_a_second_of_work():
    from pushrecovery.campaign.spec import COMPILED_BATCH
    from pushrecovery.sim.many import COMPILED

    # Every pair the batch runner compiles has its larger default, and no other pair.
    assert set(COMPILED_BATCH) == set(COMPILED)

    def default(model, controller, samples, backend="analytic"):
        spec = CampaignSpec(backend, model, controller, P, x0=(0.0, 0.0, 1.0),
                            xdot=(0.0, 0.5, 1.0), samples=samples)  # fmt: skip
        return spec.batch, spec.batches

    # Small campaigns keep 100 per batch; from 1,600 pushes the batch grows to keep 16
    # batches, up to 10,000 (pendulum) or 1,000 (stepping + recovery).
    assert default("pendulum", "ankle-pd", 1_000) == (100, 10)
    assert default("pendulum", "ankle-pd", 16_000) == (1_000, 16)
    assert default("pendulum", "ankle-pd", 16_001) == (1_001, 16)
    assert default("pendulum", "ankle-pd", 10**6) == (10_000, 100)
    assert default("lipm", "ankle-pd", 10**6) == (10_000, 100)
    assert default("stepping", "recovery", 10**5) == (1_000, 100)
    assert default("stepping", "recovery", 8_000) == (500, 16)
    # The one-push loop's pairs keep theirs whatever the size.
    assert default("flywheel", "mpc", 10**6) == (100, 10_000)
    assert default("pendulum", "ankle-saturated", 10**6)[0] == 100
    assert default("foot", "ankle-pd", 10**5, backend="mujoco")[0] == 10
    assert tiny(samples=10**6, batch_size=7).batch == 7  # the spec's own wins


def test_impulses_and_random_samples_depend_on_the_seed_only():
    spec = tiny(xdot=None, impulse=(-30.0, 60.0, 7.2))
    assert spec.push(1).xdot == pytest.approx((-30.0 + 7.2) / P.mass)
    sampled = tiny(samples=50, seed=7)
    again = tiny(samples=50, seed=7, batch_size=13)
    other = tiny(samples=50, seed=8)
    assert [sampled.push(i) for i in range(50)] == [again.push(i) for i in range(50)]
    assert sampled.push(3) != other.push(3)
    xs = np.array([sampled.push(i).xdot for i in range(50)])
    assert xs.min() >= -0.4 and xs.max() <= 0.8 and np.unique(xs).size == 50


def test_same_results_on_one_two_and_dask_workers(tmp_path):
    from distributed import LocalCluster

    spec = tiny()
    serial = run_campaign(spec, tmp_path / "one", workers=1)
    pair = run_campaign(spec, tmp_path / "two", workers=2)
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        dask = run_campaign(spec, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert serial.table.num_rows == 26
    assert serial.table.equals(pair.table) and serial.table.equals(dask.table)
    files = [(tmp_path / d / "pushes.parquet").read_bytes() for d in ("one", "two", "dask")]
    assert files[0] == files[1] == files[2]
    assert serial.summary == pair.summary == dask.summary


def test_summary_against_the_pushes_and_eq4(tmp_path):
    result = run_campaign(tiny(), tmp_path / "c", workers=1)
    table, summary = result.table, result.summary
    recovered = table.column("outcome").to_numpy(zero_copy_only=False) == "recovered"
    agrees = table.column("predicted_recovers").to_numpy() == recovered
    assert summary["accuracy"] == pytest.approx(agrees.mean())
    assert np.sum(summary["confusion"]["counts"]) == summary["pushes"] == 26
    assert summary["outcomes"]["recovered"] == recovered.sum()
    # Joined and summarised batch by batch (6 batches: 6 row groups), the counts are the
    # table's own.
    import pyarrow.parquet as pq

    assert pq.ParquetFile(result.pushes_file).metadata.num_row_groups == 6
    labels = summary["confusion"]["labels"]
    predicted = table.column("predicted").to_numpy(zero_copy_only=False)
    used_by_run = table.column("used").to_numpy(zero_copy_only=False)
    crosstab = [
        [int(np.sum((predicted == p) & (used_by_run == u))) for u in labels] for p in labels
    ]
    assert summary["confusion"]["counts"] == crosstab
    # The PD falls within 1.3 % of Eq. (4) (docs/ankle_pd.md): the grid's bracket, 0.1 m/s
    # wide, must hold the analytic critical push up to that.
    for row in summary["boundary"]:
        low, high = row["bracket"]
        analytic = predicted_critical_velocity(P, "ankle", row["x0"], row["direction"])
        assert row["analytic"] == pytest.approx(analytic)
        assert abs(low) <= abs(analytic) * 1.013 and abs(high) >= abs(analytic) * 0.987, row
        assert row["monotone"]
    # The pushes themselves: a push inside Eq. (4) recovers with the ankle.
    margins = table.column("cop_margin").to_numpy()
    used = table.column("used").to_numpy(zero_copy_only=False)
    assert np.all(used[margins > 0.01] == "ankle")
    assert np.all(used[margins < -0.01] == "fall")


def test_stopped_and_resumed_gives_the_same_file(tmp_path):
    spec = tiny()
    run_campaign(spec, tmp_path / "whole", workers=1)
    assert run_campaign(spec, tmp_path / "parts", workers=1, max_batches=2) is None
    assert missing_batches(spec, tmp_path / "parts") == [2, 3, 4, 5]
    with pytest.raises(CampaignError, match="pass --resume"):
        run_campaign(spec, tmp_path / "parts", workers=1)
    with pytest.raises(CampaignError, match="differs in seed"):
        run_campaign(tiny(seed=3), tmp_path / "parts", workers=1, resume=True)
    resumed = run_campaign(spec, tmp_path / "parts", workers=2, resume=True)
    assert resumed.ran == 4
    assert (tmp_path / "parts" / "pushes.parquet").read_bytes() == (
        tmp_path / "whole" / "pushes.parquet"
    ).read_bytes()


# Analytic multi-step recoveries in batches of one: about 4 ms a batch since the stepping
# campaigns run compiled (with its Parquet file), so 243 of them (about a second) for a kill
# after the first batch to land part-way; 9 finished before the kill on a busy machine.
SLOW_PUSHES = (
    "--model stepping --controller recovery --x0 0 0.1 0.05 --xdot 2.0 3.0 0.0125 "
    "--batch-size 1 --workers 1 --no-plot"
).split()
SLOW_COUNT = 3 * 81


def _cli(*args: str) -> list[str]:
    exe = Path(sys.executable).with_name("pushrecovery")
    return [str(exe), "campaign", *args]


def test_cli_campaign_killed_then_resumed(tmp_path):
    # A real kill (SIGKILL, nothing can be saved at the last moment) after the first batch.
    args = SLOW_PUSHES
    out = tmp_path / "killed"
    proc = subprocess.Popen([*_cli(*args, "--out", str(out))], stderr=subprocess.PIPE)
    batches = out / "batches"
    deadline = time.monotonic() + 120
    while not (batches.is_dir() and any(batches.glob("*.parquet"))):
        assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    saved = len(list(batches.glob("batch-*.parquet")))
    assert 1 <= saved < SLOW_COUNT  # killed part-way
    done = subprocess.run(
        _cli("--out", str(out), "--resume", "--json", "--no-plot"),
        capture_output=True,
        text=True,
        check=True,
    )
    summary = json.loads(done.stdout)
    assert summary["pushes"] == SLOW_COUNT
    whole = tmp_path / "whole"
    subprocess.run(_cli(*args, "--out", str(whole)), capture_output=True, check=True)
    assert pq.read_table(out / "pushes.parquet").equals(pq.read_table(whole / "pushes.parquet"))


def test_cli_campaign_ctrl_c_keeps_the_batches(tmp_path):
    args = SLOW_PUSHES
    out = tmp_path / "c"
    command = [sys.executable, *AS_FROM_A_TERMINAL, "campaign", *args, "--out", str(out)]
    proc = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not ((out / "batches").is_dir() and any((out / "batches").glob("*.parquet"))):
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.01)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert "rerun with --resume" in err and "Traceback" not in err
    assert any((out / "batches").glob("*.parquet"))


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--x0", "0.1", "0", "0.05", "--xdot", "0", "1", "0.5"], "--x0 needs START <= STOP"),
        (["--x0", "0", "0.1", "0", "--xdot", "0", "1", "0.5"], "STEP > 0"),
        (["--x0", "0", "0.1", "0.05"], "one of --xdot, --impulse"),
        (["--x0", "0", "0.2", "0.05", "--xdot", "0", "1", "0.5"], "x0 must lie on the foot"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--param", "wingspan=1:2:1"],
         "unknown parameter 'wingspan'"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--param", "mass=10:5"],
         "NAME=START:STOP:STEP"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--param", "mass=-10:10:10"],
         "mass"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--model", "biped"],
         "model must be one of"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--model", "stepping-plane"],
         "which model 'stepping-plane'"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--controller", "recovery-plane"],
         "use the stepping-plane model"),
        (["--x0", "0", "0", "1", "--xdot", "0", "nan", "0.5"], "--xdot must be finite"),
        (["--x0", "0", "0", "1", "--xdot", "0", "1", "0.5", "--samples", "0"], "samples"),
    ],
)  # fmt: skip
def test_cli_bad_campaign_specs(tmp_path, args, words):
    done = subprocess.run(_cli(*args, "--out", str(tmp_path / "c")), capture_output=True, text=True)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], done.stderr
    assert not (tmp_path / "c" / "spec.json").exists()


def test_unreachable_scheduler(tmp_path, monkeypatch):
    import pushrecovery.campaign.cluster as cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 1.0)
    with pytest.raises(
        CampaignError, match=r"cannot reach the Dask scheduler at tcp://127\.0\.0\.1:9"
    ):
        run_campaign(tiny(), tmp_path / "c", scheduler="tcp://127.0.0.1:9")
    assert not (tmp_path / "c").exists()  # nothing written: the same command can run again


def test_bad_library_arguments(tmp_path):
    with pytest.raises(InvalidParameterError, match="workers must be >= 1"):
        run_campaign(tiny(), tmp_path / "c", workers=0)
    with pytest.raises(InvalidParameterError, match="exactly one of xdot and impulse"):
        tiny(impulse=(0.0, 1.0, 1.0))
    with pytest.raises(InvalidParameterError, match="backend must be one of"):
        CampaignSpec("bullet", "foot", "ankle-pd", P, x0=(0.0, 0.0, 1.0), xdot=(0.0, 1.0, 1.0))
    with pytest.raises(CampaignError, match="no campaign in"):
        from pushrecovery.campaign import read_spec

        read_spec(tmp_path / "nothing")
    assert os.listdir(tmp_path) == []  # nothing written for a bad request


def test_sweep_order_is_part_of_the_campaign(tmp_path):
    first = {"torque_max": (50.0, 100.0, 50.0), "flywheel_inertia": (8.0, 10.0, 2.0)}
    spec = CampaignSpec(
        "analytic", "flywheel", "mpc", P, x0=(0.0, 0.0, 1.0), xdot=(0.5, 0.5, 1.0), sweeps=first
    )
    run_campaign(spec, tmp_path / "c", workers=1, max_batches=0)
    swapped = dataclasses.replace(spec, sweeps=dict(reversed(list(first.items()))))
    with pytest.raises(CampaignError, match="differs in sweeps"):
        run_campaign(swapped, tmp_path / "c", workers=1, resume=True)


def test_spec_checks_are_fast_and_complete(tmp_path):
    start = time.monotonic()
    with pytest.raises(InvalidParameterError, match="at most 1000000"):
        tiny(sweeps={"torque_max": (50.0, 150.0, 1e-3), "mass": (60.0, 70.0, 1e-3)})
    assert time.monotonic() - start < 5.0
    # Random draws cover the whole interval: a heel swept past x0 is caught at its corner.
    with pytest.raises(InvalidParameterError, match="x0 must lie on the foot"):
        tiny(x0=(-0.04, -0.04, 1.0), sweeps={"heel": (-0.1, -0.001, 0.5)}, samples=20)
    # Grid values are the decimal ones, never beyond STOP.
    spec = tiny(x0=(0.0, 0.149999999999, 0.05))
    assert [spec.push(i * 13).x0 for i in range(3)] == [0.0, 0.05, 0.1]
    assert spec.push(4).xdot == 0.0 and spec.push(7).xdot == 0.3
    with pytest.raises(InvalidParameterError, match="moves the upper body: use the flywheel"):
        CampaignSpec("analytic", "lipm", "mpc", P, x0=(0.0, 0.0, 1.0), xdot=(0.0, 1.0, 1.0))
    with pytest.raises(InvalidParameterError, match="seed must be an integer"):
        tiny(seed=1.5)


def test_malformed_scheduler_address(tmp_path):
    with pytest.raises(CampaignError, match="--scheduler must be an address"):
        run_campaign(tiny(), tmp_path / "c", scheduler="foo bar")
    assert not (tmp_path / "c").exists()
