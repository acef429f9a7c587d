"""The biped's gait control: gains and timings, the swing path and the joint torque laws."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import BPoly

from pushrecovery.params import BodyParams
from pushrecovery.sim.mujoco.models import (
    ANKLE_HEIGHT,
)

FloatArray = NDArray[np.float64]

__all__ = ["BipedServos", "GaitState", "Phase"]

# --- control -----------------------------------------------------------------------------------
#: Stance knee held straight or locked during a swing [N m/rad, N m s/rad]; the damping makes
#: a locked bent leg (κ 0.3-0.8 rad) a critically damped radial spring under the body.
KNEE_LOCK_GAINS = (2000.0, 100.0)
#: Swing and trailing leg: thigh (absolute angle), knee, foot (absolute pitch) PD gains.
HIP_GAINS = (1500.0, 50.0)
KNEE_GAINS = (1000.0, 22.0)
FOOT_GAINS = (100.0, 3.0)
#: Height servo of the stance after a landing: ω_z = 60 rad/s, critically damped [1/s², 1/s].
HEIGHT_GAINS = (3600.0, 120.0)
#: Height of the swing sole above the floor until the leg nears its touchdown angle [m].
CLEARANCE = 0.03
#: How far ahead a leg in the air looks for the vertical it will swing through [s]: about
#: the knee's lag (2 / BEND_RATE) with a margin.
CLEARANCE_LEAD = 0.05
#: Angle before the touchdown angle over which the clearance is let go [rad].
CLEARANCE_ANGLE = 0.1
#: Knee bend of a straight-standing swing leg at touchdown [rad]: shortens it by 2.8 mm.
TOUCHDOWN_BEND = 0.15
#: The trailing leg hangs with its sole this much above the sole level [m].
HANG = 0.1
#: The swing sole must first rise this much before a contact counts as the landing [m].
ARM_HEIGHT = 0.002
#: Time the height servo takes to absorb a landing [s] (about 2/ω_z): the state reports the
#: measured ż, so the controller sees the stance after the impact, as in the analytic model.
IMPACT_TIME = 0.03
#: Bandwidth of the knee bend reference of a leg in the air [rad/s].
BEND_RATE = 80.0
#: Longest and shortest swing to the touchdown angle [s]; in between, ``SWING_SHARE`` of the
#: predicted time to the landing: the rest lets the leg settle (a longer swing lands it late, a
#: shorter one reacts harder on the torso).
SWING_TIME = (0.15, 0.04)
SWING_SHARE = 0.6
#: Foot tilt feedback [m]: the ankle torque drops by TILT_GAIN m g per radian of stance-foot
#: pitch, so a foot that starts to roll over an edge (where the CoP is pinned whatever the
#: torque) brings its CoP back inside instead of tipping over.
TILT_GAIN = 1.0
#: Foot pitch below which the tilt feedback is off [rad]: the soft contact alone pitches a
#: loaded foot by up to 3.5e-4 rad with the CoP at an edge.
TILT_DEADBAND = 1e-3
#: Largest hip torque on a leg in the air [N m].
FREE_HIP_MAX = 200.0
#: Time the trailing leg takes to hang under the hip [s].
TRAIL_TIME = 0.3

# qpos/qvel layout: x, z, pitch, then hip, knee, ankle of each leg (checked in __init__).
_X, _Z, _PITCH = 0, 1, 2


def _path(start: float, rate: float, goal: float, t: float, duration: float) -> tuple[float, float]:
    """Quintic from ``start`` at ``rate`` to rest at ``goal`` in ``duration``: value, rate at t.

    Zero acceleration at both ends (with ``rate`` = 0 the minimum-jerk path): scipy's
    Bernstein polynomial with those end derivatives, built once per plan.
    """
    if t >= duration:
        return goal, 0.0
    path, slope = _quintic(start, rate, goal, duration)
    return float(path(t)), float(slope(t))


@functools.lru_cache(maxsize=16)
def _quintic(start: float, rate: float, goal: float, duration: float) -> tuple[BPoly, BPoly]:
    path = BPoly.from_derivatives([0.0, duration], [[start, rate, 0.0], [goal, 0.0, 0.0]])
    return path, path.derivative()


class Phase(Enum):
    """Where the gait is (docs/biped.md): the control and the state differ by phase."""

    STANDING = "standing"  # both feet down, legs straight: the pendulum of the start
    SWING = "swing"  # a foot on its way to the touchdown, the stance leg locked
    IMPACT = "impact"  # landed; the height servo absorbs the impact (IMPACT_TIME)
    STANCE = "stance"  # one foot, the LIPM at the held height


@dataclass(slots=True)
class GaitState:
    """What the biped's phase machine remembers between physics steps.

    Attributes
    ----------
    stance : tuple of int
        Legs on the floor (both at the start, then one).
    lipm : bool
        Stance kind: straight-leg pendulum (standing) or the held height (after a landing).
    height, hip_height : float
        Reported CoM height in stance, and the hip height the servo holds [m].
    swing : (leg, direction ±1, touchdown angle [rad], touchdown length [m]) or None
        The step under way.
    armed : bool
        The swing sole has risen ``ARM_HEIGHT``: a contact now is a landing.
    anchor, lock : float
        World x of the stance ankle at the swing's start [m]; the stance knee angle locked
        during the swing [rad].
    at_stop : bool
        The torso is at its joint stop.
    ticks, impact_end : int
        Physics steps since the reset; the step at which the last landing's impact is over.
    plans : list
        Per leg in the air: its angle's path (from, at rate, to, start tick, duration [s]).
    hip_acc : (float, float)
        The hip's acceleration (a_x / g, 1 + a_z / g).
    bends : list
        Knee bend references of the legs in the air and their rates [rad, rad/s].
    """

    stance: tuple[int, ...] = (0, 1)
    lipm: bool = False
    height: float = 0.0
    hip_height: float = 0.0
    swing: tuple[int, float, float, float] | None = None
    armed: bool = False
    anchor: float = 0.0
    lock: float = 0.0
    at_stop: bool = False
    ticks: int = 0
    plans: list[tuple[float, float, float, int, float]] = field(
        default_factory=lambda: [(0.0, 0.0, 0.0, 0, 1.0), (0.0, 0.0, 0.0, 0, 1.0)]
    )
    hip_acc: tuple[float, float] = (0.0, 1.0)
    bends: list[tuple[float, float]] = field(default_factory=lambda: [(0.0, 0.0), (0.0, 0.0)])
    impact_end: int = 0

    @property
    def phase(self) -> Phase:
        """Return the phase the remembered state is in."""
        if self.swing is not None:
            return Phase.SWING
        if len(self.stance) == 2:
            return Phase.STANDING
        return Phase.IMPACT if self.ticks < self.impact_end else Phase.STANCE


class BipedServos:
    """The biped's torque laws: the stance foot, the knee lock, a leg in the air (docs/biped.md)."""

    # Set by the plant (plant.py).
    params: BodyParams
    model: Any
    data: Any
    _mj: Any
    _force: FloatArray
    _substep: float
    _length: float
    _segment: float
    _base_z: float
    _sole_ids: tuple[int, ...]
    _thigh_w: tuple[float, float]
    _shank_w: tuple[float, float]
    _foot_w: tuple[float, float, float]
    gait: GaitState

    def _sole_load(self, i: int) -> float:
        """Return the floor's normal force on leg i's sole in the last physics step [N]."""
        d, sole = self.data, self._sole_ids[i]
        total = 0.0
        for k, (g1, g2) in enumerate(d.contact.geom.tolist()):
            if sole in (g1, g2):
                self._mj.mj_contactForce(self.model, d, k, self._force)
                total += float(self._force[0])
        return total

    def _foot(self, q: list[float], i: int) -> float:
        """Ankle torque the stance foot i itself takes off the CoP map [N m].

        Its weight, ahead of the ankle, would shift the floor's CoP forward (0.3 mm for both
        feet of the preset standing). And a foot that starts to roll over an edge (its CoP
        pinned there whatever the torque) gets ``TILT_GAIN`` m g less torque per radian of
        pitch beyond ``TILT_DEADBAND``, which brings its CoP back inside.
        """
        k = 3 + 3 * i
        pitch = q[_PITCH] + q[k] + q[k + 1] + q[k + 2]
        weight, fx, fz = self._foot_w
        excess = pitch - max(-TILT_DEADBAND, min(TILT_DEADBAND, pitch))
        return weight * (fx * math.cos(pitch) + fz * math.sin(pitch)) + (
            TILT_GAIN * self.params.weight * excess
        )

    def _knee_lock(
        self, q: list[float], v: list[float], i: int, angle: float, load: float
    ) -> float:
        """Knee torque holding ``angle`` under ``load`` [N] along the ankle-to-hip segment."""
        k = 4 + 3 * i
        kp, kd = KNEE_LOCK_GAINS
        # A load along the segment flexes a bent knee with the lever (L/2) sin(κ/2).
        return -load * self._segment * math.sin(0.5 * q[k]) - kp * (q[k] - angle) - kd * v[k]

    def _free_leg(
        self,
        q: list[float],
        v: list[float],
        i: int,
        angle: float,
        angle_rate: float,
        longest: float,
        clearance: float,
        ctrl: list[float],
    ) -> None:
        """Torques of a leg in the air: segment angle to ``angle``, sole clear, foot flat.

        The ankle-to-hip segment is at most ``longest`` and short enough to keep the sole
        ``clearance`` above the floor; gravity and the hip's acceleration are fed forward.
        """
        k = 3 + 3 * i
        length, seg = self._length, self._segment
        a1 = q[_PITCH] + q[k]
        kappa = q[k + 1]
        a2 = a1 + kappa
        beta = a2 + q[k + 2]
        w1 = v[_PITCH] + v[k]
        # The steepest the segment gets within the knee's lag: a leg swinging through the
        # vertical must be short before it gets there, or its sole scuffs the floor.
        now = a1 + 0.5 * kappa
        ahead = now + (w1 + 0.5 * v[k + 1]) * CLEARANCE_LEAD
        cos = 1.0 if now * ahead <= 0.0 else max(math.cos(now), math.cos(ahead))
        wanted = longest
        if cos > 0.0:
            wanted = min(wanted, (self._base_z + q[_Z] - ANKLE_HEIGHT - clearance) / cos)
        wanted = max(0.5 * length, min(length, wanted))
        # The knee follows the bend the clearance asks for through a critically damped
        # filter: a jump (or a jump of its rate) would kick the thigh and, through the torso,
        # the stance leg.
        h, omega = self._substep, BEND_RATE
        bend, bend_rate = self.gait.bends[i]
        goal = 2.0 * math.acos(wanted / length)
        bend_rate += h * omega * (omega * (goal - bend) - 2.0 * bend_rate)
        bend += h * bend_rate
        self.gait.bends[i] = (bend, bend_rate)
        # Σ m (a_x r_z − (g + a_z) r_x) over the masses below each joint, r from the joint.
        ax, up = self.gait.hip_acc
        s1, c1, s2, c2 = math.sin(a1), math.cos(a1), math.sin(a2), math.cos(a2)
        sb, cb = math.sin(beta), math.cos(beta)
        (wt, ct), (ws, cs), (wf, fx, fz) = self._thigh_w, self._shank_w, self._foot_w
        foot_x, foot_z = fx * cb + fz * sb, fz * cb - fx * sb
        knee_x = ws * cs * s2 + wf * (seg * s2 - foot_x)
        knee_z = ws * cs * c2 + wf * (seg * c2 - foot_z)
        upper = wt * ct + (ws + wf) * seg
        hip_g = up * (knee_x + upper * s1) - ax * (knee_z + upper * c1)
        knee_g = up * knee_x - ax * knee_z
        foot_g = -wf * (up * foot_x + ax * foot_z)
        (hp, hd), (kp, kd), (fp, fd) = HIP_GAINS, KNEE_GAINS, FOOT_GAINS
        # Thigh at path − bend/2, knee at bend: the segment on its path, its length set. A leg
        # still on the floor shortens this way (the knee moves forward), as a straight leg
        # cannot be flexed from the knee alone.
        error = a1 - angle + 0.5 * bend
        hip = hip_g - hp * error - hd * (w1 - angle_rate + 0.5 * bend_rate)
        # Bounded: a leg caught on the floor must not spin the torso (its reaction).
        ctrl[k - 3] = max(-FREE_HIP_MAX, min(FREE_HIP_MAX, hip))
        ctrl[k - 2] = knee_g - kp * (kappa - bend) - kd * (v[k + 1] - bend_rate)
        ctrl[k - 1] = foot_g - fp * beta - fd * (w1 + v[k + 1] + v[k + 2])
