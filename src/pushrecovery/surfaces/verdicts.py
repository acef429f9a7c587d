"""The sagittal verdicts of many states at once: classify's numbers, vectorised, without plans.

The strategy a state needs on the line (:mod:`pushrecovery.surfaces.classify`, whose
``classify`` calls :func:`sagittal_verdicts` with one state) from its capture point ξ = x + ẋ/ω:
``ankle`` when ξ is strictly inside the foot (Eq. 4), ``hip`` inside the CMP region (corrected
Eq. 15), ``step`` when at most ``max_steps`` steps capture it (the N-step intervals of
:mod:`pushrecovery.surfaces.step_regions`), else ``fall``. A campaign's rows need these for a
whole batch, not the plans.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import finite_array, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_margin
from pushrecovery.surfaces.cop import capture_point, cop_margin
from pushrecovery.surfaces.step_regions import LineSteps, line_steps
from pushrecovery.surfaces.strategy import Strategy

__all__ = ["SagittalVerdicts", "sagittal_verdicts"]


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
