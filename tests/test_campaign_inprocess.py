"""A campaign's fixed cost: --workers 1 runs in this process; a tiny ankle-PD campaign loops.

The numbers are ``benchmarks/campaign_cost.py``'s; these tests check the paths and that the
rows do not depend on them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from pushrecovery import load_params
from pushrecovery.campaign import CampaignSpec, execute
from pushrecovery.campaign import pushes as pushes_module
from pushrecovery.campaign.pushes import run_batch
from pushrecovery.campaign.spec import COMPILED_BATCH
from pushrecovery.cli import main
from pushrecovery.sim.many import LOOP_UP_TO

P = load_params()
ARGS = ["campaign", "--model", "pendulum", "--controller", "ankle-pd", "--x0", "0", "0.05",
        "0.05", "--xdot", "0", "0.4", "0.2", "--no-plot", "--json"]  # fmt: skip


def run_cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as caught:
        main(list(args))
    out, err = capsys.readouterr()
    return int(caught.value.code or 0), out, err


def test_one_worker_runs_the_campaign_in_this_process(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def pool(*args: Any) -> Any:
        raise AssertionError("--workers 1 started a worker process")

    monkeypatch.setattr(execute, "_processes", pool)
    code, out, err = run_cli(capsys, *ARGS, "--workers", "1", "--out", str(tmp_path / "c"))
    assert code == 0, err
    assert json.loads(out)["pushes"] == 6


def test_one_worker_isolates_mujoco_pushes_in_a_worker_process(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # MuJoCo is C: a push that crashes it must cost one error row (the isolation's tests),
    # not the campaign, so --workers 1 runs MuJoCo pushes in one worker process.
    def here(*args: Any) -> Any:
        raise AssertionError("--workers 1 ran MuJoCo pushes in the campaign's own process")

    monkeypatch.setattr(execute, "_serial", here)
    args = ["campaign", "--backend", "mujoco", "--model", "foot", "--controller", "ankle-pd",
            "--x0", "0", "0", "1", "--xdot", "0.1", "0.1", "1", "--duration", "0.5",
            "--no-plot", "--json", "--workers", "1", "--out", str(tmp_path / "m")]  # fmt: skip
    code, out, err = run_cli(capsys, *args)
    assert code == 0, err
    assert json.loads(out)["pushes"] == 1


@pytest.mark.parametrize("workers", ["0", "-3"])
def test_bad_worker_counts_are_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, workers: str
) -> None:
    code, _, err = run_cli(capsys, *ARGS, "--workers", workers, "--out", str(tmp_path / "c"))
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "workers must be >= 1" in lines[0], err
    assert not (tmp_path / "c").exists()


def test_the_compiled_pairs_are_sim_batched_s() -> None:
    from pushrecovery.sim.many import COMPILED

    assert set(COMPILED_BATCH) == set(COMPILED)


@pytest.mark.parametrize("model", ["pendulum", "lipm"])
def test_a_tiny_ankle_pd_campaign_loops_and_gives_the_compiled_rows(
    model: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    spec = CampaignSpec(
        "analytic", model, "ankle-pd", P, x0=(-0.04, 0.11, 0.075), xdot=(-0.9, 0.9, 0.45),
        sweeps={"toe": (0.12, 0.18, 0.06)}, duration=3.0,
    )  # fmt: skip
    assert spec.size <= LOOP_UP_TO
    compiled = pushes_module.push_rows(spec, spec.pushes(0), engine="compiled")
    import pushrecovery.sim.many as many

    def refuse(*args: Any) -> Any:
        raise AssertionError("the compiled loop ran")

    monkeypatch.setattr(many, "_compiled", refuse)
    _, rows = run_batch(spec, 0)
    assert {"recovered", "fell"} <= {row["outcome"] for row in rows}
    assert repr(rows) == repr(compiled)  # every column, NaN and None included, to the bit


@pytest.mark.parametrize("sweeps", [{}, {"toe": (0.12, 0.18, 0.06)}])
@pytest.mark.parametrize("samples", [None, 7])
def test_a_batch_s_pushes_are_the_numbered_pushes(sweeps: dict, samples: int | None) -> None:
    # pushes() shares the bodies of equal swept values (and the spec's own without sweeps).
    spec = CampaignSpec(
        "analytic", "pendulum", "ankle-pd", P, x0=(0.0, 0.05, 0.05), xdot=(0.0, 0.4, 0.2),
        sweeps=sweeps, samples=samples, batch_size=5,
    )  # fmt: skip
    batched = [push for b in spec.batch_indices() for push in spec.pushes(b)]
    assert batched == [spec.push(i) for i in range(spec.size)]
    for b in spec.batch_indices():  # one body per distinct swept values in a batch
        pushes = spec.pushes(b)
        assert len({id(push.params) for push in pushes}) == len({push.params for push in pushes})
    if not sweeps:
        assert all(push.params is spec.params for push in batched)
