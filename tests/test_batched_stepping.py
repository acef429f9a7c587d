"""The compiled batch of the recovery controller on the stepping model, against the one-push loop.

Ground truth is ``simulate`` with ``RecoveryController`` on ``SteppingPlant``
(:func:`~pushrecovery.campaign.pushes.run_push`): every column of every row must be equal, bit
for bit, over pushes that the ankles, the hip (the MPC's QPs) and one or more steps recover,
that fall, or stay undecided, on swept bodies.
"""

from __future__ import annotations

import dataclasses
from collections import Counter

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.campaign import CampaignSpec
from pushrecovery.campaign.pushes import push_rows, run_batch, run_push
from pushrecovery.campaign.spec import Push
from pushrecovery.errors import PushRecoveryError
from pushrecovery.kernels.batched import stepping as kernel
from pushrecovery.sim.batched import recovery_pushes
from pushrecovery.sim.many import COMPILED

P = load_params()


#: The full grid (3 stances × 25 pushes × 2 hip limits) and a sixth of it that still takes every
#: branch of the loop (make test; the full grid runs in make validate).
FULL = {"x0": (-0.03, 0.09, 0.06), "xdot": (-3.6, 3.6, 0.3)}
SHORT = {"x0": (0.0, 0.0, 1.0), "xdot": (-3.6, 3.6, 0.6)}


def spec(
    duration: float = 10.0, grid: dict[str, tuple[float, float, float]] = FULL
) -> CampaignSpec:
    return CampaignSpec(
        "analytic", "stepping", "recovery", P, **grid,
        sweeps={"torque_max": (40.0, 80.0, 40.0)}, duration=duration, batch_size=1000,
    )  # fmt: skip


@pytest.mark.parametrize(
    "duration, grid, size",
    [
        pytest.param(10.0, SHORT, 2 * 13, id="every-branch"),
        pytest.param(10.0, FULL, 2 * 3 * 25, id="every-branch-full", marks=pytest.mark.validate),
        pytest.param(0.4, FULL, 2 * 3 * 25, id="undecided"),
    ],
)
def test_batched_rows_equal_the_one_push_loop(
    duration: float, grid: dict[str, tuple[float, float, float]], size: int
) -> None:
    campaign = spec(duration, grid)
    assert ("stepping", "recovery") in COMPILED
    _, rows = run_batch(campaign, 0)  # the compiled loop
    assert len(rows) == campaign.size == size
    loop = push_rows(campaign, campaign.pushes(0), engine="loop")
    for row, push, expected in zip(rows, campaign.pushes(0), loop, strict=True):
        assert row == expected, push
    if duration > 1.0:
        # Every branch of the loop was taken: the ankles, the hip, one and several steps, falls.
        used = Counter(row["used"] for row in rows)
        assert set(used) == {"ankle", "hip", "step", "fall"}, used
        assert max(row["steps"] for row in rows) >= 2
        assert any(row["used"] == "hip" and row["peak_hip_torque"] > 1.0 for row in rows)
    else:
        assert "undecided" in {row["outcome"] for row in rows}


def test_a_batch_shares_its_controllers_as_the_loop_does() -> None:
    # The MPC of a stance height warm-starts from the previous push's last QP in both loops:
    # the same pushes in another order give the same rows as the loop in that order.
    campaign = spec()
    pushes = campaign.pushes(0)[::-1]
    controllers: dict = {}
    runs = recovery_pushes(
        [p.params for p in pushes], [p.x0 for p in pushes], [p.xdot for p in pushes],
        duration=campaign.duration, controllers=controllers,
    )  # fmt: skip
    assert set(controllers) == {p.params for p in pushes}
    for k, row in enumerate(push_rows(campaign, pushes, engine="loop")):
        assert (runs.outcomes[k].value, float(runs.times[k])) == (row["outcome"], row["time"])
        assert float(runs.peak_hip_torque[k]) == row["peak_hip_torque"]
        assert int(runs.steps[k]) == row["steps"]


def test_the_kernel_asks_for_what_it_cannot_do() -> None:
    # A hip push: the controller's body at the height first, then the MPC's command.
    c = np.array([P.mass, P.com_height, P.gravity, P.heel, P.toe, P.flywheel_inertia,
                  P.flywheel_angle_max, P.torque_max, 1e-3, 1e-3])  # fmt: skip
    f, n, ab = kernel.new_records()
    kernel.start(c, 0.0, 0.6, f, n)
    assert kernel.advance(c, 100, 500, f, n, ab) == kernel.NEED_BODY
    assert n[kernel.K] == 0  # nothing simulated before the first command


def test_bad_batches() -> None:
    with pytest.raises(InvalidParameterError, match="one entry per push"):
        recovery_pushes([P, P], [0.0], [0.1], duration=1.0)
    for duration in (0.0, -1.0, float("nan"), 61.0, "x", None):
        with pytest.raises(PushRecoveryError, match="duration must be"):
            recovery_pushes([P], [0.0], [0.1], duration=duration)
    with pytest.raises(PushRecoveryError, match="bodies"):
        recovery_pushes(P, [0.0], [0.1], duration=1.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="xdot"):
        recovery_pushes([P], [0.0], [1e6], duration=1.0)
    with pytest.raises(InvalidParameterError, match="x0"):
        recovery_pushes([P], [float("nan")], [0.1], duration=1.0)


def test_a_start_off_the_model_is_refused_as_in_the_loop() -> None:
    campaign = spec()
    far = Push(0, dataclasses.replace(P), (), 0.0, 1e6)  # a CoM velocity no body has
    with pytest.raises(InvalidParameterError):
        run_push(campaign, far)
    with pytest.raises(InvalidParameterError):
        push_rows(campaign, [far], engine="compiled")
