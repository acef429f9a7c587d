"""Many pushes in compiled loops (issue 17): the ankle PD, and the recovery controller stepping.

:func:`ankle_pd_pushes` gives, for each push, what :func:`~pushrecovery.sim.simulate.simulate`
gives for ``AnklePD`` (default gains) on ``PendulumPlant`` or ``LipmPlant`` with the default
control period and rest criterion: the outcome, the time it was decided and the CoP excursion,
the same numbers (``tests/test_batched.py``), without a Python call per tick.
:func:`recovery_pushes` does the same for ``RecoveryController`` on ``SteppingPlant``
(``tests/test_batched_stepping.py``): the loop is compiled, and only the MPC's QPs, the step
plans and the controller's body at a new stance height are asked of Python
(:mod:`pushrecovery.kernels.batched.stepping`). Campaigns of these pairs use them
(:func:`~pushrecovery.campaign.pushes.run_batch`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, require_type, sample_array
from pushrecovery.control.ankle import default_pd_gains
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import check_com_state
from pushrecovery.sim.many import DIVERGED, PushRuns
from pushrecovery.sim.plants import PendulumPlant
from pushrecovery.sim.result import Outcome
from pushrecovery.sim.simulate import DEFAULT_CONTROL_PERIOD, MAX_DURATION, RestCriterion

if TYPE_CHECKING:  # the recovery controller loads the MPC and scipy: only its batches need it
    from pushrecovery.control.recovery import RecoveryController

__all__ = ["ankle_pd_pushes", "recovery_pushes"]

_OUTCOMES = (Outcome.UNDECIDED, Outcome.RECOVERED, Outcome.FELL)


def ankle_pd_pushes(
    model: str,
    bodies: Sequence[BodyParams],
    x0: Sequence[float],
    xdot: Sequence[float],
    *,
    duration: float,
) -> PushRuns:
    """Simulate the ankle PD after each push (x0[i], xdot[i]) on bodies[i].

    Parameters
    ----------
    model : {"pendulum", "lipm"}
        The plant.
    bodies : sequence of BodyParams
        Each push's body (default PD gains, :func:`~pushrecovery.control.ankle.default_pd_gains`).
    x0, xdot : sequence of float
        CoM position [m] and velocity [m/s] just after each push (checked as the plants'
        ``reset`` does).
    duration : float
        Longest simulated time per push [s], in (0, 60].

    Returns
    -------
    PushRuns
        One entry per push, in order.

    Raises
    ------
    InvalidParameterError
        An unknown model, sequences of different lengths, a start no model can have, a
        duration outside (0, 60] s.
    ParameterTypeError
        ``bodies`` not a list or tuple of BodyParams.
    """
    from pushrecovery.kernels.batched.ankle import ankle_pd_pushes as kernel

    if not (isinstance(model, str) and model in ("pendulum", "lipm")):
        raise InvalidParameterError(f"model must be 'pendulum' or 'lipm', got {model!r:.40}")
    starts, speeds, ticks, rest_ticks = _checked_pushes(bodies, x0, xdot, duration)
    dt, rest = DEFAULT_CONTROL_PERIOD, RestCriterion()
    assert dt <= PendulumPlant.max_substep  # one RK4 substep per tick, as the kernel does
    count = len(bodies)
    columns = np.array(
        [(b.mass, b.com_height, b.gravity, b.heel, b.toe, *default_pd_gains(b)) for b in bodies],
        dtype=np.float64,
    ).reshape(count, 7)
    code, end = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    cop_min, cop_max = np.empty(count), np.empty(count)
    mass, height, gravity, heel, toe, kp, kd = (
        np.ascontiguousarray(columns[:, j]) for j in range(7)
    )
    kernel(
        model == "pendulum",
        starts,
        speeds,
        mass,
        height,
        gravity,
        heel,
        toe,
        kp,
        kd,
        dt,
        ticks,
        rest_ticks,
        rest.speed,
        code,
        end,
        cop_min,
        cop_max,
    )
    times: NDArray[np.float64] = end.astype(np.float64) * dt
    zeros = np.zeros(count, dtype=np.int64)
    return PushRuns(
        tuple(_OUTCOMES[c] for c in code.tolist()), times, cop_min, cop_max, steps=zeros,
        peak_hip_torque=np.zeros(count), stop_impacts=zeros, errors=(None,) * count,
        engine="compiled",
    )  # fmt: skip


def recovery_pushes(
    bodies: Sequence[BodyParams],
    x0: Sequence[float],
    xdot: Sequence[float],
    *,
    duration: float,
    controllers: dict[BodyParams, RecoveryController] | None = None,
) -> PushRuns:
    """Simulate the recovery controller on the stepping model after each push (x0[i], xdot[i]).

    What ``simulate(SteppingPlant(b), RecoveryController(b), [x0, 0, L, ẋ, 0, 0])`` gives with
    the default control period (1 ms) and rest criterion, push after push, the same numbers:
    the loop runs compiled (:mod:`pushrecovery.kernels.batched.stepping`) and asks Python only
    for the MPC's QPs, the step plans and the controller's body at a new stance height, from
    one :class:`~pushrecovery.control.recovery.RecoveryController` per body, as a campaign
    batch of one-push runs shares one (its MPCs warm-start from the previous push's last QP).

    Parameters
    ----------
    bodies : sequence of BodyParams
        Each push's body.
    x0, xdot : sequence of float
        CoM position [m] and velocity [m/s] just after each push, relative to the ankle.
    duration : float
        Longest simulated time per push [s], in (0, 60].
    controllers : dict, optional
        The controllers per body to use and fill (a batch's cache); default a new one.

    Returns
    -------
    PushRuns
        One entry per push, in order; the errors are :func:`ankle_pd_pushes`'s (no model).
    """
    from pushrecovery.control.recovery import RecoveryController
    from pushrecovery.kernels.batched import stepping as kernel

    starts, speeds, ticks, rest_ticks = _checked_pushes(bodies, x0, xdot, duration)
    controllers = {} if controllers is None else controllers
    require_type("controllers", controllers, dict)
    count, rest = len(bodies), RestCriterion()
    code, end = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    steps, stops = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    cop_min, cop_max, peak = np.empty(count), np.empty(count), np.empty(count)
    diverged = np.zeros(count, dtype=np.bool_)
    f, n, ab = kernel.new_records()
    constants: dict[BodyParams, NDArray[np.float64]] = {}
    for i, body in enumerate(bodies):
        controller = controllers.get(body)
        if controller is None:
            controller = controllers[body] = RecoveryController(body)
            assert controller.control_period == DEFAULT_CONTROL_PERIOD  # the kernel's tick
        c = constants.get(body)
        if c is None:
            c = constants[body] = np.array(
                [
                    body.mass, body.com_height, body.gravity, body.heel, body.toe,
                    body.flywheel_inertia, body.flywheel_angle_max, body.torque_max,
                    DEFAULT_CONTROL_PERIOD, rest.speed,
                ]
            )  # fmt: skip
        kernel.start(c, float(starts[i]), float(speeds[i]), f, n)
        while (request := kernel.advance(c, ticks, rest_ticks, f, n, ab)) != kernel.DONE:
            if request == kernel.DIVERGED:
                diverged[i] = True
                break
            _answer(request, controller, f, n)
        code[i], end[i] = n[kernel.OUTCOME], n[kernel.K]
        steps[i], stops[i] = n[kernel.LANDINGS], n[kernel.STOPS]
        cop_min[i], cop_max[i], peak[i] = f[kernel.COP_MIN], f[kernel.COP_MAX], f[kernel.PEAK_TAU]
    times: NDArray[np.float64] = end.astype(np.float64) * DEFAULT_CONTROL_PERIOD
    return PushRuns(
        tuple(_OUTCOMES[c] for c in code.tolist()), times, cop_min, cop_max, steps=steps,
        peak_hip_torque=peak, stop_impacts=stops,
        errors=tuple(DIVERGED if d else None for d in diverged.tolist()), engine="compiled",
    )  # fmt: skip


def _answer(
    request: int, controller: RecoveryController, f: NDArray[np.float64], n: NDArray[np.int64]
) -> None:
    """Answer the compiled loop's request with the controller's own objects (their caches)."""
    from pushrecovery.control.recovery import plan_step_now
    from pushrecovery.kernels.batched import stepping as kernel
    from pushrecovery.surfaces.cmp import cmp_region

    height = float(f[kernel.Z])
    body = controller._body(height)  # the controller's own cache, shared
    if request == kernel.NEED_BODY:
        region = cmp_region(body)
        f[kernel.CMP_LO], f[kernel.CMP_HI] = region.lower, region.upper
        f[kernel.ANGLE_LIMIT], f[kernel.BODY_Z] = body.flywheel_angle_max, height
        return
    n[kernel.REPLY] = request
    if request == kernel.NEED_MPC:
        t = int(n[kernel.TICK]) * DEFAULT_CONTROL_PERIOD  # the controller's period
        mpc = controller._mpc(height)
        state = np.array([f[kernel.X], f[kernel.TH], f[kernel.XD], f[kernel.THD]])
        command = mpc.compute(t, state)
        plan = mpc.last_plan
        n[kernel.REPLY_OK] = plan is not None and plan.feasible
        n[kernel.REPLY_FLAG] = command.saturated
        f[kernel.REPLY_COP], f[kernel.REPLY_TAU] = command.cop, command.flywheel_torque
        f[kernel.REPLY_UNTIL] = t + mpc.settings.dt
    else:
        ready, feasible, step_length = plan_step_now(float(f[kernel.X]), float(f[kernel.XD]), body)
        n[kernel.REPLY_OK], n[kernel.REPLY_FLAG] = ready, feasible
        f[kernel.REPLY_STEP] = step_length


def _checked_pushes(
    bodies: Sequence[BodyParams], x0: Sequence[float], xdot: Sequence[float], duration: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], int, int]:
    """Check a batch as the plants' ``reset`` and ``simulate`` do.

    Returns the starts, the speeds, and the ticks of the duration and of the rest criterion
    (1 ms control period).
    """
    require_type("bodies", bodies, (list, tuple))
    for body in bodies:
        require_type("bodies[i]", body, BodyParams)
    starts = sample_array("x0", x0)
    speeds = sample_array("xdot", xdot)
    if not len(bodies) == len(starts) == len(speeds):
        raise InvalidParameterError(
            f"bodies, x0 and xdot must have one entry per push, got {len(bodies)}, "
            f"{len(starts)} and {len(speeds)}"
        )
    for body, start, speed in zip(bodies, starts.tolist(), speeds.tolist(), strict=True):
        check_com_state(start, speed, body)  # as the plants' reset
    dt, rest = DEFAULT_CONTROL_PERIOD, RestCriterion()
    duration = bounded_float("duration", duration, 0.0, MAX_DURATION, "s")
    if duration < dt:  # not one control tick: nothing would be simulated
        raise InvalidParameterError(
            f"duration must be in [{dt:g}, {MAX_DURATION:g}] s (one control tick at least), "
            f"got {duration:g}"
        )
    # As simulate(): whole ticks in the duration, and in the rest criterion's time.
    ticks = math.ceil(duration / dt - 1e-9)
    rest_ticks = max(1, math.ceil(rest.duration / dt - 1e-9))
    return starts, speeds, ticks, rest_ticks
