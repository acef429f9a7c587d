"""Planar biped that steps, in MuJoCo (model ``biped``): the stepping model of Sec. IV.

Model
-----
A floating pelvis/torso (slide x, slide z, pitch about the hip) carries two legs, each a hip
hinge, a thigh, a knee hinge, a shank, an ankle hinge and a foot box spanning [heel, toe]
around the ankle, the ankle ``ANKLE_HEIGHT`` above the sole (the feet of the other models).
Mapping to the paper:

- **m** = ``params.mass`` in total: the torso m − 2 m_leg, each leg m_leg = ``LEG_MASS`` (thigh
  0.5 kg, shank 0.3 kg, foot 0.2 kg: both legs 2.8 % of the preset's 72 kg; the paper's legs
  are massless).
- **L** = ``params.com_height`` = ``params.leg_length`` is the hip's height above the ankle with
  the leg straight: thigh = shank = L/2. The legs hang below the hip, so the whole-body CoM
  stands 0.985 L above the ankles (preset).
- **I** = ``params.flywheel_inertia`` is the torso's inertia about its centre of mass, which is
  *at the hip*: turning the torso does not move the CoM (the flywheel of Sec. III). The limit
  |θ| ≤ θmax acts on the torso's absolute pitch (a limit of the floating base's hinge), as the
  flywheel angle of :class:`~pushrecovery.sim.plants.SteppingPlant`.
- The legs touch the floor only, not each other: they are drawn at y = ±0.1 m but move in the
  same plane. The knee flexes one way (range [0, ``KNEE_MAX``], 0 straight). Six torque motors.

State
-----
``[x, theta, z, xdot, theta_dot, zdot]`` as the analytic stepping model: the whole-body CoM
relative to the current stance ankle (joint kinematics; the stance ankle is at rest, so its
velocities are the CoM's), the torso's absolute pitch and rate, and in stance the CoM height
the stance holds (measured at its start) with ż = 0. During a swing, and during the
``IMPACT_TIME`` after a landing in which the stance leg absorbs the impact (the analytic impact
is instantaneous), z and ż are measured. Each step's ``StepInfo`` says which: ``stance`` is
True only in the held stance (how the recovery controller learns a landing), and
``footholds`` lists the world x of every stance ankle.

Control: commands → joint torques, every 1 ms physics step
---------------------------------------------------------
- **Standing** (the start): both feet side by side, legs straight: one support polygon. The
  CoP command becomes the exact pendulum ankle torque (:func:`ankle_torque_for_cop`, errata
  E3, the CoM as the pendulum's mass), split over both ankles; the flywheel torque (clipped to
  τmax) is the hips' reaction on the torso, split over both hips; the knees are held straight
  by a stiff PD against their stop.
- **Swing** (a command with ``step_length`` d): as in the paper the stance ankle is passive and
  the stance leg keeps its length l (knee PD, critically damped for a bent knee, plus the
  pendulum's load fed forward): the CoM falls as Hofmann's pendulum. A swing foot still on the
  floor first lifts (a loaded leg cannot swing); then the leg's ankle-to-hip angle follows a
  quintic from its current angle and rate to rest at its touchdown angle, in 60 % of the
  predicted time to the landing, the knee bent only as much as keeps the sole ``CLEARANCE``
  above the floor until the last ``CLEARANCE_ANGLE``, the foot flat (gravity and the hip's
  acceleration fed forward). There the leg is held at length l (at most L with the knee bent
  ``TOUCHDOWN_BEND``: a straight knee could not yield at the impact), at the angle that closes
  the triangle stance leg, swing leg, floor = |d|: the sole meets the floor, by geometry, when
  the stance lean reaches the landing angle, asin(|d|/2l) when both legs have length l (all
  steps but the first from straight legs, where it is about 4 mrad later). The swing hip's
  reaction goes to the torso, which the controller brakes (it is what the flywheel is for): the
  stance pendulum feels the flywheel command only, as with the paper's massless swing leg.
  That brake needs a stance foot on the floor: one that is off it (no normal force in the last
  physics step) would only swing the light leg and kick the foot back, so its hip holds the leg
  over the stance ankle's place at the swing's start instead, where the foot lands again. The
  foot leaves the floor after a hard push from a CoM ahead of the ankle: the 10 ms push's
  component along the leaning legs, m v / 10 ms · sin α, lifts the body (about the weight at
  2 m/s from x0 = 0.05 m): with the brake on the airborne leg, such pushes used to fall before
  the step. It also leaves the floor for moments when the pendulum's load is small (fast
  pushes).
- **Landing**: the first contact of the swing sole that carries a normal force (its lowest
  corner below the floor, where MuJoCo's contact starts, margin 0, and a force in the last
  physics step) after it has lifted ``ARM_HEIGHT``. A corner that only grazes the floor, or a
  contact whose force builds a step later, is no landing yet: the stance torques below on a
  foot still in the air tipped it heel or toe first, bounced it off and the body fell. From
  then on the state is relative to the new ankle and ``footholds`` has the new ankle's world x.
- **Stance after a landing**: the paper's LIPM at the landing height (Eq. 20), held by a height
  servo on the hip, the forces mapped to joint torques with the statics of a massless leg:
  a floor force F at the CoP δ with F_z = m (g + k_p Δz − k_d ż) and F_x from the moments about
  the hip, so that the hip torque on the torso is the flywheel command; the ankle torque is the
  LIPM's τ = δ m g + h F_x. The servo makes the impact about that of Eqs. (18)-(20): it
  removes the vertical velocity with a force along the new leg, over about 1/ω_z = 17 ms (a
  locked leg would also remove the velocity along it, which the LIPM keeps). Measured after the
  impact, the capture point is within 1 cm of Eq. (20)'s for pushes of 1 and 2 m/s and
  −0.8 m/s; a hard backward landing (−2 m/s) loses more speed (3 cm).
- **Trailing leg**: lifted at the landing (single support, as in the paper) and hung under the
  hip, its sole ``HANG`` above the floor; it is the next swing leg, so the legs alternate.
- **Feet**: the ankle torque also carries the foot's own weight (its CoM is ahead of the ankle),
  and a stance foot that starts to roll over an edge (its CoP pinned there, whatever the ankle
  torque) gets ``TILT_GAIN`` m g less ankle torque per radian of pitch beyond
  ``TILT_DEADBAND``, which brings the CoP back inside; without it the 1-2 % errors of the
  servo's load on a CoP commanded 2 mm inside the toe tip the foot during the hip strategy.

Falls: the base class's (anything but a sole touching the floor, the CoM below half height, a
stance foot tipped beyond ``FOOT_TIP_LIMIT``) and, during a swing, a CoM whose lean rate turns
back from the step: that foot can never land.
"""

from __future__ import annotations

import functools
import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import BPoly

from pushrecovery.control.base import Command, StepInfo
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.pendulum import ankle_torque_for_cop
from pushrecovery.models.stepping import STEPPING_STATE
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import check_com_state
from pushrecovery.sim.mujoco.models import (
    ANKLE_HEIGHT,
    FOOT_HALF_THICKNESS,
    FOOT_MASS,
    add_motor,
    add_upper_body,
    model_spec,
)
from pushrecovery.sim.mujoco.plant import DEFAULT_COP_MARGIN, FOOT_TIP_LIMIT, MujocoPlant

__all__ = ["LEG_MASS", "MujocoBipedPlant", "biped_model"]

FloatArray = NDArray[np.float64]

# --- model -------------------------------------------------------------------------------------
#: Thigh and shank masses [kg]; with the foot's, one leg's.
THIGH_MASS = 0.5
SHANK_MASS = 0.3
#: Mass of one leg [kg].
LEG_MASS = THIGH_MASS + SHANK_MASS + FOOT_MASS
#: Leg names, in the order of the joints and motors.
LEGS = ("left", "right")
#: Half the distance between the legs, drawn only [m].
HIP_SPREAD = 0.1
THIGH_RADIUS = 0.03
SHANK_RADIUS = 0.025
#: Knee range [rad]: 0 straight (the stop), positive flexion (the shank swings back).
KNEE_MAX = 2.5
#: Reflected rotor inertia of knee and ankle [kg m²]: keeps the 1 ms explicit PD stable on the
#: light shank and foot; 1e-4 of m L² and 1e-3 of it, too small to change the balance.
KNEE_ARMATURE = 0.05
ANKLE_ARMATURE = 0.01

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


def biped_model(params: BodyParams) -> Any:
    """Return the ``MjSpec`` of the planar ``biped`` for ``params`` (module docstring).

    Raises
    ------
    InvalidParameterError
        If ``leg_length != com_height`` (the straight legs carry the hip at the CoM height L)
        or the mass does not exceed the legs'.
    """
    import mujoco

    if params.leg_length != params.com_height:
        raise InvalidParameterError(
            "the biped's straight legs carry the hip at the CoM height: leg_length must equal "
            f"com_height, got {params.leg_length:g} m and {params.com_height:g} m"
        )
    torso_mass = params.mass - 2.0 * LEG_MASS
    if torso_mass <= 0.0:
        raise InvalidParameterError(
            f"mass must exceed the legs' {2.0 * LEG_MASS:g} kg, got {params.mass:g} kg"
        )
    hinge, capsule = mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtGeom.mjGEOM_CAPSULE
    y_axis, leg_colour = [0.0, 1.0, 0.0], [0.4, 0.5, 0.8, 1.0]
    length = params.com_height
    segment = 0.5 * length
    limit = params.flywheel_angle_max
    spec = model_spec("biped", params)
    torso = add_upper_body(spec.worldbody, params, torso_mass, [0.0, 0.0, length + ANKLE_HEIGHT])
    torso.add_joint(name="x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1.0, 0.0, 0.0])
    torso.add_joint(name="z", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 0.0, 1.0])
    torso.add_joint(
        name="pitch",
        type=hinge,
        axis=y_axis,
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        range=[-limit, limit],
    )
    # The joints come before the body's geoms in the compiled model whatever the order here.
    # The shank's capsule ends 1.5 cm above the ankle, so that only the sole reaches the floor.
    shank_end = segment - SHANK_RADIUS - 0.015
    # contype 2 / conaffinity 1: every body geom touches the floor (1/1), none touches another.
    for name, y in zip(LEGS, (HIP_SPREAD, -HIP_SPREAD), strict=True):
        thigh = torso.add_body(name=f"{name}_thigh", pos=[0.0, y, 0.0])
        thigh.add_joint(name=f"{name}_hip", type=hinge, axis=y_axis)
        thigh.add_geom(
            name=f"{name}_thigh", type=capsule, fromto=[0.0, 0.0, 0.0, 0.0, 0.0, -segment],
            size=[THIGH_RADIUS, 0.0, 0.0], mass=THIGH_MASS, contype=2, conaffinity=1,
            rgba=leg_colour,
        )  # fmt: skip
        shank = thigh.add_body(name=f"{name}_shank", pos=[0.0, 0.0, -segment])
        shank.add_joint(
            name=f"{name}_knee", type=hinge, axis=y_axis, range=[0.0, KNEE_MAX],
            solref_limit=[0.005, 1.0], armature=KNEE_ARMATURE,
        )  # fmt: skip
        shank.add_geom(
            name=f"{name}_shank", type=capsule, fromto=[0.0, 0.0, 0.0, 0.0, 0.0, -shank_end],
            size=[SHANK_RADIUS, 0.0, 0.0], mass=SHANK_MASS, contype=2, conaffinity=1,
            rgba=leg_colour,
        )  # fmt: skip
        foot = shank.add_body(name=f"{name}_foot", pos=[0.0, 0.0, -segment])
        foot.add_joint(name=f"{name}_ankle", type=hinge, axis=y_axis, armature=ANKLE_ARMATURE)
        foot.add_geom(
            name=f"{name}_sole", type=mujoco.mjtGeom.mjGEOM_BOX,
            pos=[0.5 * (params.toe + params.heel), 0.0, -FOOT_HALF_THICKNESS],
            size=[0.5 * (params.toe - params.heel), 0.05, FOOT_HALF_THICKNESS],
            mass=FOOT_MASS, contype=2, conaffinity=1, rgba=[0.3, 0.3, 0.3, 1.0],
        )  # fmt: skip
    for name in LEGS:
        for joint in ("hip", "knee", "ankle"):
            add_motor(spec, f"{name}_{joint}")
    return spec


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


class MujocoBipedPlant(MujocoPlant):
    """Planar biped in MuJoCo (model ``biped``), the physical twin of ``SteppingPlant``.

    Same state, commands, ``footholds`` and ``fall_limits`` as
    :class:`~pushrecovery.sim.plants.SteppingPlant`; the module docstring describes the model
    and how commands become joint torques. A push can be a velocity (:meth:`reset`) or
    a force (:meth:`schedule_push`, on the torso at the hip).
    """

    name: ClassVar[str] = "mujoco-biped"
    state_labels: ClassVar[tuple[str, ...]] = STEPPING_STATE
    model_name: ClassVar[str] = "biped"
    pushed_body: ClassVar[str] = "torso"

    @classmethod
    def build(cls, params: BodyParams) -> Any:
        """Return the model's ``MjSpec`` for ``params`` (:func:`biped_model`)."""
        return biped_model(params)

    def __init__(self, params: BodyParams, cop_margin: float = DEFAULT_COP_MARGIN) -> None:
        super().__init__(params, cop_margin)
        model = self.model
        joints = ["x", "z", "pitch"] + [f"{n}_{j}" for n in LEGS for j in ("hip", "knee", "ankle")]
        for i, joint in enumerate(joints):
            if model.joint(joint).qposadr[0] != i or model.joint(joint).dofadr[0] != i:
                # The generated model and this plant disagree: a bug here, not bad input.
                raise RuntimeError(f"the biped model's joint {joint!r} is not at index {i}")
        # As SteppingPlant: beyond δ± ± τmax/(m g) no CMP stops an outgoing CoM.
        self.fall_limits = params.hip_fall_limits
        self.footholds: list[float] = [0.0]
        self._length = params.com_height
        self._segment = 0.5 * params.com_height
        self._base_z = params.com_height + ANKLE_HEIGHT  # hip above the floor at qpos z = 0
        # Mass distribution of a leg: weight [N] and CoM offsets in the segment frames [m].
        g, total = params.gravity, params.mass
        thigh, shank, foot = (model.body(f"{LEGS[0]}_{b}") for b in ("thigh", "shank", "foot"))
        self._thigh_w = (g * float(thigh.mass[0]), -float(thigh.ipos[2]))
        self._shank_w = (g * float(shank.mass[0]), -float(shank.ipos[2]))
        self._foot_w = (g * float(foot.mass[0]), float(foot.ipos[0]), float(foot.ipos[2]))
        # Mass fractions, for the CoM: thigh, shank and foot of one leg.
        self._fractions = (
            float(thigh.mass[0]) / total,
            float(shank.mass[0]) / total,
            float(foot.mass[0]) / total,
        )
        self._sole_ids = tuple(model.geom(f"{leg}_sole").id for leg in LEGS)
        self._reset_phase()

    def _reset_phase(self) -> None:
        """Standing on both feet, nothing in the air."""
        self._stance: tuple[int, ...] = (0, 1)
        self._lipm = False  # stance kind: straight-leg pendulum (standing) or held height
        self._height = 0.0  # reported CoM height in stance [m] (set by initial_state)
        self._hip_height = 0.0  # hip height the servo holds after a landing [m]
        # Swing: leg, direction ±1, touchdown angle [rad], touchdown length [m].
        self._swing: tuple[int, float, float, float] | None = None
        self._armed = False
        self._anchor = 0.0  # world x of the stance ankle when the swing started [m]
        self._lock = 0.0  # stance knee angle locked during the swing [rad]
        self._at_stop = False
        self._ticks = 0  # physics steps since the reset
        # Per leg in the air: path of its angle (from, at rate, to, start tick, duration [s]).
        self._plans = [(0.0, 0.0, 0.0, 0, 1.0), (0.0, 0.0, 0.0, 0, 1.0)]
        self._hip_acc = (0.0, 1.0)  # hip acceleration (a_x / g, 1 + a_z / g)
        # Knee bend references of the legs in the air and their rates [rad, rad/s].
        self._bends = [(0.0, 0.0), (0.0, 0.0)]
        self._impact_end = 0  # tick at which the impact of the last landing is over
        self.footholds = [0.0]

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
        dx = dz = dvx = dvz = 0.0
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

    # --- state ---------------------------------------------------------------------------
    def read_state(self) -> FloatArray:
        """``[x, theta, z, xdot, theta_dot, zdot]`` (module docstring) [m, rad, m/s, rad/s]."""
        q, v = self._qpos.tolist(), self._qvel.tolist()
        if self._swing is not None:
            self._check_landing(q, v)
        x, z, xdot, zdot = self._com(q, v, self._stance[0])
        if self._swing is None and self._ticks >= self._impact_end:
            z, zdot = self._height, 0.0  # the height the stance holds (info().stance)
        return np.array([x, q[_PITCH], z, xdot, v[_PITCH], zdot])

    def ankle_x(self) -> float:
        """World x of the stance ankle (of the first foot when standing on both) [m]."""
        q = self._qpos.tolist()
        alpha, length, _ = self._leg(q, self._stance[0])
        return float(q[_X] - length * math.sin(alpha))

    def pose(self, x: float, xdot: float) -> None:
        """Lean the straight legs about the ankles so the CoM is at x, moving at ẋ.

        The feet stay as they settled and the torso upright and at rest.
        """
        q, qd = self._qpos, self._qvel
        qs = q.tolist()
        alpha, length, _ = self._leg(qs, 0)
        ankle_x = qs[_X] - length * math.sin(alpha)
        ankle_z = self._base_z + qs[_Z] - length * math.cos(alpha)
        feet = [qs[_PITCH] + qs[k] + qs[k + 1] + qs[k + 2] for k in (3, 6)]
        big = self._length

        def lean_to(lean: float) -> list[float]:
            conf = [0.0] * len(qs)
            for k, foot in zip((3, 6), feet, strict=True):
                conf[k], conf[k + 2] = lean, foot - lean
            return conf

        # The legs' mass moves the CoM with the lean: solve x = L sin(lean) + offset(lean).
        zero = [0.0] * len(qs)
        lean = 0.0
        for _ in range(5):
            offset = self._com_offset(lean_to(lean), zero)[0]
            lean = math.asin(max(-0.99, min(0.99, (x - offset) / big)))
        conf = lean_to(lean)
        conf[_X] = ankle_x + big * math.sin(lean)
        conf[_Z] = ankle_z + big * math.cos(lean) - self._base_z
        # Joint rates of a unit lean rate: the hip on its circle, the feet at rest.
        unit = [0.0] * len(qs)
        unit[_X], unit[_Z] = big * math.cos(lean), -big * math.sin(lean)
        unit[3] = unit[6] = 1.0
        unit[5] = unit[8] = -1.0
        rate = xdot / (unit[_X] + self._com_offset(conf, unit)[2])
        q[:] = conf
        qd[:] = [rate * u for u in unit]

    def reset(self, x: float, xdot: float) -> FloatArray:
        """Stand on both feet, legs straight, the CoM at x moving at ẋ, torso upright.

        As the other MuJoCo plants, the body first settles upright for ``SETTLE_TIME``;
        ``z`` is then the standing CoM height, held for the first stance.
        """
        self._reset_phase()
        self._height = self._standing_height()
        return super().reset(x, xdot)

    def _restart_records(self) -> None:
        super()._restart_records()
        self.footholds = [self.ankle_x()]

    def info(self) -> StepInfo:
        """Stance once a landing's impact is over and no foot swings (contract item 5)."""
        measured = self.measured_cops[-1] if self._measuring and self.measured_cops else None
        stance = self._swing is None and self._ticks >= self._impact_end
        return StepInfo(stance, tuple(self.footholds), self.stop_impacts, measured)

    def _standing_height(self) -> float:
        """CoM height above the ankles standing straight and upright [m]."""
        q = [0.0] * self.model.nq
        return self._length + self._com_offset(q, q)[1]

    def check_state(self, state: FloatArray) -> None:
        """Require ``[x, theta, z, xdot, theta_dot, zdot]`` in stance."""
        if state.shape != (6,):
            raise InvalidParameterError(
                f"state must be [x, theta, z, xdot, theta_dot, zdot], got shape {state.shape}"
            )
        if not (float(state[2]) > 0.0 and float(state[5]) == 0.0):
            raise InvalidParameterError("the biped starts in stance: z > 0, zdot = 0")
        check_com_state(float(state[0]), float(state[3]), self.params)

    def foot_tipped(self) -> bool:
        """Tell whether a stance foot's pitch is beyond ``FOOT_TIP_LIMIT``."""
        q = self._qpos.tolist()
        return any(
            abs(q[_PITCH] + q[3 + 3 * i] + q[4 + 3 * i] + q[5 + 3 * i]) > FOOT_TIP_LIMIT
            for i in self._stance
        )

    def falling(self, state: FloatArray) -> bool:
        """Tell a fall: the base class's, or a swing whose CoM turns back (it cannot land)."""
        if self._swing is not None:
            x, z, xdot, zdot = (float(state[i]) for i in (0, 2, 3, 5))
            if self._swing[1] * (xdot * z - zdot * x) <= 0.0:
                return True
        return super().falling(state)

    # --- phases --------------------------------------------------------------------------
    def _start_swing(self, q: list[float], v: list[float], step: float) -> None:
        """Lock the stance leg and plan the swing of the other one for a step of ``step`` [m]."""
        stance, swing = (0, 1) if len(self._stance) == 2 else (self._stance[0], 1 - self._stance[0])
        self._stance = (stance,)
        lean, length, kappa = self._leg(q, stance)
        sign = 1.0 if step > 0.0 else -1.0
        reach = min(length, self._length * math.cos(0.5 * TOUCHDOWN_BEND))
        d = min(abs(step), 0.99 * (length + reach))
        # Triangle stance leg, swing leg, floor = d: the hip is `along` from the stance ankle.
        along = (length * length - reach * reach + d * d) / (2.0 * d)
        target = -sign * math.asin(max(-1.0, min(1.0, (d - along) / reach)))
        landing = math.asin(max(-1.0, min(1.0, along / length)))  # lean at touchdown, unsigned
        self._swing = (swing, sign, target, reach)
        self._lock = kappa
        self._armed = self._sole_height(q, swing) > ARM_HEIGHT
        self._anchor = q[_X] - length * math.sin(lean)
        # The pendulum's time to the landing lean, from its energy (trapezoid on the rate).
        x, z = length * math.sin(lean), length * math.cos(lean)
        rate = sign * (v[_X] * z - v[_Z] * x) / (length * length)
        lean *= sign
        drop = math.cos(lean) - math.cos(landing)
        final = rate * rate + 2.0 * self.params.gravity / length * drop
        time = 2.0 * max(0.0, landing - lean) / max(1e-6, rate + math.sqrt(max(0.0, final)))
        longest, shortest = SWING_TIME
        duration = min(longest, max(shortest, SWING_SHARE * time))
        now = (self._leg(q, swing)[0], self._leg_rate(v, swing))
        self._plans[swing] = (*now, target, self._ticks, duration)
        self._bends[swing] = (q[4 + 3 * swing], v[4 + 3 * swing])

    def _check_landing(self, q: list[float], v: list[float]) -> None:
        """Land when the swing sole reaches the floor after it has lifted."""
        assert self._swing is not None
        leg = self._swing[0]
        height = self._sole_height(q, leg)
        if not self._armed:
            self._armed = height > ARM_HEIGHT
            return
        if height > 0.0:
            return
        if self._sole_load(leg) <= 0.0:
            # Not yet pressed on the floor (or grazing it on the way up): the stance torques
            # would act on a leg in the air, tip the foot heel or toe first and bounce it.
            return
        old = self._stance[0]
        rate = self._leg_rate(v, old)
        self._plans[old] = (self._leg(q, old)[0], rate, 0.0, self._ticks, TRAIL_TIME)
        self._bends[old] = (q[4 + 3 * old], 0.0)
        self._stance = (leg,)
        self._swing = None
        self._lipm = True
        alpha, length, _ = self._leg(q, leg)
        self.footholds.append(float(q[_X] - length * math.sin(alpha)))
        self._hip_height = length * math.cos(alpha)
        self._height = self._hip_height + self._com_offset(q, [0.0] * len(q))[1]
        self._impact_end = self._ticks + round(IMPACT_TIME / self._substep)

    # --- control -------------------------------------------------------------------------
    def actuate(self, cop: float, command: Command) -> float:
        """Joint torques for this physics step (module docstring); return the hip torque.

        The returned torque is the flywheel command clipped to ±τmax, the torque on the torso.
        """
        q, v = self._qpos.tolist(), self._qvel.tolist()
        p = self.params
        fly = p.clip_hip_torque(command.flywheel_torque)
        if self._swing is None and command.step_length is not None:
            self._start_swing(q, v, command.step_length)
        elif self._swing is not None:
            self._check_landing(q, v)
        self._ticks += 1
        ctrl = [0.0] * 6
        stance = self._stance
        alpha, length, kappa = self._leg(q, stance[0])
        sin, cos = math.sin(alpha), math.cos(alpha)
        x, z = length * sin, length * cos  # hip relative to the stance ankle
        rate = (v[_X] * z - v[_Z] * x) / (length * length)
        g = p.gravity
        if self._swing is not None:
            # The hip on the passive, locked stance leg moves as a pendulum.
            spin = length * rate * rate / g
            self._hip_acc = (sin * cos - spin * sin, cos * cos - spin * cos)
        else:
            self._hip_acc = ((x - cop) / z, 1.0)  # the LIPM's
        others = 0.0  # hip torques of the legs in the air (they react on the torso)
        for i in (0, 1):
            if i in stance:
                continue
            start, start_rate, goal, tick, duration = self._plans[i]
            if not self._armed and self._swing is not None and self._swing[0] == i:
                # A foot still on the floor lifts first (a loaded leg cannot swing), moving
                # with the body meanwhile, and the swing starts from there: the lift eats
                # into the swing's time.
                start, start_rate = self._leg(q, i)[0], self._leg_rate(v, i)
                duration = max(SWING_TIME[1], duration - self._substep)
                tick = self._ticks
                self._plans[i] = (start, start_rate, goal, tick, duration)
            ref, ref_rate = _path(
                start, start_rate, goal, (self._ticks - tick) * self._substep, duration
            )
            if self._swing is not None and self._swing[0] == i:
                _, sign, target, reach = self._swing
                left = sign * (q[_PITCH] + q[3 + 3 * i] + 0.5 * q[4 + 3 * i] - target)
                clearance = CLEARANCE * min(1.0, max(0.0, left / CLEARANCE_ANGLE))
                self._free_leg(q, v, i, ref, ref_rate, reach, clearance, ctrl)
            else:
                self._free_leg(q, v, i, ref, ref_rate, self._length - HANG, CLEARANCE, ctrl)
            others += ctrl[3 * i]
        n = len(stance)
        if self._swing is not None:
            # The swing hip's reaction goes to the torso, which the controller brakes: the
            # passive stance pendulum feels only the command, as with the paper's massless
            # swing leg. (Through the stance hip it would disturb the pendulum and, near the
            # single-step limit, lift the unloaded stance foot off the floor.)
            others = 0.0
        # The torso feels the flywheel command; in stance the stance hips also take the
        # reaction of the leg in the air, which the CoP map accounts for.
        hip = (-fly - others) / n
        if self._swing is not None:
            # Passive ankle; the knee locked against the pendulum's load along the leg.
            load = p.mass * (g * cos - length * rate * rate)
            for i in stance:
                if self._sole_load(i) > 0.0:
                    ctrl[3 * i] = hip
                else:
                    # A stance foot off the floor (after a push along the leaning leg lifted
                    # the body, or as the contact chatters) cannot hold the hip torque: it
                    # would swing the light leg and kick the foot back. The hip holds the
                    # leg over the foothold instead, where the foot lands again.
                    hp, hd = HIP_GAINS
                    over = math.asin(max(-0.99, min(0.99, (q[_X] - self._anchor) / length)))
                    over_rate = v[_X] / (length * math.cos(over))
                    error_rate = self._leg_rate(v, i) - over_rate
                    ctrl[3 * i] = -hp * (alpha - over) - hd * error_rate
                ctrl[3 * i + 1] = self._knee_lock(q, v, i, self._lock, load)
        elif not self._lipm:
            cx, cz, cvx, cvz = self._com(q, v, stance[0])
            reach = math.hypot(cx, cz)
            torque = ankle_torque_for_cop(
                math.atan2(cx, cz),
                (cvx * cz - cvz * cx) / (reach * reach),
                cop,
                p.mass,
                reach,
                g,
                hip_torque=fly + others,
                push_force=self.push_now,
                ankle_height=ANKLE_HEIGHT,
            )
            for i in stance:
                ctrl[3 * i] = hip
                ctrl[3 * i + 1] = self._knee_lock(q, v, i, 0.0, 0.0)
                ctrl[3 * i + 2] = torque / n - self._foot(q, i)
        else:
            i, h, seg = stance[0], ANKLE_HEIGHT, self._segment
            kp, kd = HEIGHT_GAINS
            fz = max(0.0, p.mass * (g + kp * (self._hip_height - z) - kd * v[_Z]))
            # Moments about the hip of the (massless) leg: the hip torque on it is `hip`.
            fx = ((x - cop) * fz + hip) / (z + h)
            a2 = alpha + 0.5 * kappa  # the shank's angle
            ctrl[3 * i] = hip
            ctrl[3 * i + 1] = (seg * math.cos(a2) + h) * fx - (seg * math.sin(a2) - cop) * fz
            # The LIPM's CoP map, τ = δ m g + h F_x: the servo's F_z differs from the floor's
            # load by the legs' mass it does not model (a steady 1 % would offset the CoP and
            # make the CoM creep), and while a landing's contact builds up it asks more than
            # the floor carries (the full δ F_z would tip the foot).
            ctrl[3 * i + 2] = cop * p.weight + h * fx - self._foot(q, i)
        self._ctrl[:] = ctrl
        at_stop = abs(q[_PITCH]) >= p.flywheel_angle_max - 1e-3
        if at_stop and not self._at_stop:
            self.stop_impacts += 1
        self._at_stop = at_stop
        return fly

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
        cos = math.cos(a1 + 0.5 * kappa)
        wanted = longest
        if cos > 0.0:
            wanted = min(wanted, (self._base_z + q[_Z] - ANKLE_HEIGHT - clearance) / cos)
        wanted = max(0.5 * length, min(length, wanted))
        # The knee follows the bend the clearance asks for through a critically damped
        # filter: a jump (or a jump of its rate) would kick the thigh and, through the torso,
        # the stance leg.
        h, omega = self._substep, BEND_RATE
        bend, bend_rate = self._bends[i]
        goal = 2.0 * math.acos(wanted / length)
        bend_rate += h * omega * (omega * (goal - bend) - 2.0 * bend_rate)
        bend += h * bend_rate
        self._bends[i] = (bend, bend_rate)
        # Σ m (a_x r_z − (g + a_z) r_x) over the masses below each joint, r from the joint.
        ax, up = self._hip_acc
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
