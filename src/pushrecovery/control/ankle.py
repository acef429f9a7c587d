"""Ankle-strategy (CoP balancing) controllers of Fig. 3.

Both command a CoP on the foot; on the pendulum model the CoP becomes the exact ankle torque
that puts it there (:mod:`pushrecovery.models.pendulum`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, positive_float, require_type
from pushrecovery.control.base import Command, Controller, register
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cop import capture_point

__all__ = ["AnkleCapturePoint", "AnklePD", "AnkleSaturated", "default_pd_gains"]


@register
class AnkleSaturated(Controller):
    """Saturated ankle torque of Fig. 3(a): the CoP on the edge that opposes the push.

    At reset the controller notes the direction of the CoM velocity. While the CoM still moves
    that way it holds the CoP on that edge (the toe for a forward push): the open-loop,
    maximal braking of Eq. (3). Once the CoM has stopped it places the CoP at the capture
    point ξ = x + ẋ/ω (clipped to the foot), under which the CoM comes to rest, so that a
    stopped body stays stopped. States inside Eq. (4) with the CoM over the foot therefore end
    at rest. (A CoM outside the foot moving back toward it, as after a step, needs the CoP on
    the *other* edge; :class:`AnklePD` with its default gains recovers all of Eq. (4).)
    """

    name = "ankle-saturated"

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        self._direction = 0.0
        self._omega = params.omega

    def reset(self, state: NDArray[np.float64]) -> None:
        """Record the push direction from the initial CoM velocity."""
        xdot = float(state[len(state) // 2])
        self._direction = math.copysign(1.0, xdot) if xdot != 0.0 else 0.0

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """CoP on the braking edge until the CoM stops, then at the capture point [m]."""
        x, xdot = float(state[0]), float(state[len(state) // 2])
        if self._direction != 0.0 and xdot * self._direction > 0.0:
            edge = self.params.toe if self._direction > 0.0 else self.params.heel
            return Command(edge, saturated=True)
        self._direction = 0.0
        cop, clipped = self.clip_cop(capture_point(x, xdot, self._omega))
        return Command(cop, saturated=clipped)


def default_pd_gains(params: BodyParams) -> tuple[float, float]:
    """Default ankle PD gains (stiffness [N m/rad], damping [N m s/rad]).

    Capture-point gains: k_p = 3 m g L and k_d = k_p / ω. Linearised (θ ≈ x/L), the commanded
    CoP is then δ = (k_p / m g L) ξ, a multiple > 1 of the capture point, so ξ̇ = ω (ξ − δ)
    moves ξ monotonically back to 0 and, on the LIPM, every state inside Eq. (4) is
    recovered, exactly as predicted. ``docs/ankle_pd.md`` measures other gains.
    """
    require_type("params", params, BodyParams)
    stiffness = 3.0 * params.weight * params.com_height
    return stiffness, stiffness / params.omega


@register
class AnklePD(Controller):
    """Saturated PD controller on the ankle joint, Fig. 3(b).

    The ankle torque τ = k_p θ + k_d θ̇, with the lean angle θ = asin(x / L) and rate
    θ̇ = ẋ / (L cos θ), is commanded as the CoP it produces in quasi-static stance,
    δ = τ / (m g) (Eq. 2 with F_z = m g), clipped to the foot: the torque limit of Fig. 3(b).
    Positive τ is plantar flexion (pushes the body backward).

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    stiffness : float, optional
        k_p [N m/rad], > m g L so that the upright stance is stable; default
        :func:`default_pd_gains`.
    damping : float, optional
        k_d [N m s/rad], >= 0; default :func:`default_pd_gains`.
    """

    name = "ankle-pd"

    def __init__(
        self, params: BodyParams, stiffness: float | None = None, damping: float | None = None
    ) -> None:
        super().__init__(params)
        default_kp, default_kd = default_pd_gains(params)
        kp = default_kp if stiffness is None else finite_float("stiffness", stiffness, "N m/rad")
        kd = default_kd if damping is None else finite_float("damping", damping, "N m s/rad")
        mgl = params.weight * params.com_height
        if kp <= mgl:
            raise InvalidParameterError(
                f"stiffness must be > m g L = {mgl:g} N m/rad for a stable stance, got {kp:g}"
            )
        if kd < 0.0:
            raise InvalidParameterError(f"damping must be >= 0 N m s/rad, got {kd:g}")
        self.stiffness, self.damping = kp, kd
        self._inv_weight = 1.0 / params.weight
        self._length = params.com_height

    def reset(self, state: NDArray[np.float64]) -> None:
        """Do nothing: the PD controller has no internal state."""

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """CoP τ / (m g) of the PD ankle torque, clipped to the foot [m]."""
        x, xdot = float(state[0]), float(state[len(state) // 2])
        lean = math.asin(max(-1.0, min(1.0, x / self._length)))
        cos = math.cos(lean)
        lean_rate = xdot / (self._length * cos) if cos > 0.0 else 0.0
        torque = self.stiffness * lean + self.damping * lean_rate
        cop, clipped = self.clip_cop(torque * self._inv_weight)
        return Command(cop, saturated=clipped)


@register
class AnkleCapturePoint(Controller):
    """CoP at the capture point, clipped to the foot: the exact controller of Eq. (4).

    With δ = ξ, ξ̇ = ω (ξ − δ) = 0, so a capture point on the foot stays put and the CoM
    converges to rest above it (ẋ = ω (ξ − x)); one beyond an edge gets the edge, the best any
    CoP can do, and runs away only if Eq. (4) says so. It recovers exactly the states inside
    Eq. (4), wherever the CoM starts. ``omega`` [1/s] defaults to sqrt(g / L); pass the one of
    another CoM height (e.g. after a step).
    """

    name = "ankle-capture-point"

    def __init__(self, params: BodyParams, omega: float | None = None) -> None:
        super().__init__(params)
        self._omega = params.omega if omega is None else positive_float("omega", omega, "1/s")

    def reset(self, state: NDArray[np.float64]) -> None:
        """Do nothing: the controller has no internal state."""

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """CoP at ξ = x + ẋ/ω, clipped to the foot [m]."""
        x, xdot = float(state[0]), float(state[len(state) // 2])
        cop, clipped = self.clip_cop(capture_point(x, xdot, self._omega))
        return Command(cop, saturated=clipped)
