"""The compiled batch of ankle-PD pushes against the one-push loop: the same rows, bit for bit.

Ground truth is ``simulate`` with ``AnklePD`` on ``PendulumPlant`` / ``LipmPlant``
(:func:`~pushrecovery.campaign.pushes.run_push`): every column of every row must be equal,
outcomes, decision times and CoP excursions included, over pushes that recover, fall or stay
undecided, on swept bodies.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.campaign import CampaignSpec
from pushrecovery.campaign.pushes import push_rows, run_batch, run_push
from pushrecovery.errors import PushRecoveryError
from pushrecovery.sim.batched import ankle_pd_pushes

P = load_params()


def spec(model: str, duration: float = 6.0) -> CampaignSpec:
    return CampaignSpec(
        "analytic", model, "ankle-pd", P, x0=(-0.04, 0.11, 0.0375), xdot=(-0.9, 0.9, 0.15),
        sweeps={"toe": (0.12, 0.18, 0.06)}, duration=duration, batch_size=1000,
    )  # fmt: skip


@pytest.mark.parametrize("model", ["pendulum", "lipm"])
@pytest.mark.parametrize("duration", [6.0, 0.3])
def test_batched_rows_equal_the_one_push_loop(model: str, duration: float) -> None:
    campaign = spec(model, duration)
    _, rows = run_batch(campaign, 0)  # the compiled loop
    assert len(rows) == campaign.size == 2 * 5 * 13
    assert rows == push_rows(campaign, campaign.pushes(0), engine="loop")
    outcomes = {row["outcome"] for row in rows}
    assert outcomes == ({"recovered", "fell"} if duration > 1.0 else {"undecided", "fell"})


def test_bad_batches() -> None:
    with pytest.raises(InvalidParameterError, match="model must be 'pendulum' or 'lipm'"):
        ankle_pd_pushes("flywheel", [P], [0.0], [0.1], duration=1.0)
    with pytest.raises(InvalidParameterError, match="one entry per push"):
        ankle_pd_pushes("lipm", [P, P], [0.0], [0.1], duration=1.0)
    for duration in (0.0, -1.0, float("nan"), 61.0, "x", None):
        with pytest.raises(PushRecoveryError, match="duration must be"):
            ankle_pd_pushes("lipm", [P], [0.0], [0.1], duration=duration)


def test_a_start_off_the_model_is_refused_as_in_the_loop() -> None:
    from pushrecovery.campaign.spec import Push

    campaign = spec("pendulum")
    far = Push(0, dataclasses.replace(P), (), 0.0, 1e6)  # a CoM velocity no body has
    with pytest.raises(InvalidParameterError):
        run_push(campaign, far)
    with pytest.raises(InvalidParameterError):
        push_rows(campaign, [far], engine="compiled")
    assert np.isfinite(ankle_pd_pushes("lipm", [P], [0.0], [0.1], duration=1.0).times).all()


def test_row_predictions_are_classify_s() -> None:
    # The rows' verdicts come from one vectorised call per body; classify, state by state,
    # must give the same numbers, on a grid that reaches every strategy.
    from pushrecovery.surfaces.classify import classify

    campaign = CampaignSpec(
        "analytic", "lipm", "ankle-pd", P, x0=(-0.04, 0.11, 0.05), xdot=(-4.5, 4.5, 0.25),
        sweeps={"toe": (0.12, 0.18, 0.06)}, batch_size=1000,
    )  # fmt: skip
    _, rows = run_batch(campaign, 0)
    assert {row["predicted"] for row in rows} == {"ankle", "hip", "step", "fall"}
    for row, push in zip(rows, campaign.pushes(0), strict=True):
        found = classify(push.x0, push.xdot, push.params)
        assert row["predicted"] == found.strategy.value
        assert row["capture_point"] == found.capture_point
        assert (row["cop_margin"], row["cmp_margin"], row["step_margin"]) == (
            found.margins["cop"], found.margins["cmp"], found.margins["step"]
        )  # fmt: skip
        assert row["predicted_steps"] == (-1 if found.steps is None else found.steps)
