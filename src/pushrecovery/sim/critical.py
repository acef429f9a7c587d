"""The critical push: the largest CoM velocity jump a model + controller recovers from."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from pushrecovery._validate import finite_float, positive_float
from pushrecovery.control.base import make_controller
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.plants import make_plant
from pushrecovery.sim.push import direction_sign
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import strategy_region
from pushrecovery.surfaces.cop import critical_velocity

__all__ = ["CriticalPush", "NotRecoverableError", "critical_push", "find_critical_velocity"]


class NotRecoverableError(InvalidParameterError):
    """The start state is lost even without a push, so there is no critical push."""


#: Pushes beyond this [m/s] are not searched: at sqrt(g L) the stance foot already unloads.
MAX_SEARCH_VELOCITY = 20.0


@dataclass(frozen=True, slots=True)
class CriticalPush:
    """Result of a critical-push search from one initial position.

    Attributes
    ----------
    velocity : float
        Largest velocity found to recover, signed like ẋ (negative backward) [m/s].
    bracket : tuple of float
        (recovered, not recovered) velocities that bound the true critical velocity [m/s].
    iterations : int
        Simulations run.
    """

    velocity: float
    bracket: tuple[float, float]
    iterations: int
    predicted_velocity: float = float("nan")

    def relative_error(self) -> float:
        """Return (|velocity| − |predicted|) / |predicted|; < 0 when doing worse than Eq. 4."""
        predicted = abs(self.predicted_velocity)
        return (abs(self.velocity) - predicted) / predicted


def find_critical_velocity(
    outcome_of: Callable[[float], Outcome],
    direction: str,
    *,
    guess: float,
    tolerance: float = 1e-4,
) -> CriticalPush:
    """Bisect the velocity at which ``outcome_of`` stops returning ``recovered``.

    Assumes the recovered velocities in a direction form an interval starting at 0 (a harder
    push in the same direction is never easier). ``undecided`` counts as not recovered.

    Parameters
    ----------
    outcome_of : callable
        Maps a signed initial CoM velocity [m/s] to the outcome of a simulation.
    direction : {"forward", "backward"}
        Direction of the push.
    guess : float
        Expected magnitude of the critical velocity [m/s] (e.g. Eq. 4's), >= 0.
    tolerance : float
        Width of the final bracket [m/s], > 0.

    Returns
    -------
    CriticalPush

    Raises
    ------
    InvalidParameterError
        If the body falls without a push, or no push below 20 m/s makes it fall.
    """
    sign = direction_sign(direction)
    tolerance = positive_float("tolerance", tolerance, "m/s")
    guess = abs(finite_float("guess", guess, "m/s"))
    runs = 1
    at_rest = outcome_of(0.0)
    if at_rest is not Outcome.RECOVERED:
        raise NotRecoverableError(
            f"the body does not recover even without a push (outcome: {at_rest.value})"
        )
    low, high = 0.0, max(1.25 * guess, 4.0 * tolerance)
    while True:
        runs += 1
        if outcome_of(sign * high) is not Outcome.RECOVERED:
            break
        low, high = high, 2.0 * high
        if high > MAX_SEARCH_VELOCITY:
            raise InvalidParameterError(
                f"no push up to {MAX_SEARCH_VELOCITY:g} m/s makes the body fall; "
                "is the controller or model unbounded?"
            )
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        runs += 1
        if outcome_of(sign * middle) is Outcome.RECOVERED:
            low = middle
        else:
            high = middle
    return CriticalPush(float(np.copysign(low, sign)), (sign * low, sign * high), runs)


def critical_push(
    params: BodyParams,
    model: str,
    controller: str,
    x0: float,
    direction: str,
    *,
    tolerance: float = 1e-4,
    duration: float = 10.0,
    control_period: float | None = None,
    controller_options: dict[str, Any] | None = None,
) -> CriticalPush:
    """Critical push of a model + controller from CoM position ``x0``, with its prediction.

    The prediction is the critical velocity of the decision surface of the controller's
    strategy: Eq. (4) for the ankle controllers, corrected Eq. (15) for the hip controllers.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    model : str
        Plant name (``lipm``, ``pendulum`` or ``flywheel``).
    controller : str
        Controller name (``ankle-saturated``, ``ankle-pd``, ``bang-bang``, ``mpc``).
    x0 : float
        CoM position before the push, strictly on the foot [m].
    direction : {"forward", "backward"}
        Push direction.
    tolerance : float
        Bracket width [m/s].
    duration, control_period : float
        Simulation length and controller period [s], see :func:`simulate` (the period
        defaults to the controller's own).
    controller_options : dict, optional
        Keyword options of the controller (e.g. ``stiffness``, ``damping``).

    Returns
    -------
    CriticalPush
        ``velocity`` signed like ẋ [m/s]; ``predicted_velocity`` from the surface.
    """
    x0 = finite_float("x", x0, "m")
    if not params.heel < x0 < params.toe:
        raise InvalidParameterError(
            f"x must lie on the foot, heel={params.heel:g} < x < toe={params.toe:g} m, got x={x0:g}"
        )
    sign = direction_sign(direction)
    plant = make_plant(model, params)
    ctrl = make_controller(controller, params, **(controller_options or {}))
    region = strategy_region(ctrl.strategy, params)
    predicted = float(critical_velocity(x0, sign, params, region=region))

    def outcome_of(velocity: float) -> Outcome:
        run = simulate(
            plant,
            ctrl,
            plant.initial_state(x0, velocity),
            duration=duration,
            control_period=control_period,
        )
        return run.outcome

    found = find_critical_velocity(outcome_of, direction, guess=predicted, tolerance=tolerance)
    return CriticalPush(found.velocity, found.bracket, found.iterations, predicted)
