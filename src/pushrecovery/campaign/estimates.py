"""A campaign's state estimates: each push's noisy estimate and its verdict probabilities.

With a spec's ``state_sd`` (σ_x [m], σ_ẋ [m/s]) each planar push gets an estimate of its
pushed state, (x0, ẋ) plus independent normal errors drawn from a generator seeded with
(``seed``, the push's index), so that a push's estimate does not depend on the batch it runs in
or the number of workers. Its columns (:data:`~.rows.COLUMNS_UNCERTAIN`): the estimate, the
probability that the controller's strategy suffices and that no strategy of the model does,
given the estimate, diag(σ²) and the spec's ``latency`` (:mod:`pushrecovery.surfaces.probability`),
and whether the certain verdict of the estimate is within the strategy. Scored against the
outcomes in the campaign's summary (``calibration``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.surfaces.probability import verdict_probability_table

if TYPE_CHECKING:
    from pushrecovery.campaign.spec import CampaignSpec, Push

__all__ = ["estimate_columns"]


def estimate_columns(spec: CampaignSpec, pushes: Sequence[Push]) -> list[dict[str, Any]]:
    """Return each push's estimate columns (module docstring); empty dicts without them."""
    from pushrecovery.campaign.spec import CampaignSpec, Push

    require_type("spec", spec, CampaignSpec)
    for push in pushes:
        require_type("each of pushes", push, Push)
    if spec.state_sd is None and spec.latency == 0.0:
        return [{} for _ in pushes]
    sd = np.array(spec.state_sd if spec.state_sd is not None else (0.0, 0.0))
    found: list[dict[str, Any]] = [{} for _ in pushes]
    groups: dict[Any, list[int]] = {}
    for k, push in enumerate(pushes):
        groups.setdefault(push.params, []).append(k)
    for params, members in groups.items():
        truth = np.array([[pushes[k].x0, pushes[k].xdot] for k in members])
        errors = np.array(
            [np.random.default_rng((spec.seed, pushes[k].index)).normal(0.0, sd) for k in members]
        )
        estimates = truth + errors
        # The strategies up to the controller's: ankle (level 0), hip (1), or any steps.
        reach = {"ankle": 0, "hip": 1}.get(spec.strategy, 1 + params.max_steps)
        chances = verdict_probability_table(estimates, np.diag(sd**2), params,
                                            latency=spec.latency)  # fmt: skip
        certain = verdict_probability_table(estimates, np.zeros((2, 2)), params,
                                            latency=spec.latency)  # fmt: skip
        recovers = np.cumsum(chances.levels, axis=1)[:, reach]
        certain_recovers = np.cumsum(certain.levels, axis=1)[:, reach] > 0.5
        for j, k in enumerate(members):
            found[k] = {
                "estimate_x": float(estimates[j, 0]),
                "estimate_xdot": float(estimates[j, 1]),
                "p_recovers": float(min(max(recovers[j], 0.0), 1.0)),
                "p_fall": float(chances.fall[j]),
                "estimate_recovers": bool(certain_recovers[j]),
            }
    return found
