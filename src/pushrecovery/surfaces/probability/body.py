"""How well the body is known: a spread of its parameters, sampled by scrambled Sobol points."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from scipy.special import ndtr, ndtri

from pushrecovery.arguments import non_negative_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams

__all__ = ["TRUNCATION", "BodySpread"]

#: A body parameter's spread is cut at this many standard deviations.
TRUNCATION = 3.0


@dataclass(frozen=True, slots=True)
class BodySpread:
    """How well the body is known: standard deviations about its parameters' values.

    Each parameter is normal about the body's value with this standard deviation, truncated
    at ±3 SD (``TRUNCATION``); zero: known exactly. A person's body from anthropometric tables,
    or a robot whose payload and CoM are uncertain.

    Attributes
    ----------
    mass : float
        SD of the mass [kg] (the hip region's reach is τmax / (m g)).
    com_height : float
        SD of the CoM height L [m] (ω = sqrt(g / L) and every region).
    foot_length : float
        SD of the foot's length [m], heel and toe scaled together about the ankle.
    torque_max : float
        SD of the hip's torque limit [N m].
    """

    mass: float = 0.0
    com_height: float = 0.0
    foot_length: float = 0.0
    torque_max: float = 0.0

    def __post_init__(self) -> None:
        for name, unit in (("mass", "kg"), ("com_height", "m"), ("foot_length", "m"),
                           ("torque_max", "N m")):  # fmt: skip
            non_negative_float(name, getattr(self, name), unit)

    def active(self) -> tuple[str, ...]:
        """Return the parameters with a spread."""
        return tuple(
            n for n in ("mass", "com_height", "foot_length", "torque_max") if getattr(self, n) > 0
        )

    def bodies(self, params: BodyParams, count: int, seed: int) -> list[BodyParams]:
        """``count`` bodies of a scrambled Sobol sequence (seed ``seed``) over the spread."""
        from scipy.stats import qmc

        names = self.active()
        if not names:
            return [params] * count
        unit = qmc.Sobol(len(names), scramble=True, seed=seed).random(count)
        low = ndtr(-TRUNCATION)
        z = ndtri(low + unit * (1.0 - 2.0 * low))
        bodies = []
        for row in z:
            change: dict[str, Any] = {}
            for name, value in zip(names, row.tolist(), strict=True):
                if name == "foot_length":
                    scale = 1.0 + self.foot_length * value / (params.toe - params.heel)
                    change["heel"], change["toe"] = params.heel * scale, params.toe * scale
                else:
                    change[name] = getattr(params, name) + getattr(self, name) * value
            try:
                bodies.append(dataclasses.replace(params, **change))
            except InvalidParameterError as exc:
                raise InvalidParameterError(
                    f"spread: the body ±{TRUNCATION:g} SD leaves its valid range ({exc})"
                ) from None
        return bodies
