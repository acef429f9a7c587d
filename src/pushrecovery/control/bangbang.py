"""Bang-bang flywheel control with a saturated ankle, Sec. III-A (Eqs. 8-12)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import positive_float
from pushrecovery.control.base import Command, Controller, register
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.flywheel import FLYWHEEL_STATE, bang_bang_switch_time, max_spin_up_time
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cop import capture_point

__all__ = ["BangBang"]


@register
class BangBang(Controller):
    """Saturated ankle plus bang-bang hip torque, then CoP balancing.

    At reset the controller looks at the capture point ξ0. Inside the foot it only balances
    with the ankle. Beyond the toe (heel) it holds the CoP on the toe (heel) and drives the
    flywheel with τ = ±τmax on [0, T), ∓τmax on [T, 2T) and 0 afterwards (Eq. 8 as
    corrected, errata E8), which leaves the flywheel at rest at ±τmax T²/I (Eq. 11). T is the
    shortest spin-up that brings the capture point to the middle of the foot at 2T (Eq. 13
    solved for T), capped at T_max (Eq. 12, the paper's worst case); a fixed T = T_max would
    overshoot states just outside the foot past the opposite edge. From 2T on it places the
    CoP at the capture point (clipped to the foot), under which the CoM comes to rest, with the
    flywheel parked. It recovers every state inside the corrected Eq. (15).

    Parameters
    ----------
    params : BodyParams
        Body parameters.
    switch_time : float, optional
        A fixed T [s] in (0, T_max] instead of the per-state choice (the paper's Fig. 5 uses
        T = T_max).
    """

    name = "bang-bang"
    strategy = "hip"
    state_labels = FLYWHEEL_STATE

    def __init__(self, params: BodyParams, switch_time: float | None = None) -> None:
        super().__init__(params)
        spin_up = max_spin_up_time(params)
        if math.isinf(spin_up):
            raise InvalidParameterError("bang-bang needs torque_max > 0 N m")
        if switch_time is not None:
            switch_time = positive_float("switch_time", switch_time, "s")
            if switch_time > spin_up * (1.0 + 1e-12):
                raise InvalidParameterError(
                    f"switch_time must be <= T_max = {spin_up:g} s (Eq. 12), got {switch_time:g}"
                )
        self.fixed_switch_time = switch_time
        # Its own period puts T_max on a whole number of ticks (about 1 ms), so that both
        # torque pulses last equally long and the flywheel ends at rest (Eq. 10).
        self._tick = spin_up / math.ceil(spin_up / 1e-3)
        self.control_period = self._tick
        self.switch_time = 0.0
        self._omega = params.omega
        self._direction = 0.0

    def reset(self, state: NDArray[np.float64]) -> None:
        """Choose the direction and length of the spin-up from the initial capture point."""
        p = self.params
        capture = capture_point(float(state[0]), float(state[len(state) // 2]), self._omega)
        if capture >= p.toe:
            self._direction, edge = 1.0, p.toe
        elif capture <= p.heel:
            self._direction, edge = -1.0, p.heel
        else:
            self._direction, self.switch_time = 0.0, 0.0
            return
        if self.fixed_switch_time is not None:
            self.switch_time = self.fixed_switch_time
        else:
            switch = bang_bang_switch_time(
                capture, 0.5 * (p.heel + p.toe), p, cop=edge, direction=self._direction
            )
            self.switch_time = round(switch / self._tick) * self._tick

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """Bang-bang on [0, 2T) with the CoP on the edge, then CoP at the capture point."""
        # Half a microsecond of slack so that t = k dt lands on the intended side of a switch.
        direction, switch = self._direction, self.switch_time - 5e-7
        if direction != 0.0 and t < 2.0 * switch:
            edge = self.params.toe if direction > 0.0 else self.params.heel
            sign = direction if t < switch else -direction
            return Command(edge, sign * self.params.torque_max, saturated=True)
        x, xdot = float(state[0]), float(state[len(state) // 2])
        cop, clipped = self.clip_cop(capture_point(x, xdot, self._omega))
        return Command(cop, saturated=clipped)
