"""The biped plant: MuJoCo stepping behind the backend contract (docs/biped.md)."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command, StepInfo
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.pendulum import ankle_torque_for_cop_unchecked
from pushrecovery.models.stepping import STEPPING_STATE
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import check_com_state
from pushrecovery.sim.mujoco.biped.control import (
    _PITCH,
    _X,
    _Z,
    ARM_HEIGHT,
    CLEARANCE,
    CLEARANCE_ANGLE,
    HANG,
    HEIGHT_GAINS,
    HIP_GAINS,
    IMPACT_TIME,
    SWING_SHARE,
    SWING_TIME,
    TOUCHDOWN_BEND,
    TRAIL_TIME,
    BipedServos,
    GaitState,
    Phase,
    _path,
)
from pushrecovery.sim.mujoco.biped.kinematics import BipedKinematics
from pushrecovery.sim.mujoco.biped.model import LEGS, biped_model
from pushrecovery.sim.mujoco.models import (
    ANKLE_HEIGHT,
)
from pushrecovery.sim.mujoco.plant import DEFAULT_COP_MARGIN, FOOT_TIP_LIMIT, MujocoPlant

FloatArray = NDArray[np.float64]

__all__ = ["MujocoBipedPlant"]


class MujocoBipedPlant(BipedKinematics, BipedServos, MujocoPlant):
    """Planar biped in MuJoCo (model ``biped``), the physical twin of ``SteppingPlant``.

    Same state, commands, ``footholds`` and ``fall_limits`` as
    :class:`~pushrecovery.sim.plants.SteppingPlant`; the module docstring describes the model
    and how commands become joint torques. A push can be a velocity (:meth:`reset`) or
    a force (:meth:`apply_push`, on the torso at the hip).
    """

    name: ClassVar[str] = "mujoco-biped"
    state_labels: ClassVar[tuple[str, ...]] = STEPPING_STATE
    model_name: ClassVar[str] = "biped"
    pushed_body: ClassVar[str] = "torso"
    feet: ClassVar[tuple[str, ...]] = tuple(f"{leg}_foot" for leg in LEGS)

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
        self._length = params.leg_length
        self._segment = 0.5 * params.leg_length
        self._base_z = params.leg_length + ANKLE_HEIGHT  # hip above the floor at qpos z = 0
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
        torso = model.body("torso")
        self._torso = (float(torso.mass[0]) / total, float(torso.ipos[2]))
        self._sole_ids = tuple(model.geom(f"{leg}_sole").id for leg in LEGS)
        self._reset_phase()

    def _reset_phase(self) -> None:
        """Standing on both feet, nothing in the air."""
        self.gait = GaitState()
        self.footholds = [0.0]

    # --- state ---------------------------------------------------------------------------
    def read_state(self) -> FloatArray:
        """``[x, theta, z, xdot, theta_dot, zdot]`` (module docstring) [m, rad, m/s, rad/s]."""
        q, v = self._qpos.tolist(), self._qvel.tolist()
        if self.gait.swing is not None:
            self._check_landing(q, v)
        x, z, xdot, zdot = self._com(q, v, self.gait.stance[0])
        if self.gait.phase in (Phase.STANDING, Phase.STANCE):
            z, zdot = self.gait.height, 0.0  # the height the stance holds (info().stance)
        return np.array([x, q[_PITCH], z, xdot, v[_PITCH], zdot])

    def ankle_x(self) -> float:
        """World x of the stance ankle (of the first foot when standing on both) [m]."""
        q = self._qpos.tolist()
        alpha, length, _ = self._leg(q, self.gait.stance[0])
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
        self.gait.height = self._standing_height()
        return super().reset(x, xdot)

    def _restart_records(self) -> None:
        super()._restart_records()
        self.footholds = [self.ankle_x()]

    def info(self) -> StepInfo:
        """Stance once a landing's impact is over and no foot swings (contract item 5)."""
        measured = self.measured_cops[-1] if self._measuring and self.measured_cops else None
        stance = self.gait.phase in (Phase.STANDING, Phase.STANCE)
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
            for i in self.gait.stance
        )

    def falling(self, state: FloatArray) -> bool:
        """Tell a fall: the base class's, or a swing whose CoM turns back (it cannot land)."""
        if self.gait.swing is not None:
            x, z, xdot, zdot = (float(state[i]) for i in (0, 2, 3, 5))
            if self.gait.swing[1] * (xdot * z - zdot * x) <= 0.0:
                return True
        return super().falling(state)

    # --- phases --------------------------------------------------------------------------
    def _start_swing(self, q: list[float], v: list[float], step: float) -> None:
        """Lock the stance leg and plan the swing of the other one for a step of ``step`` [m]."""
        stance, swing = (
            (0, 1) if len(self.gait.stance) == 2 else (self.gait.stance[0], 1 - self.gait.stance[0])
        )
        self.gait.stance = (stance,)
        lean, length, kappa = self._leg(q, stance)
        sign = 1.0 if step > 0.0 else -1.0
        reach = min(length, self._length * math.cos(0.5 * TOUCHDOWN_BEND))
        d = min(abs(step), 0.99 * (length + reach))
        # Triangle stance leg, swing leg, floor = d: the hip is `along` from the stance ankle.
        along = (length * length - reach * reach + d * d) / (2.0 * d)
        target = -sign * math.asin(max(-1.0, min(1.0, (d - along) / reach)))
        landing = math.asin(max(-1.0, min(1.0, along / length)))  # lean at touchdown, unsigned
        self.gait.swing = (swing, sign, target, reach)
        self.gait.lock = kappa
        self.gait.armed = self._sole_height(q, swing) > ARM_HEIGHT
        self.gait.anchor = q[_X] - length * math.sin(lean)
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
        self.gait.plans[swing] = (*now, target, self.gait.ticks, duration)
        self.gait.bends[swing] = (q[4 + 3 * swing], v[4 + 3 * swing])

    def _check_landing(self, q: list[float], v: list[float]) -> None:
        """Land when the swing sole reaches the floor after it has lifted."""
        assert self.gait.swing is not None
        leg = self.gait.swing[0]
        height = self._sole_height(q, leg)
        if not self.gait.armed:
            self.gait.armed = height > ARM_HEIGHT
            return
        if height > 0.0:
            return
        if self._sole_load(leg) <= 0.0:
            # Not yet pressed on the floor (or grazing it on the way up): the stance torques
            # would act on a leg in the air, tip the foot heel or toe first and bounce it.
            return
        old = self.gait.stance[0]
        rate = self._leg_rate(v, old)
        self.gait.plans[old] = (self._leg(q, old)[0], rate, 0.0, self.gait.ticks, TRAIL_TIME)
        self.gait.bends[old] = (q[4 + 3 * old], 0.0)
        self.gait.stance = (leg,)
        self.gait.swing = None
        self.gait.lipm = True
        alpha, length, _ = self._leg(q, leg)
        self.footholds.append(float(q[_X] - length * math.sin(alpha)))
        self.gait.hip_height = length * math.cos(alpha)
        self.gait.height = self.gait.hip_height + self._com_offset(q, [0.0] * len(q))[1]
        self.gait.impact_end = self.gait.ticks + round(IMPACT_TIME / self._substep)

    # --- control -------------------------------------------------------------------------
    def actuate(self, cop: float, command: Command) -> float:
        """Joint torques for this physics step (module docstring); return the hip torque.

        The returned torque is the flywheel command clipped to ±τmax, the torque on the torso.
        """
        q, v = self._qpos.tolist(), self._qvel.tolist()
        p = self.params
        fly = p.clip_hip_torque(command.flywheel_torque)
        if self.gait.swing is None and command.step_length is not None:
            self._start_swing(q, v, command.step_length)
        elif self.gait.swing is not None:
            self._check_landing(q, v)
        self.gait.ticks += 1
        ctrl = [0.0] * 6
        stance = self.gait.stance
        alpha, length, kappa = self._leg(q, stance[0])
        sin, cos = math.sin(alpha), math.cos(alpha)
        x, z = length * sin, length * cos  # hip relative to the stance ankle
        rate = (v[_X] * z - v[_Z] * x) / (length * length)
        g = p.gravity
        if self.gait.swing is not None:
            # The hip on the passive, locked stance leg moves as a pendulum.
            spin = length * rate * rate / g
            self.gait.hip_acc = (sin * cos - spin * sin, cos * cos - spin * cos)
        else:
            self.gait.hip_acc = ((x - cop) / z, 1.0)  # the LIPM's
        others = 0.0  # hip torques of the legs in the air (they react on the torso)
        for i in (0, 1):
            if i in stance:
                continue
            start, start_rate, goal, tick, duration = self.gait.plans[i]
            if not self.gait.armed and self.gait.swing is not None and self.gait.swing[0] == i:
                # A foot still on the floor lifts first (a loaded leg cannot swing), moving
                # with the body meanwhile, and the swing starts from there: the lift eats
                # into the swing's time.
                start, start_rate = self._leg(q, i)[0], self._leg_rate(v, i)
                duration = max(SWING_TIME[1], duration - self._substep)
                tick = self.gait.ticks
                self.gait.plans[i] = (start, start_rate, goal, tick, duration)
            ref, ref_rate = _path(
                start, start_rate, goal, (self.gait.ticks - tick) * self._substep, duration
            )
            if self.gait.swing is not None and self.gait.swing[0] == i:
                _, sign, target, reach = self.gait.swing
                left = sign * (q[_PITCH] + q[3 + 3 * i] + 0.5 * q[4 + 3 * i] - target)
                clearance = CLEARANCE * min(1.0, max(0.0, left / CLEARANCE_ANGLE))
                self._free_leg(q, v, i, ref, ref_rate, reach, clearance, ctrl)
            else:
                self._free_leg(q, v, i, ref, ref_rate, self._length - HANG, CLEARANCE, ctrl)
            others += ctrl[3 * i]
        n = len(stance)
        if self.gait.swing is not None:
            # The swing hip's reaction goes to the torso, which the controller brakes: the
            # passive stance pendulum feels only the command, as with the paper's massless
            # swing leg. (Through the stance hip it would disturb the pendulum and, near the
            # single-step limit, lift the unloaded stance foot off the floor.)
            others = 0.0
        # The torso feels the flywheel command; in stance the stance hips also take the
        # reaction of the leg in the air, which the CoP map accounts for.
        hip = (-fly - others) / n
        if self.gait.swing is not None:
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
                    over = math.asin(max(-0.99, min(0.99, (q[_X] - self.gait.anchor) / length)))
                    over_rate = v[_X] / (length * math.cos(over))
                    error_rate = self._leg_rate(v, i) - over_rate
                    ctrl[3 * i] = -hp * (alpha - over) - hd * error_rate
                ctrl[3 * i + 1] = self._knee_lock(q, v, i, self.gait.lock, load)
        elif not self.gait.lipm:
            cx, cz, cvx, cvz = self._com(q, v, stance[0])
            reach = math.hypot(cx, cz)
            torque = ankle_torque_for_cop_unchecked(
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
            fz = max(0.0, p.mass * (g + kp * (self.gait.hip_height - z) - kd * v[_Z]))
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
        if at_stop and not self.gait.at_stop:
            self.stop_impacts += 1
        self.gait.at_stop = at_stop
        return fly
