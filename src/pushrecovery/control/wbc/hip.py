"""The hip (CMP balancing) law of the whole-body controller: Stephens Sec. III as a feedback.

With F_z ≈ m g the CoM obeys the LIPM about the CMP p + δ, δ = (L̇_y, −L̇_x)/(m g) (L the
centroidal angular momentum, :func:`~.momentum.momentum_rows`). Per horizontal axis,
:class:`HipLaw` runs Stephens' bang-bang torque profile (Eqs. 8-12) as a switching feedback on
the measured state: *idle → push* when the library's decision (:meth:`HipLaw.decide`) says ξ
left the CoP region P inside the CMP region of
:func:`~pushrecovery.surfaces.plane.cmp_polygon`; *push → brake* when braking now still brings ξ
μ_ξ inside the edge, or the flywheel would overrun θmax; *brake → idle* when the momentum into
the fall is spent. Afterwards the torso returns upright, paced by the CoP's room
(:meth:`HipLaw.paced_return`), until within :data:`UPRIGHT`. docs/humanoid3d_wbc.md, "The hip
task", derives each switch and the paced return.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, positive_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll

FloatArray = NDArray[np.float64]

__all__ = ["BRAKE", "IDLE", "PUSH", "UPRIGHT", "HipLaw"]

#: Phases of an axis.
IDLE, PUSH, BRAKE = 0, 1, 2
#: Torso tilt [rad] (and spin [rad/s]) under which the return gains hand back to the usual.
UPRIGHT = 0.01
#: How far short of θmax the brake aims the flywheel's stop [rad] (the stop's estimate errs).
ANGLE_MARGIN = 0.03


class HipLaw:
    """Bang-bang CMP balancing per horizontal axis, as a switching feedback (module docstring).

    Parameters
    ----------
    params : BodyParams
        The flywheel's limits: τmax (``torque_max``, ``torque_max_roll``) [N m], I
        (``flywheel_inertia``, ``flywheel_inertia_roll``) [kg m²], θmax
        (``flywheel_angle_max``, ``flywheel_angle_max_roll``) [rad].
    support : ConvexPolygon
        The CoP region P (both soles' hull) [m], world xy.
    weight : float
        m g of the model [N] (> 0).
    omega : float
        ω = sqrt(g / z_c) [1/s] (> 0).
    period : float
        The control period Δt [s] (> 0).
    margin : float
        μ_ξ, how far inside the edge the brake aims ξ [m] (≥ 0).

    Raises
    ------
    InvalidParameterError
        If ``params`` is not a BodyParams or a number is out of range.
    """

    def __init__(
        self, params: BodyParams, support: ConvexPolygon, weight: float, omega: float,
        period: float, margin: float = 0.02,
    ) -> None:  # fmt: skip
        if not isinstance(params, BodyParams):
            raise InvalidParameterError(f"hip must be a BodyParams, got {type(params).__name__}")
        require_type("support", support, ConvexPolygon)
        for name, value, unit in (("weight", weight, "N"), ("omega", omega, "1/s"),
                                  ("period", period, "s")):  # fmt: skip
            if positive_float(name, value, unit) > 1e7:
                raise InvalidParameterError(f"{name} must be in (0, 1e7] {unit}, got {value!r}")
        margin = bounded_float("margin", margin, 0.0, 1.0, "m")
        self.torque = np.array([params.torque_max, params.torque_max_roll])
        self.inertia = np.array([params.flywheel_inertia, params.flywheel_inertia_roll])
        self.angle_max = np.array([params.flywheel_angle_max, params.flywheel_angle_max_roll])
        self.weight, self.omega, self.period = float(weight), float(omega), float(period)
        self.margin = float(margin)
        self.reach = self.torque / self.weight  # a = τmax / (m g) [m]
        self.support = support
        self.cmp_region = support.grown(cmp_offset(params), cmp_offset_roll(params), 0.0)
        self.low = np.array([support.xmin, support.ymin])
        self.high = np.array([support.xmax, support.ymax])
        self.phase = np.full(2, IDLE)
        self.side = np.zeros(2)
        self.decision = "ankle"

    def reset(self) -> None:
        """Both axes idle."""
        self.phase[:] = IDLE
        self.side[:] = 0.0
        self.decision = "ankle"

    @property
    def active(self) -> bool:
        """Whether an axis pushes or brakes."""
        return bool((self.phase != IDLE).any())

    def decide(self, xi: FloatArray) -> str:
        """Return the library's decision for capture point ``xi`` [m]: ankle, hip or step.

        "ankle": ξ inside the CoP region P (Eq. 4); "hip": outside P, inside the CMP region
        P ⊕ box(a'_x, a'_y) (corrected Eq. 15, :func:`~pushrecovery.surfaces.plane.cmp_polygon`);
        "step": beyond both.
        """
        x, y = float(xi[0]), float(xi[1])  # the scalar signed distance: strictly inside
        if self.support.point_signed_distance(x, y) > 0.0:
            return "ankle"
        if self.cmp_region.point_signed_distance(x, y) > 0.0:
            return "hip"
        return "step"

    def saturate(self, cop: FloatArray) -> FloatArray:
        """Return ``cop`` [m] with each acting axis's CoP on the edge δ⁺ (the ankle saturated).

        Stephens' bang-bang assumes the CoP stays on the edge while the flywheel acts; the
        DCM law would pull it back inside as soon as ξ re-enters P, slowing the capture.
        """
        out = np.array(cop, dtype=float)
        for k in range(2):
            if self.phase[k] != IDLE:
                out[k] = self.high[k] if self.side[k] > 0 else self.low[k]
        return out

    def update(
        self, xi: FloatArray, momentum: FloatArray, tilt: FloatArray, spin: FloatArray | None = None
    ) -> FloatArray:
        """Advance each axis's phase and return the CMP offset δ = (δ_x, δ_y) [m].

        Parameters
        ----------
        xi : float array, shape (2,)
            The capture point [m] (world xy).
        momentum : float array, shape (2,)
            (L_y, −L_x): the centroidal angular momentum about the axis that moves the CMP
            along x, then y [N m s].
        tilt : float array, shape (2,)
            The upper body's pitch and −roll since reset [rad] (the same signs).
        spin : float array, shape (2,), optional
            The upper body's (ω_y, −ω_x) [rad/s]; None: the flywheel's h/I alone.
        """
        self.decision = self.decide(xi)
        rate, offset = spin, np.zeros(2)
        for k in range(2):
            if self.phase[k] == IDLE and self.decision != "ankle":
                if xi[k] > self.high[k]:
                    self.phase[k], self.side[k] = PUSH, 1.0
                elif xi[k] < self.low[k]:
                    self.phase[k], self.side[k] = PUSH, -1.0
            if self.phase[k] == IDLE:
                continue
            side = self.side[k]
            spin = side * float(momentum[k])  # h
            torque, reach = float(self.torque[k]), float(self.reach[k])
            if self.phase[k] == PUSH:
                edge = self.high[k] if side > 0 else self.low[k]
                inside = side * (float(xi[k]) - edge)
                braking = max(spin, 0.0) / torque
                stop = side * float(tilt[k])
                turn = max(spin, 0.0) ** 2 / (2.0 * self.inertia[k] * torque)
                if rate is not None:  # the measured spin over the braking time
                    turn = max(turn, max(side * float(rate[k]), 0.0) * 0.5 * braking)
                stop += turn
                aim = -reach * (1.0 - math.exp(-self.omega * braking)) - self.margin
                if inside <= aim or stop >= self.angle_max[k] - ANGLE_MARGIN:
                    self.phase[k] = BRAKE
                else:
                    offset[k] = side * reach
            if self.phase[k] == BRAKE:
                if spin <= 0.0:
                    self.phase[k] = IDLE
                else:
                    offset[k] = -side * min(torque, spin / self.period) / self.weight
        return offset

    def paced_return(
        self, target: FloatArray, accel: FloatArray, margin: float = 0.01
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Return the return's CMP offset δ, CoP target and torso α (module docstring).

        Parameters
        ----------
        target : float array, shape (2,)
            r, the DCM law's CMP (the unclipped p_des) [m], world xy.
        accel : float array, shape (2,)
            The return law's torso angular acceleration (α_x, α_y) [rad/s²], world.
        margin : float
            μ_p, how far inside the support's box the CoP stays [m].

        Returns
        -------
        offset, cop, accel : float arrays, shape (2,)
            δ [m], the CoP r − δ on the support polygon [m], and (α_x, α_y) after the clip.
        """
        inertia_x, inertia_y = float(self.inertia[0]), float(self.inertia[1])
        wanted = np.array([inertia_x * accel[1], -inertia_y * accel[0]]) / self.weight
        low = target - (self.high - margin)
        high = target - (self.low + margin)
        offset = np.clip(wanted, low, high)
        offset = np.clip(offset, np.minimum(wanted, 0.0), np.maximum(wanted, 0.0))
        cop_x, cop_y = (target - offset).tolist()
        if not self.support.point_signed_distance(cop_x, cop_y) > 0.0:
            cop_x, cop_y = self.support.nearest_point(cop_x, cop_y)
        paced = self.weight * np.array([-offset[1] / inertia_y, offset[0] / inertia_x])
        return offset, np.array([cop_x, cop_y]), paced
