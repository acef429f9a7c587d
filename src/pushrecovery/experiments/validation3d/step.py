r"""The step column of the 3-D validation: the critical push with stepping, from every direction.

Issue 19 item 5 (the step column beside :mod:`~pushrecovery.experiments.validation3d`'s ankle
and hip columns). For a 3-D model (the generated ``biped3d``, or the ``g1`` with the ``robots``
extra) and each push azimuth ψ (0 forward +x, 90 left +y, degrees):

**Predicted** (the library's one-step capturability, :mod:`pushrecovery.surfaces.n_step`). A push
J at ψ puts the capture point of the standing body (CoM ground point r₀) at
ξ = r₀ + J/(m ω) (cos ψ, sin ψ). One step captures it when ξ lies in

.. math:: C_1 = (1 - a_1) S \oplus a_1 (q_0 + F \oplus R), \qquad a_1 = e^{-\omega \Delta t_s},

(S1) of ``n_step`` with N = 1 and no hip (the controller plans without its hip task): S the
stance foot, q₀ its ankle, F the landing foot, R the reach disc of radius ``max_step_length``,
Δt_s = ``min_step_time`` after the push (``viable_region``). The foot on the push's side
swings (the library's rule, ``capture_region``: the left for 0 ≤ ψ ≤ 180°), as the controller
does; the critical impulse is J* = m ω ρ_{C_1}(r₀, ψ), ρ the distance from r₀ to C₁'s edge
along ψ. Beside the +y edge of C₁ for a left step of a rectangle foot, ρ = w/2 − s/2 + a₁ l
(w the foot's width, s the stance width, l the reach).
**Corrected** (the push's height, as the ankle and hip columns): J*/(1 + d/z₀).

**Measured.** The largest impulse at ψ the body stands (:func:`~.runs3d.run_push3d` at the
plant's pushed body, its whole-body controller with ``stepping=True``: ankles and steps, no
hip task, reacting through the push's 10 ms as a robot's would: ``Push3D(...,
scheduled=True)``) by :func:`~pushrecovery.sim.critical.bisect_critical`: a run *falls* when
it ends in the plant's fall set (under a controller that steps: the CoM below 0.7 z₀,
``plant3d``) or the torso
tilted more than 1 rad after the push, or ends with ξ more than :data:`FALL_MARGIN` outside
the support polygon of the feet it stands on then (undecided within ``duration``). Each stood
run at the measured impulse reports its steps, their longest swing time and its largest
foothold distance from the stance ankle.

**Cause** (:meth:`StepRow.cause`), where measured and predicted differ by more than 10 %:
the simple model takes a touchdown Δt_s after the push and a step as long as
``max_step_length``; the biped's swing lasts what its hip motors drive
(``control.wbc.stepper.leg.leg_swing_time``), and its leg, standing with the hip ~0.99 ℓ above the
ankle, reaches far less than ℓ: the stepper lowers the pelvis for a long step
(``StepSettings.knee_reach``, ``max_drop`` 0.2 m), which still leaves it short of ℓ. After a
touchdown the trailing foot steps (``control.wbc.stepper.plan.choose_step``): several steps count.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.experiments.validation3d import CURVE_AZIMUTHS, DEFAULT_AZIMUTHS, MAX_RUNS
from pushrecovery.experiments.validation3d.predict import CriticalErrors, critical_impulse_along
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import Backend
from pushrecovery.surfaces.n_step import step_options, viable_region

if TYPE_CHECKING:
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant

__all__ = [
    "FALL_MARGIN",
    "StepRow",
    "StepValidation",
    "measure_step_critical",
    "predicted_step_critical",
    "run_step_validation",
]

#: A run ending with ξ this far outside its feet's support polygon fell [m].
FALL_MARGIN = 0.05


def predicted_step_critical(
    params: BodyParams,
    azimuth: float,
    *,
    origin: tuple[float, float] | None = None,
    step_time: float | None = None,
) -> float:
    """Return the one-step critical impulse m ω ρ_{C_1}(r₀, ψ) [N s] (module docstring).

    Parameters
    ----------
    params : BodyParams
        The body (mass, ω, feet, stance, ``max_step_length``, ``min_step_time``).
    azimuth : float
        ψ [deg] in [−360, 360], 0 forward, 90 left.
    origin : (float, float), optional
        r₀ [m]; default the ankles' midpoint.
    step_time : float, optional
        Δt_s [s] in [0, 5]; default ``params.min_step_time``.
    """
    require_type("params", params, BodyParams)
    support = Support.from_params(params)
    start = support.ankle if origin is None else origin
    t = params.min_step_time if step_time is None else step_time
    t = bounded_float("step_time", t, 0.0, 5.0, "s")
    heading = bounded_float("azimuth", azimuth, -360.0, 360.0, "deg")
    swing = Stance.LEFT if math.sin(math.radians(heading)) >= 0.0 else Stance.RIGHT
    option = step_options(params, support, swing)[0]
    region = viable_region(params, option, (t,), hip=False)
    return critical_impulse_along(region, start, heading, params.mass, params.omega)


@dataclass(frozen=True)
class SteppingRun:
    """What one stepping run did: whether it stood, its steps, longest swing [s] and reach [m].

    The reach is the largest distance of a landed ankle from the stance ankle [m]; the foot
    slip [m] and peak vertical ground force [m g] are the run's physical checks
    (docs/physical_checks.md; NaN: no run).
    """

    stood: bool
    steps: int
    swing_time: float
    step_length: float
    foot_slip: float = math.nan
    peak_force: float = math.nan


def _stepping_run(plant: Humanoid3DPlant, impulse: float, azimuth: float, duration: float,
                  swing_time: float | None) -> SteppingRun:  # fmt: skip
    from pushrecovery.control.wbc.controller import WholeBodyController
    from pushrecovery.control.wbc.stepper.settings import StepSettings
    from pushrecovery.sim.mujoco.humanoid3d.measure import body_origins
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import run_push3d
    from pushrecovery.sim.push import Push3D
    from pushrecovery.sim.result import Outcome

    controller = WholeBodyController(plant.model, plant.feet, plant.upright,
                                     observation=plant.observation, stepping=True,
                                     params=plant.params,
                                     step_settings=StepSettings(swing_time=swing_time))  # fmt: skip
    push = Push3D(impulse, azimuth, scheduled=True)  # the controller reacts during it
    run = run_push3d(plant, controller, push, duration=duration)
    assert run.extras is not None
    down = run.outcome is Outcome.FELL or run.extras.max_torso_tilt > 1.0
    xi = run.states[-1, :2] + run.states[-1, 3:5] / controller.omega
    assert controller.support is not None
    outside = -float(controller.support.point_signed_distance(float(xi[0]), float(xi[1])))
    stepper = controller.stepper
    assert stepper is not None
    landed = [s for s in stepper.steps if s.landed is not None]
    # Each foothold's distance from the stance foot's (the reach R of (S1)), from where the
    # feet stood (the foot bodies' origins, as ``StepRecord.landed``).
    origins = body_origins(plant.model, plant.qpos, plant.feet)
    where = {foot: xyz[:2] for foot, xyz in origins.items()}
    reaches = []
    for step in landed:
        (other,) = (foot for foot in plant.feet if foot != step.foot)
        assert step.landed is not None
        reaches.append(float(np.linalg.norm(step.landed - where[other])))
        where[step.foot] = step.landed
    swings = [s.touchdown - s.liftoff for s in landed if s.touchdown is not None]
    assert run.physics is not None  # run_push3d's
    return SteppingRun(
        stood=not down and outside <= FALL_MARGIN,
        steps=len(stepper.steps),
        swing_time=max(swings, default=0.0),
        step_length=max(reaches, default=0.0),
        foot_slip=run.physics.foot_slip,
        peak_force=run.physics.peak_force_ratio,
    )


@dataclass(frozen=True)
class StepRow(CriticalErrors):
    """One azimuth of the step column.

    Attributes
    ----------
    azimuth : float
        ψ [deg].
    predicted, corrected : float
        The one-step critical impulse m ω ρ_{C_1} and it over (1 + d/z₀) [N s].
    measured : float
        The largest impulse that stood [N s] (0 when none of the bracket's did).
    bracket : (float, float)
        (stood, fell) [N s].
    runs : int
        Simulations of the bisection.
    steps : int
        Steps taken in the run at ``measured``.
    swing_time, step_length : float
        That run's longest swing (lift-off to touchdown) [s] and its largest distance from a
        landed ankle to the stance ankle [m] (the reach of (S1)).
    refit : float
        The corrected prediction with that swing as Δt_s and that step as the reach [N s]
        (nan when no step landed): the simple model given the biped's own step.
    foot_slip, peak_force : float
        That run's largest loaded-foot slip [m] and vertical ground force / (m g) [-] (a
        landing's strike; NaN: unknown).
    """

    azimuth: float
    predicted: float
    corrected: float
    measured: float
    bracket: tuple[float, float]
    runs: int
    steps: int
    swing_time: float
    step_length: float
    refit: float = math.nan
    foot_slip: float = math.nan
    peak_force: float = math.nan

    def cause(self, params: BodyParams) -> str:
        """Name the simple model's assumptions the run broke (module docstring), or ``""``."""
        if abs(self.corrected_error) <= 0.1:
            return ""
        causes = []
        if self.swing_time > params.min_step_time + 0.02:
            causes.append(f"swing {self.swing_time:.2f} s > Δt_s {params.min_step_time:g} s")
        if self.step_length < 0.8 * params.max_step_length:
            causes.append(f"step {self.step_length:.2f} m < reach {params.max_step_length:.3g} m")
        if self.steps > 1:
            causes.append(f"{self.steps} steps")
        return "; ".join(causes)


@dataclass(frozen=True)
class StepValidation:
    """The step column of one body (:func:`run_step_validation`).

    Attributes
    ----------
    params : BodyParams
        The body.
    rows : tuple of StepRow
        By azimuth.
    origin : (float, float)
        r₀ [m].
    lever, standing_height : float
        d and z₀ of the correction [m].
    rel_tolerance, duration : float
        The bisection's width (fraction of the corrected prediction) and each run's time [s].
    model : str
        The 3-D model measured (``biped3d`` or ``g1``).
    curve : tuple of float
        The one-step critical impulse m ω ρ_{C_1}(r₀, ψ) [N s] at every azimuth of
        ``validation3d.CURVE_AZIMUTHS`` (empty for a result made without it).
    """

    params: BodyParams
    rows: tuple[StepRow, ...]
    origin: tuple[float, float]
    lever: float
    standing_height: float
    rel_tolerance: float
    duration: float
    model: str = "biped3d"
    curve: tuple[float, ...] = ()

    def to_table(self) -> str:
        """Return the rows as a markdown table (impulses [N s], errors in %)."""
        lines = [
            "| azimuth [deg] | predicted [N s] | corrected [N s] | measured [N s] | error | "
            "error vs corrected | steps | swing [s] | step [m] | refit [N s] | foot slip [mm] | "
            "peak force [m g] | cause |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
        ]
        for row in self.rows:
            lines.append(
                f"| {row.azimuth:g} | {row.predicted:.1f} | {row.corrected:.1f} | "
                f"{row.measured:.1f} (fell {row.bracket[1]:.1f}) | "
                f"{100 * row.relative_error:+.1f} % | {100 * row.corrected_error:+.1f} % | "
                f"{row.steps} | {row.swing_time:.2f} | {row.step_length:.2f} | "
                f"{row.refit:.1f} | {1e3 * row.foot_slip:.1f} | {row.peak_force:.1f} | "
                f"{row.cause(self.params)} |"
            )
        return "\n".join(lines)


def measure_step_critical(
    params: BodyParams,
    azimuth: float,
    *,
    guess: float,
    rel_tolerance: float = 0.02,
    duration: float = 3.0,
    swing_time: float | None = None,
    plant: Humanoid3DPlant | None = None,
) -> tuple[float, tuple[float, float], int, SteppingRun]:
    """Bisect the largest impulse at ``azimuth`` [deg] the body stands with stepping.

    The bracket starts at 0.5 and 1.0 × ``guess`` [N s] (> 0), widens (×0.7 down, ×1.3 up)
    until it holds a stand and a fall, then halves to ``rel_tolerance`` × guess (in [1e-3,
    0.5]); ``duration`` [s] in (0, 59.9] after a push at 0.1 s (module docstring); the
    controller's shortest swing ``swing_time`` [s] (``StepSettings``; None: the body's
    ``min_step_time``). The body: ``plant``'s (a 3-D plant, ``Biped3DPlant`` or ``G1Plant``,
    of ``params``), else the biped3d of ``params``. Returns the measured impulse, the
    bracket, the runs made and the run at the measured impulse.
    """
    from pushrecovery.sim.critical import bisect_critical
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, Humanoid3DPlant
    from pushrecovery.sim.push import IMPULSE_MAX, Push3D

    require_type("params", params, BodyParams)
    guess = bounded_float("guess", guess, 1e-6, IMPULSE_MAX, "N s")
    rel_tolerance = bounded_float("rel_tolerance", rel_tolerance, 1e-3, 0.5)
    duration = bounded_float("duration", duration, 1e-3, 59.9, "s")
    Push3D(0.0, azimuth)  # checks the azimuth
    if plant is None:
        plant = Biped3DPlant(params)
    require_type("plant", plant, Humanoid3DPlant)
    if plant.params != params:
        raise InvalidParameterError("plant must be of the body params (plant.params)")
    done: dict[float, SteppingRun] = {}

    def stands(impulse: float) -> tuple[bool, str]:
        if len(done) >= MAX_RUNS:
            raise InvalidParameterError(
                f"guess {guess:g} N s: no stand/fall bracket within {MAX_RUNS} runs"
            )
        done[impulse] = _stepping_run(plant, impulse, azimuth, duration, swing_time)
        return done[impulse].stood, "step" if done[impulse].steps else "ankle"

    low, bracket, _ = bisect_critical(stands, 0.5 * guess, guess, rel_tolerance * guess,
                                      grow=1.3, shrink=0.7)  # fmt: skip
    return low, bracket, len(done), done.get(low, SteppingRun(False, 0, 0.0, 0.0))


def run_step_validation(
    azimuths: Sequence[float] = DEFAULT_AZIMUTHS,
    *,
    model: str = "biped3d",
    params: BodyParams | None = None,
    rel_tolerance: float = 0.02,
    duration: float = 3.0,
    swing_time: float | None = None,
    plant: Humanoid3DPlant | None = None,
) -> StepValidation:
    """Predict and measure the step critical impulse of a 3-D model at each azimuth.

    Parameters
    ----------
    azimuths : sequence of float
        ψ [deg], each in [−360, 360]; 1 to 72 of them.
    model : str
        ``biped3d`` or ``g1`` (needs the ``robots`` extra: ``RobotsExtraMissing`` otherwise).
    params : BodyParams, optional
        The biped3d's body (default the ``paper`` preset); the G1's must be its own.
    rel_tolerance : float
        The bisection's width as a fraction of the corrected prediction, in [1e-3, 0.5].
    duration : float
        Simulated time of each run after its push [s], in (0, 59.9].
    swing_time : float, optional
        The controller's shortest swing [s] (``StepSettings``); default the body's
        ``min_step_time``, the prediction's Δt_s.
    plant : Humanoid3DPlant, optional
        The plant to validate (an MJCF file's; ``model`` then only names it); default the
        built-in ``model``'s.

    Raises
    ------
    InvalidParameterError
        Naming the bad argument.
    """
    require_type("model", model, str)
    if params is not None:
        require_type("params", params, BodyParams)
    if plant is not None:
        require_type("plant", plant, Backend)
    from pushrecovery.experiments.validation3d import MODELS, azimuth_list, validation_plant

    if plant is None and model not in MODELS:
        raise InvalidParameterError(f"model must be one of {list(MODELS)}, got {model!r}")
    angles = azimuth_list(azimuths)
    if params is not None:
        require_type("params", params, BodyParams)
    rel_tolerance = bounded_float("rel_tolerance", rel_tolerance, 1e-3, 0.5)
    duration = bounded_float("duration", duration, 1e-3, 59.9, "s")
    plant = validation_plant(model, params) if plant is None else plant
    params, origin, height = plant.params, plant.standing_origin, float(plant.standing_height)
    lever = plant.push_lever
    factor = 1.0 / (1.0 + lever / height)
    rows = []
    for angle in angles:
        predicted = predicted_step_critical(params, angle, origin=origin)
        measured, bracket, runs, run = measure_step_critical(
            params, angle, guess=factor * predicted, rel_tolerance=rel_tolerance,
            duration=duration, swing_time=swing_time, plant=plant,
        )  # fmt: skip
        refit = math.nan
        if run.step_length > 0.0:
            own = replace(params, max_step_length=run.step_length)
            refit = factor * predicted_step_critical(own, angle, origin=origin,
                                                     step_time=run.swing_time)  # fmt: skip
        rows.append(StepRow(angle, predicted, factor * predicted, measured, bracket, runs,
                            run.steps, run.swing_time, run.step_length, refit,
                            run.foot_slip, run.peak_force))  # fmt: skip
    curve = tuple(predicted_step_critical(params, a, origin=origin) for a in CURVE_AZIMUTHS)
    return StepValidation(params, tuple(rows), origin, lever, height, rel_tolerance, duration,
                          model, curve)  # fmt: skip
