"""Validation of the decision surfaces against simulation: critical pushes and a confusion matrix.

Each strategy runs on the model built for it, with the paper's controller for it:

========  ======================  ==========================  =========================
strategy  MuJoCo model            analytic model              controller
========  ======================  ==========================  =========================
ankle     ``foot``                ``pendulum``                ``ankle-pd``
hip       ``torso``               ``flywheel``                ``mpc`` (Eqs. 16-17)
step      ``biped``               ``stepping``                ``recovery``
========  ======================  ==========================  =========================

On MuJoCo a push is a real force at the CoM (an impulse over ``PUSH_DURATION``, the body holding
still meanwhile), so the prediction is offered twice: the paper's surface at the pre-push
position, and a *corrected* one for the two things the physics adds to the ankle and hip
surfaces: the CoP margin the feet need (docs/validation.md, "From the paper's commands to joint
torques") and the CoM's travel during the push
(x moves by v D / 2 under a constant force of duration D).

Over 400 lines on purpose: the critical-push table and the confusion matrix share the
setups, the predictions they are measured against and the physical checks of each run.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    non_negative_float,
    require_type,
)
from pushrecovery.control.base import make_controller
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import BodyParams
from pushrecovery.sim.critical import critical_push, pushed_state
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.registry import MUJOCO_MODELS, available_models, make_plant
from pushrecovery.sim.simulate import MAX_DURATION, simulate
from pushrecovery.surfaces.classify import classify, strategy_region

__all__ = [
    "LABELS",
    "SETUPS",
    "ConfusionMatrix",
    "CriticalRow",
    "available_strategies",
    "confusion_matrix",
    "corrected_critical_velocity",
    "critical_table",
    "mujoco_corrected_prediction",
    "needed_strategy",
]

#: backend -> strategy -> (model, controller).
SETUPS: dict[str, dict[str, tuple[str, str]]] = {
    "mujoco": {
        "ankle": ("foot", "ankle-pd"),
        "hip": ("torso", "mpc"),
        "step": ("biped", "recovery"),
    },
    "analytic": {
        "ankle": ("pendulum", "ankle-pd"),
        "hip": ("flywheel", "mpc"),
        "step": ("stepping", "recovery"),
    },
}
#: Rows and columns of the confusion matrix, the strategies in escalating order.
LABELS = ("ankle", "hip", "step", "fall")


def _strategies(strategies: object, progress: object = None) -> tuple[str, ...]:
    """Return the strategies asked for as a tuple; check that ``progress`` is callable."""
    if isinstance(strategies, str) or not isinstance(strategies, Sequence):
        raise ParameterTypeError(f"strategies must be a sequence of names, got {strategies!r:.40}")
    if progress is not None and not callable(progress):
        raise ParameterTypeError(f"progress must be callable, got {type(progress).__name__}")
    return tuple(strategies)


def _setup(backend: str, strategy: str) -> tuple[str, str]:
    if not (isinstance(backend, str) and isinstance(strategy, str)):
        raise ParameterTypeError(
            f"backend and strategy must be names, got {type(backend).__name__} and "
            f"{type(strategy).__name__}"
        )
    try:
        model, controller = SETUPS[backend][strategy]
    except KeyError:
        raise InvalidParameterError(
            f"backend must be one of {sorted(SETUPS)} and strategy one of {list(LABELS[:3])}, "
            f"got backend={backend!r}, strategy={strategy!r}"
        ) from None
    if backend == "mujoco" and model not in MUJOCO_MODELS:
        raise InvalidParameterError(
            f"strategy {strategy!r} needs the MuJoCo model {model!r}, not available; "
            f"available: {list(MUJOCO_MODELS)}"
        )
    return model, controller


def available_strategies(backend: str) -> tuple[str, ...]:
    """Return the strategies whose model exists on ``backend`` (raises as ``available_models``)."""
    models = available_models(backend)
    return tuple(strategy for strategy, (model, _) in SETUPS[backend].items() if model in models)


def corrected_critical_velocity(
    strategy: str,
    x0: float,
    direction: float,
    params: BodyParams,
    *,
    cop_margin: float,
    push_duration: float,
    timestep: float = 0.0,
) -> float:
    """Critical push of the ankle or hip surface on a real foot, pushed by a real force [m/s].

    Three corrections, each from the physics of a push J = m v at the CoM of a pendulum leaning
    φ0 = asin(x0 / L) that holds still meanwhile: the foot is shortened by ``cop_margin`` [m]
    at each edge; the leg takes only the tangential part of the impulse, so the CoM leaves at
    ẋ = v cos²φ0; and it travels ẋ (D + h)/2 during a push of duration D [s] integrated in
    steps of h = ``timestep`` [s] (semi-implicit Euler adds half a step to the exact D/2). The
    capture point after the push is x0 + v cos²φ0 ((D + h)/2 + 1/ω); solving for the region's
    edge e: v = (e − x0) / (cos²φ0 (1/ω + (D + h)/2)), signed like the push.

    Raises
    ------
    ParameterTypeError
        If ``strategy`` is not a str or ``params`` not a
        :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        A strategy other than ``ankle`` or ``hip``, ``direction`` other than ±1, abs(x0) >=
        ``com_height`` (the CoM above the ankle's horizon, as
        :func:`~pushrecovery.sim.backend.check_com_state`; cos²φ0 vanishes there), a negative
        or non-finite ``cop_margin``, ``push_duration`` or ``timestep``, or a margin that
        leaves no foot.
    """
    require_type("strategy", strategy, str)
    if not isinstance(strategy, str) or strategy not in ("ankle", "hip"):
        raise InvalidParameterError(f"strategy must be 'ankle' or 'hip', got {strategy!r}")
    require_type("params", params, BodyParams)
    x0 = finite_float("x0", x0, "m")
    if abs(x0) >= params.com_height:
        raise InvalidParameterError(
            f"x0 must satisfy |x0| < com_height = {params.com_height:g} m, got x0={x0:g}"
        )
    direction = finite_float("direction", direction, allowed="+1 or -1")
    if direction not in (1.0, -1.0):
        raise InvalidParameterError(f"direction must be +1 or -1, got {direction!r}")
    cop_margin = non_negative_float("cop_margin", cop_margin, "m")
    push_duration = non_negative_float("push_duration", push_duration, "s")
    timestep = non_negative_float("timestep", timestep, "s")
    shortened = dataclasses.replace(
        params, heel=params.heel + cop_margin, toe=params.toe - cop_margin
    )
    region = strategy_region(strategy, shortened)
    edge = region.upper if direction > 0.0 else region.lower
    tangential = 1.0 - (x0 / params.com_height) ** 2  # cos² φ0
    return (edge - x0) / (tangential * (1.0 / params.omega + 0.5 * (push_duration + timestep)))


def mujoco_corrected_prediction(
    strategy: str, x0: float, direction: float, params: BodyParams
) -> float:
    """:func:`corrected_critical_velocity` for the MuJoCo plants' CoP margin, push and step."""
    from pushrecovery.sim.mujoco.models import TIMESTEP
    from pushrecovery.sim.mujoco.plant import DEFAULT_COP_MARGIN, PUSH_DURATION

    return corrected_critical_velocity(
        strategy,
        x0,
        direction,
        params,
        cop_margin=DEFAULT_COP_MARGIN,
        push_duration=PUSH_DURATION,
        timestep=TIMESTEP,
    )


@dataclass(frozen=True, slots=True)
class CriticalRow:
    """One line of the critical-push table (velocities signed like ẋ, [m/s]).

    ``corrected`` is :func:`corrected_critical_velocity` (NaN where no correction is
    offered: the step strategy, or the analytic backend where nothing needs correcting).
    ``foot_slip`` [m] and ``peak_force`` [m g] are the physical checks of the run at the
    measured push (MuJoCo; NaN on the analytic backend).
    """

    strategy: str
    model: str
    controller: str
    direction: str
    x0: float
    predicted: float
    corrected: float
    measured: float
    bracket: tuple[float, float]
    simulations: int
    foot_slip: float = math.nan
    peak_force: float = math.nan

    @property
    def relative_error(self) -> float:
        """(abs(measured) − abs(predicted)) / abs(predicted); negative when the body does worse."""
        return (abs(self.measured) - abs(self.predicted)) / abs(self.predicted)

    @property
    def corrected_error(self) -> float:
        """(abs(measured) − abs(corrected)) / abs(corrected), NaN without a corrected prediction."""
        return (abs(self.measured) - abs(self.corrected)) / abs(self.corrected)

    def to_dict(self, mass: float) -> dict[str, Any]:
        """JSON form; impulses [N s] from the body ``mass`` [kg]; NaN becomes null."""

        def clean(value: float) -> float | None:
            return None if math.isnan(value) else value

        return {
            "strategy": self.strategy,
            "model": self.model,
            "controller": self.controller,
            "direction": self.direction,
            "x0": self.x0,
            "predicted": self.predicted,
            "predicted_impulse": mass * self.predicted,
            "corrected": clean(self.corrected),
            "measured": self.measured,
            "measured_impulse": mass * self.measured,
            "relative_error": self.relative_error,
            "corrected_error": clean(self.corrected_error),
            "bracket": list(self.bracket),
            "simulations": self.simulations,
            "foot_slip": clean(self.foot_slip),
            "peak_force": clean(self.peak_force),
        }


def critical_table(
    params: BodyParams,
    *,
    backend: str = "mujoco",
    strategies: Sequence[str] = ("ankle", "hip", "step"),
    x0s: Sequence[float] = (0.0, 0.05),
    directions: Sequence[str] = ("forward", "backward"),
    tolerance: float = 2e-3,
    duration: float = 6.0,
    progress: Callable[[int], None] | None = None,
) -> list[CriticalRow]:
    """Critical push of every strategy, direction and start position against its surface.

    Parameters
    ----------
    params : BodyParams
        Body parameters (the models are generated from them).
    backend : {"mujoco", "analytic"}
        Physics; MuJoCo pushes with real forces (module docstring).
    strategies : sequence of str
        Among ``ankle``, ``hip``, ``step``.
    x0s : sequence of float
        CoM positions before the push, on the foot [m].
    directions : sequence of str
        ``forward`` and/or ``backward``.
    tolerance : float
        Width of each bisection bracket [m/s].
    duration : float
        Longest simulated time per push [s].
    progress : callable, optional
        Called with 1 after each row (e.g. a progress bar's ``update``).

    Returns
    -------
    list of CriticalRow
    """
    require_type("params", params, BodyParams)
    strategies = _strategies(strategies, progress)
    x0s = finite_array("x0s", x0s).reshape(-1).tolist()
    if isinstance(directions, str) or not isinstance(directions, Sequence):
        raise ParameterTypeError(f"directions must be a sequence of names, got {directions!r:.40}")
    for strategy in strategies:
        _setup(backend, strategy)  # every strategy checked before any simulation
    rows = []
    for strategy in strategies:
        model, controller = _setup(backend, strategy)
        for x0 in x0s:
            for direction in directions:
                found = critical_push(
                    params,
                    model,
                    controller,
                    x0,
                    direction,
                    tolerance=tolerance,
                    duration=duration,
                    backend=backend,
                )
                sign = 1.0 if direction == "forward" else -1.0
                corrected = math.nan
                if backend == "mujoco" and strategy != "step":
                    corrected = mujoco_corrected_prediction(strategy, x0, sign, params)
                rows.append(
                    CriticalRow(
                        strategy,
                        model,
                        controller,
                        direction,
                        x0,
                        found.predicted_velocity,
                        corrected,
                        found.velocity,
                        found.bracket,
                        found.iterations,
                        *_checks(found.physics),
                    )
                )
                if progress is not None:
                    progress(1)
    return rows


def _checks(physics: PhysicalChecks | None) -> tuple[float, float]:
    """Return a run's foot slip [m] and peak ground force [m g] (NaN: not audited)."""
    if physics is None:
        return math.nan, math.nan
    return physics.foot_slip, physics.peak_force_ratio


def needed_strategy(
    params: BodyParams,
    x0: float,
    velocity: float,
    *,
    backend: str = "mujoco",
    strategies: Sequence[str] = ("ankle", "hip", "step"),
    duration: float = 6.0,
) -> str:
    """Return the least strategy that recovers a push in simulation, or ``fall``.

    Tries each strategy's model and controller in escalating order (ankle, hip, step); a push
    of ``velocity`` [m/s] from ``x0`` [m], as a real force on MuJoCo.
    """
    strategies = _strategies(strategies)
    for strategy in strategies:
        _setup(backend, strategy)
    for strategy in LABELS[:3]:
        if strategy not in strategies:
            continue
        model, controller = _setup(backend, strategy)
        plant = make_plant(model, params, backend)
        start = pushed_state(plant, x0, velocity, force=backend == "mujoco")
        run = simulate(plant, make_controller(controller, params), start, duration=duration)
        if run.recovered:
            return strategy
    return "fall"


@dataclass(frozen=True, slots=True)
class ConfusionMatrix:
    """Predicted strategy (rows) against the strategy simulation needed (columns).

    ``counts[i, j]`` counts pushes predicted ``LABELS[i]`` that needed ``LABELS[j]``;
    ``cases`` lists (x0 [m], velocity [m/s], predicted, needed) for every push.
    """

    counts: NDArray[np.int64]
    cases: list[tuple[float, float, str, str]] = field(default_factory=list)

    @property
    def accuracy(self) -> float:
        """Fraction of pushes whose predicted strategy is the one simulation needed."""
        total = int(self.counts.sum())
        return float(np.trace(self.counts)) / total if total else math.nan

    def to_dict(self) -> dict[str, Any]:
        """JSON form: labels, counts (rows predicted, columns needed), accuracy, cases."""
        return {
            "labels": list(LABELS),
            "counts": self.counts.tolist(),
            "accuracy": self.accuracy,
            "cases": [
                {"x0": x0, "xdot": v, "predicted": predicted, "needed": needed}
                for x0, v, predicted, needed in self.cases
            ],
        }


def confusion_matrix(
    params: BodyParams,
    x0s: Sequence[float],
    velocities: Sequence[float],
    *,
    backend: str = "mujoco",
    strategies: Sequence[str] = ("ankle", "hip", "step"),
    duration: float = 6.0,
    progress: Callable[[int], None] | None = None,
) -> ConfusionMatrix:
    """Classify every push of the grid ``x0s`` × ``velocities`` and simulate what it needs.

    The prediction is :func:`~pushrecovery.surfaces.classify.classify` of the state after
    the push (x0, v); a strategy left out of ``strategies`` counts as failing. Every
    argument is checked before the first run (``duration`` in (0, 60] s), an empty grid too.
    """
    require_type("params", params, BodyParams)
    duration = bounded_float("duration", duration, 0.0, MAX_DURATION, "s")
    if duration == 0.0:
        raise InvalidParameterError(f"duration must be in (0, {MAX_DURATION:g}] s, got 0")
    x0s = finite_array("x0s", x0s).reshape(-1).tolist()
    velocities = finite_array("velocities", velocities).reshape(-1).tolist()
    strategies = _strategies(strategies, progress)
    for strategy in strategies:
        _setup(backend, strategy)
    counts = np.zeros((len(LABELS), len(LABELS)), dtype=np.int64)
    cases = []
    for x0 in x0s:
        for velocity in velocities:
            predicted = str(classify(x0, velocity, params).strategy)
            needed = needed_strategy(
                params, x0, velocity, backend=backend, strategies=strategies, duration=duration
            )
            counts[LABELS.index(predicted), LABELS.index(needed)] += 1
            cases.append((float(x0), float(velocity), predicted, needed))
            if progress is not None:
                progress(1)
    return ConfusionMatrix(counts, cases)
