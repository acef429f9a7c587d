r"""Planning a step of the whole-body controller: the swing leg, its foothold and swing time.

World frame, x forward, y left, z up, SI units. Used by :class:`~.stepper.stepper.Stepper`:
:func:`plan_foothold` takes the recommended ``foothold`` (the Chebyshev centre) of the
library's one-step capture region
(:func:`~pushrecovery.surfaces.capture.region.capture_region`) for the stance foot alone, cut
to the half-plane ``min_step_width`` out on the landing side when the straight swing would meet
the stance sole (:func:`collides`, :func:`planning_params`), with a two-step plan and a clipped
fallback after it; :func:`choose_step` picks the foot (the library's side rule; after a
touchdown the trailing foot, unless the landed foot's plan captures in fewer steps); and
:func:`~.leg.leg_swing_time` the swing time the swing hip can drive,

.. math:: T \ge \sqrt{\frac{10}{\sqrt 3}\,\frac{\Delta\theta\, I}{\kappa\, \tau}}

per axis. docs/humanoid3d_stepping.md, "The plan", gives each rule and why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.region import capture_region

FloatArray = NDArray[np.float64]

__all__ = ["StepRecord"]

#: Peak acceleration of a rest-to-rest quintic over its distance / duration² [-]: 10/√3.
QUINTIC_PEAK = 10.0 / math.sqrt(3.0)


@dataclass
class StepRecord:
    """One step: the swing foot, its timing [s] and its footholds [m] (world xy).

    ``plans`` lists (time, foothold x, foothold y) of the first plan and every re-plan;
    ``origin`` is the ankle's ground point at lift-off, ``landed`` at touchdown (None while
    in the air); ``count`` the steps of the capture plan at lift-off (1 or 2; 0: the clipped
    fallback, no plan captured).
    """

    foot: str
    liftoff: float
    planned_touchdown: float
    plans: list[tuple[float, float, float]] = field(default_factory=list)
    touchdown: float | None = None
    landed: FloatArray | None = None
    origin: FloatArray | None = None
    count: int = 1

    @property
    def length(self) -> float:
        """Distance from the lift-off ankle to the landed one [m] (nan in the air)."""
        if self.landed is None or self.origin is None:
            return math.nan
        return float(np.linalg.norm(self.landed - self.origin))

    @property
    def foothold(self) -> FloatArray:
        """Return the last planned foothold [m]."""
        return np.array(self.plans[-1][1:])

    @property
    def error(self) -> float:
        """Distance from the landed ankle to the last planned foothold [m] (nan in the air)."""
        if self.landed is None:
            return math.nan
        return float(np.linalg.norm(self.landed - self.foothold))


def quintic(p0: FloatArray, v0: FloatArray, a0: FloatArray, p1: FloatArray,
            duration: float) -> FloatArray:  # fmt: skip
    """Return c (6, d) with p(τ) = Σ_k c_k τ^k from (p0, v0, a0) to (p1, 0, 0) at τ = duration.

    Raises
    ------
    InvalidParameterError
        If ``duration`` is not positive.
    """
    if not duration > 0.0:
        raise InvalidParameterError(f"duration must be > 0 s, got {duration!r}")
    t = duration
    gap = p1 - p0 - v0 * t - 0.5 * a0 * t**2
    rate, curve = -v0 - a0 * t, -a0
    c3 = (10.0 * gap - 4.0 * rate * t + 0.5 * curve * t**2) / t**3
    c4 = (-15.0 * gap + 7.0 * rate * t - curve * t**2) / t**4
    c5 = (6.0 * gap - 3.0 * rate * t + 0.5 * curve * t**2) / t**5
    return np.array([p0, v0, 0.5 * a0, c3, c4, c5])


def evaluate(coeffs: FloatArray, tau: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Return p, ṗ, p̈ of the polynomial Σ_k c_k τ^k (c from :func:`quintic`) at τ [s]."""
    powers = tau ** np.arange(6)
    k = np.arange(6)
    p = powers @ coeffs
    v = (k[1:] * powers[:-1]) @ coeffs[1:]
    a = (k[2:] * (k[2:] - 1) * powers[:-2]) @ coeffs[2:]
    return p, v, a


def yaw_of(rot: FloatArray) -> float:
    """Return the heading [rad] of rotation matrix ``rot``: atan2(R_10, R_00)."""
    return math.atan2(float(rot[1, 0]), float(rot[0, 0]))


def rotation_vector(rot: FloatArray) -> FloatArray:
    """Return the rotation vector (axis × angle) of rotation matrix ``rot`` [rad]."""
    angle = math.acos(max(-1.0, min(1.0, 0.5 * (float(np.trace(rot)) - 1.0))))
    axial = 0.5 * np.array([rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]])
    return axial if angle < 1e-9 else axial * (angle / math.sin(angle))


def lipm_com(com: FloatArray, vel: FloatArray, cop: FloatArray, omega: float,
             t: float) -> FloatArray:  # fmt: skip
    """Return the LIPM's CoM [m] after t [s] on a still CoP: p + (c − p) cosh ωt + ċ/ω sinh ωt."""
    return cop + (com - cop) * math.cosh(omega * t) + vel / omega * math.sinh(omega * t)


def planning_params(params: BodyParams, clearance: float | None) -> BodyParams:
    """Return ``params`` with ``min_step_width`` at least ``foot_width`` + ``clearance`` [m].

    The library's reach cut (:func:`~pushrecovery.surfaces.n_step.reach_polygon`) then keeps
    each landing ankle that far out on its own side of the stance ankle: the swing foot, on a
    straight path between two points of that half-plane, never crosses the stance foot. None:
    ``params`` unchanged (crossing footholds allowed). :func:`plan_foothold` plans with it only
    when the straight swing to the uncut region's foothold would meet the stance sole (the cut
    moves the region's Chebyshev centre even where the old one was clear: a backward push's
    first step, landing behind the stance foot, moved 4 cm out, and the step critical push at
    180° fell from 59 to 47 N s).
    """
    if clearance is None:
        return params
    width = params.foot_width + clearance
    if params.min_step_width is not None:
        width = max(width, params.min_step_width)
    return replace(params, min_step_width=width)


def _other(side: Stance) -> Stance:
    return Stance.RIGHT if side is Stance.LEFT else Stance.LEFT


def collides(params: BodyParams, stance: FootPose, start: FloatArray, end: FloatArray,
             clearance: float) -> bool:  # fmt: skip
    """Whether the swing ankle's straight path from ``start`` to ``end`` [m] meets the stance sole.

    In the stance foot's frame, two soles of the body's length L = toe − heel and width w
    (same yaw) overlap when the ankles' offset lies in the open box abs(Δx) < L, abs(Δy) < w;
    enlarged by ``clearance`` [m], sampled at 33 points of the path (1/32 of it apart).
    """
    c, s = math.cos(stance.yaw), math.sin(stance.yaw)
    ends = np.array([start, end], dtype=float) - np.array([stance.x, stance.y])
    local = ends @ np.array([[c, -s], [s, c]])
    path = local[0] + np.linspace(0.0, 1.0, 33)[:, None] * (local[1] - local[0])
    half = np.array([params.toe - params.heel, params.foot_width]) + clearance
    return bool(np.any(np.all(np.abs(path) < half, axis=1)))


def _outward(side: Stance, pose: FootPose) -> FloatArray:
    """Return the unit vector from the ``side`` stance foot toward the landing foot's side."""
    outward = -1.0 if side is Stance.LEFT else 1.0
    return np.array([-math.sin(pose.yaw), math.cos(pose.yaw)]) * outward


def plan_foothold(
    params: BodyParams,
    state: tuple[float, float, float, float],
    stance: tuple[Stance, FootPose],
    swing_pose: FootPose,
    t: float,
    *,
    hip: bool,
    cut: BodyParams | None = None,
) -> tuple[FloatArray, int]:
    """Return the foothold [m] (ankle, world xy) of the free foot and the plan's step count.

    ``state`` is (x, y, ẋ, ẏ) of the CoM [m, m/s], ``stance`` the stance side and its pose,
    ``swing_pose`` the swing foot's pose now, ``t`` the time to touchdown [s]; ``hip``: the
    controller's hip task helps (the region's box H). One step, then two: the region of
    ``params``; when the straight swing to its foothold meets the stance sole
    (:func:`collides`, with the clearance ``cut.min_step_width`` − ``foot_width``), the region
    of ``cut`` (:func:`planning_params`: the library's reach cut to the half-plane that far
    out on the landing foot's side, in which a straight swing never meets the stance sole).
    Step count 1 or 2, 0 for the clipped fallback (module docstring), moved out to the width
    when ``cut`` is given.
    """
    side, pose = stance
    poses = {"left": pose, "right": swing_pose} if side is Stance.LEFT else {
        "left": swing_pose, "right": pose}  # fmt: skip
    support = Support.from_params(params, side, **poses)
    ankle, lateral = np.array([pose.x, pose.y]), _outward(side, pose)
    width = None if cut is None else cut.min_step_width
    for count in (1, 2):
        for body in (params,) if width is None else (params, cut):
            assert body is not None
            region = capture_region(*state, body, support, t, steps=count, hip=hip)
            if region.foothold is None:
                continue
            foothold = np.asarray(region.foothold, dtype=float)
            start = np.array([swing_pose.x, swing_pose.y])
            if (
                body is cut
                or width is None
                or not collides(params, pose, start, foothold, width - params.foot_width)
            ):
                return foothold, count
    xi = np.array(state[:2]) + np.array(state[2:]) / params.omega
    offset = xi - ankle
    offset *= min(1.0, params.max_step_length / max(float(np.linalg.norm(offset)), 1e-9))
    if width is not None:
        offset += max(width - float(offset @ lateral), 0.0) * lateral
    return ankle + offset, 0


def choose_step(
    params: BodyParams,
    state: tuple[float, float, float, float],
    poses: tuple[FootPose, FootPose],
    t: float,
    *,
    hip: bool,
    landed: Stance | None = None,
    cut: BodyParams | None = None,
) -> tuple[Stance, FloatArray, int]:
    """Return the swing foot, its foothold [m] and the plan's step count, from double support.

    ``poses`` are the (left, right) feet's poses, ``landed`` the foot that has just landed
    (None for a first step), ``cut`` the no-crossing plan (:func:`plan_foothold`).
    **First step**: the foot on the capture point's side of the ankles' midpoint (the
    library's rule, :func:`capture_region`), its foothold from :func:`plan_foothold`.
    **After a touchdown**, when the other foot is the trailing one (its ankle behind the
    landed one along ξ's offset from the ankles' midpoint), each foot's plan counts the steps
    its capture takes (one, two, or none: the clipped fallback); the trailing foot swings
    unless the landed foot's plan captures in fewer steps (the plan says so: e.g. a diagonal
    push whose capture point runs past the landed foot's outer side, which the trailing foot
    could only reach by crossing). Otherwise the library's rule.
    """
    xi = np.array(state[:2]) + np.array(state[2:]) / params.omega
    left, right = poses
    middle = 0.5 * np.array([left.x + right.x, left.y + right.y])
    yaw = math.atan2(math.sin(left.yaw) + math.sin(right.yaw),
                     math.cos(left.yaw) + math.cos(right.yaw))  # fmt: skip
    lateral = -math.sin(yaw) * (xi[0] - middle[0]) + math.cos(yaw) * (xi[1] - middle[1])
    order = [Stance.LEFT if lateral >= 0.0 else Stance.RIGHT]
    if landed is not None:
        ankle = {
            Stance.LEFT: np.array([left.x, left.y]),
            Stance.RIGHT: np.array([right.x, right.y]),
        }
        ahead = xi - middle
        if float((ankle[_other(landed)] - ankle[landed]) @ ahead) < 0.0:  # the other trails
            order = [_other(landed), landed]

    def plan(swing: Stance) -> tuple[FloatArray, int]:
        stance = _other(swing)
        own, free = (left, right) if stance is Stance.LEFT else (right, left)
        return plan_foothold(params, state, (stance, own), free, t, hip=hip, cut=cut)

    foothold, count = plan(order[0])
    if len(order) == 2 and count != 1:  # the landed foot only on a plan of fewer steps
        again, more = plan(order[1])
        if 0 < more < (count or 3):
            return order[1], again, more
    return order[0], foothold, count
