"""Capture-point bounds and velocity thresholds of every strategy (``pushrecovery bounds``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams

__all__ = ["bounds_data", "plane_bounds"]


def bounds_data(params: BodyParams, support: Support | None = None) -> dict[str, Any]:
    """Capture-point bounds and velocity thresholds of each strategy, as a JSON-ready dict.

    The same keys and numbers as ``pushrecovery bounds --json``: ``params``; ``omega`` =
    sqrt(g/L) [1/s]; ``cop`` the capture-point interval of CoP balancing, Eq. (4) [m]; ``cmp``
    that of CMP balancing, corrected Eq. (15) [m], with its ``margin`` beyond the foot [m] and
    ``t_max`` the longest bang-bang half period, Eq. (12) [s] (None without hip torque);
    ``thresholds`` the largest recoverable CoM velocity from x = 0, [backward, forward], per
    strategy [m/s] (ankle: ω δ±, hip: ω times the CMP bounds, step: ω times the bounds of the
    ``max_steps``-step interval of :mod:`pushrecovery.surfaces.step.regions`, the ``step``
    verdict's limit), ``steps`` the same for each N = 1 ... max_steps and ``"inf"`` (Koolen's
    d_∞), and ``step_sec4`` Sec. IV's instantaneous single step (the paper's model);
    ``plane`` the ground-plane bounds of :func:`plane_bounds`.

    Parameters
    ----------
    params : BodyParams
        The body.
    support : Support, optional
        Stance and feet for ``plane``; default double support on the default feet.

    Returns
    -------
    dict
        The bounds (see above).
    """
    from pushrecovery.models.flywheel import max_spin_up_time
    from pushrecovery.surfaces.cmp import cmp_offset, cmp_region
    from pushrecovery.surfaces.cop import cop_region
    from pushrecovery.surfaces.step import step_thresholds
    from pushrecovery.surfaces.step.regions import sagittal_step_interval

    cop, cmp = cop_region(params), cmp_region(params)
    omega = params.omega
    steps: dict[str, list[float]] = {}
    for n in range(1, params.max_steps + 1):
        interval = sagittal_step_interval(params, n)
        steps[str(n)] = [omega * interval.lower, omega * interval.upper]
    limit = sagittal_step_interval(params, 10**6)  # β^N underflows: the series' sum, d_∞
    steps["inf"] = [omega * limit.lower, omega * limit.upper]
    spin_up = max_spin_up_time(params)
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
            "step": steps[str(params.max_steps)],
            "steps": steps,
            "step_sec4": list(step_thresholds(params)),
        },
        "plane": plane_bounds(params, Support.from_params(params) if support is None else support),
    }


def plane_bounds(params: BodyParams, support: Support) -> dict[str, Any]:
    """Ground-plane bounds: the support polygon, the CMP region and per-direction thresholds.

    ``thresholds`` holds, per strategy, the largest push speed [m/s] (unsigned) from a CoM at
    rest above ``support.ankle`` along ``forward`` (+x), ``backward``, ``left`` (+y) and
    ``right``: ω times the distance to the region's edge
    (:func:`~pushrecovery.surfaces.plane.direction_thresholds`) for ankle, hip and step (the
    farthest edge of the N-step regions, N <= max_steps, the ``step`` verdict's limit);
    ``steps`` the same per N, and ``step_sec4`` Sec. IV's single step along the direction
    (:func:`~pushrecovery.surfaces.plane.step_threshold_xy`). ``cmp_offset`` gives the
    hip region's growth along the pitch axis (the stance's heading) and the roll axis (its
    left) [m]; with yawed feet these are not the world's x and y.
    """
    from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll
    from pushrecovery.surfaces.n_step import _ray_distances, step_options
    from pushrecovery.surfaces.plane import (
        DIRECTIONS,
        cmp_polygon,
        direction_thresholds,
        step_threshold_xy,
    )

    hip = cmp_polygon(support, params)
    omega = params.omega
    # Every region up to N counts (a state needing fewer steps is a step verdict too), from
    # either foot in double support: the farthest edge of all of them, from (S2) directly.
    steps: dict[str, dict[str, float]] = {}
    best = np.zeros(len(DIRECTIONS))
    options = step_options(params, support)
    headings = np.array(list(DIRECTIONS.values()))
    for n in range(1, params.max_steps + 1):
        times = tuple(params.min_step_time * (k + 1) for k in range(n))
        for option in options:
            best = np.maximum(
                best, omega * _ray_distances(params, option, times, support.ankle, headings)
            )
        steps[str(n)] = {name: float(v) for name, v in zip(DIRECTIONS, best, strict=True)}
    return {
        "support": support.to_dict(),
        "reference": list(support.ankle),
        "cmp_region": hip.to_list(),
        "cmp_offset": {"pitch": cmp_offset(params), "roll": cmp_offset_roll(params)},
        "thresholds": {
            "ankle": direction_thresholds(support.polygon, support.ankle, omega),
            "hip": direction_thresholds(hip, support.ankle, omega),
            "step": steps.get(str(params.max_steps), dict.fromkeys(DIRECTIONS, 0.0)),
            "steps": steps,
            "step_sec4": {
                name: step_threshold_xy(params, support, heading)
                for name, heading in DIRECTIONS.items()
            },
        },
    }
