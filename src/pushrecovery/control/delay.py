"""A controller that reacts late: the CoP held at the foot's middle for a latency, then control.

:func:`reaction_delay` wraps any sagittal controller. For ``latency`` seconds after its reset
it commands the CoP at the middle of the foot, (heel + toe)/2, no hip torque and no step (the
body as it stood); at the first tick from then on it resets the wrapped controller on the
state it finds and hands every tick to it, with the time since that reset. This is the
latency law of :mod:`pushrecovery.surfaces.probability.latency`: the state measured at the
push is τ old when the command acts, the CoP held meanwhile, so ξ(τ) = p + (ξ − p)e^{ωτ}.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.control.base import Command, Controller, StepInfo

__all__ = ["ReactionDelay", "reaction_delay"]


class ReactionDelay(Controller):
    """The wrapped controller, ``latency`` seconds late (module docstring)."""

    name = "reaction-delay"

    def __init__(self, inner: Controller, latency: float) -> None:
        require_type("inner", inner, Controller)
        super().__init__(inner.params)
        self.inner = inner
        self.latency = latency
        self.control_period = inner.control_period
        self._held = Command(0.5 * (inner.params.heel + inner.params.toe), 0.0)
        self._start: float | None = None

    def reset(self, state: NDArray[np.float64]) -> None:
        """Start a run: hold for the latency, then reset the wrapped controller."""
        self._start = None

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """Hold until ``latency`` [s], then the wrapped controller's command."""
        if t < self.latency:
            return self._held
        if self._start is None:
            self._start = t
            self.inner.reset(state)
        return self.inner.compute(t - self._start, state)

    def observe(self, info: StepInfo) -> None:
        """Pass the plant's report on once the wrapped controller runs."""
        if self._start is not None:
            self.inner.observe(info)


def reaction_delay(controller: Controller, latency: float) -> Controller:
    """Return ``controller`` made to react ``latency`` [s] late, in [0, 1] (module docstring).

    The wrapper keeps the wrapped controller's name, strategy, state labels and period (a
    subclass made for it), so that the simulator and the campaigns treat it as that one.
    """
    require_type("controller", controller, Controller)
    latency = bounded_float("latency", latency, 0.0, 1.0, "s")
    kind = type(controller)
    attributes: dict[str, Any] = {
        "name": kind.name,
        "strategy": kind.strategy,
        "fixed_period": kind.fixed_period,
        "state_labels": kind.state_labels,
    }
    wrapper = type(f"Delayed{kind.__name__}", (ReactionDelay,), attributes)
    return wrapper(controller, latency)
