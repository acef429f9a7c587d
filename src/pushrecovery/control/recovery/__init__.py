"""The push-recovery controller: ankle, then hip, then a step, as Sec. I-B proposes."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import NDArray

from pushrecovery.control.base import Command, Controller, StepInfo, register
from pushrecovery.control.mpc import MPCController
from pushrecovery.errors import InvalidParameterError
from pushrecovery.models.stepping import STEPPING_STATE
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import capture_point
from pushrecovery.surfaces.step import compiled_plan_step

__all__ = ["RecoveryController"]

# Flywheel angle [rad] and rate [rad/s] below which the upper body counts as upright and still.
_UPRIGHT = 1e-4
# During a swing the flywheel is braked to rest over about this time [s].
STEP_BRAKE_TIME = 1e-2


@register
class RecoveryController(Controller):
    """Watch the state against the decision surfaces and escalate ankle → hip → step.

    For the stepping model, state ``[x, θ, z, ẋ, θ̇, ż]`` relative to the current stance ankle.
    Each stance starts in **ankle** mode: the CoP at the capture point ξ = x + ẋ/ω(z), ω(z) =
    sqrt(g/z) of the current height (exact for Eq. 4). When ξ leaves the foot (or the upper body
    is not upright and still) it escalates to **hip**: the paper's MPC (Eqs. 16-17) for the
    current height, recomputed every MPC dt and held in between. It escalates to **step** when
    the hip provably cannot recover any more, or has nothing left: the QP is infeasible; the
    flywheel is parked at its limit with the capture point off the foot; or the flywheel-aware
    capture point ξ + (I/(m g))(ω θ̇ + ω² θ) lies beyond δ± ± ω² I θmax/(m g), outside which no
    admissible hip torque can capture the state (errata E12, step 3, with θ ≤ θmax). It then
    takes the Eq. (21) step of :func:`~pushrecovery.surfaces.step.plan_steps`
    (moved within reach if needed; the longest step as a last resort), braking the flywheel
    during the swing. After the landing it starts again in ankle mode on the new foot.
    Modes only escalate within a stance, so the controller does not chatter between surfaces.
    """

    name = "recovery"
    strategy = "step"
    state_labels = STEPPING_STATE

    def __init__(self, params: BodyParams) -> None:
        super().__init__(params)
        self.control_period = 1e-3
        self.mode = "ankle"
        self._bodies: dict[float, BodyParams] = {}
        self._mpcs: dict[float, MPCController] = {}
        self._swing_start: float | None = None
        self._held: Command | None = None
        self._held_until = -1.0
        self._stance = True
        # Load the compiled step planner now (machine code from numba's disk cache, ~15 ms the
        # first time in a process), not on the first tick that needs a step.
        compiled_plan_step()

    def reset(self, state: NDArray[np.float64]) -> None:
        """Start in ankle mode on the current foot."""
        if np.shape(state) != (6,):
            raise InvalidParameterError(
                "the recovery controller needs the stepping model's state "
                f"[x, theta, z, xdot, theta_dot, zdot], got shape {np.shape(state)}"
            )
        self.mode, self._swing_start, self._held = "ankle", None, None
        self._stance = True

    def observe(self, info: StepInfo) -> None:
        """Learn from the plant whether the feet carry the body (a landing ends a swing)."""
        self._stance = info.stance

    def _mpc(self, height: float) -> MPCController:
        """Return the MPC of this stance height, built when the hip is first needed there."""
        mpc = self._mpcs.get(height)
        if mpc is None:
            mpc = self._mpcs[height] = MPCController(self._body(height))
        return mpc

    def _body(self, height: float) -> BodyParams:
        entry = self._bodies.get(height)
        if entry is None:
            body = dataclasses.replace(self.params, com_height=height)
            # The MPC bounds θ only at its samples; between them θ is a parabola that can
            # overshoot by u dt² / 8. Give it that much margin so the body never meets the stop.
            dt = MPCController.default_dt
            margin = min(
                body.torque_max / body.flywheel_inertia * dt * dt / 8.0,
                0.5 * body.flywheel_angle_max,
            )
            limited = dataclasses.replace(body, flywheel_angle_max=body.flywheel_angle_max - margin)
            entry = self._bodies[height] = limited
        return entry

    def compute(self, t: float, state: NDArray[np.float64]) -> Command:
        """Command for the current mode (escalating first if the state calls for it)."""
        x, theta, z, xdot, theta_rate, _ = (float(v) for v in state)
        p = self.params
        if self._swing_start is not None:  # swinging: wait for the landing
            # The plant reports the landing (observe): the first tick in stance after the step.
            if not self._stance or t <= self._swing_start:
                brake = -p.flywheel_inertia * theta_rate / STEP_BRAKE_TIME
                return Command(0.0, p.clip_hip_torque(brake))
            self._swing_start, self.mode, self._held = None, "ankle", None
        body = self._body(z)
        omega = math.sqrt(p.gravity / z)
        capture = capture_point(x, xdot, omega)
        upright = abs(theta) < _UPRIGHT and abs(theta_rate) < _UPRIGHT
        if self.mode == "ankle" and not (p.heel < capture < p.toe and upright):
            region = cmp_region(body)
            self.mode = "hip" if region.lower < capture < region.upper else "step"
        if self.mode == "hip":
            exhausted = (
                abs(theta) >= body.flywheel_angle_max - _UPRIGHT
                and abs(theta_rate) < 1e-2
                and not p.heel < capture < p.toe
            )
            scale = p.flywheel_inertia / p.weight
            effective = capture + scale * (omega * theta_rate + omega**2 * theta)
            reserve = scale * omega**2 * p.flywheel_angle_max
            hopeless = not p.heel - reserve < effective < p.toe + reserve
            command = None if exhausted or hopeless else self._hip(t, state, z)
            if command is not None:
                return command
            self.mode = "step"
        if self.mode == "step":
            command = self._step(t, x, xdot, body)
            if command is not None:
                return command
        cop, clipped = self.clip_cop(capture)
        return Command(cop, saturated=clipped)

    def _hip(self, t: float, state: NDArray[np.float64], height: float) -> Command | None:
        if self._held is not None and t < self._held_until - 1e-9:
            return self._held
        mpc = self._mpc(height)
        # The MPC's own command, with its clipping and saturation flag (rest criterion).
        command = mpc.compute(t, state[[0, 1, 3, 4]])
        if mpc.last_plan is None or not mpc.last_plan.feasible:
            return None
        self._held, self._held_until = command, t + mpc.settings.dt
        return command

    def _step(self, t: float, x: float, xdot: float, body: BodyParams) -> Command | None:
        ready, feasible, step_length = plan_step_now(x, xdot, body)
        if not ready:
            return None  # the CoM is not yet falling toward the step: keep balancing meanwhile
        # Feasible: the recommended step; otherwise the best effort, the admissible step whose
        # capture point lands nearest the new foot.
        self._swing_start = t
        return Command(0.0, step_length=step_length, saturated=not feasible)


def plan_step_now(x: float, xdot: float, body: BodyParams) -> tuple[bool, bool, float]:
    """Return ``plan_steps(x, xdot, body)``'s ready, feasible and step length [m], compiled.

    Unchecked (not in ``__all__``): the loops' states are the plant's, already checked.

    The controller's plan (:func:`~pushrecovery.surfaces.step.compiled_plan_step`, a few µs
    where the interpreted one takes ~100 µs); the compiled batch of
    :mod:`pushrecovery.sim.batched` asks it too, so both loops take the same steps to the bit.
    """
    _, ready, feasible, _, step_length, _, _, _ = compiled_plan_step()(
        x, xdot, body.heel, body.toe, body.com_height, body.gravity, body.max_step_length
    )
    return bool(ready), bool(feasible), float(step_length)
