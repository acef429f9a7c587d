"""Capture-point bounds and velocity thresholds of every strategy (``pushrecovery bounds``)."""

from __future__ import annotations

from typing import Any

from pushrecovery.params import BodyParams

__all__ = ["bounds_data"]


def bounds_data(params: BodyParams) -> dict[str, Any]:
    """Capture-point bounds and velocity thresholds of each strategy, as a JSON-ready dict.

    The same keys and numbers as ``pushrecovery bounds --json``: ``params``; ``omega`` =
    sqrt(g/L) [1/s]; ``cop`` the capture-point interval of CoP balancing, Eq. (4) [m]; ``cmp``
    that of CMP balancing, corrected Eq. (15) [m], with its ``margin`` beyond the foot [m] and
    ``t_max`` the longest bang-bang half period, Eq. (12) [s] (None without hip torque);
    ``thresholds`` the largest recoverable CoM velocity from x = 0, [backward, forward], per
    strategy [m/s] (ankle: ω δ±, hip: ω times the CMP bounds, step: the single-step limit of
    Sec. IV).

    Parameters
    ----------
    params : BodyParams
        The body.

    Returns
    -------
    dict
        The bounds (see above).
    """
    from pushrecovery.models.flywheel import max_spin_up_time
    from pushrecovery.surfaces.cmp import cmp_offset, cmp_region
    from pushrecovery.surfaces.cop import cop_region
    from pushrecovery.surfaces.step import step_thresholds

    cop, cmp = cop_region(params), cmp_region(params)
    spin_up = max_spin_up_time(params)
    omega = params.omega
    return {
        "params": params.to_dict(),
        "omega": omega,
        "cop": {"lower": cop.lower, "upper": cop.upper},
        "cmp": {
            "lower": cmp.lower,
            "upper": cmp.upper,
            "margin": cmp_offset(params),
            # JSON has no infinity: without hip torque there is no spin-up at all.
            "t_max": spin_up if spin_up != float("inf") else None,
        },
        "thresholds": {
            "ankle": [omega * cop.lower, omega * cop.upper],
            "hip": [omega * cmp.lower, omega * cmp.upper],
            "step": list(step_thresholds(params)),
        },
    }
