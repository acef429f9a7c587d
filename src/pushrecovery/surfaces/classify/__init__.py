"""The strategy a state needs: the complete strategy map of the paper, on a line or the plane.

Vocabulary (stable, part of the JSON contract), escalating as the paper proposes (Sec. I-B):
``ankle`` (CoP balancing, Eq. 4), ``hip`` (CMP balancing, corrected Eq. 15), ``step`` (at most
``max_steps`` steps capture the state: the N-step regions of
:mod:`pushrecovery.surfaces.step.regions`, touchdowns every ``min_step_time``) and ``fall``.

On the ground plane (:func:`classify` with ``y``, ``ydot`` or a ``support``) the ankle and hip
regions are the support polygon and the CMP region of :mod:`pushrecovery.surfaces.plane` and
the step regions are polygons; on the line, intervals (``docs/steps.md``).

Over 400 lines on purpose: one decision (the strategy a state needs) on the line and on the
plane, with the plans, impacts and ranges a verdict builds only when asked.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import MAX_POSE, Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.plan import CapturePlan, plan_loads
from pushrecovery.surfaces.capture.region import MAX_POSITION, MAX_SPEED
from pushrecovery.surfaces.classify.many import classify_states
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import CaptureInterval, cop_region
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.step.impact import TouchdownImpact, plan_impacts
from pushrecovery.surfaces.step.regions import StepRegions, _line_plan
from pushrecovery.surfaces.strategy import STRATEGY_CODES, Strategy
from pushrecovery.surfaces.verdicts import (  # sagittal_verdicts: campaign.pushes imports it here
    _first_step_range,
    _steps,
    _strategy,
    sagittal_verdict,
    sagittal_verdicts,  # noqa: F401
)

__all__ = [
    "STRATEGY_CODES",
    "Classification",
    "Strategy",
    "classify",
    "classify_states",
    "strategy_region",
]


_REGIONS: dict[str, Callable[[BodyParams], CaptureInterval]] = {
    Strategy.ANKLE: cop_region,
    Strategy.HIP: cmp_region,
}


def strategy_region(strategy: str, params: BodyParams) -> CaptureInterval:
    """Capture-point interval of a balancing strategy (``ankle`` or ``hip``) [m].

    Raises
    ------
    ParameterTypeError
        If ``strategy`` is not a str or ``params`` not a
        :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        If ``strategy`` names no balancing strategy.
    """
    require_type("strategy", strategy, str)
    try:
        return _REGIONS[strategy](params)
    except KeyError:
        raise InvalidParameterError(
            f"strategy must be one of {sorted(_REGIONS)}, got {strategy!r}"
        ) from None


_Details = tuple[dict[str, Any], CapturePlan, tuple[TouchdownImpact, ...]]


class _Planned:
    """A ``step`` verdict's first step, plan and impacts, built on first use and kept.

    Two threads reading at once may both build them (the same values); neither sees a part.
    """

    __slots__ = ("_build", "_value")

    def __init__(self, build: Callable[[], _Details]) -> None:
        self._build = build
        self._value: _Details | None = None

    def get(self) -> _Details:
        value = self._value
        if value is None:
            value = self._value = self._build()
        return value

    def __reduce__(self) -> tuple[Callable[[_Details], _Planned], tuple[_Details]]:
        """Pickle (and deep-copy) the built values, not the closure that builds them."""
        return _built, (self.get(),)


def _built(value: _Details) -> _Planned:
    """Return a :class:`_Planned` holding ``value`` (unpickling)."""
    planned = _Planned(lambda: value)
    planned._value = value
    return planned


@dataclass(frozen=True, slots=True)
class Classification:
    """Strategy needed by one state, with the capture point, the margins [m] and the steps.

    ``margins``: ``cop`` and ``cmp`` are signed distances of the capture point to the regions'
    edges; ``step`` is its largest signed distance to the N-step regions (N <= max_steps,
    :mod:`pushrecovery.surfaces.step.regions`), positive exactly when steps capture the state
    and null in JSON otherwise. ``steps`` is the number of steps needed (0: ankle or hip,
    None: more than ``max_steps``) and ``plan`` the plan of a ``step`` verdict (footholds,
    touchdown times, CoPs; ``impact``: each touchdown's capture point without and with Sec.
    IV's impact, :mod:`pushrecovery.surfaces.step.impact`; whether a step crosses over and the
    ankle torques and ground forces of its CoPs from this state,
    :class:`~pushrecovery.surfaces.capture.plan.CapturePlan`). ``step`` describes its first
    step: ``step_length`` (stance ankle to landing ankle, signed like the step on the line),
    ``com_to_foot`` (landing ankle minus CoM at touchdown), ``theta`` (the stance leg's lean
    at touchdown, atan of the CoM's distance ahead of the stance ankle over L) and the
    ``step_length_range`` of first steps along the same direction that still capture with
    the plan's number of steps.

    On the ground plane also ``capture_point_xy`` (ξ in the world frame [m]), the ``support``
    and the CMP region's vertices (``cmp_region``); margins are then signed Euclidean
    distances in the plane, and ``step`` adds ``foothold_xy`` [m] and ``direction_xy``, the
    unit vector from the stance ankle to the first foothold, turned to the heading's side
    for a step mostly backward, whose ``step_length`` is then negative (as on the line).

    ``step``, ``plan`` and ``impacts`` are built when first read (a verdict alone costs
    microseconds; its plan up to a few hundred): the same values as built eagerly.
    """

    capture_point: float
    strategy: Strategy
    margins: dict[str, float] = field(default_factory=dict)
    capture_point_xy: tuple[float, float] | None = None
    support: Support | None = None
    cmp_region: list[list[float]] | None = None
    steps: int | None = None
    _planned: _Planned | None = field(default=None, repr=False, compare=False)

    @property
    def step(self) -> dict[str, object] | None:
        """The first step of a ``step`` verdict's plan (class docstring), else None."""
        return None if self._planned is None else self._planned.get()[0]

    @property
    def plan(self) -> CapturePlan | None:
        """The plan of a ``step`` verdict (footholds, touchdowns, CoPs), else None."""
        return None if self._planned is None else self._planned.get()[1]

    @property
    def impacts(self) -> tuple[TouchdownImpact, ...]:
        """Each touchdown's capture point without and with Sec. IV's impact (a plan's)."""
        return () if self._planned is None else self._planned.get()[2]

    def to_dict(self) -> dict[str, object]:
        """JSON form: ``{"capture_point", "strategy", "margins", "steps"}`` (+ ``"step"``...)."""
        margins = {k: (v if math.isfinite(v) else None) for k, v in self.margins.items()}
        step_margin = margins.get("step")
        if step_margin is not None and not step_margin > 0.0:
            margins["step"] = None
        data: dict[str, object] = {
            "capture_point": self.capture_point,
            "strategy": self.strategy.value,
            "margins": margins,
            "steps": self.steps,
        }
        if self.step is not None:
            data["step"] = dict(self.step)
            data["step_length"] = self.step["step_length"]
        if self.plan is not None:
            plan = self.plan.to_dict()
            plan["impact"] = [impact.to_dict() for impact in self.impacts]
            data["plan"] = plan
        if self.capture_point_xy is not None:
            data["capture_point_xy"] = list(self.capture_point_xy)
        if self.support is not None:
            data["support"] = self.support.to_dict()
        if self.cmp_region is not None:
            data["cmp_region"] = self.cmp_region
        return data


def classify(
    x: float,
    xdot: float,
    params: BodyParams,
    *,
    y: float | None = None,
    ydot: float | None = None,
    support: Support | None = None,
    landing_yaw: float | None = None,
) -> Classification:
    """Classify one CoM state (upper body upright and at rest, as the surfaces assume).

    Without ``y``, ``ydot`` and ``support`` this is the sagittal model of the paper (the foot
    the interval [heel, toe]); with any of them, the ground plane (module docstring), where
    ``support`` defaults to double support on the default feet
    (:meth:`~pushrecovery.ground.Support.from_params`). With y = ẏ = 0 and the default double
    support of a foot no longer than the stance is wide (the paper preset), both give the same
    verdict, capture point and ankle and hip margins.

    Parameters
    ----------
    x : float
        CoM position [m], x forward: relative to the ankle (sagittal), or in the world frame
        of the support (plane).
    xdot : float
        CoM velocity [m/s].
    params : BodyParams
        Body parameters.
    y : float, optional
        Lateral CoM position in the world frame [m], y left (default 0).
    ydot : float, optional
        Lateral CoM velocity [m/s] (default 0).
    support : Support, optional
        Stance and feet on the ground plane.
    landing_yaw : float, optional
        Yaw of the plan's landing feet [rad], in [−π, π] (ground plane; default: the stance
        foot's yaw). The verdict keeps the regions of the stance's yaw; the plan and its
        margin are those of the landing yaw
        (:meth:`~pushrecovery.surfaces.step.regions.StepRegions.plan`), while the first
        step's ``step_length_range`` stays that of the stance's yaw.

    Returns
    -------
    Classification
        ``ankle`` when the capture point is strictly inside the foot or support polygon
        (Eq. 4), ``hip`` when it is inside the CMP region (corrected Eq. 15, in the plane:
        the polygon grown by each axis's offset), ``step`` when at most ``max_steps`` steps
        capture it (with the plan), else ``fall``. The plan says whether it crosses over and
        what its CoPs ask of the ankle and the ground
        (:class:`~pushrecovery.surfaces.capture.plan.CapturePlan`).
    """
    x = finite_float("x", x, "m")
    xdot = finite_float("xdot", xdot, "m/s")
    if landing_yaw is not None:
        landing_yaw = bounded_float("landing_yaw", landing_yaw, -math.pi, math.pi, "rad")
    if y is not None or ydot is not None or support is not None or landing_yaw is not None:
        return _classify_plane(x, xdot, params, y, ydot, support, landing_yaw)
    verdict = sagittal_verdict(x, xdot, params)
    capture, strategy, steps = verdict.capture_point, verdict.strategy, verdict.steps
    margins = {"cop": verdict.cop_margin, "cmp": verdict.cmp_margin, "step": verdict.step_margin}
    planned = None
    if strategy is Strategy.STEP:

        def build() -> _Details:
            plan = _line_plan(capture, params, steps)
            step = _first_step(plan, (x, 0.0), (xdot, 0.0), (0.0, 0.0), params)
            step["step_length_range"] = list(_first_step_range(capture, steps, params))
            impacts = tuple(plan_impacts(plan, (x, 0.0), (xdot, 0.0), params))
            loads = plan_loads(plan, params, (x, 0.0), (xdot, 0.0))
            return step, plan.with_loads(loads), impacts

        planned = _eager_if_out_of_range(_Planned(build), x, 0.0, xdot, 0.0)
    return Classification(
        capture, strategy, margins, steps=_steps(strategy, steps), _planned=planned
    )


def _eager_if_out_of_range(
    planned: _Planned, x: float, y: float, xdot: float, ydot: float
) -> _Planned:
    """Build now a plan that would refuse its state (beyond the ranges of capture_region).

    A step verdict's plan takes positions within ±MAX_POSITION and speeds within ±MAX_SPEED;
    beyond them classify raises its InvalidParameterError itself, as when it built every plan.
    """
    positions, speeds = max(abs(x), abs(y)), max(abs(xdot), abs(ydot))
    if not (positions <= MAX_POSITION and speeds <= MAX_SPEED):
        planned.get()  # raises
    return planned


def _first_step(
    plan: CapturePlan,
    position: tuple[float, float],
    velocity: tuple[float, float],
    ankle: tuple[float, float],
    params: BodyParams,
) -> dict[str, Any]:
    """Return the ``step`` object of the plan's first step (class docstring).

    The CoM at touchdown t_1 follows the LIPM with the first CoP p held (the hip's share
    aside): r(t) = p + (r0 − p) cosh ωt + (ṙ0/ω) sinh ωt.
    """
    omega, t = params.omega, float(plan.touchdowns[0])
    cop = plan.cops[0]
    com = [
        cop[i]
        + (position[i] - cop[i]) * math.cosh(omega * t)
        + velocity[i] / omega * math.sinh(omega * t)
        for i in (0, 1)
    ]
    foot = plan.footholds[0]
    gap = (float(foot[0] - ankle[0]), float(foot[1] - ankle[1]))
    length = math.hypot(*gap)
    lean = math.hypot(com[0] - ankle[0], com[1] - ankle[1])
    return {
        "step_length": math.copysign(length, gap[0]) if gap[1] == 0.0 else length,
        "com_to_foot": math.hypot(float(foot[0]) - com[0], float(foot[1]) - com[1])
        * (1.0 if (foot[0] - com[0]) * gap[0] + (foot[1] - com[1]) * gap[1] >= 0.0 else -1.0),
        "theta": math.atan2(lean, params.com_height),
    }


@dataclass(frozen=True, slots=True, eq=False)
class _PlaneTables:
    """A support's regions for one state's verdict.

    ``cop`` and ``cmp``: the support polygon's and the CMP region's edges as
    :func:`pushrecovery.kernels.single_margins.signed_distance` reads them.
    """

    inv_omega: float
    cop: NDArray[np.float64]
    cmp: NDArray[np.float64]
    cmp_region: tuple[tuple[float, ...], ...]
    regions: StepRegions


@functools.lru_cache(maxsize=32)
def _plane_tables(params: BodyParams, support: Support) -> _PlaneTables:
    """Return the tables of one support (kept: a loop asks for the same support again)."""
    from pushrecovery.kernels.single_margins import edge_rows

    hip_region = cmp_polygon(support, params)
    cop, cmp = (edge_rows(p.vertices, p.normals, p.offsets) for p in (support.polygon, hip_region))
    cmp_region = tuple(map(tuple, hip_region.to_list()))
    regions = StepRegions.of(params, support)
    return _PlaneTables(1.0 / params.omega, cop, cmp, cmp_region, regions)


@functools.lru_cache(maxsize=32)
def _default_support(params: BodyParams) -> Support:
    """Double support on the default feet (kept, as a frozen value)."""
    return Support.from_params(params)


def _classify_plane(
    x: float,
    xdot: float,
    params: BodyParams,
    y: float | None,
    ydot: float | None,
    support: Support | None,
    landing_yaw: float | None = None,
) -> Classification:
    """:func:`classify` on the ground plane: the verdict in one compiled call, the plan lazily."""
    from pushrecovery.kernels.single_margins import signed_distance

    y = 0.0 if y is None else finite_float("y", y, "m")
    ydot = 0.0 if ydot is None else finite_float("ydot", ydot, "m/s")
    require_type("params", params, BodyParams)
    if support is None:
        support = _default_support(params)
    require_type("support", support, Support)
    tables = _plane_tables(params, support)
    # ξ as capture_point computes it: x + ẋ (1/ω).
    xi = (x + xdot * tables.inv_omega, y + ydot * tables.inv_omega)
    if not (abs(xi[0]) <= MAX_POSE and abs(xi[1]) <= MAX_POSE):  # as BalanceMonitor.query
        raise InvalidParameterError(
            f"states are too large: the capture point must be within ±{MAX_POSE:g} m of the "
            f"origin (as a foot pose), got ({xi[0]:g}, {xi[1]:g})"
        )
    cop, cmp = signed_distance(tables.cop, *xi), signed_distance(tables.cmp, *xi)
    steps, step_margin = tables.regions.locate(*xi)
    strategy = _strategy(cop, cmp, steps)
    planned = None
    if strategy is Strategy.STEP:
        regions, chosen = tables.regions, support

        def build() -> _Details:
            return _plane_details(x, y, xdot, ydot, params, chosen, regions, xi, steps, landing_yaw)

        planned = _eager_if_out_of_range(_Planned(build), x, y, xdot, ydot)
    margins = {"cop": cop, "cmp": cmp, "step": step_margin}
    return Classification(
        xi[0],
        strategy,
        margins,
        xi,
        support,
        [list(vertex) for vertex in tables.cmp_region],
        steps=_steps(strategy, steps),
        _planned=planned,
    )


def _plane_details(
    x: float,
    y: float,
    xdot: float,
    ydot: float,
    params: BodyParams,
    support: Support,
    regions: StepRegions,
    xi: tuple[float, float],
    steps: int,
    landing_yaw: float | None = None,
) -> _Details:
    """Return the first step, plan and impacts of a ``step`` verdict on the ground plane."""
    plan = regions.plan(*xi, steps, landing_yaw=landing_yaw)
    option = next(o for o in regions.options if o.swing is plan.swings[0])
    ankle = (float(option.ankle[0]), float(option.ankle[1]))
    step = _first_step(plan, (x, y), (xdot, ydot), ankle, params)
    foot = plan.footholds[0]
    gap = (float(foot[0]) - ankle[0], float(foot[1]) - ankle[1])
    # Signed like the sagittal step: a step mostly backward is negative along the
    # direction turned to the heading's side; others keep their own direction.
    heading = (math.cos(support.yaw), math.sin(support.yaw))
    forward = gap[0] * heading[0] + gap[1] * heading[1]
    sideways = -gap[0] * heading[1] + gap[1] * heading[0]
    ahead = -1.0 if forward < 0.0 and abs(forward) >= abs(sideways) else 1.0
    length = ahead * math.hypot(*gap)
    step["step_length"] = length
    # + 0.0 turns the −0.0 of a zero component into 0.0 in the JSON.
    step["direction_xy"] = [gap[0] / length + 0.0, gap[1] / length + 0.0]
    step["foothold_xy"] = [float(foot[0]) + 0.0, float(foot[1]) + 0.0]
    step["step_length_range"] = _plane_range(x, y, xdot, ydot, params, support, plan, ankle, gap)
    impacts = tuple(plan_impacts(plan, (x, y), (xdot, ydot), params, plan.landing_yaw))
    loads = plan_loads(plan, params, (x, y), (xdot, ydot))
    return step, plan.with_loads(loads), impacts


def _plane_range(
    x: float,
    y: float,
    xdot: float,
    ydot: float,
    params: BodyParams,
    support: Support,
    plan: CapturePlan,
    ankle: tuple[float, float],
    gap: tuple[float, float],
) -> list[float]:
    """First step lengths along the first step's direction within its N-step foothold region."""
    from pushrecovery.surfaces.capture.region import capture_region

    region = capture_region(
        x, y, xdot, ydot, params, support, steps=plan.steps, swing=plan.swings[0]
    ).polygon
    length = math.hypot(*gap)
    if region is None or length == 0.0:
        return [length, length]
    u = (gap[0] / length, gap[1] / length)
    # The chord of the convex region along the ray ankle + s u: each half-plane bounds s.
    low, high = 0.0, math.inf
    for (nx, ny), b in zip(region.normals.tolist(), region.offsets.tolist(), strict=True):
        rate = nx * u[0] + ny * u[1]
        room = b - nx * ankle[0] - ny * ankle[1]
        if rate > 0.0:
            high = min(high, room / rate)
        elif rate < 0.0:
            low = max(low, room / rate)
    return [low, high]
