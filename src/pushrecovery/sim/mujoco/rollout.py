"""Many pushes of the ankle PD on MuJoCo's ``foot`` at once: ``mujoco.rollout`` in lockstep.

:func:`ankle_pd_rollout` gives, for each push, what :func:`~pushrecovery.sim.simulate.simulate`
gives for :class:`~pushrecovery.control.ankle.AnklePD` (default gains) on
:class:`~pushrecovery.sim.mujoco.pendulums.MujocoFootPlant` after a force push (the campaigns'
``pushed_state(..., force=True)``), with the default control period (1 ms, one physics step)
and rest criterion: the outcome, the time it was decided and the CoP excursion.

How: every push is pushed by its plant (the 10 ms force, the body held still), then all of
them step together, one control tick at a time. At each tick the controller's law and the
plant's CoP → ankle-torque map (errata E3) are evaluated for every running push at once
(numpy), and one ``mujoco.rollout`` call advances them all by the tick on MuJoCo's threads;
the fall and rest criteria are judged on the new states, vectorised, and decided pushes drop
out of the batch. Python runs once per tick for the whole batch, not once per push and step.

Why not the PD as a MuJoCo actuator (a general actuator with bias −k_p q − k_d q̇ and a force
range), which would let one rollout run the whole duration open-loop? The ankle PD feeds back
the body's *absolute* lean φ = foot pitch + ankle angle, while an actuator feeds back its own
transmission, the ankle angle alone: the stiffness an actuator adds to the joint-space
equations is Σ c cᵀ (symmetric), and −k_p e_ankle (e_pitch + e_ankle)ᵀ is not, so no set of
actuators expresses it. Measured on a grid of 86 pushes (CHANGELOG.md), the actuator
form rocks the light foot in a limit cycle (abs(ẋ) ≈ 2e-3 m/s, never at rest: 48 verdicts
differ) and, its torque clamp being constant where the map's edge torque depends on the load,
tips the foot at the toe during saturated braking.

What differs from the one loop: nothing in the control law or its sampling (the command is
computed from the state at the start of each 1 ms tick and held over it, as in the loop);
the solver's warm start between ticks is rebuilt from the velocity change of the last tick
(``mujoco.rollout`` does not return it), which moves the constraint solution within the
solver's tolerance, and numpy's transcendental functions may differ from ``math``'s in the
last bit. Verdicts agree away from the critical push; times and CoP excursions to within the
tolerances of ``tests/test_mujoco_rollout.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, require_type, sample_array
from pushrecovery.control.ankle import default_pd_gains
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import check_com_state
from pushrecovery.sim.mujoco.models import ANKLE_HEIGHT, FOOT_MASS
from pushrecovery.sim.mujoco.pendulums import MujocoFootPlant
from pushrecovery.sim.mujoco.plant import DEFAULT_COP_MARGIN, FOOT_TIP_LIMIT
from pushrecovery.sim.push import Push
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import DEFAULT_CONTROL_PERIOD, MAX_DURATION, RestCriterion

__all__ = ["RolloutRuns", "ankle_pd_rollout"]

FloatArray = NDArray[np.float64]
_OUTCOMES = (Outcome.UNDECIDED, Outcome.RECOVERED, Outcome.FELL)
#: Most threads a rollout may use.
MAX_THREADS = 64


@dataclass(frozen=True, slots=True)
class RolloutRuns:
    """The runs of :func:`ankle_pd_rollout`, one entry per push, in order.

    Attributes
    ----------
    outcomes : tuple of Outcome
        Recovered, fell or undecided (as ``SimulationResult.outcome``).
    times : ndarray
        Simulated time at which the run ended: its outcome decided, or the duration [s]
        (the campaign's ``time`` column).
    cop_min, cop_max : ndarray
        Excursion of the CoP the plant applied (the command clipped to the foot shortened
        by the CoP margin) over the run, relative to the ankle [m].
    diverged : ndarray of bool
        MuJoCo's physics blew up before the run was decided (where the loop raises
        :class:`~pushrecovery.errors.SimulationDiverged`: a campaign's error row); the
        other columns of such a push are NaN and its outcome undecided.
    """

    outcomes: tuple[Outcome, ...]
    times: FloatArray
    cop_min: FloatArray
    cop_max: FloatArray
    diverged: NDArray[np.bool_]


def ankle_pd_rollout(
    params: BodyParams,
    x0: Sequence[float] | FloatArray,
    xdot: Sequence[float] | FloatArray,
    *,
    duration: float,
    threads: int = 1,
    cop_margin: float = DEFAULT_COP_MARGIN,
) -> RolloutRuns:
    """Simulate the ankle PD on MuJoCo's ``foot`` after each force push (x0[i], xdot[i]).

    Each push is what a campaign's MuJoCo row simulates: the body standing at x0 [m] is
    pushed at its CoM with the impulse m ẋ over 10 ms, then
    :class:`~pushrecovery.control.ankle.AnklePD` (default gains k_p = 3 m g L,
    k_d = k_p / ω) balances it at 1 kHz until it falls (the plant's absorbing fall set),
    rests (abs(ẋ) <= 1e-3 m/s over the foot with an unsaturated command for 0.5 s) or
    ``duration`` runs out.

    Parameters
    ----------
    params : BodyParams
        The body (one model is compiled for all the pushes).
    x0 : sequence of float
        CoM position before each push, relative to the ankle [m] (abs(x0) < L).
    xdot : sequence of float
        The velocity each push gives, J/m [m/s] (abs(ẋ) < 10 sqrt(g L)).
    duration : float
        Longest simulated time per push [s], in (0, 60].
    threads : int
        MuJoCo's threads for the batch, in [1, 64]; the results do not depend on it.
    cop_margin : float
        The plant's CoP margin inside the foot edges [m], as ``MujocoFootPlant``'s.

    Returns
    -------
    RolloutRuns
        One entry per push, in order.

    Raises
    ------
    InvalidParameterError
        Sequences of different lengths (none gives no runs), a start no model can have, a duration
        outside (0, 60] s, a thread count outside [1, 64], a bad CoP margin.
    ParameterTypeError
        ``params`` not a BodyParams.
    """
    require_type("params", params, BodyParams)
    starts, speeds = sample_array("x0", x0), sample_array("xdot", xdot)
    if len(starts) != len(speeds):
        raise InvalidParameterError(
            f"x0 and xdot must have one entry per push, got {len(starts)} and {len(speeds)}"
        )
    for start, speed in zip(starts.tolist(), speeds.tolist(), strict=True):
        check_com_state(start, speed, params)
    duration = bounded_float("duration", duration, 0.0, MAX_DURATION, "s")
    if duration == 0.0:
        raise InvalidParameterError(f"duration must be in (0, {MAX_DURATION:g}] s, got 0")
    if not (type(threads) is int and 1 <= threads <= MAX_THREADS):  # a bool is no count
        raise InvalidParameterError(
            f"threads must be an int in [1, {MAX_THREADS}], got {threads!r}"
        )
    plant = MujocoFootPlant(params, cop_margin)  # checks the margin
    if starts.size == 0:
        empty = np.empty(0)
        return RolloutRuns((), empty, empty.copy(), empty.copy(), np.empty(0, dtype=bool))
    return _Lockstep(plant, threads).run(starts, speeds, duration)


class _Lockstep:
    """The batch of one :func:`ankle_pd_rollout` call: its plant, MuJoCo data and constants."""

    def __init__(self, plant: MujocoFootPlant, threads: int) -> None:
        import mujoco

        self.mj: Any = mujoco
        self.plant = plant
        # The plant's model with a sensor of the whole body's CoM (the foot is the root body):
        # sensors read, they do not change the physics.
        spec = plant.build(plant.params)
        spec.add_sensor(
            name="com",
            type=mujoco.mjtSensor.mjSENS_SUBTREECOM,
            objtype=mujoco.mjtObj.mjOBJ_BODY,
            objname="foot",
        )
        self.model = model = spec.compile()
        self.datas = [mujoco.MjData(model) for _ in range(threads)]
        self.h = float(model.opt.timestep)
        self.full = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
        self.ctrl_spec = int(mujoco.mjtState.mjSTATE_CTRL)
        self.com_z = int(model.sensor("com").adr[0]) + 2
        p = plant.params
        nq = model.nq
        # Columns of the FULLPHYSICS state: time, qpos, qvel, act (MuJoCo's order).
        self.pitch, self.ankle = 1 + plant._pitch, 1 + plant._ankle
        self.pitch_v, self.ankle_v = 1 + nq + plant._pitch_v, 1 + nq + plant._ankle_v
        self.qvel = slice(1 + nq, 1 + nq + model.nv)
        self.kp, self.kd = default_pd_gains(p)
        self.low, self.high = p.heel + plant.cop_margin, p.toe - plant.cop_margin

    def pushed(self, x0: float, xdot: float) -> tuple[FloatArray, FloatArray]:
        """Return the state and warm start just after the push, by the plant (as a campaign)."""
        plant, mj = self.plant, self.mj
        plant.reset(x0, 0.0)
        plant.apply_push(Push(xdot))
        state = np.empty(mj.mj_stateSize(plant.model, self.full))
        mj.mj_getState(plant.model, plant.data, state, self.full)
        return state, plant.data.qacc_warmstart.copy()

    def controls(self, states: FloatArray) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
        """Return the tick's ankle controls, applied CoPs and saturation flags.

        As ``AnklePD.compute`` (θ = asin(x/L), τ = k_p θ + k_d θ̇, δ = τ/(m g) clipped to
        [heel, toe]) then the plant: δ clipped to the margins and turned into the ankle torque
        that puts the CoP there (``models.pendulum.ankle_torque_for_cop_unchecked``, ankle
        height and foot mass included, no push, no hip), sent as −τ (MuJoCo's hinge sign).
        """
        p = self.plant.params
        length, mass, gravity = p.com_height, p.mass, p.gravity
        lean = states[:, self.pitch] + states[:, self.ankle]
        rate = states[:, self.pitch_v] + states[:, self.ankle_v]
        x, xdot = length * np.sin(lean), length * np.cos(lean) * rate
        theta = np.arcsin(np.clip(x / length, -1.0, 1.0))
        cos_theta = np.cos(theta)
        theta_rate = np.where(cos_theta > 0.0, xdot / (length * cos_theta), 0.0)
        wanted = (self.kp * theta + self.kd * theta_rate) * (1.0 / p.weight)
        saturated = (wanted > p.toe) | (wanted < p.heel)
        cop = np.minimum(self.high, np.maximum(self.low, np.clip(wanted, p.heel, p.toe)))
        cos, sin = np.cos(lean), np.sin(lean)
        spin = length * rate * rate
        h, centre = ANKLE_HEIGHT, 0.5 * (p.heel + p.toe)
        lever = h * cos - cop * sin
        torque = (
            cop * mass * (gravity - cos * spin)
            - h * (mass * sin * spin)
            + FOOT_MASS * gravity * (cop - centre)
            + lever * (mass * gravity * sin)
        ) / (1.0 + lever / length)
        accel = (mass * gravity * length * sin - torque) / (mass * length * length)
        load = mass * (gravity - length * (sin * accel + cos * rate * rate))
        torque = np.where(load > 0.0, torque, 0.0)
        return -torque, cop, saturated

    def step(
        self, pool: Any, before: FloatArray, ctrl: FloatArray, warm: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """Advance the running pushes by one physics step; return their states and CoM z.

        The CoM height is MuJoCo's of the step's start (as the plant's ``falling`` reads
        ``subtree_com`` after ``mj_step``).
        """
        count = before.shape[0]
        state = np.empty((count, 1, before.shape[1]))
        sensed = np.empty((count, 1, self.model.nsensordata))
        threads = len(self.datas)
        pool.rollout(
            [self.model] * count,
            self.datas,
            before,
            np.ascontiguousarray(ctrl.reshape(count, 1, 1)),
            control_spec=self.ctrl_spec,
            skip_checks=True,
            nstep=1,
            initial_warmstart=np.ascontiguousarray(warm),
            state=state,
            sensordata=sensed,
            chunk_size=max(1, -(-count // threads)),
        )
        return state[:, 0, :], sensed[:, 0, self.com_z]

    def run(self, starts: FloatArray, speeds: FloatArray, duration: float) -> RolloutRuns:
        """Push, then step the batch tick by tick until every push is decided."""
        from mujoco import rollout

        p, h = self.plant.params, self.h
        dt = DEFAULT_CONTROL_PERIOD
        if abs(dt - h) > 1e-12:  # pragma: no cover - the models' step is the control period
            raise InvalidParameterError(f"the foot model's step must be {dt:g} s, got {h:g}")
        rest = RestCriterion()
        ticks = math.ceil(duration / dt - 1e-9)
        rest_ticks = max(1, math.ceil(rest.duration / dt - 1e-9))
        count = len(starts)
        pushed = [self.pushed(a, b) for a, b in zip(starts.tolist(), speeds.tolist(), strict=True)]
        states = np.array([s for s, _ in pushed])
        warm = np.array([w for _, w in pushed])
        code = np.zeros(count, dtype=np.int64)
        end = np.full(count, ticks, dtype=np.int64)
        cop_min, cop_max = np.full(count, np.inf), np.full(count, -np.inf)
        diverged = np.zeros(count, dtype=bool)
        at_rest = np.zeros(count, dtype=np.int64)
        active = np.arange(count)
        half_height = 0.5 * (p.com_height + ANKLE_HEIGHT)
        # One thread pool for the whole batch (none for one thread: the calling thread steps).
        pool = rollout.Rollout(nthread=0 if len(self.datas) == 1 else len(self.datas))
        try:
            for k in range(ticks):
                before = np.ascontiguousarray(states[active])
                ctrl, cop, saturated = self.controls(before)
                cop_min[active] = np.minimum(cop_min[active], cop)
                cop_max[active] = np.maximum(cop_max[active], cop)
                after, com_z = self.step(pool, before, ctrl, warm[active])
                # MuJoCo resets the data of a blown-up step: its clock goes back to 0.
                blown = ~(np.abs(after[:, 0] - before[:, 0] - h) < 0.5 * h)
                blown |= ~np.isfinite(after).all(axis=1)
                lean = after[:, self.pitch] + after[:, self.ankle]
                rate = after[:, self.pitch_v] + after[:, self.ankle_v]
                x = p.com_height * np.sin(lean)
                xdot = p.com_height * np.cos(lean) * rate
                fell = (com_z < half_height) | (np.abs(after[:, self.pitch]) > FOOT_TIP_LIMIT)
                resting = ~saturated & (np.abs(xdot) <= rest.speed) & (x > p.heel) & (x < p.toe)
                at_rest[active] = np.where(resting, at_rest[active] + 1, 0)
                recovered = ~fell & (at_rest[active] >= rest_ticks)
                warm[active] = (after[:, self.qvel] - before[:, self.qvel]) / h
                states[active] = after
                done = blown | fell | recovered
                if done.any():
                    finished = active[done]
                    diverged[finished] = blown[done]
                    code[finished] = np.where(blown[done], 0, np.where(fell[done], 2, 1))
                    end[finished] = k + 1
                    active = active[~done]
                    if active.size == 0:
                        break
        finally:
            pool.close()
        times = end.astype(np.float64) * dt
        times[diverged] = cop_min[diverged] = cop_max[diverged] = np.nan
        return RolloutRuns(
            tuple(_OUTCOMES[c] for c in code.tolist()), times, cop_min, cop_max, diverged
        )
