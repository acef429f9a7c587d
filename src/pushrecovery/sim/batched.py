"""Many pushes in one compiled loop: the ankle PD on the pendulum and on the LIPM (issue 17).

:func:`ankle_pd_pushes` gives, for each push, what :func:`~pushrecovery.sim.simulate.simulate`
gives for ``AnklePD`` (default gains) on ``PendulumPlant`` or ``LipmPlant`` with the default
control period and rest criterion: the outcome, the time it was decided and the CoP excursion,
the same numbers (``tests/test_batched.py``), without a Python call per tick. Campaigns of
these pairs use it (:func:`~pushrecovery.campaign.pushes.run_batch`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery._validate import bounded_float, require_type, sample_array
from pushrecovery.control.ankle import default_pd_gains
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import check_com_state
from pushrecovery.sim.plants import PendulumPlant
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import DEFAULT_CONTROL_PERIOD, MAX_DURATION, RestCriterion

__all__ = ["BATCHED", "BatchedRuns", "ankle_pd_pushes"]

#: (model, controller) pairs with a compiled loop.
BATCHED = frozenset({("pendulum", "ankle-pd"), ("lipm", "ankle-pd")})
_OUTCOMES = (Outcome.UNDECIDED, Outcome.RECOVERED, Outcome.FELL)


@dataclass(frozen=True, slots=True)
class BatchedRuns:
    """The runs of :func:`ankle_pd_pushes`, one entry per push.

    Attributes
    ----------
    outcomes : tuple of Outcome
        Recovered, fell or undecided.
    times : ndarray
        Simulated time at which the run ended (its outcome decided, or the duration) [s].
    cop_min, cop_max : ndarray
        CoP excursion applied over the run [m].
    """

    outcomes: tuple[Outcome, ...]
    times: NDArray[np.float64]
    cop_min: NDArray[np.float64]
    cop_max: NDArray[np.float64]


def ankle_pd_pushes(
    model: str,
    bodies: Sequence[BodyParams],
    x0: Sequence[float],
    xdot: Sequence[float],
    *,
    duration: float,
) -> BatchedRuns:
    """Simulate the ankle PD after each push (x0[i], xdot[i]) on bodies[i].

    Parameters
    ----------
    model : {"pendulum", "lipm"}
        The plant.
    bodies : sequence of BodyParams
        Each push's body (default PD gains, :func:`~pushrecovery.control.ankle.default_pd_gains`).
    x0, xdot : sequence of float
        CoM position [m] and velocity [m/s] just after each push (checked as the plants'
        ``reset`` does).
    duration : float
        Longest simulated time per push [s], in (0, 60].

    Returns
    -------
    BatchedRuns
        One entry per push, in order.

    Raises
    ------
    InvalidParameterError
        An unknown model, sequences of different lengths, a start no model can have, a
        duration outside (0, 60] s.
    ParameterTypeError
        ``bodies`` not a list or tuple of BodyParams.
    """
    from pushrecovery.sim._batched_kernels import ankle_pd_pushes as kernel

    if not (isinstance(model, str) and model in ("pendulum", "lipm")):
        raise InvalidParameterError(f"model must be 'pendulum' or 'lipm', got {model!r:.40}")
    require_type("bodies", bodies, (list, tuple))
    for body in bodies:
        require_type("bodies[i]", body, BodyParams)
    starts = sample_array("x0", x0)
    speeds = sample_array("xdot", xdot)
    if not len(bodies) == len(starts) == len(speeds):
        raise InvalidParameterError(
            f"bodies, x0 and xdot must have one entry per push, got {len(bodies)}, "
            f"{len(starts)} and {len(speeds)}"
        )
    for body, start, speed in zip(bodies, starts.tolist(), speeds.tolist(), strict=True):
        check_com_state(start, speed, body)  # as the plants' reset
    duration = bounded_float("duration", duration, 0.0, MAX_DURATION, "s")
    if duration == 0.0:
        raise InvalidParameterError(f"duration must be in (0, {MAX_DURATION:g}] s, got 0")
    dt = DEFAULT_CONTROL_PERIOD
    assert dt <= PendulumPlant.max_substep  # one RK4 substep per tick, as the kernel does
    rest = RestCriterion()
    # As simulate(): whole ticks in the duration, and in the rest criterion's time.
    ticks = math.ceil(duration / dt - 1e-9)
    rest_ticks = max(1, math.ceil(rest.duration / dt - 1e-9))
    count = len(bodies)
    columns = np.array(
        [(b.mass, b.com_height, b.gravity, b.heel, b.toe, *default_pd_gains(b)) for b in bodies],
        dtype=np.float64,
    ).reshape(count, 7)
    code, end = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    cop_min, cop_max = np.empty(count), np.empty(count)
    mass, height, gravity, heel, toe, kp, kd = (
        np.ascontiguousarray(columns[:, j]) for j in range(7)
    )
    kernel(
        model == "pendulum",
        starts,
        speeds,
        mass,
        height,
        gravity,
        heel,
        toe,
        kp,
        kd,
        dt,
        ticks,
        rest_ticks,
        rest.speed,
        code,
        end,
        cop_min,
        cop_max,
    )
    times: NDArray[np.float64] = end.astype(np.float64) * dt
    return BatchedRuns(tuple(_OUTCOMES[c] for c in code.tolist()), times, cop_min, cop_max)
