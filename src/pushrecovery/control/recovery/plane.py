r"""Push recovery on the ground plane: ankle, hip, then the N-step plan, re-planned at touchdowns.

The controller of the planar stepping model (``stepping-plane``; state
``[x, y, θp, θr, ẋ, ẏ, θ̇p, θ̇r]``, world frame) works on the capture point: with c the CMP
offset of the hip torques, the body is captured when

.. math:: \xi(t) = \omega\int_t^\infty e^{-\omega(s - t)}\,\big(p(s) + c(s)\big)\,ds ,

so a hip manoeuvre under way contributes its remaining share h(t) (:func:`hip_share`) and the
feet have to capture ξ_e = ξ − h. Each tick: at the commanded touchdown the landed foot is the
support and the plan is dropped; ξ_e inside the support → the CoP at ξ_e (ankle); ξ inside the
CMP region with the hip unused → ξ split over the support and the hip's box
(:func:`~pushrecovery.ground.minkowski.decompose`) and the bang-bang profile started (hip);
else the plan of the smallest N whose region C_N holds ξ_e
(:class:`~pushrecovery.surfaces.step.regions.StepRegions`; beyond ``max_steps`` a best effort
flagged ``saturated``). docs/steps.md, "Multi-step recovery on the ground plane", gives the
details. The controller keeps its own copy of the feet, moved by the steps it commands.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, non_negative_float, positive_float
from pushrecovery.control.base import Command, Controller, StepInfo, register
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.minkowski import stacked_shapes
from pushrecovery.ground.support import FootPose, Stance, Support
from pushrecovery.models.flywheel import max_spin_up_time
from pushrecovery.models.flywheel.plane import PLANE_STATE_LABELS, roll_axis
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.capture.plan import CapturePlan
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll
from pushrecovery.surfaces.cop import capture_point
from pushrecovery.surfaces.edge_rows import Edges, cmp_rows, signed_distance
from pushrecovery.surfaces.n_step import hip_box
from pushrecovery.surfaces.step.regions import StepRegions

__all__ = ["PlaneRecoveryController", "hip_share"]

FloatArray = NDArray[np.float64]


def hip_share(elapsed: float, spin_up: float, omega: float) -> float:
    """Remaining capture-point share of a unit bang-bang hip profile, in units of τ/(m g).

    For c(s) = +1 on [0, T), −1 on [T, 2T), 0 after, the share ω∫_u^∞ e^{−ω(s−u)} c(s) ds at
    ``elapsed`` u [s]: 1 − 2 e^{−ω(T−u)} + e^{−ω(2T−u)} for u < T (which is (1 − e^{−ωT})²,
    corrected Eq. 15, at u = 0), −(1 − e^{−ω(2T−u)}) for T ≤ u < 2T, and 0 from 2T on.

    Raises
    ------
    InvalidParameterError
        If ``elapsed`` is negative or not finite, ``spin_up`` T is not finite and > 0, or
        ``omega`` is outside [0.1, 100] 1/s (:data:`~pushrecovery.params.OMEGA_MIN`,
        :data:`~pushrecovery.params.OMEGA_MAX`).
    """
    elapsed = non_negative_float("elapsed", elapsed, "s")
    spin_up = positive_float("spin_up", spin_up, "s")
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    return _hip_share(elapsed, spin_up, omega)


def _hip_share(elapsed: float, spin_up: float, omega: float) -> float:
    """:func:`hip_share` unchecked (the controller's tick; T = inf for an axis with no torque)."""
    if elapsed < spin_up:
        return (
            1.0
            - 2.0 * math.exp(-omega * (spin_up - elapsed))
            + math.exp(-omega * (2.0 * spin_up - elapsed))
        )
    if elapsed < 2.0 * spin_up:
        return -(1.0 - math.exp(-omega * (2.0 * spin_up - elapsed)))
    return 0.0


def _profile_mean(start: float, end: float, spin_up: float) -> float:
    """Mean of the unit bang-bang profile (+1, −1, 0; :func:`hip_share`) over [start, end]."""

    def integral(u: float) -> float:  # ∫_0^u c(s) ds
        if u <= spin_up:
            return max(u, 0.0)
        return max(2.0 * spin_up - u, 0.0)

    return (integral(end) - integral(start)) / (end - start)


@dataclasses.dataclass(frozen=True, slots=True)
class _HipManoeuvre:
    """A scaled bang-bang profile per axis started at ``start`` [s]."""

    start: float
    fractions: tuple[float, float]  # of τmax, pitch and roll, in [−1, 1]
    yaw: float  # of the body's axes [rad]


@register
class PlaneRecoveryController(Controller):
    """Ankle → hip → N-step plan on the ground plane (module docstring)."""

    name = "recovery-plane"
    strategy = "step"
    state_labels = PLANE_STATE_LABELS

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        self.control_period = 1e-3
        self._without_hip = dataclasses.replace(params, torque_max=0.0, torque_max_roll=0.0)
        self._spin_up = (max_spin_up_time(params), max_spin_up_time(roll_axis(params)))
        self._offsets = (cmp_offset(params), cmp_offset_roll(params))
        self._torques = (params.torque_max, params.torque_max_roll)
        # The CMP region's rows of the last support asked (supports are immutable: kept
        # across resets, so a run from the default feet builds none).
        self._cmp: tuple[Support | None, Edges] = (None, ())
        self.reset(np.zeros(len(PLANE_STATE_LABELS)))
        # The compiled paths (the CMP region's sum, the regions' placement and tests) loaded
        # now rather than in the loop: a support change then costs tens of µs, any pose or yaw.
        self._cmp_margin(0.0, 0.0)
        # Plans are made in the stance foot's frame: these are every plan's terms, kept.
        for body in (params, self._without_hip):
            regions = StepRegions.of(body, self.support)
            for steps in range(1, body.max_steps + 1):
                for side in (0.5, -0.5):  # either foot first
                    regions.plan(0.0, side, steps)
        if hip_box(params, 0.0) is not None:
            self._start_hip(0.0, np.array([0.0, 0.2]))  # the hip's split, compiled
            self.reset(np.zeros(len(PLANE_STATE_LABELS)))

    def reset(self, state: NDArray[np.float64]) -> None:
        """Start on both feet (the default poses), hip unused, no step under way."""
        if np.shape(state) != (len(PLANE_STATE_LABELS),):
            raise InvalidParameterError(
                f"the {self.name} controller needs the state {list(PLANE_STATE_LABELS)}, "
                f"got shape {np.shape(state)}"
            )
        self.support = Support.from_params(self.params, Stance.DOUBLE)
        self.mode = "ankle"
        self.plan: CapturePlan | None = None
        self._hip: _HipManoeuvre | None = None
        self._swing: tuple[Stance, tuple[float, float], float] | None = None

    def observe(self, info: StepInfo) -> None:
        """Take the feet a plant reports (``info.feet``) when no step is under way.

        ``stepping-plane`` reports the stance and feet a run starts on right after
        :meth:`reset` and after every tick: between steps the next plan starts from them (a
        run from one foot plans from that foot). While a step is under way the controller
        keeps its own feet (the commanded foothold lands at the commanded time).
        """
        if info.feet is not None and info.stance and self.plan is None:
            self.support = info.feet

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """Return the command of the current phase (module docstring)."""
        swing = self._swing
        if swing is not None and t >= swing[2] - 1e-9:
            self._land(*swing)
        omega = self.params.omega
        values = np.asarray(state, dtype=np.float64).tolist()  # floats: the tick off numpy
        px = capture_point(values[0], values[4], omega)
        py = capture_point(values[1], values[5], omega)
        pitch, roll = self._hip_torques(t)
        if self._swing is not None and self.plan is not None:
            cop = self.plan.cops[0]
            saturated = self.plan.margin <= 0.0
            return Command(float(cop[0]), pitch, saturated, cop_y=float(cop[1]), roll_torque=roll)
        hx, hy = self._hip_remaining(t)
        ex, ey = px - hx, py - hy  # ξ_e = ξ − h(t)
        if self.support.polygon.point_signed_distance(ex, ey) > 0.0:
            self.mode = "ankle" if self._hip is None else self.mode
            return Command(ex, pitch, cop_y=ey, roll_torque=roll)
        if self._hip is None and self._cmp_margin(px, py) > 0.0:
            return self._start_hip(t, np.array([px, py]))
        return self._start_step(t, ex, ey)

    def _cmp_margin(self, px: float, py: float) -> float:
        """Signed distance of ξ to the support's CMP region [m] (``BalanceMonitor``'s).

        The region is built only here, when a support first needs it: a lift-off and a swing
        need none.
        """
        if self._cmp[0] is not self.support:
            self._cmp = (self.support, cmp_rows(self.support, *self._offsets))
        return signed_distance(self._cmp[1], px, py)

    def _start_hip(self, t: float, xi: FloatArray) -> Command:
        """Split ξ over the support and the hip's box; start the scaled profile."""
        box = hip_box(self.params, self.support.yaw)
        if box is None:  # pragma: no cover - the CMP region is the support without a box
            raise InvalidParameterError("no hip torque: the CMP region is the support")
        from pushrecovery.kernels.polygons import decompose_loop, minkowski_loop

        # decompose (ground.minkowski) compiled: one sum and one split, µs for any yaw.
        shapes, counts, weights = stacked_shapes([(1.0, box), (1.0, self.support.polygon)])
        origin = np.zeros(2)
        total = minkowski_loop(shapes, counts, weights, origin)
        points, _ = decompose_loop(np.asarray(xi, dtype=np.float64), shapes, counts, weights,
                                   origin, total)  # fmt: skip
        self._begin_hip(t, points[0])
        self.mode = "hip"
        pitch, roll = self._hip_torques(t)
        cop = points[1]
        return Command(float(cop[0]), pitch, cop_y=float(cop[1]), roll_torque=roll)

    def _start_step(self, t: float, px: float, py: float) -> Command:
        """Lift the first foot of the smallest plan that captures ξ_e = (px, py) [m]."""
        body = self.params if self._hip is None else self._without_hip
        regions = StepRegions.of(body, self.support)
        steps, _ = regions.locate(px, py)
        plan = regions.plan(px, py, steps if steps else body.max_steps)
        hx, hy = plan.hip.tolist()
        if self._hip is None and (hx or hy):
            self._begin_hip(t, plan.hip)
        foothold = (float(plan.footholds[0, 0]), float(plan.footholds[0, 1]))
        touchdown = t + float(plan.touchdowns[0])
        side = plan.swings[0]
        self.plan, self.mode = plan, "step"
        self._swing = (side, foothold, touchdown)
        stance = Stance.RIGHT if side is Stance.LEFT else Stance.LEFT
        if self.support.stance is not stance:  # from double support: the other foot lifts
            self.support = self.support.single(stance)
        pitch, roll = self._hip_torques(t)
        cop = plan.cops[0]
        return Command(
            float(cop[0]),
            pitch,
            plan.margin <= 0.0,
            cop_y=float(cop[1]),
            roll_torque=roll,
            foothold=foothold,
            touchdown=touchdown,
            swing=side.value,
        )

    def _land(self, side: Stance, foothold: tuple[float, float], _: float) -> None:
        support = self.support
        yaw = (support.left if support.stance is Stance.LEFT else support.right).yaw
        pose = FootPose(foothold[0], foothold[1], yaw)
        left, right = (pose, support.right) if side is Stance.LEFT else (support.left, pose)
        self.support = Support.from_params(self.params, side, left=left, right=right)
        self._swing, self.plan = None, None

    def _begin_hip(self, t: float, share: FloatArray) -> None:
        """Start the profile whose capture-point share is ``share`` (world frame) [m]."""
        yaw = self.support.yaw
        along = (
            math.cos(yaw) * float(share[0]) + math.sin(yaw) * float(share[1]),
            -math.sin(yaw) * float(share[0]) + math.cos(yaw) * float(share[1]),
        )
        fractions = tuple(
            max(-1.0, min(1.0, value / offset)) if offset > 0.0 else 0.0
            for value, offset in zip(along, self._offsets, strict=True)
        )
        self._hip = _HipManoeuvre(t, (fractions[0], fractions[1]), yaw)

    def _hip_remaining(self, t: float) -> tuple[float, float]:
        """Return the hip manoeuvre's remaining capture-point share h(t), world frame [m]."""
        if self._hip is None:
            return 0.0, 0.0
        omega, weight = self.params.omega, self.params.weight
        along = [
            fraction * torque / weight * _hip_share(t - self._hip.start, spin_up, omega)
            for fraction, torque, spin_up in zip(
                self._hip.fractions, self._torques, self._spin_up, strict=True
            )
        ]
        c, s = math.cos(self._hip.yaw), math.sin(self._hip.yaw)
        return c * along[0] - s * along[1], s * along[0] + c * along[1]

    def _hip_torques(self, t: float) -> tuple[float, float]:
        """Pitch and roll torques [N m]: the profile's mean over this tick (exact under ZOH)."""
        if self._hip is None:
            return 0.0, 0.0
        start = t - self._hip.start
        end = start + (self.control_period or 1e-3)
        pitch, roll = (
            fraction * torque * _profile_mean(start, end, spin_up)
            for fraction, torque, spin_up in zip(
                self._hip.fractions, self._torques, self._spin_up, strict=True
            )
        )
        return pitch, roll
