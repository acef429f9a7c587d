"""The sagittal verdicts of many states at once: classify's numbers, vectorised, without plans.

The strategy a state needs on the line (:mod:`pushrecovery.surfaces.classify`, whose
``classify`` calls :func:`sagittal_verdicts` with one state) from its capture point ξ = x + ẋ/ω:
``ankle`` when ξ is strictly inside the foot (Eq. 4), ``hip`` inside the CMP region (corrected
Eq. 15), ``step`` when at most ``max_steps`` steps capture it (the N-step intervals of
:mod:`pushrecovery.surfaces.step.regions`), else ``fall``. A campaign's rows need these for a
whole batch, not the plans.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import finite_array, finite_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_margin, cmp_offset, cmp_region
from pushrecovery.surfaces.cop import capture_point, cop_margin, cop_region
from pushrecovery.surfaces.step.regions import LineSteps, _growth, line_steps
from pushrecovery.surfaces.strategy import Strategy

__all__ = ["SagittalVerdict", "SagittalVerdicts", "sagittal_verdict", "sagittal_verdicts"]


def _strategy(cop: float, cmp: float, steps: int) -> Strategy:
    """Return the first strategy whose region holds the capture point."""
    if cop > 0.0:
        return Strategy.ANKLE
    if cmp > 0.0:
        return Strategy.HIP
    return Strategy.STEP if steps > 0 else Strategy.FALL


def _steps(strategy: Strategy, steps: int) -> int | None:
    """Return the steps needed: 0 for ankle and hip, N for step, None for fall."""
    if strategy is Strategy.FALL:
        return None
    return steps if strategy is Strategy.STEP else 0


@dataclass(frozen=True, slots=True)
class SagittalVerdicts:
    """The verdicts of many sagittal states (:func:`sagittal_verdicts`), one entry per state.

    Attributes
    ----------
    capture_point, cop_margin, cmp_margin : ndarray
        ξ = x + ẋ/ω and its signed distances to the CoP region (Eq. 4) and the CMP region
        (corrected Eq. 15) [m], positive inside.
    line : LineSteps
        The N-step verdicts on the line (``steps``, ``margin`` to C_{max_steps}, first steps).
    strategies : tuple of Strategy
        The strategy each state needs, as :func:`classify` gives it.
    """

    capture_point: NDArray[np.float64]
    cop_margin: NDArray[np.float64]
    cmp_margin: NDArray[np.float64]
    line: LineSteps
    strategies: tuple[Strategy, ...]

    def steps(self, k: int) -> int | None:
        """Return the steps state k needs: 0 for ankle and hip, N for step, None for fall."""
        return _steps(self.strategies[k], int(self.line.steps[k]))


def sagittal_verdicts(x: ArrayLike, xdot: ArrayLike, params: BodyParams) -> SagittalVerdicts:
    """Return the verdicts of :func:`classify` on the sagittal line for 1-D arrays of states.

    The same numbers as :func:`classify` state by state (which calls it with one state),
    without the plan of a ``step`` verdict: what a campaign's rows need, for a whole batch.

    Parameters
    ----------
    x, xdot : array_like
        CoM positions relative to the ankle [m] and velocities [m/s], 1-D (or one number
        each), of one length.
    params : BodyParams
        Body parameters.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        States that are not finite, of other shapes, or whose capture point overflows.
    """
    require_type("params", params, BodyParams)
    positions = np.atleast_1d(finite_array("x", x))
    speeds = np.atleast_1d(finite_array("xdot", xdot))
    if positions.ndim != 1 or positions.shape != speeds.shape:
        raise InvalidParameterError(
            f"x and xdot must be 1-D arrays of one length, got shapes {positions.shape} and "
            f"{speeds.shape}"
        )
    cop = cop_margin(positions, speeds, params)
    cmp = cmp_margin(positions, speeds, params)
    capture = capture_point(positions, speeds, params.omega)
    if not np.isfinite(capture).all():
        raise InvalidParameterError("states are too large: the capture point overflows")
    line = line_steps(capture, params.heel, params.toe, 0.0, params)
    strategies = tuple(
        _strategy(c, m, s)
        for c, m, s in zip(cop.tolist(), cmp.tolist(), line.steps.tolist(), strict=True)
    )
    return SagittalVerdicts(capture, cop, cmp, line, strategies)


@dataclass(frozen=True, slots=True)
class SagittalVerdict:
    """The verdict of one sagittal state (:func:`sagittal_verdict`).

    Attributes
    ----------
    capture_point, cop_margin, cmp_margin : float
        ξ = x + ẋ/ω and its signed distances to the CoP and CMP regions [m], + inside.
    steps : int
        Smallest N <= max_steps whose interval C_N holds ξ strictly; 0 if none.
    step_margin : float
        Signed distance of ξ to C_{max_steps} [m].
    strategy : Strategy
        The strategy the state needs.
    """

    capture_point: float
    cop_margin: float
    cmp_margin: float
    steps: int
    step_margin: float
    strategy: Strategy


@functools.lru_cache(maxsize=64)
def _line_bounds(
    params: BodyParams,
) -> tuple[float, float, float, float, float, tuple[tuple[float, float], ...]]:
    """1/ω, the CoP and CMP intervals' centres and half widths, C_1 ... C_{max_steps}.

    Each number as the vectorised path computes it (:func:`cop_margin`,
    :func:`~pushrecovery.surfaces.step.regions.line_steps` with the ankle at 0 and the
    support [heel, toe]), so that the scalar path agrees to the bit.
    """
    cop, cmp = cop_region(params), cmp_region(params)
    beta, grows = _growth(params, True)
    base_low = beta * (0.0 + params.heel) + (1.0 - beta) * params.heel
    base_high = beta * (0.0 + params.toe) + (1.0 - beta) * params.toe
    levels = tuple((base_low - grow, base_high + grow) for grow in grows[1:].tolist())
    return 1.0 / params.omega, cop.centre, cop.half_width, cmp.centre, cmp.half_width, levels


def sagittal_verdict(x: float, xdot: float, params: BodyParams) -> SagittalVerdict:
    """Return the verdict of one sagittal state: :func:`sagittal_verdicts` on Python floats.

    The same numbers, to the bit, without building arrays (a single-state call's hot path).

    Parameters
    ----------
    x, xdot : float
        CoM position relative to the ankle [m] and velocity [m/s], finite.
    params : BodyParams
        Body parameters.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        A state that is not finite or whose capture point overflows.
    """
    require_type("params", params, BodyParams)
    inv, cop_centre, cop_half, cmp_centre, cmp_half, levels = _line_bounds(params)
    x, xdot = finite_float("x", x, "m"), finite_float("xdot", xdot, "m/s")
    capture = x + xdot * inv
    if not math.isfinite(capture):
        raise InvalidParameterError("states are too large: the margin overflows")
    cop = cop_half - abs(capture - cop_centre)
    cmp = cmp_half - abs(capture - cmp_centre)
    steps = 0
    for n, (low, high) in enumerate(levels, start=1):
        if low < capture < high:
            steps = n
            break
    low, high = levels[-1]
    margin = min(capture - low, high - capture)
    return SagittalVerdict(capture, cop, cmp, steps, margin, _strategy(cop, cmp, steps))


def _first_step_range(capture: float, steps: int, params: BodyParams) -> tuple[float, float]:
    """``(shortest, longest)`` of :func:`line_steps` for one capture point [m], on floats.

    The first steps along the recommended one's direction that still capture with ``steps``
    steps (>= 1), the stance foot [heel, toe] about the ankle at 0: the same operations as
    the vectorised path, so the same bits.
    """
    reach, hip = params.max_step_length, cmp_offset(params)
    scale = math.exp(params.omega * params.min_step_time)
    _, without_hip = _growth(params, False)
    more = float(without_hip[steps - 1])
    first = scale * capture - scale * hip - (scale - 1.0) * params.toe - params.toe - more
    last = scale * capture + scale * hip - (scale - 1.0) * params.heel - params.heel + more
    first, last = max(first - 0.0, -reach), min(last - 0.0, reach)
    if 0.5 * (first + last) >= 0.0:
        return max(first, 0.0), last
    return max(-last, 0.0), -first
