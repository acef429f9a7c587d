"""Compiled closed loop of the recovery controller on Sec. IV's stepping model (issue 17).

:func:`advance` runs one push of :class:`~pushrecovery.control.recovery.RecoveryController`
on :class:`~pushrecovery.sim.stepping_plant.SteppingPlant`, tick after tick as
:func:`~pushrecovery.sim.simulate.simulate` does (1 ms control period, the command held over
one plant step, fall test then rest test at the end of each tick), with the same IEEE
operations in the same order. Three things it does not do itself; it returns to its caller
(:func:`pushrecovery.sim.batched.recovery_pushes`) with a request, and resumes from the same
tick once the answer is in the record:

- :data:`NEED_BODY`: the controller's body at a new stance height (its CMP region and the
  flywheel limit less the MPC's margin, ``RecoveryController._body``);
- :data:`NEED_MPC`: the MPC's command (a QP, solved by DAQP), at most once every 20 ms of hip
  balancing;
- :data:`NEED_PLAN`: the Eq. (21) step plan of :func:`~pushrecovery.surfaces.step.plan_steps`
  while the controller is in step mode (a few times per stance).

The controller's ``compute`` is re-entered from its start on resumption: everything it does
before a request is idempotent (an escalation of the mode is kept, and the same state makes the
same request, which now finds its answer). ``tests/test_batched_stepping.py`` checks every row
of a campaign against the one-push loop, bit for bit.

Records: the float record ``f`` and the integer record ``n`` hold one push's run, indexed by the
slot constants below; ``ab`` the held-step matrices [A | B] of the stance (Eq. 16's ZOH,
:func:`~pushrecovery.models.flywheel.flywheel_discrete`) for the height and step in
``f[AB_Z]``, ``f[AB_DT]``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.kernels.jit import njit

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

# Return codes of advance(): the run is over, or what it needs to go on.
DONE, NEED_BODY, NEED_MPC, NEED_PLAN, DIVERGED = 0, 1, 2, 3, 4
# Outcomes and the controller's modes.
UNDECIDED, RECOVERED, FELL = 0, 1, 2
ANKLE, HIP, STEP = 0, 1, 2

# Body constants ``c``.
MASS, HEIGHT, GRAVITY, HEEL, TOE, INERTIA, ANGLE_MAX, TORQUE_MAX, DT, REST_SPEED = range(10)
BODY_SIZE = 10

# Float record ``f``: the plant's state [x, θ, z, ẋ, θ̇, ż], its swing (leg length, landing
# lean, direction), the controller's step time, held MPC command and current command, the
# run's extremes, the controller's body at a height, the caller's answer, the A|B key.
X, TH, Z, XD, THD, ZD = range(6)
SW_LEN, SW_LAND, SW_SIGN, SW_START = 6, 7, 8, 9
HELD_COP, HELD_TAU, HELD_UNTIL = 10, 11, 12
CMD_COP, CMD_TAU, CMD_STEP = 13, 14, 15
COP_MIN, COP_MAX, PEAK_TAU = 16, 17, 18
BODY_Z, CMP_LO, CMP_HI, ANGLE_LIMIT = 19, 20, 21, 22
REPLY_COP, REPLY_TAU, REPLY_UNTIL, REPLY_STEP = 23, 24, 25, 26
AB_Z, AB_DT = 27, 28
FLOAT_SIZE = 29

# Integer record ``n``.
K, TICK, MODE, SWINGING, STEPPED, HELD, HELD_SAT, STANCE = range(8)
AT_REST, STOPS, LANDINGS, OUTCOME, CMD_SAT, REPLY, REPLY_OK, REPLY_FLAG = range(8, 16)
INT_SIZE = 16

#: Swing substep [s] (SteppingPlant.substep).
SUBSTEP = 1e-4
#: RecoveryController's thresholds: upright [rad, rad/s] and the swing's flywheel brake [s].
UPRIGHT = 1e-4
BRAKE_TIME = 1e-2


def new_records() -> tuple[FloatArray, IntArray, FloatArray]:
    """Return empty ``f``, ``n`` and ``ab`` records."""
    return np.zeros(FLOAT_SIZE), np.zeros(INT_SIZE, dtype=np.int64), np.zeros((4, 6))


@njit(cache=True)
def start(c: FloatArray, x: float, xdot: float, f: FloatArray, n: IntArray) -> None:
    """Begin a run standing at the CoM height with the CoM at x [m] moving at ẋ [m/s]."""
    f[:] = 0.0
    n[:] = 0
    f[X], f[Z], f[XD] = x, c[HEIGHT], xdot
    f[COP_MIN], f[COP_MAX] = math.inf, -math.inf
    f[BODY_Z] = f[AB_Z] = math.nan
    f[CMD_STEP] = math.nan
    n[STANCE] = 1


@njit(cache=True)
def _clip(value: float, low: float, high: float) -> float:
    """BodyParams.clip_cop / clip_hip_torque: min(high, max(low, value))."""
    return min(high, max(low, value))


@njit(cache=True)
def _command(f: FloatArray, n: IntArray, cop: float, torque: float, saturated: bool) -> None:
    f[CMD_COP], f[CMD_TAU], f[CMD_STEP] = cop, torque, math.nan
    n[CMD_SAT] = 1 if saturated else 0


@njit(cache=True)
def _compute(c: FloatArray, f: FloatArray, n: IntArray, t: float) -> int:
    """RecoveryController.compute at time t: the command into f/n, or a request code."""
    x, theta, z, xdot, theta_rate = f[X], f[TH], f[Z], f[XD], f[THD]
    heel, toe, inertia, torque_max = c[HEEL], c[TOE], c[INERTIA], c[TORQUE_MAX]
    if n[STEPPED] == 1:  # swinging: wait for the landing
        if n[STANCE] == 0 or t <= f[SW_START]:
            brake = -inertia * theta_rate / BRAKE_TIME
            _command(f, n, 0.0, _clip(brake, -torque_max, torque_max), False)
            return DONE
        n[STEPPED], n[MODE], n[HELD] = 0, ANKLE, 0
    if not f[BODY_Z] == z:
        return NEED_BODY
    omega = math.sqrt(c[GRAVITY] / z)
    capture = x + xdot * (1.0 / omega)
    upright = abs(theta) < UPRIGHT and abs(theta_rate) < UPRIGHT
    if n[MODE] == ANKLE and not (heel < capture < toe and upright):
        n[MODE] = HIP if f[CMP_LO] < capture < f[CMP_HI] else STEP
    if n[MODE] == HIP:
        exhausted = (
            abs(theta) >= f[ANGLE_LIMIT] - UPRIGHT
            and abs(theta_rate) < 1e-2
            and not heel < capture < toe
        )
        scale = inertia / (c[MASS] * c[GRAVITY])
        effective = capture + scale * (omega * theta_rate + omega**2 * theta)
        reserve = scale * omega**2 * c[ANGLE_MAX]
        hopeless = not heel - reserve < effective < toe + reserve
        if not (exhausted or hopeless):
            if n[HELD] == 1 and t < f[HELD_UNTIL] - 1e-9:
                _command(f, n, f[HELD_COP], f[HELD_TAU], n[HELD_SAT] == 1)
                return DONE
            if n[REPLY] != NEED_MPC:
                return NEED_MPC
            if n[REPLY_OK] == 1:  # a feasible plan: hold it for the MPC's period
                n[HELD], n[HELD_SAT] = 1, n[REPLY_FLAG]
                f[HELD_COP], f[HELD_TAU], f[HELD_UNTIL] = f[REPLY_COP], f[REPLY_TAU], f[REPLY_UNTIL]
                _command(f, n, f[HELD_COP], f[HELD_TAU], n[HELD_SAT] == 1)
                return DONE
        n[MODE] = STEP
    if n[MODE] == STEP:
        if n[REPLY] != NEED_PLAN:
            return NEED_PLAN
        if n[REPLY_OK] == 1:  # ready: the recommended step (or the best effort)
            n[STEPPED], f[SW_START] = 1, t
            _command(f, n, 0.0, 0.0, n[REPLY_FLAG] == 0)
            f[CMD_STEP] = f[REPLY_STEP]
            return DONE
    if capture > toe:
        _command(f, n, toe, 0.0, True)
    elif capture < heel:
        _command(f, n, heel, 0.0, True)
    else:
        _command(f, n, capture, 0.0, False)
    return DONE


@njit(cache=True)
def _stance_step(
    c: FloatArray, f: FloatArray, n: IntArray, ab: FloatArray, dt: float, cop: float, tau: float
) -> None:
    """FlywheelPlant.advance at the stance height: X' = A X + B U (Eq. 16), the joint stop."""
    z = f[Z]
    if not (f[AB_Z] == z and f[AB_DT] == dt):  # flywheel_discrete(body at z, dt)
        omega = math.sqrt(c[GRAVITY] / z)
        weight, inertia = c[MASS] * c[GRAVITY], c[INERTIA]
        ch, sh = math.cosh(omega * dt), math.sinh(omega * dt)
        ab[:, :] = 0.0
        ab[0, 0], ab[0, 2], ab[0, 4], ab[0, 5] = ch, sh / omega, 1.0 - ch, (1.0 - ch) / weight
        ab[1, 1], ab[1, 3], ab[1, 5] = 1.0, dt, 0.5 * dt * dt / inertia
        ab[2, 0], ab[2, 2], ab[2, 4] = omega * sh, ch, -omega * sh
        ab[2, 5] = -omega * sh / weight
        ab[3, 3], ab[3, 5] = 1.0, dt / inertia
        f[AB_Z], f[AB_DT] = z, dt
    s0, s1, s2, s3 = f[X], f[TH], f[XD], f[THD]
    x, theta = _row(ab, 0, s0, s1, s2, s3, cop, tau), _row(ab, 1, s0, s1, s2, s3, cop, tau)
    xdot, rate = _row(ab, 2, s0, s1, s2, s3, cop, tau), _row(ab, 3, s0, s1, s2, s3, cop, tau)
    limit = c[ANGLE_MAX]
    if abs(theta) > limit:
        theta = math.copysign(limit, theta)
        xdot += c[INERTIA] * rate / (c[MASS] * z)
        rate = 0.0
        n[STOPS] += 1
    f[X], f[TH], f[XD], f[THD], f[ZD] = x, theta, xdot, rate, 0.0


@njit(cache=True, inline="always")
def _row(
    ab: FloatArray, i: int, s0: float, s1: float, s2: float, s3: float, cop: float, tau: float
) -> float:
    """Row i of A X + B U in plants._held_step's order of operations."""
    return (
        ab[i, 0] * s0
        + ab[i, 1] * s1
        + ab[i, 2] * s2
        + ab[i, 3] * s3
        + (ab[i, 4] * cop + ab[i, 5] * tau)
    )


@njit(cache=True)
def _swing_acceleration(theta: float, length: float, gravity: float) -> float:
    """models.pendulum._pendulum_acceleration with no ankle torque (δ = 0, m = 1)."""
    return gravity * math.sin(theta) / length - 0.0 / (1.0 * length * length)


@njit(cache=True)
def _rk4(theta: float, rate: float, h: float, length: float, gravity: float) -> tuple[float, float]:
    """models.pendulum.pendulum_step_unchecked, one substep."""
    k1a = _swing_acceleration(theta, length, gravity)
    k2q = rate + 0.5 * h * k1a
    k2a = _swing_acceleration(theta + 0.5 * h * rate, length, gravity)
    k3q = rate + 0.5 * h * k2a
    k3a = _swing_acceleration(theta + 0.5 * h * k2q, length, gravity)
    k4q = rate + h * k3a
    k4a = _swing_acceleration(theta + h * k3q, length, gravity)
    theta += h / 6.0 * (rate + 2.0 * k2q + 2.0 * k3q + k4q)
    rate += h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a)
    return theta, rate


@njit(cache=True)
def _start_swing(f: FloatArray, n: IntArray, step_length: float) -> None:
    """SteppingPlant._start_swing: the leg locks, only the tangential velocity survives."""
    x, z, xdot = f[X], f[Z], f[XD]
    length = math.sqrt(x * x + z * z)
    sign = 1.0 if step_length > 0.0 else -1.0
    lean = math.atan2(x, z)
    landing = max(math.asin(min(1.0, abs(step_length) / (2.0 * length))), sign * lean)
    f[SW_LEN], f[SW_LAND], f[SW_SIGN] = length, landing, sign
    n[SWINGING] = 1
    rate = xdot * math.cos(lean) / length
    f[X], f[Z] = length * math.sin(lean), length * math.cos(lean)
    f[XD], f[ZD] = length * math.cos(lean) * rate, -length * math.sin(lean) * rate


@njit(cache=True)
def _swing_step(c: FloatArray, f: FloatArray, n: IntArray, ab: FloatArray, dt: float) -> None:
    """SteppingPlant._swing_step with the held torque f[CMD_TAU] clipped (and the impact)."""
    length, landing, sign = f[SW_LEN], f[SW_LAND], f[SW_SIGN]
    g = c[GRAVITY]
    torque = _clip(f[CMD_TAU], -c[TORQUE_MAX], c[TORQUE_MAX])
    lean = math.atan2(f[X], f[Z])
    rate = (f[XD] * math.cos(lean) - f[ZD] * math.sin(lean)) / length
    left = dt
    while left > 1e-15:
        h = min(SUBSTEP, left)
        new_lean, new_rate = _rk4(lean, rate, h, length, g)
        if sign * new_lean >= landing:
            # Land exactly at the landing lean; its rate follows from energy.
            impact = sign * landing
            speed2 = rate * rate + 2.0 * g / length * (math.cos(lean) - math.cos(impact))
            rate = math.copysign(math.sqrt(max(0.0, speed2)), rate)
            fraction = (impact - lean) / (new_lean - lean) if new_lean != lean else 1.0
            _impact(c, f, n, ab, length, impact, rate, left - fraction * h)
            return
        lean, rate = new_lean, new_rate
        left -= h
        if sign * rate <= 0.0 or abs(lean) >= 0.5 * math.pi:
            break  # falls back (or flat): never lands
    f[X], f[Z] = length * math.sin(lean), length * math.cos(lean)
    f[XD], f[ZD] = length * math.cos(lean) * rate, -length * math.sin(lean) * rate
    f[THD] += torque / c[INERTIA] * dt
    f[TH] += f[THD] * dt
    limit = c[ANGLE_MAX]
    if abs(f[TH]) > limit:
        f[TH], f[THD] = math.copysign(limit, f[TH]), 0.0
        n[STOPS] += 1


@njit(cache=True)
def _impact(
    c: FloatArray,
    f: FloatArray,
    n: IntArray,
    ab: FloatArray,
    length: float,
    lean: float,
    rate: float,
    remaining: float,
) -> None:
    """Eqs. (18)-(20) (SteppingPlant._impact), then the rest of the step in stance, δ = τ = 0."""
    after = length * rate * math.cos(2.0 * lean) / math.cos(lean)
    height = length * math.cos(lean)
    n[LANDINGS] += 1
    n[SWINGING] = 0
    f[X], f[Z], f[XD], f[ZD] = -length * math.sin(lean), height, after, 0.0
    if remaining > 1e-12:
        _stance_step(c, f, n, ab, remaining, _clip(0.0, c[HEEL], c[TOE]), 0.0)


@njit(cache=True)
def _falling(c: FloatArray, f: FloatArray, n: IntArray) -> bool:
    """SteppingPlant.falling: the swing's fall tests, or the flywheel model's fall set."""
    x, xdot = f[X], f[XD]
    if n[SWINGING] == 1:
        length = f[SW_LEN]
        lean = math.atan2(x, f[Z])
        rate = (xdot * math.cos(lean) - f[ZD] * math.sin(lean)) / length
        pulls = length * rate * rate > c[GRAVITY] * math.cos(lean)
        return f[SW_SIGN] * rate <= 0.0 or abs(lean) >= 0.5 * math.pi - 1e-9 or pulls
    reach = c[TORQUE_MAX] / (c[MASS] * c[GRAVITY])
    lower, upper = c[HEEL] - reach, c[TOE] + reach
    momentum = c[MASS] * f[Z] * xdot + c[INERTIA] * f[THD]
    return (x > upper and xdot >= 0.0 and momentum >= 0.0) or (
        x < lower and xdot <= 0.0 and momentum <= 0.0
    )


@njit(cache=True)
def advance(
    c: FloatArray, ticks: int, rest_ticks: int, f: FloatArray, n: IntArray, ab: FloatArray
) -> int:
    """Run the push in ``f``/``n`` until it is decided, its ``ticks`` are over or it needs help.

    Returns :data:`DONE` (``n[OUTCOME]``, ``n[K]`` and the extremes are final), a request
    (:data:`NEED_BODY`, :data:`NEED_MPC`, :data:`NEED_PLAN`: answer it and call again), or
    :data:`DIVERGED` (a state that is not finite).
    """
    dt = c[DT]
    while n[K] < ticks and n[OUTCOME] == UNDECIDED:
        code = _compute(c, f, n, n[TICK] * dt)
        if code != DONE:
            return code
        n[REPLY] = 0  # an answer serves one tick
        n[TICK] += 1
        # The plant's step (SteppingPlant._phase_step): a step command starts a swing.
        if n[SWINGING] == 0 and not math.isnan(f[CMD_STEP]):
            _start_swing(f, n, f[CMD_STEP])
        if n[SWINGING] == 0:
            cop = _clip(f[CMD_COP], c[HEEL], c[TOE])
            tau = _clip(f[CMD_TAU], -c[TORQUE_MAX], c[TORQUE_MAX])
            _stance_step(c, f, n, ab, dt, cop, tau)
        else:
            cop, tau = 0.0, _clip(f[CMD_TAU], -c[TORQUE_MAX], c[TORQUE_MAX])
            _swing_step(c, f, n, ab, dt)
        n[STANCE] = 1 - n[SWINGING]
        f[COP_MIN], f[COP_MAX] = min(f[COP_MIN], cop), max(f[COP_MAX], cop)
        f[PEAK_TAU] = max(f[PEAK_TAU], abs(tau))
        n[K] += 1
        for i in range(6):
            if not math.isfinite(f[i]):
                return DIVERGED
        if _falling(c, f, n):
            n[OUTCOME] = FELL
            break
        x = f[X]
        resting = n[CMD_SAT] == 0 and abs(f[XD]) <= c[REST_SPEED] and c[HEEL] < x < c[TOE]
        n[AT_REST] = n[AT_REST] + 1 if resting else 0
        if n[AT_REST] >= rest_ticks:
            n[OUTCOME] = RECOVERED
    return DONE
