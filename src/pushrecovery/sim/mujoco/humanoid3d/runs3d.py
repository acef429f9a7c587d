"""A pushed run of the 3-D plants and the critical push from any direction (issue 19, item 4).

:func:`run_push3d`: quiet standing until ``push_time``, the push
(:class:`~pushrecovery.sim.push.Push3D`), then the whole-body controller every
:data:`~.plant3d.CONTROL_PERIOD` until the plant's fall set, rest over the support polygon for
``rest_duration``, or ``duration``: the one loop, :func:`~pushrecovery.sim.simulate.simulate`,
whose :class:`~pushrecovery.sim.result.SimulationResult` carries the run's
:class:`~pushrecovery.sim.result.Push3DExtras` (:func:`pushed_rows`: the rows a reader of the
push sees); a :class:`WbcTrace` passed to it records the controller's figures tick by tick.
:func:`critical_push3d`: the largest impulse at an azimuth that does not fall. The plants are
:mod:`.plant3d`'s.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, flag, require_type
from pushrecovery.control.base import Command
from pushrecovery.control.wbc.bodies import body_id, sole_points
from pushrecovery.control.wbc.controller import WholeBodyController
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.backend import Step
from pushrecovery.sim.critical import bisect_critical
from pushrecovery.sim.events import Observer, ScheduledPush
from pushrecovery.sim.mujoco.humanoid3d.plant3d import (
    CONTROL_PERIOD,
    Humanoid3DPlant,
    wbc_for,
)
from pushrecovery.sim.physical_checks import DEFAULT_SLIP_LIMIT
from pushrecovery.sim.push import PUSH_TIME, Push3D
from pushrecovery.sim.result import Outcome, Push3DExtras, SimulationResult
from pushrecovery.sim.simulate import MAX_DURATION, RestCriterion, simulate

FloatArray = NDArray[np.float64]

__all__ = [
    "PUSH_TIME",
    "CriticalPush3D",
    "WbcTrace",
    "critical_push3d",
    "pushed_rows",
    "run_push3d",
]


def pushed_rows(result: SimulationResult) -> NDArray[np.intp]:
    """Return the rows of a :func:`run_push3d` result that show the push.

    The standing start, then every row from the end of the push on (the rows during the 10 ms
    push left out): what the CLI reports and a filmstrip shows.

    Raises
    ------
    InvalidParameterError
        If ``result`` has no :class:`~pushrecovery.sim.result.Push3DExtras`.
    """
    require_type("result", result, SimulationResult)
    if result.extras is None:
        raise InvalidParameterError("result must be a pushed 3-D run's (run_push3d)")
    return np.r_[0, result.extras.push_row : len(result.time)]


def run_push3d(
    plant: Humanoid3DPlant,
    controller: WholeBodyController,
    push: Push3D,
    *,
    duration: float = 3.0,
    push_time: float = PUSH_TIME,
    rest_speed: float = 5e-3,
    rest_duration: float = 0.5,
    record: bool = False,
    observers: Sequence[Observer] = (),
    slip_limit: float = DEFAULT_SLIP_LIMIT,
) -> SimulationResult:
    """Stand, push, and run the whole-body controller until a decision (module docstring).

    The run is :func:`~pushrecovery.sim.simulate.simulate` (the one loop) with the push at
    ``push_time`` and the controller running on through it: a push held still (the default
    ``Push3D``) lasts physics steps of its own, the motors holding, with a row on either
    side of it; a ``scheduled`` one acts over the next ticks while the controller reacts.
    The rows are the plant's (MuJoCo's clock).

    Parameters
    ----------
    plant : Humanoid3DPlant
        The plant (reset here).
    controller : WholeBodyController
        Its controller (:func:`wbc_for`), reset here on the standing state.
    push : Push3D
        The push, at ``push_time`` (``scheduled``: the controller reacts during it).
    duration : float
        Longest simulated time after the push [s], in (0, 60 − ``push_time``].
    push_time : float
        Quiet standing before the push, in [0, 10] s.
    rest_speed, rest_duration : float
        Recovered after ‖ċ_xy‖ <= rest_speed [m/s] over P for rest_duration [s] (rest_speed
        > 0; at least one tick at rest).
    record : bool
        Keep ``qpos``, ``qvel`` and ``ctrl`` at each row (the extras'), for rendering.
    observers : sequence of Observer
        Also see every control tick (e.g. a :class:`WbcTrace`); not a held push's own steps.
    slip_limit : float
        Largest loaded-foot slip of a run that may count as recovered [m], in [1e-6, 1].

    Returns
    -------
    SimulationResult
        The run, its ``extras`` a :class:`~pushrecovery.sim.result.Push3DExtras`, its
        ``physics`` the plant's :class:`~pushrecovery.sim.physical_checks.PhysicalChecks` of
        the run (a run at rest that slid is ``slipped``, not ``recovered``).
    """
    require_type("plant", plant, Humanoid3DPlant)
    require_type("controller", controller, WholeBodyController)
    require_type("push", push, Push3D)
    push_time = bounded_float("push_time", push_time, 0.0, 10.0, "s")
    duration = bounded_float("duration", duration, 1e-3, MAX_DURATION - push_time, "s")
    rest_speed = bounded_float("rest_speed", rest_speed, 1e-6, 10.0, "m/s")
    rest_duration = bounded_float("rest_duration", rest_duration, 0.0, 60.0, "s")
    plant.audit.slip_limit = bounded_float("slip_limit", slip_limit, 1e-6, 1.0, "m")
    plant.recording = bool(record)
    ticks = round(push_time / CONTROL_PERIOD) + max(1, round(duration / CONTROL_PERIOD))
    figures = _ControllerFigures(controller, plant, round(push_time / CONTROL_PERIOD))
    result = simulate(
        plant, controller, plant.reset(),
        duration=ticks * CONTROL_PERIOD,
        control_period=CONTROL_PERIOD,
        rest=RestCriterion(rest_speed, rest_duration),
        push=ScheduledPush(push_time, push, react=True),
        observers=(figures, *observers),
    )  # fmt: skip
    after = plant.push_row
    if after is None:  # the run ended (fell) before the force did
        after = len(result.time) - 1
    # The motors from the push on against those held before it (row k: tick k's inputs).
    first = round(push_time / CONTROL_PERIOD)
    inputs = result.inputs[first:]
    held = result.inputs[first - 1] if first else np.zeros(len(plant.input_labels))
    hips = plant.hip_motors
    frames = np.array(plant.frames) if record else None
    nq, nv = int(plant.model.nq), int(plant.model.nv)
    extras = Push3DExtras(
        push=push,
        push_row=after,
        peak_hip_torque=figures.peak_hip_torque,
        peak_hip_motor_torque=max(0.0, float(np.abs(inputs - held)[:, hips].max()))
        if hips
        else 0.0,
        max_torso_tilt=plant.max_torso_tilt,
        peak_torque=float(np.abs(inputs).max(initial=0.0)),
        failed_ticks=figures.failed_ticks,
        steps=_landed(controller),
        qpos=None if frames is None else frames[:, :nq],
        qvel=None if frames is None else frames[:, nq : nq + nv],
        ctrl=None if frames is None else frames[:, nq + nv :],
    )
    return replace(result, extras=extras)  # the loop judged the outcome by the audit


class WbcTrace:
    """Observer of a :func:`run_push3d` run, tick by tick: the body and its controller's QP.

    Row k is control tick k (a push held still lasts 10 ms of no tick; a scheduled one acts
    during ticks): the body at the tick's end, ``time`` [s] (MuJoCo's clock), and the
    controller's figures of the command held over it, computed at ``time`` −
    :data:`~.plant3d.CONTROL_PERIOD`.

    Parameters
    ----------
    plant : Humanoid3DPlant
        The run's plant.
    controller : WholeBodyController
        Its controller.

    Attributes
    ----------
    time : float array, shape (n,)
        [s].
    pelvis : float array, shape (n, 3)
        The upright body's origin [m] (world).
    torso_tilt : float array, shape (n,)
        Angle between the upright body's z axis and the vertical [rad].
    sole_lift : float array, shape (n, len(feet))
        Each foot's highest sole point above z = 0 [m] (0 on the floor).
    wrenches : float array, shape (n, len(feet), 6)
        The QP's wrench per foot (F, T) in its sole frame [N, N m].
    desired_cop : float array, shape (n, 2)
        The DCM law's CoP [m] (world xy).
    cmp_offset : float array, shape (n, 2)
        The hip law's CMP offset δ from the CoP [m] (0 with the ankles only).
    ok : bool array, shape (n,)
        Whether DAQP solved the tick.
    """

    _FIELDS = ("time", "pelvis", "torso_tilt", "sole_lift", "wrenches", "desired_cop",
               "cmp_offset", "ok")  # fmt: skip

    def __init__(self, plant: Humanoid3DPlant, controller: WholeBodyController) -> None:
        require_type("plant", plant, Humanoid3DPlant)
        require_type("controller", controller, WholeBodyController)
        self.plant, self.controller = plant, controller
        self._upright = body_id(plant.model, plant.upright)
        self._feet = [body_id(plant.model, foot) for foot in plant.feet]
        self._rows: dict[str, list[object]] = {name: [] for name in self._FIELDS}

    def on_step(self, index: int, step: Step, command: Command) -> None:
        """Keep the tick's row (class docstring)."""
        plant, controller, rows, feet = self.plant, self.controller, self._rows, self._feet
        model, data, solution = plant.model, plant.data, controller.last
        assert solution is not None  # the tick computed its command
        rows["time"].append(plant.clock)
        rows["pelvis"].append(np.array(data.xpos[self._upright]))
        rows["torso_tilt"].append(plant.torso_tilt())
        rows["sole_lift"].append([float(sole_points(model, data, f)[:, 2].max()) for f in feet])
        rows["wrenches"].append(solution.wrenches.copy())
        rows["desired_cop"].append(controller.desired_cop.copy())
        rows["cmp_offset"].append(controller.cmp_offset.copy())
        rows["ok"].append(solution.ok)

    def __getattr__(self, name: str) -> NDArray[np.generic]:
        """Return the column ``name`` (class docstring) as an array."""
        if name in WbcTrace._FIELDS:
            return np.array(self.__dict__["_rows"][name])
        raise AttributeError(name)


class _ControllerFigures:
    """Observer of the controller's figures: DAQP's failed ticks, the hip law's peak after the push.

    Parameters
    ----------
    controller : WholeBodyController
        The controller of the run (its ``last`` solve and ``cmp_offset`` after each tick).
    plant : Humanoid3DPlant
        Its plant (the body's weight).
    push_tick : int
        The plant step at which the push comes.
    """

    def __init__(
        self, controller: WholeBodyController, plant: Humanoid3DPlant, push_tick: int
    ) -> None:
        self.controller, self.push_tick = controller, push_tick
        self.weight = plant.params.mass * plant.params.gravity
        self.failed_ticks = 0
        self.peak_hip_torque = 0.0

    def on_step(self, index: int, step: Step, command: Command) -> None:
        """Count a failed solve; after the push, keep the largest m g abs(δ) [N m]."""
        controller = self.controller
        self.failed_ticks += 0 if controller.last is None or controller.last.ok else 1
        if index >= self.push_tick:
            offset = self.weight * float(np.hypot(*controller.cmp_offset))
            self.peak_hip_torque = max(self.peak_hip_torque, offset)


def _landed(controller: WholeBodyController) -> int:
    """Return the steps of ``controller``'s stepping task that touched down."""
    stepper = controller.stepper
    if stepper is None:
        return 0
    return sum(1 for step in stepper.steps if step.touchdown is not None)


@dataclass(frozen=True)
class CriticalPush3D:
    """The largest recovered impulse at one azimuth (:func:`critical_push3d`).

    Attributes
    ----------
    impulse : float
        The largest impulse that did not fall [N s] (the bracket's low end).
    bracket : tuple of float
        (stood, fell) impulses [N s], at most ``tolerance`` apart.
    simulations : int
        Runs made.
    strategy : str
        The strategy of the run at ``impulse``.
    foot_slip : float
        The largest loaded-foot slip of the run at ``impulse`` [m] (0 when no run stood): a
        run that slid stands for the bisection (it did not fall) but is ``slipped``, not
        ``recovered`` (:mod:`pushrecovery.sim.physical_checks`).
    """

    impulse: float
    bracket: tuple[float, float]
    simulations: int
    strategy: str
    foot_slip: float = 0.0


def critical_push3d(
    plant: Humanoid3DPlant,
    azimuth: float,
    *,
    tolerance: float = 0.5,
    duration: float = 3.0,
    body: str = "torso",
    hip: bool | None = None,
    stepping: bool = False,
) -> CriticalPush3D:
    """Bisect the impulse at ``azimuth`` [deg] between a run that stands and one that falls.

    The upper end starts at m · 0.25 m/s and doubles while the body recovers (up to the
    push's largest impulse); then the bracket halves until it is at most ``tolerance`` [N s]
    wide (in (0, 1e3]). Each run is :func:`run_push3d` with the plant's WBC
    (:func:`~.plant3d.wbc_for` with ``hip``, None: the plant's own choice, the hip task on the
    biped3d, not on the G1, whose critical pushes it lowers; with ``stepping`` the stepping
    task, reacting during the push, ``Push3D(scheduled=True)``), ``duration`` [s] after the
    push; a run that has not fallen by then (recovered, slipped or still undecided) counts as
    standing: falls are decided within a second, rest takes seconds.
    """
    require_type("plant", plant, Humanoid3DPlant)
    tolerance = bounded_float("tolerance", tolerance, 1e-6, 1e3, "N s")
    Push3D(0.0, azimuth, body)  # checks azimuth and body
    stepping = flag("stepping", stepping)
    wbc_for(plant, hip=hip, stepping=stepping)  # checks hip before any run
    slips: dict[float, float] = {}

    def recovers(impulse: float) -> tuple[bool, str]:
        run = run_push3d(plant, wbc_for(plant, hip=hip, stepping=stepping),
                         Push3D(impulse, azimuth, body, scheduled=stepping),
                         duration=duration)  # fmt: skip
        slips[impulse] = 0.0 if run.physics is None else run.physics.foot_slip
        return run.outcome is not Outcome.FELL, run.strategy_used().value

    low, bracket, strategy = bisect_critical(recovers, 0.0, 0.25 * plant.params.mass, tolerance)
    return CriticalPush3D(low, bracket, len(slips), strategy, slips.get(low, 0.0))
