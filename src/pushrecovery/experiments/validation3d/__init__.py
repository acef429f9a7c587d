r"""The 2-D prediction of the critical push against the 3-D bodies, from every direction.

For a 3-D model (``biped3d``, or ``g1`` with the ``robots`` extra) and push azimuths ψ (0 forward
+x, 90 left +y, degrees), each strategy's **predicted** critical impulse J* = m ω ρ_R(r₀, ψ)
comes from the ground plane's regions (:mod:`~pushrecovery.experiments.validation3d.predict`),
its **corrected** one J*/(1 + d/z₀) puts back the push's height d above the CoM, and its
**measured** one is bisected under the whole-body controller in MuJoCo
(:func:`measure_critical_impulse`). The relative error is (measured − predicted)/predicted.
docs/validation3d.md, "The critical push from every direction", has the derivation and the
numbers.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from pushrecovery.arguments import bounded_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.experiments.validation3d.predict import (
    CriticalErrors,
    critical_impulse_along,
    predicted_critical_impulses,
)
from pushrecovery.params import BodyParams
from pushrecovery.sim.backend import Backend

if TYPE_CHECKING:
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Humanoid3DPlant

__all__ = [
    "CURVE_AZIMUTHS",
    "DEFAULT_AZIMUTHS",
    "MODELS",
    "STRATEGIES",
    "MeasuredCritical",
    "Validation3D",
    "ValidationRow",
    "azimuth_list",
    "critical_impulse_along",
    "measure_critical_impulse",
    "predicted_critical_impulses",
    "run_validation3d",
    "validation_plant",
]

#: Push azimuths of the validation [deg]: every 30°.
DEFAULT_AZIMUTHS: tuple[float, ...] = tuple(float(a) for a in range(0, 360, 30))
#: Where the prediction is drawn as a curve, every 2° [deg]: the regions' edges are polygons,
#: whose ray distance is not a straight line between the measured azimuths.
CURVE_AZIMUTHS: tuple[float, ...] = tuple(float(a) for a in range(0, 361, 2))
#: Strategies with a 2-D prediction and a WBC that uses only them (no stepping task yet).
STRATEGIES: tuple[str, ...] = ("ankle", "hip")
#: The 3-D models (``sim.registry.PLANTS_3D``).
MODELS: tuple[str, ...] = ("biped3d", "g1")
#: Most runs of one bisection (the bracket's widening included).
MAX_RUNS = 40


@dataclass(frozen=True)
class MeasuredCritical:
    """One measured critical impulse (:func:`measure_critical_impulse`).

    Attributes
    ----------
    impulse : float
        The largest impulse that stood (the bracket's low end) [N s].
    bracket : (float, float)
        (stood, fell) [N s].
    runs : int
        Simulations made.
    strategy_used : str
        The strategy of the run at ``impulse`` (``sim.result.strategy_used``).
    foot_slip : float
        The run at ``impulse``: its largest loaded-foot slip [m] (NaN: no run stood).
    peak_force : float
        The run at ``impulse``: its largest vertical ground force / (m g) [-] (NaN: none).
    """

    impulse: float
    bracket: tuple[float, float]
    runs: int
    strategy_used: str
    foot_slip: float = math.nan
    peak_force: float = math.nan


def measure_critical_impulse(
    plant: Humanoid3DPlant,
    azimuth: float,
    *,
    hip: bool,
    guess: float,
    rel_tolerance: float = 0.01,
    duration: float = 3.0,
) -> MeasuredCritical:
    """Bracket and bisect the critical impulse at ``azimuth`` under the WBC.

    The largest impulse that does not fall within ``duration`` (a run still undecided counts as
    standing), under the WBC with the ankles only (``hip=False``) or with its hip task. The
    bracket starts at 0.8 and 1.2 × ``guess``, widens (×0.7 down, ×1.3 up) until it holds a
    stand and a fall, then halves until at most ``rel_tolerance`` × ``guess`` wide; the
    measured value is its low end.

    Parameters
    ----------
    plant : Humanoid3DPlant
        The 3-D plant (reset by each run).
    azimuth : float
        ψ [deg].
    hip : bool
        Whether the WBC has its hip task (False: ankles only).
    guess : float
        Where the bracket starts, 0.8 and 1.2 × guess (> 0) [N s].
    rel_tolerance : float
        The final bracket's width as a fraction of ``guess``, in [1e-4, 0.5].
    duration : float
        Simulated time after the push, in (0, 60] s.

    Raises
    ------
    InvalidParameterError
        For a non-positive guess, a tolerance or duration out of range.
    """
    from pushrecovery.sim.critical import bisect_critical
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import wbc_for
    from pushrecovery.sim.mujoco.humanoid3d.runs3d import run_push3d
    from pushrecovery.sim.push import IMPULSE_MAX, Push3D
    from pushrecovery.sim.result import Outcome

    guess = bounded_float("guess", guess, 1e-6, IMPULSE_MAX, "N s")
    rel_tolerance = bounded_float("rel_tolerance", rel_tolerance, 1e-4, 0.5)
    duration = bounded_float("duration", duration, 1e-3, 60.0, "s")
    Push3D(0.0, azimuth)  # checks the azimuth
    runs = 0
    checks: dict[float, tuple[float, float]] = {}  # impulse -> (foot slip, peak force)

    def stands(impulse: float) -> tuple[bool, str]:
        nonlocal runs
        runs += 1
        if runs > MAX_RUNS:
            raise InvalidParameterError(
                f"guess {guess:g} N s: no stand/fall bracket within {MAX_RUNS} runs"
            )
        run = run_push3d(
            plant, wbc_for(plant, hip=hip), Push3D(impulse, azimuth), duration=duration
        )
        if run.physics is not None:
            checks[impulse] = (run.physics.foot_slip, run.physics.peak_force_ratio)
        return run.outcome is not Outcome.FELL, run.strategy_used().value

    low, bracket, used = bisect_critical(
        stands, 0.8 * guess, min(1.2 * guess, IMPULSE_MAX), rel_tolerance * guess,
        grow=1.3, shrink=0.7,
    )  # fmt: skip
    slip, peak = checks.get(low, (math.nan, math.nan))
    return MeasuredCritical(low, bracket, runs, used, slip, peak)


@dataclass(frozen=True)
class ValidationRow(CriticalErrors):
    """One azimuth and strategy of the validation.

    Attributes
    ----------
    azimuth : float
        ψ [deg].
    strategy : str
        ``ankle`` or ``hip``.
    predicted : float
        m ω ρ_R(r₀, ψ), ρ_R the distance from r₀ to the region's boundary along ψ [N s].
    corrected : float
        predicted / (1 + d/z₀): the push at the torso's height [N s].
    measured : float
        The largest impulse that stood [N s].
    bracket : (float, float)
        (stood, fell) [N s].
    runs : int
        Simulations of the bisection.
    strategy_used : str
        The strategy of the run at ``measured``.
    foot_slip : float
        That run's largest loaded-foot slip [m] (docs/physical_checks.md; NaN: unknown).
    peak_force : float
        That run's largest vertical ground force / (m g) [-] (NaN: unknown).
    """

    azimuth: float
    strategy: str
    predicted: float
    corrected: float
    measured: float
    bracket: tuple[float, float]
    runs: int
    strategy_used: str
    foot_slip: float = math.nan
    peak_force: float = math.nan


@dataclass(frozen=True)
class Validation3D:
    """The validation of one model (:func:`run_validation3d`).

    Attributes
    ----------
    model : str
        ``biped3d`` or ``g1``.
    rows : tuple of ValidationRow
        Azimuth-major, strategies in the order asked.
    mass, omega : float
        m [kg] and ω [1/s] of the prediction.
    origin : (float, float)
        The standing CoM's ground point r₀ [m].
    lever, standing_height : float
        d and z₀ of the correction [m].
    rel_tolerance, duration : float
        The bisection's width (fraction of the prediction) and each run's time after the push
        [s].
    strategies : tuple of str
        The strategies measured.
    curves : tuple of (str, tuple of float)
        Per strategy, the predicted critical impulse m ω ρ_R(r₀, ψ) [N s] at every azimuth of
        :data:`CURVE_AZIMUTHS` (the corrected one is it over 1 + d/z₀); empty for a result
        made without it.
    """

    model: str
    rows: tuple[ValidationRow, ...]
    mass: float
    omega: float
    origin: tuple[float, float]
    lever: float
    standing_height: float
    rel_tolerance: float
    duration: float
    strategies: tuple[str, ...] = field(default=STRATEGIES)
    curves: tuple[tuple[str, tuple[float, ...]], ...] = ()

    def rows_for(self, strategy: str) -> tuple[ValidationRow, ...]:
        """Return the rows of ``strategy``, by azimuth."""
        return tuple(row for row in self.rows if row.strategy == strategy)

    def worst_error(self, strategy: str, *, corrected: bool = False) -> float:
        """Largest abs(relative error) of ``strategy`` (against the corrected value if asked)."""
        errors = [
            abs(row.corrected_error if corrected else row.relative_error)
            for row in self.rows_for(strategy)
        ]
        if not errors:
            raise InvalidParameterError(f"strategy {strategy!r} was not run")
        return max(errors)

    def to_table(self) -> str:
        """Return the rows as a markdown table (impulses [N s], errors in %)."""
        lines = [
            "| azimuth [deg] | strategy | predicted [N s] | measured [N s] | error | "
            "corrected [N s] | error vs corrected | used | foot slip [mm] | peak force [m g] |",
            "|---:|---|---:|---:|---:|---:|---:|---|---:|---:|",
        ]
        for row in self.rows:
            lines.append(
                f"| {row.azimuth:g} | {row.strategy} | {row.predicted:.1f} | "
                f"{row.measured:.1f} (fell {row.bracket[1]:.1f}) | "
                f"{100 * row.relative_error:+.1f} % | {row.corrected:.1f} | "
                f"{100 * row.corrected_error:+.1f} % | {row.strategy_used} | "
                f"{1e3 * row.foot_slip:.1f} | {row.peak_force:.2f} |"
            )
        return "\n".join(lines)


def azimuth_list(azimuths: Sequence[float]) -> list[float]:
    """Return ``azimuths`` [deg] as floats: a sequence of 1 to 72 angles in [-360, 360].

    Raises
    ------
    InvalidParameterError
        Not a sequence (a str is not one), too few or many angles, or one out of range.
    """
    if isinstance(azimuths, str | bytes) or not isinstance(azimuths, Sequence):
        raise InvalidParameterError("azimuths must be a sequence of angles [deg]")
    if not 1 <= len(azimuths) <= 72:
        raise InvalidParameterError(f"azimuths must hold 1 to 72 angles, got {len(azimuths)}")
    return [bounded_float("azimuths", a, -360.0, 360.0, "deg") for a in azimuths]


def validation_plant(model: str, params: BodyParams | None = None) -> Humanoid3DPlant:
    """Return the 3-D plant that ``model`` is validated on.

    Parameters
    ----------
    model : str
        ``biped3d`` (its body ``params``, default the ``paper`` preset) or ``g1`` (``params``
        None or the robot's own; needs the ``robots`` extra).
    params : BodyParams, optional
        The body.

    Raises
    ------
    InvalidParameterError
        If ``model`` is not one of :data:`MODELS`, or ``params`` is not a BodyParams (or not
        the G1's own).
    """
    require_type("model", model, str)
    if params is not None:
        require_type("params", params, BodyParams)
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant, G1Plant

    if model not in MODELS:
        raise InvalidParameterError(f"model must be one of {list(MODELS)}, got {model!r}")
    if params is not None:
        require_type("params", params, BodyParams)
    if model == "biped3d":
        if params is None:
            from pushrecovery.presets import load_params

            params = load_params()
        return Biped3DPlant(params)
    from pushrecovery.sim.mujoco.humanoid3d.robots import robot_params

    return G1Plant(robot_params("g1") if params is None else params)


def run_validation3d(
    model: str = "biped3d",
    azimuths: Sequence[float] = DEFAULT_AZIMUTHS,
    strategies: Sequence[str] = STRATEGIES,
    *,
    params: BodyParams | None = None,
    rel_tolerance: float = 0.01,
    duration: float = 3.0,
    plant: Humanoid3DPlant | None = None,
) -> Validation3D:
    """Predict and measure each strategy's critical impulse at each azimuth (module doc).

    Parameters
    ----------
    model : str
        ``biped3d`` or ``g1`` (needs the ``robots`` extra: ``RobotsExtraMissing`` otherwise).
    azimuths : sequence of float
        ψ [deg], each in [−360, 360]; at least one, at most 72.
    strategies : sequence of str
        Among ``ankle`` and ``hip``, without repeats.
    params : BodyParams, optional
        The biped3d's body (default the ``paper`` preset); the G1's must be its own.
    rel_tolerance : float
        The bisection's final width as a fraction of the prediction, in [1e-4, 0.5].
    duration : float
        Simulated time after each push, in (0, 60] s (a run not fallen by then stands).
    plant : Humanoid3DPlant, optional
        The plant to validate (an MJCF file's, :mod:`~pushrecovery.sim.mujoco.humanoid3d.mjcf`;
        ``model`` then only names it); default the built-in ``model``'s.

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
    if plant is None and model not in MODELS:
        raise InvalidParameterError(f"model must be one of {list(MODELS)}, got {model!r}")
    angles = azimuth_list(azimuths)
    if isinstance(strategies, str) or not isinstance(strategies, Sequence):
        raise InvalidParameterError(f"strategies must be a sequence of {list(STRATEGIES)}")
    chosen = tuple(strategies)
    if not chosen or len(set(chosen)) != len(chosen) or not set(chosen) <= set(STRATEGIES):
        raise InvalidParameterError(
            f"strategies must be distinct names among {list(STRATEGIES)}, got {list(chosen)}"
        )
    rel_tolerance = bounded_float("rel_tolerance", rel_tolerance, 1e-4, 0.5)
    duration = bounded_float("duration", duration, 1e-3, 60.0, "s")
    plant = validation_plant(model, params) if plant is None else plant
    body, origin, lever = plant.params, plant.standing_origin, plant.push_lever
    factor = 1.0 / (1.0 + lever / float(plant.standing_height))
    rows = []
    for angle in angles:
        predicted = predicted_critical_impulses(body, angle, origin=origin)
        for strategy in chosen:
            guess = factor * predicted[strategy]
            found = measure_critical_impulse(
                plant, angle, hip=strategy == "hip", guess=guess, rel_tolerance=rel_tolerance,
                duration=duration,
            )  # fmt: skip
            rows.append(ValidationRow(angle, strategy, predicted[strategy], guess, found.impulse,
                                      found.bracket, found.runs, found.strategy_used,
                                      found.foot_slip, found.peak_force))  # fmt: skip
    dense = [predicted_critical_impulses(body, angle, origin=origin) for angle in CURVE_AZIMUTHS]
    curves = tuple((strategy, tuple(p[strategy] for p in dense)) for strategy in chosen)
    return Validation3D(model, tuple(rows), body.mass, body.omega, origin, lever,
                        float(plant.standing_height), rel_tolerance, duration, chosen,
                        curves)  # fmt: skip
