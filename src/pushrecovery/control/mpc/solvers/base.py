"""The contract of the MPC's solvers: a state and a :class:`Guess` in, a Plan out.

A solver is built once for one problem (the sparse Eq. (17),
:class:`~pushrecovery.control.mpc.problem.SparseQP`, or the condensed one,
:class:`~pushrecovery.control.mpc.qp.CondensedQP`) and allocates its workspace then; each tick
it solves that problem from the measured state, starting where the :class:`Guess` says, and
returns a :class:`~pushrecovery.control.mpc.plan.Plan` whose ``status`` says whether (and how)
it found one. The route that chains them is
:class:`~pushrecovery.control.mpc.solvers.route.Route`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.mpc.plan import Plan

__all__ = ["Guess", "Solver"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Guess:
    """Where a solve starts; every field is optional (the default: the solver's own warm start).

    Parameters
    ----------
    active : ndarray of int8, shape (N, 3), optional
        An active set to start from, rows (δ_i, τ_i, θ_{i+1}), −1 at the lower bound, +1 at the
        upper: the Riccati passes start from it (and keep it as their own), DAQP starts from it
        as its dual active set, the interior point starts its rows near those bounds. None: the
        solver's own (its last solve's), or a cold start.
    shift : bool
        Whether the active set is the last tick's, to be shifted one stage (the receding
        horizon), rather than one for this state (the Riccati passes).
    inputs : ndarray, shape (N, 2), optional
        The last tick's plan (δ [m], τ [N m]), shifted one stage: the interior point's warm start.
    forced : (int, int)
        (k, side): the torques of the first k stages held at full braking, side τmax (the
        flywheel on the boundary of its viable set,
        :meth:`~pushrecovery.control.mpc.feasibility.FlywheelFeasibility.forced_braking`).
    budget : int, optional
        Passes or iterations allowed; None: the solver's default.
    resume : bool
        The interior point: continue its last solve's unfinished iterate, shifted by one stage
        (the real-time mode's iterations spread over ticks); ``inputs`` and ``active`` unused.
    """

    active: NDArray[np.int8] | None = None
    shift: bool = True
    inputs: FloatArray | None = None
    forced: tuple[int, int] = (0, 0)
    budget: int | None = None
    resume: bool = False


class Solver(Protocol):
    """A solver of Eq. (17) for one problem: what every module of this package implements."""

    def solve(self, x0: FloatArray, guess: Guess) -> Plan:
        """Solve from ``x0`` = [x, θ, ẋ, θ̇] [m, rad, m/s, rad/s], starting from ``guess``."""
        ...

    def reset(self) -> None:
        """Forget the warm start: the next solve starts cold (unless its guess says otherwise)."""
        ...
