"""Kinematics of the planar biped: leg segments, the whole-body CoM and its rate, sole heights."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.biped.control import _PITCH, _X, _Z
from pushrecovery.sim.mujoco.models import (
    FOOT_HALF_THICKNESS,
)

FloatArray = NDArray[np.float64]

__all__ = ["BipedKinematics"]


class BipedKinematics:
    """The biped's planar kinematics from its joints (tested against MuJoCo's ``subtree_com``)."""

    # Set by the plant (plant.py).
    params: BodyParams
    _length: float
    _segment: float
    _base_z: float
    _fractions: tuple[float, float, float]
    _torso: tuple[float, float]
    _thigh_w: tuple[float, float]
    _shank_w: tuple[float, float]
    _foot_w: tuple[float, float, float]

    # --- kinematics ----------------------------------------------------------------------
    def _leg(self, q: list[float], i: int) -> tuple[float, float, float]:
        """Ankle-to-hip segment of leg i: absolute angle (lean) [rad], length [m], knee [rad].

        Thigh = shank = L/2, so the segment bisects the knee: angle = thigh + κ/2, length =
        L cos(κ/2).
        """
        k = 3 + 3 * i
        kappa = q[k + 1]
        return q[_PITCH] + q[k] + 0.5 * kappa, self._length * math.cos(0.5 * kappa), kappa

    def _leg_rate(self, v: list[float], i: int) -> float:
        """Rate of the ankle-to-hip segment angle of leg i [rad/s]."""
        k = 3 + 3 * i
        return v[_PITCH] + v[k] + 0.5 * v[k + 1]

    def _com_offset(self, q: list[float], v: list[float]) -> tuple[float, float, float, float]:
        """Whole-body CoM minus the hip, and its rate (world x, z) [m, m/s]."""
        (ft, fs, ff), seg = self._fractions, self._segment
        ct, cs = self._thigh_w[1], self._shank_w[1]
        _, fx, fz = self._foot_w
        # The torso's CoM, c above the hip along its pitch (0 when leg_length = com_height).
        fu, c = self._torso
        sp, cp, wp = math.sin(q[_PITCH]), math.cos(q[_PITCH]), v[_PITCH]
        dx, dz = fu * c * sp, fu * c * cp
        dvx, dvz = fu * c * cp * wp, -fu * c * sp * wp
        for k in (3, 6):
            a1 = q[_PITCH] + q[k]
            a2 = a1 + q[k + 1]
            b = a2 + q[k + 2]
            w1 = v[_PITCH] + v[k]
            w2 = w1 + v[k + 1]
            wb = w2 + v[k + 2]
            s1, c1, s2, c2 = math.sin(a1), math.cos(a1), math.sin(a2), math.cos(a2)
            sb, cb = math.sin(b), math.cos(b)
            # Thigh CoM at ct, shank CoM at seg + cs, foot CoM at (fx, fz) in the foot frame.
            u = ft * ct + (fs + ff) * seg
            w = fs * cs + ff * seg
            dx += -u * s1 - w * s2 + ff * (fx * cb + fz * sb)
            dz += -u * c1 - w * c2 + ff * (fz * cb - fx * sb)
            dvx += -u * c1 * w1 - w * c2 * w2 + ff * (fz * cb - fx * sb) * wb
            dvz += u * s1 * w1 + w * s2 * w2 - ff * (fx * cb + fz * sb) * wb
        return dx, dz, dvx, dvz

    def _com(self, q: list[float], v: list[float], i: int) -> tuple[float, float, float, float]:
        """CoM relative to the ankle of leg i, and its velocity (the ankle at rest)."""
        alpha, length, _ = self._leg(q, i)
        dx, dz, dvx, dvz = self._com_offset(q, v)
        return (
            length * math.sin(alpha) + dx,
            length * math.cos(alpha) + dz,
            v[_X] + dvx,
            v[_Z] + dvz,
        )

    def _sole_height(self, q: list[float], i: int) -> float:
        """Height of the lowest corner of leg i's sole above the floor [m]."""
        k = 3 + 3 * i
        a1 = q[_PITCH] + q[k]
        a2 = a1 + q[k + 1]
        sb = math.sin(a2 + q[k + 2])
        ankle = self._base_z + q[_Z] - self._segment * (math.cos(a1) + math.cos(a2))
        lowest = max(self.params.heel * sb, self.params.toe * sb)
        return ankle - 2.0 * FOOT_HALF_THICKNESS * math.sqrt(1.0 - sb * sb) - lowest
