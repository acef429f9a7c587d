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
    "analytic", "pendulum", "ankle-pd", P, x0=(0.0, 0.05, 0.05), xdot=(-0.4, 0.6, 0.2),
    batch_size=4,
)  # fmt: skip
CRASH = 5  # the push that kills its process: in batch 1 of 3


def crash_batch(spec: CampaignSpec, batch: int) -> tuple[int, list[dict[str, Any]]]:
    if any(push.index == CRASH for push in spec.pushes(batch)):
        os.kill(os.getpid(), signal.SIGSEGV)
    return run_batch(spec, batch)


def crash_push(spec: CampaignSpec, push: Any, cache: Any = None) -> dict[str, Any]:
    if push.index == CRASH:
        os.kill(os.getpid(), signal.SIGSEGV)
    return run_push(spec, push, cache)


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
    real = pushes_module.simulate

    def diverging(plant: Any, controller: Any, state: Any, **kwargs: Any) -> Any:
        if abs(state[1] + 0.4) < 1e-9:  # the first push of the batch, ẋ = -0.4 m/s
            raise SimulationDiverged("MuJoCo: BADQACC at t = 0.1 s")
        return real(plant, controller, state, **kwargs)

    monkeypatch.setattr(pushes_module, "simulate", diverging)
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


def test_a_ctrl_c_while_workers_start_is_deferred_not_lost() -> None:
    # The pool starts its workers inside this window; a Ctrl-C then used to be ignored, and
    # the campaign ran to its end. Now this process gets it when the window closes.
    from pushrecovery.campaign.isolation import interrupts_deferred

    reached_end = False
    with pytest.raises(KeyboardInterrupt):
        with interrupts_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            reached_end = True  # nothing was raised inside the window
    assert reached_end
