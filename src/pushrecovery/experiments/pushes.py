"""Pushes chosen relative to a body's own thresholds, so that a figure tells its story for any body.

A push fixed in N s means a different thing for a 45 kg robot and a 72 kg person: the 40 N s
"hip strategy" push of the paper's body is beyond a light robot's hip region. These pushes are
placed between the body's own thresholds from upright (x = 0, forward): Eq. (4) for the ankle,
corrected Eq. (15) for the hip, Sec. IV's single step (:func:`~pushrecovery.surfaces.step.
step_critical_velocity`) for stepping.
"""

from __future__ import annotations

from dataclasses import dataclass

from pushrecovery.arguments import finite_float, finite_vector, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import critical_velocity
from pushrecovery.surfaces.step import step_critical_velocity

__all__ = [
    "ANKLE_FRACTION",
    "STEP_FRACTION",
    "StrategyPushes",
    "push_scale",
    "scaled_range",
    "strategy_pushes",
]

#: The ankle push, as a fraction of the ankle's critical push (well inside Eq. 4).
ANKLE_FRACTION = 0.74
#: The step push: this fraction of the way from the hip's critical push to one step's.
STEP_FRACTION = 0.24


@dataclass(frozen=True, slots=True)
class StrategyPushes:
    """One push per strategy from upright, forward, as CoM velocity jumps [m/s].

    Attributes
    ----------
    ankle : float
        ``ANKLE_FRACTION`` of the ankle's critical push [m/s].
    hip : float
        Midway between the ankle's and the hip's critical pushes [m/s].
    step : float
        ``STEP_FRACTION`` of the way from the hip's critical push to one step's [m/s].
    """

    ankle: float
    hip: float
    step: float

    def impulse(self, strategy: str, mass: float) -> float:
        """Return the push of ``strategy`` as an impulse m Δẋ [N s], rounded to 1 N s."""
        velocity = {"ankle": self.ankle, "hip": self.hip, "step": self.step}[strategy]
        return float(round(mass * velocity))


def strategy_pushes(params: BodyParams) -> StrategyPushes:
    """Return the pushes between ``params``' own thresholds (module docstring)."""
    ankle = float(critical_velocity(0.0, 1.0, params))
    hip = float(critical_velocity(0.0, 1.0, params, region=cmp_region(params)))
    step = step_critical_velocity(0.0, 1.0, params)
    return StrategyPushes(
        ankle=ANKLE_FRACTION * ankle,
        hip=0.5 * (ankle + hip),
        step=hip + STEP_FRACTION * (step - hip),
    )


def _threshold(params: BodyParams, strategy: str) -> float:
    if strategy == "hip":
        return float(critical_velocity(0.0, 1.0, params, region=cmp_region(params)))
    if strategy == "step":
        return step_critical_velocity(0.0, 1.0, params)
    return float(critical_velocity(0.0, 1.0, params))


def push_scale(params: BodyParams, strategy: str, reference: BodyParams) -> float:
    """Return how much larger ``params``' critical push of ``strategy`` is than ``reference``'s.

    The forward critical push from upright: Eq. (4) (``ankle``), corrected Eq. (15) (``hip``)
    or Sec. IV's single step (``step``). A grid of pushes drawn for ``reference`` and scaled
    by it covers the same part of ``params``' strategy map.

    Raises
    ------
    InvalidParameterError
        If ``strategy`` is not ``"ankle"``, ``"hip"`` or ``"step"``, or a body is not a
        BodyParams.
    """
    require_type("params", params, BodyParams)
    require_type("reference", reference, BodyParams)
    if not isinstance(strategy, str) or strategy not in ("ankle", "hip", "step"):
        raise InvalidParameterError(
            f"strategy must be 'ankle', 'hip' or 'step', got {str(strategy)[:40]!r}"
        )
    return _threshold(params, strategy) / _threshold(reference, strategy)


def scaled_range(triple: tuple[float, float, float], scale: float) -> tuple[float, float, float]:
    """Return (start, stop, step) [m/s] multiplied by ``scale`` (6 significant digits)."""
    triple = tuple(finite_vector("triple", triple, 3))
    scale = finite_float("scale", scale)
    return (
        float(f"{triple[0] * scale:.6g}"),
        float(f"{triple[1] * scale:.6g}"),
        float(f"{triple[2] * scale:.6g}"),
    )
