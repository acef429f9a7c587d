"""Stepping decision surface (Sec. IV): a single step within reach that recovers, or none.

For a CoM state (x, ẋ) beyond the balancing regions the body steps in the direction of its
capture point. The stance leg (the ankle-to-CoM segment, l = sqrt(x² + L²)) then falls as
Hofmann's pendulum from its lean θ0 with rate θ̇0; energy gives
θ̇(θ)² = θ̇0² + 2 (g/l)(cos θ0 − cos θ) for θ ≥ θ0, so :mod:`pushrecovery.models.stepping`
applies, with the step taken at an angle θ ≥ θ0 (slow falls below the top of the pendulum
included). A step at θ recovers when the post-impact capture point lies inside the new foot
(θ_low < θ < θ_high), the foot lands within reach (2 l sin θ ≤ max_step_length) and the stance
leg is still in compression at the landing (l θ̇² ≤ g cos θ). The recommended step is Eq. (21)'s
θ*, moved into that feasible interval if needed. Backward steps are the mirror image (heel and
toe swapped).

One function decides a state: :func:`pushrecovery.kernels.step_scalar.decide`, plain Python
(``math`` only). :func:`plan_step`, :func:`step_critical_velocity` and :func:`step_thresholds`
run it as it is, with neither numba nor scipy imported; :func:`plan_steps` runs it as it is for
a few states and compiled by numba (cached on disk, parallel for large arrays) for more;
:func:`compiled_plan_step` hands out its compiled form for real-time loops.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    require_type,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.kernels.step_scalar import MIN_STEP_LENGTH as MIN_STEP_LENGTH
from pushrecovery.kernels.step_scalar import decide, feasible
from pushrecovery.params import BodyParams

__all__ = [
    "StepDecision",
    "StepPlan",
    "compiled_plan_step",
    "plan_step",
    "plan_steps",
    "step_critical_velocity",
    "step_feasible",
    "step_thresholds",
]

FloatArray = NDArray[np.float64]
#: Signature of :func:`compiled_plan_step`'s planner: (x, xdot, heel, toe, com_height, gravity,
#: max_step_length) to (direction, ready, feasible, theta, step_length, shortest, longest,
#: margin), the fields of :class:`StepDecision`.
ScalarPlanner = Callable[
    [float, float, float, float, float, float, float],
    tuple[float, bool, bool, float, float, float, float, float],
]

#: Up to this many states, :func:`plan_steps` runs the pure-Python decision (about 20 µs a
#: state) instead of loading numba (0.4 s, once per process) and its compiled loops.
_PYTHON_MAX_SIZE = 32


@dataclass(frozen=True, slots=True)
class StepPlan:
    """Step decision for arrays of CoM states; all fields have the states' shape.

    Attributes
    ----------
    direction : ndarray
        +1 step forward, −1 backward (the side of the capture point).
    ready : ndarray of bool
        The CoM falls toward that side, so a step can be taken now.
    feasible : ndarray of bool
        A single step within reach recovers the state.
    theta : ndarray
        Recommended stance-leg angle at impact [rad] (NaN where not ready). Where infeasible it
        is the best effort: the admissible angle whose capture point lands nearest the foot.
    step_length : ndarray
        Recommended step, foot to foot, signed like ``direction`` [m] (NaN where not ready).
    shortest, longest : ndarray
        Shortest and longest recovering step within reach, foot to foot, unsigned [m].
    margin : ndarray
        max_step_length minus the shortest recovering step [m]: positive when a step within
        reach exists (−inf when no step length recovers at all).
    """

    direction: FloatArray
    ready: NDArray[np.bool_]
    feasible: NDArray[np.bool_]
    theta: FloatArray
    step_length: FloatArray
    shortest: FloatArray
    longest: FloatArray
    margin: FloatArray


@dataclass(frozen=True, slots=True)
class StepDecision:
    """Step decision for one CoM state: the fields of :class:`StepPlan` as Python scalars.

    Attributes
    ----------
    direction : float
        +1.0 step forward, −1.0 backward.
    ready, feasible : bool
        A step can be taken now; a single step within reach recovers the state.
    theta : float
        Recommended stance-leg angle at impact [rad] (NaN when not ready).
    step_length : float
        Recommended step, foot to foot, signed like ``direction`` [m] (NaN when not ready).
    shortest, longest : float
        Shortest and longest recovering step within reach, foot to foot [m].
    margin : float
        max_step_length minus the shortest recovering step [m] (−inf when none recovers).
    """

    direction: float
    ready: bool
    feasible: bool
    theta: float
    step_length: float
    shortest: float
    longest: float
    margin: float


def plan_steps(
    x: ArrayLike,
    xdot: ArrayLike,
    params: BodyParams,
    *,
    heel: ArrayLike | None = None,
    toe: ArrayLike | None = None,
) -> StepPlan:
    """Plan the recovering step for arrays of CoM states (module docstring).

    The stance leg is the ankle-to-CoM segment as it stands, l = sqrt(x² + L²) with L =
    ``com_height``, leaning θ0 = atan2(x, L); when it locks to fall as a pendulum only the
    tangential part of the CoM velocity survives, θ̇0 = ẋ cos θ0 / l. This is exactly what
    :class:`~pushrecovery.sim.plants.SteppingPlant` does. Each state is decided by the function
    behind :func:`plan_step`, compiled by numba (cached on disk) for more than a few states.

    Parameters
    ----------
    x : array_like
        CoM position relative to the stance ankle [m].
    xdot : array_like
        CoM velocity [m/s].
    params : BodyParams
        Body parameters (com_height, max_step_length, g, foot edges).
    heel, toe : array_like, optional
        Back and front edges of the new foot relative to its ankle along the step line [m]
        (heel < toe, by convention heel < 0 < toe), broadcast with the states; default
        ``params.heel`` and ``params.toe``. Backward steps mirror them (the foot turned round).

    Returns
    -------
    StepPlan
        Arrays of the broadcast shape of the states and feet.

    Raises
    ------
    InvalidParameterError
        If a heel is not behind its toe, or a state or an edge is NaN or infinite.
    """
    require_type("params", params, BodyParams)
    given = {"x": x, "xdot": xdot, "heel": heel, "toe": toe}
    arrays = [finite_array(n, params.heel if n == "heel" else params.toe) if a is None
              else finite_array(n, a) for n, a in given.items()]  # fmt: skip
    try:
        xs, xds, backs, fronts = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(str(a.shape) for a in arrays)
        raise InvalidParameterError(f"x, xdot, heel and toe must broadcast, got {shapes}") from None
    if heel is not None or toe is not None:
        _check_edges(not np.any(backs >= fronts), heel, toe)
    shape = xs.shape
    height, gravity, reach = params.com_height, params.gravity, params.max_step_length
    if xs.size <= _PYTHON_MAX_SIZE:
        rows = zip(xs.flat, xds.flat, backs.flat, fronts.flat, strict=True)
        decisions = [
            decide(float(a), float(b), float(c), float(d), height, gravity, reach)
            for a, b, c, d in rows
        ]
        columns = list(zip(*decisions, strict=True)) or [()] * 8
        values = np.array([columns[k] for k in (0, 3, 4, 5, 6, 7)], dtype=np.float64)
        flags = np.array(columns[1:3], dtype=np.bool_)
    else:
        from pushrecovery.kernels.stepping import plan

        values, flags = plan(xs, xds, backs, fronts, height, gravity, reach)
    values = values.reshape((6, *shape))
    flags = flags.reshape((2, *shape))
    return StepPlan(  # [k, ...]: 0-d arrays, not numpy scalars, for a single state
        direction=values[0, ...],
        ready=flags[0, ...],
        feasible=flags[1, ...],
        theta=values[1, ...],
        step_length=values[2, ...],
        shortest=values[3, ...],
        longest=values[4, ...],
        margin=values[5, ...],
    )


def plan_step(
    x: float,
    xdot: float,
    params: BodyParams,
    *,
    heel: float | None = None,
    toe: float | None = None,
) -> StepDecision:
    """Plan the recovering step for one CoM state, in pure Python (``math`` only, no numba).

    The same decision as :func:`plan_steps` for one state (see there for the arguments and the
    model), from the same function; a few tens of µs, with nothing to load or compile.

    Returns
    -------
    StepDecision

    Raises
    ------
    InvalidParameterError
        If ``heel`` is not behind ``toe``.
    """
    require_type("params", params, BodyParams)
    back = params.heel if heel is None else finite_float("heel", heel, "m")
    front = params.toe if toe is None else finite_float("toe", toe, "m")
    if heel is not None or toe is not None:
        _check_edges(not back >= front, heel, toe)
    args = (params.com_height, params.gravity, params.max_step_length)
    state = finite_float("x", x, "m"), finite_float("xdot", xdot, "m/s")
    return StepDecision(*decide(*state, back, front, *args))


def step_feasible(x: float, xdot: float, heel: float, toe: float, params: BodyParams) -> bool:
    """Whether a single step recovers one state: ``plan_step(...).feasible``, faster.

    Pure Python, without solving for the step angle (``step_scalar.feasible``: two
    evaluations of the post-impact capture point instead of three Newton solves). Arguments
    as in :func:`plan_step`, the new foot's edges ``heel`` < ``toe`` [m] given.
    """
    require_type("params", params, BodyParams)
    return feasible(
        finite_float("x", x, "m"),
        finite_float("xdot", xdot, "m/s"),
        finite_float("heel", heel, "m"),
        finite_float("toe", toe, "m"),
        params.com_height,
        params.gravity,
        params.max_step_length,
    )


@functools.cache
def compiled_plan_step() -> ScalarPlanner:
    """Return the per-state decision of :func:`plan_step`, compiled, for real-time loops.

    Loads numba and the machine code from its on-disk cache on the first call in a process
    (compiling it only on the first run on a machine, or after the code changed); the planner
    returned never compiles again.

    Returns
    -------
    callable
        ``planner(x, xdot, heel, toe, com_height, gravity, max_step_length)``, all floats in SI
        units as in :func:`plan_steps`, returning the tuple (direction, ready, feasible, theta,
        step_length, shortest, longest, margin) of :class:`StepDecision`'s fields. It does not
        validate its arguments (heel < toe, finite values) and releases the GIL.
    """
    from pushrecovery.kernels.stepping import scalar_decide

    return scalar_decide()


def _check_edges(valid: bool, heel: object, toe: object) -> None:
    if not valid:
        raise InvalidParameterError(
            f"heel must be < toe (the new foot's back and front edges), got heel={heel}, toe={toe}"
        )


def step_critical_velocity(
    x: float, direction: float, params: BodyParams, *, tolerance: float = 1e-9
) -> float:
    """Largest CoM velocity from position x [m] that one step recovers, signed [m/s].

    Found by bisection on the feasibility of :func:`plan_step` (monotone in the
    push: a harder push needs a longer step and loads the stance leg less). Pure Python: no
    numba or scipy is loaded.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`BodyParams`.
    InvalidParameterError
        If ``x`` is not finite, ``direction`` is not ±1, or ``tolerance`` is outside
        [1e-12, 0.1] m/s (a bisection of speeds up to sqrt(g L) ends at float resolution
        below, and would never end at 0).
    """
    require_type("params", params, BodyParams)
    x = finite_float("x", x, "m")
    tolerance = bounded_float("tolerance", tolerance, 1e-12, 0.1, "m/s")
    if finite_float("direction", direction) not in (1.0, -1.0):
        raise InvalidParameterError(f"direction must be +1 or -1, got {direction!r}")
    sign = 1.0 if direction > 0.0 else -1.0
    args = (params.heel, params.toe, params.com_height, params.gravity, params.max_step_length)
    x = float(x)
    low, high = 0.0, math.sqrt(params.gravity * params.leg_length)
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        if feasible(x, sign * middle, *args):  # = decide(...)[2], without the angles
            low = middle
        else:
            high = middle
    return sign * low


def step_thresholds(params: BodyParams, *, tolerance: float = 1e-9) -> tuple[float, float]:
    """Largest backward and forward CoM velocity from x = 0 that one step recovers [m/s].

    Returns
    -------
    (v_back, v_fwd) : tuple of float
        Signed: v_back < 0 < v_fwd.

    Raises
    ------
    InvalidParameterError
        If ``tolerance`` [m/s] is outside [1e-12, 0.1] (:func:`step_critical_velocity`).
    """
    require_type("params", params, BodyParams)
    return (
        step_critical_velocity(0.0, -1.0, params, tolerance=tolerance),
        step_critical_velocity(0.0, 1.0, params, tolerance=tolerance),
    )
