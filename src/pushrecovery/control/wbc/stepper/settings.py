"""The settings of the whole-body controller's stepping task (:mod:`.stepper.stepper`).

SI units; every setting is validated once here (:class:`StepSettings`), the
:class:`~.stepper.stepper.Stepper` reads them at every control tick.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from pushrecovery.errors import InvalidParameterError

__all__ = ["StepSettings"]


@dataclass(frozen=True)
class StepSettings:
    """The stepping task's settings (module docstring); all finite.

    Attributes
    ----------
    swing_time : float or None
        t_s, lift-off to touchdown [s] in [0.05, 2]; None: the body's ``min_step_time``
        (at least 0.05 s).
    lift : float
        h, the swing's apex above the straight line [m], in [0, 0.5].
    sink, sink_speed : float
        How far below the floor the reference ends [m] and its speed after t_1 [m/s], ≥ 0.
    contact_damping : float
        k_c of the feet in contact [1/s] (:class:`~.qp.WholeBodyQP`): a foot unloaded beside
        the stance foot stays down.
    contact : float
        Touchdown when the lowest sole point is this close to the floor [m], > 0.
    margin : float
        Step when ξ is this far outside the recoverable region [m], ≥ 0.
    stiffness, damping : float
        k_p [1/s²] and d_p [1/s] of the foot's position, ≥ 0.
    turn_stiffness, turn_damping : float
        k_R [1/s²] and d_R [1/s] of its orientation, ≥ 0.
    weight : float
        The foot task's W, > 0.
    replan_period : float
        Re-plan period during the swing [s], > 0.
    replan_fraction : float
        Re-plan only in this first fraction of the swing, in [0, 1].
    torque_share : float or None
        κ in [0.001, 1], a fraction: the share of the swing hip's motor limit the swing may take;
        the swing lasts at least what that torque needs (:func:`~.leg.leg_swing_time`), up to
        ``max_swing_time``. None: always ``swing_time``.
    max_swing_time : float
        The longest swing [s], in [0.05, 2], ≥ ``swing_time``.
    knee_min : float
        The knee guard [rad] in [0, 1]: a knee below it (or reaching it within 50 ms) is
        pulled back, q̈ = k_p (q_min − q) − d_p q̇ (the QP does not model the joint stop).
    knee_weight : float
        The knee guard's W, > 0.
    lift_weight : float
        The swing foot's vertical row weighs this times W, in [0.001, 1000]: a foot that
        does not leave the floor cannot step.
    clearance : float or None
        No crossing steps: the plans take the body's ``min_step_width`` as at least
        ``foot_width`` + ``clearance`` [m] in [0, 0.5], so that the landing ankle stays that far
        out on its own side of the stance ankle (the library's reach cut,
        :func:`~pushrecovery.surfaces.n_step.reach_polygon`); a region across the stance foot
        is then reached by a two-step plan. None: the body's own ``min_step_width`` (crossing
        footholds allowed; the swing goes straight, through the stance leg).
    follow_time : float
        A step decided within this time [s] in [0, 10] of the last touchdown follows it: the
        foot that has just landed does not swing again while the other one trails
        (:func:`~.plan.choose_step`); later, a step starts afresh (the library's rule).
    knee_reach : float or None
        κ [rad] in [0, 1.5]: the pelvis height task's target is lowered so that every leg
        keeps its knee bent by at least κ, the swinging leg at its foothold
        (:mod:`.height`), by at most ``max_drop``. None: the target is never lowered.
    max_drop : float
        The most the pelvis target is lowered [m], in [0, 0.5].
    """

    swing_time: float | None = 0.3
    lift: float = 0.05
    sink: float = 0.01
    sink_speed: float = 0.2
    contact: float = 2e-3
    contact_damping: float = 20.0
    margin: float = 0.01
    stiffness: float = 900.0
    damping: float = 60.0
    turn_stiffness: float = 400.0
    turn_damping: float = 40.0
    weight: float = 10.0
    replan_period: float = 0.02
    replan_fraction: float = 0.6
    torque_share: float | None = 1.0
    max_swing_time: float = 0.6
    knee_min: float = 0.1
    knee_weight: float = 10.0
    lift_weight: float = 30.0
    clearance: float | None = 0.02
    follow_time: float = 0.5
    knee_reach: float | None = 0.2
    max_drop: float = 0.2

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if value is None and item.name in (
                "swing_time",
                "torque_share",
                "clearance",
                "knee_reach",
            ):
                continue
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0.0):
                raise InvalidParameterError(f"{item.name} must be finite and ≥ 0, got {value!r}")
        bounds = {
            "lift": (0.0, 0.5),
            "replan_fraction": (0.0, 1.0),
            "contact": (1e-6, 0.1),
            "weight": (1e-9, 1e6),
            "replan_period": (1e-4, 10.0),
            "stiffness": (0.0, 1e6),
            "max_swing_time": (0.05, 2.0),
            "knee_min": (0.0, 1.0),
            "knee_weight": (1e-9, 1e6),
            "lift_weight": (1e-3, 1e3),
            "follow_time": (0.0, 10.0),
            "max_drop": (0.0, 0.5),
        }
        if self.torque_share is not None:
            bounds["torque_share"] = (1e-3, 1.0)
        if self.swing_time is not None:
            bounds["swing_time"] = (0.05, 2.0)
        if self.knee_reach is not None:
            bounds["knee_reach"] = (0.0, 1.5)
        if self.clearance is not None:
            bounds["clearance"] = (0.0, 0.5)
        for name, (low, high) in bounds.items():  # fmt: skip
            value = getattr(self, name)
            if not low <= value <= high:
                raise InvalidParameterError(f"{name} must be in [{low:g}, {high:g}], got {value!r}")
        if self.swing_time is not None and self.swing_time > self.max_swing_time:
            raise InvalidParameterError(
                f"swing_time must be ≤ max_swing_time {self.max_swing_time:g} s, "
                f"got {self.swing_time!r}"
            )
