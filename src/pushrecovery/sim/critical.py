"""The critical push: the largest CoM velocity jump a model + controller recovers from.

On the MuJoCo backend the push is a real force at the CoM (an impulse J over 10 ms) and the
search runs on the equivalent velocity J / m, so that it compares with the surfaces directly.
:func:`bisect_critical` is the same search on impulses [N s] for any run that says whether
it stood (the 3-D humanoids' :func:`~pushrecovery.sim.mujoco.humanoid3d.runs3d.critical_push3d`
and validations).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_float, positive_float, require_type
from pushrecovery.control.base import make_controller
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import Backend
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.plants import Plant
from pushrecovery.sim.push import IMPULSE_MAX, Push, direction_sign
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.classify import strategy_region
from pushrecovery.surfaces.cop import critical_velocity
from pushrecovery.surfaces.step import step_critical_velocity

__all__ = [
    "Bracket",
    "CriticalPush",
    "NotRecoverableError",
    "bisect_critical",
    "critical_push",
    "find_critical_velocity",
    "predicted_critical_velocity",
    "pushed_state",
]


class NotRecoverableError(InvalidParameterError):
    """The start state is lost even without a push, so there is no critical push."""


#: Tightest and loosest search tolerance [m/s].
TOLERANCE_RANGE = (1e-9, 0.1)


@dataclass(frozen=True, slots=True)
class Bracket:
    """Outcome of a bisection: the largest recovered and smallest failed velocity [m/s]."""

    recovered: float
    failed: float
    simulations: int


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
    predicted_velocity : float
        Critical velocity of the controller's decision surface, signed like ẋ [m/s].
    physics : PhysicalChecks or None
        The physical checks of the run at ``velocity`` (MuJoCo; None on the analytic
        models): its loaded-foot slip and peak ground force. The search counts a run that
        came to rest on feet that slid (``slipped``) as not fallen, as the 3-D critical push
        does: ``velocity`` is the largest push that does not fall, its slip beside it.
    """

    velocity: float
    bracket: tuple[float, float]
    iterations: int
    predicted_velocity: float
    physics: PhysicalChecks | None = None

    def relative_error(self) -> float:
        """Return (abs(velocity) − abs(predicted)) / abs(predicted); < 0: worse than Eq. 4."""
        predicted = abs(self.predicted_velocity)
        return (abs(self.velocity) - predicted) / predicted


def find_critical_velocity(
    outcome_of: Callable[[float], Outcome],
    direction: str,
    *,
    guess: float,
    tolerance: float = 1e-4,
    max_velocity: float,
) -> Bracket:
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
        Width of the final bracket [m/s], in [1e-9, 0.1].
    max_velocity : float
        Largest push searched [m/s], finite, > 0.

    Returns
    -------
    Bracket
        Signed like the push.

    Raises
    ------
    ParameterTypeError
        If ``outcome_of`` is not callable.
    InvalidParameterError
        If the body falls without a push, or no push below ``max_velocity`` makes it fall, or
        an argument is out of its range (``max_velocity``: finite, > 0).
    """
    if not callable(outcome_of):
        raise ParameterTypeError(
            f"outcome_of must be a callable (velocity -> Outcome), got {type(outcome_of).__name__}"
        )
    sign = direction_sign(direction)
    max_velocity = positive_float("max_velocity", max_velocity, "m/s")
    tolerance = positive_float("tolerance", tolerance, "m/s")
    if not TOLERANCE_RANGE[0] <= tolerance <= TOLERANCE_RANGE[1]:
        raise InvalidParameterError(
            f"tolerance must be in [{TOLERANCE_RANGE[0]:g}, {TOLERANCE_RANGE[1]:g}] m/s, "
            f"got {tolerance:g}"
        )
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
        if high >= max_velocity:
            raise InvalidParameterError(
                f"no push up to {max_velocity:g} m/s makes the body fall; "
                "is the controller or model unbounded?"
            )
        low, high = high, min(2.0 * high, max_velocity)
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        if middle in (low, high):  # float resolution reached
            break
        runs += 1
        if outcome_of(sign * middle) is Outcome.RECOVERED:
            low = middle
        else:
            high = middle
    return Bracket(float(np.copysign(low, sign)), float(np.copysign(high, sign)), runs)


def pushed_state(plant: Plant, x0: float, velocity: float, *, force: bool) -> NDArray[np.float64]:
    """State just after a push of ``velocity`` [m/s] from the CoM at rest at ``x0`` [m].

    A velocity jump, or with ``force`` a real force at the CoM delivering the impulse m v
    (MuJoCo plants' :meth:`push`).
    """
    require_type("plant", plant, Backend)
    if not force:
        return plant.reset(x0, velocity)
    plant.reset(x0, 0.0)
    return plant.apply_push(Push(velocity))


def predicted_critical_velocity(
    params: BodyParams, strategy: str, x0: float, direction: str
) -> float:
    """Critical push of a strategy's decision surface from ``x0`` [m], signed like ẋ [m/s].

    Eq. (4) for ``ankle``, corrected Eq. (15) for ``hip``, the single-step limit of
    :mod:`pushrecovery.surfaces.step` for ``step``.

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams` or ``strategy`` not
        a str.
    InvalidParameterError
        An unknown strategy or direction, or an ``x0`` that is not finite.
    """
    require_type("params", params, BodyParams)
    require_type("strategy", strategy, str)
    x0 = finite_float("x0", x0, "m")
    sign = direction_sign(direction)
    if strategy == "step":
        return step_critical_velocity(x0, sign, params)
    region = strategy_region(strategy, params)
    return float(critical_velocity(x0, sign, params, region=region))


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
    backend: str = "analytic",
    force: bool | None = None,
    progress: Callable[[int], None] | None = None,
) -> CriticalPush:
    """Critical push of a model + controller from CoM position ``x0``, with its prediction.

    The prediction is the critical velocity of the decision surface of the controller's
    strategy: Eq. (4) for the ankle controllers, corrected Eq. (15) for the hip controllers, the
    single-step limit of :mod:`pushrecovery.surfaces.step` for the recovery controller.

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    model : str
        Plant name (analytic: ``lipm``, ``pendulum``, ``flywheel``, ``stepping``; mujoco:
        ``foot``, ``torso``, ``biped``).
    controller : str
        Controller name (``ankle-pd``, ``bang-bang``, ``mpc``, ``recovery``, ...).
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
    backend : {"analytic", "mujoco"}
        Physics of the plant (``mujoco`` has the models ``foot``, ``torso`` and ``biped``).
    force : bool, optional
        Push with a real force (impulse m v over 10 ms at the CoM) instead of a velocity
        jump; only on the ``mujoco`` backend, where it is the default.
    progress : callable, optional
        Called with 1 after each simulation of the bisection (e.g. a progress bar's
        ``update``).

    Returns
    -------
    CriticalPush
        ``velocity`` signed like ẋ [m/s]; ``predicted_velocity`` from the surface.
    """
    require_type("params", params, BodyParams)
    x0 = finite_float("x", x0, "m")
    if not params.heel < x0 < params.toe:
        raise InvalidParameterError(
            f"x must lie on the foot, heel={params.heel:g} < x < toe={params.toe:g} m, got x={x0:g}"
        )
    direction_sign(direction)  # validates it before any simulation
    if force is None:
        force = backend == "mujoco"
    if force and backend != "mujoco":
        raise InvalidParameterError("force pushes need backend='mujoco'")
    plant = make_plant(model, params, backend)
    if "y" in plant.state_labels:  # a push along x of a planar model is not its critical push
        raise InvalidParameterError(
            f"the critical push is sagittal; model {model!r} runs with simulate"
        )
    ctrl = make_controller(controller, params, **(controller_options or {}))
    predicted = predicted_critical_velocity(params, ctrl.strategy, x0, direction)

    checks: dict[float, PhysicalChecks | None] = {}

    def outcome_of(velocity: float) -> Outcome:
        start = pushed_state(plant, x0, velocity, force=force)
        run = simulate(plant, ctrl, start, duration=duration, control_period=control_period)
        if progress is not None:
            progress(1)
        checks[velocity] = run.physics
        # The largest push that does not fall: a run at rest on feet that slid counts.
        return Outcome.RECOVERED if run.outcome is Outcome.SLIPPED else run.outcome

    # Just below the models' validity limit (check_com_state).
    limit = 9.99 * math.sqrt(params.gravity * params.com_height)
    found = find_critical_velocity(
        outcome_of, direction, guess=predicted, tolerance=tolerance, max_velocity=limit
    )
    return CriticalPush(
        found.recovered, (found.recovered, found.failed), found.simulations, predicted,
        checks.get(found.recovered),
    )  # fmt: skip


def bisect_critical(
    stands: Callable[[float], tuple[bool, str]],
    low: float,
    high: float,
    tolerance: float,
    *,
    grow: float = 2.0,
    shrink: float | None = None,
) -> tuple[float, tuple[float, float], str]:
    """Bracket and bisect the largest impulse [N s] that ``stands`` (a run: stood?, strategy).

    With ``shrink`` the lower end is run first and multiplied by it until it stands; without,
    ``low`` is taken to stand (0: no push). The upper end grows by ``grow`` (up to the push's
    largest impulse) while it stands; then the bracket halves until at most ``tolerance`` [N s]
    wide. Returns the largest impulse that stood, the bracket and that run's strategy
    ("ankle" when none stood but the assumed ``low``). Once the lower end is below
    ``tolerance`` no push (0) is taken to stand, so every loop ends: at most
    log(high / tolerance) / log(1 / shrink) + log(IMPULSE_MAX / high) / log(grow)
    + log2(IMPULSE_MAX / tolerance) + 3 runs.

    Raises
    ------
    InvalidParameterError
        If ``stands`` is not callable, 0 <= low < high <= IMPULSE_MAX (1e4 N s) fails,
        ``tolerance`` is not in [1e-6, 1e3] N s, ``grow`` not in [1.05, 100] or ``shrink`` not in
        (0, 1).
    """
    if not callable(stands):
        raise ParameterTypeError(f"stands must be callable, got {type(stands).__name__}")
    low = bounded_float("low", low, 0.0, IMPULSE_MAX, "N s")
    high = bounded_float("high", high, 0.0, IMPULSE_MAX, "N s")
    if not low < high:
        raise InvalidParameterError(f"low must be < high, got low={low:g}, high={high:g} N s")
    tolerance = bounded_float("tolerance", tolerance, 1e-6, 1e3, "N s")
    grow = bounded_float("grow", grow, 1.05, 100.0)
    strategy = "ankle"
    if shrink is not None:
        shrink = bounded_float("shrink", shrink, 1e-9, 1.0 - 1e-9)
        stood, strategy = stands(low)
        while not stood:
            high, low = low, shrink * low
            if low < tolerance:  # no push stands: the assumed end
                low, strategy = 0.0, "ankle"
                break
            stood, strategy = stands(low)
    while True:
        stood, used = stands(high)
        if not stood:
            break
        low, strategy = high, used
        if high >= IMPULSE_MAX:
            return low, (low, low), strategy
        high = min(grow * high, IMPULSE_MAX)
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        stood, used = stands(middle)
        if stood:
            low, strategy = middle, used
        else:
            high = middle
    return low, (low, high), strategy
