"""Simulation results and the outcome criterion."""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import finite_float, non_negative_float, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.push import Push3D
from pushrecovery.surfaces.classify import Strategy

__all__ = [
    "HIP_TORQUE_THRESHOLD",
    "Outcome",
    "Push3DExtras",
    "SimulationResult",
    "is_falling",
    "judge",
    "strategy_used",
]

#: Largest abs(hip torque) [N m] that still counts as not using the hip: a solver's rounding or
#: a servo holding the upper body still (the MPC leaves 2e-5 N m on a push of 0), not CMP
#: balancing (whose torques are tens of N m).
HIP_TORQUE_THRESHOLD = 1.0


class Outcome(StrEnum):
    """How a simulated push ended (docs/conventions.md, "Outcome")."""

    RECOVERED = "recovered"
    FELL = "fell"
    UNDECIDED = "undecided"
    #: Came to rest, but a loaded foot slid (or a torque passed its limit): not a recovery
    #: (:mod:`pushrecovery.sim.physical_checks`).
    SLIPPED = "slipped"


def is_falling(x: float, xdot: float, lower: float, upper: float) -> bool:
    """Tell whether the CoM is beyond a fall limit and moving away from the support.

    With the limits at the foot edges (ankle models) the state is then lost for any CoP on the
    foot: for the LIPM ẍ = ω² (x − δ) > 0 when x > δ⁺ ≥ δ; for the pendulum
    m L² θ̈ = m g L sinθ − τ and τ ≤ τ(δ⁺) < m g L sinθ when L sinθ > δ⁺ and θ̇ ≥ 0. With the
    limits at δ± ± τmax/(m g) the same holds for every CMP the flywheel model can produce
    (docs/conventions.md). Mirror for the lower limit.

    It runs at every control tick: four finite Python floats pass one test (their types and
    the finiteness of their sum); anything else is checked and converted on the slow path.

    Raises
    ------
    InvalidParameterError
        If an argument is not a finite number.
    """
    if not (
        type(x) is float
        and type(xdot) is float
        and type(lower) is float
        and type(upper) is float
        and math.isfinite(x + xdot + lower + upper)
    ):
        x, xdot = finite_float("x", x, "m"), finite_float("xdot", xdot, "m/s")
        lower, upper = finite_float("lower", lower, "m"), finite_float("upper", upper, "m")
    return (x > upper and xdot >= 0.0) or (x < lower and xdot <= 0.0)


#: Labels of results made without them, by state size (the sagittal models').
_LEGACY_LABELS = {
    2: ("x", "xdot"),
    4: ("x", "theta", "xdot", "theta_dot"),
    6: ("x", "theta", "z", "xdot", "theta_dot", "zdot"),
}
#: ``final_state`` keys in the order the JSON contract first had them.
_FIRST_KEYS = ("x", "xdot", "theta", "theta_dot", "z", "y", "ydot")


@dataclass(frozen=True, slots=True)
class Push3DExtras:
    """What a pushed run of a 3-D humanoid measured beside its rows (``runs3d.run_push3d``).

    Attributes
    ----------
    push : Push3D
        The push.
    push_row : int
        The row just after the push: the row its force ended on (a push now: ``states[push_row
        - 1]`` is the state as it began; a scheduled push: the first row with its force over).
    peak_hip_torque : float
        Largest flywheel torque the WBC's hip law commanded after the push, m g abs(δ) (δ its
        CMP offset) [N m]: 0 when the ankles sufficed.
    peak_hip_motor_torque : float
        Largest abs(hip pitch or roll motor command − its value as the push began) after the
        push began [N m].
    max_torso_tilt : float
        Largest tilt of the upright body from the vertical after the push [rad].
    peak_torque : float
        Largest abs(motor command) from the push on [N m].
    failed_ticks : int
        Ticks DAQP did not solve (the last command repeated).
    steps : int
        Steps that landed (the controller's stepping task; 0 without it).
    qpos, qvel, ctrl : float arrays, shapes (n, nq), (n, nv), (n, nu), or None
        MuJoCo's ``qpos``, ``qvel`` and the held motor commands at each row of the result
        (recorded runs, to replay and render them); None otherwise. ``qpos`` [m] for slide and
        free-joint positions, [-] for the free joint's unit quaternion, [rad] for hinges;
        ``qvel`` [m/s] and [rad/s] likewise; ``ctrl`` the motors' torques [N m] (gear 1).
    """

    push: Push3D
    push_row: int
    peak_hip_torque: float
    peak_hip_motor_torque: float
    max_torso_tilt: float
    peak_torque: float
    failed_ticks: int
    steps: int = 0
    qpos: NDArray[np.float64] | None = None
    qvel: NDArray[np.float64] | None = None
    ctrl: NDArray[np.float64] | None = None


@dataclass(frozen=True, slots=True)
class SimulationResult:
    """A simulated run.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s].
    states : ndarray, shape (n, d)
        States at those times (``[x, xdot]`` for the ankle models) [m, m/s].
    inputs : ndarray, shape (n - 1, 2) or (n - 1, 4)
        CoP [m] and hip (flywheel) torque [N m] applied over each control period; on the
        ground plane CoP x, y, pitch and roll torques.
    outcome : Outcome
        ``recovered``, ``fell``, ``undecided`` (neither within the duration) or ``slipped``
        (at rest, but the physical checks failed: :func:`judge`).
    model, controller : str
        Registry names of the plant and the controller.
    stop_impacts : int
        Times the flywheel hit its joint stop at speed (a torque beyond τmax; errata E12).
    footholds : tuple of float
        World x of every stance foot, the first at 0 [m] (more than one after steps).
    footholds_xy : tuple of (float, float)
        On the ground plane: the start's stance reference and every landed ankle (x, y) [m].
    state_labels : tuple of str
        The entries of the states (the plant's ``state_labels``).
    decided_time : float or None
        When the outcome was decided [s] (None: undecided).
    extras : Push3DExtras or None
        A 3-D humanoid's pushed run: the push, its peaks, steps and recorded frames.
    physics : PhysicalChecks or None
        A MuJoCo run's physical checks (loaded-foot slip, ground force, penetration, friction
        and torque use, joint limits); None for the analytic models.
    """

    time: NDArray[np.float64]
    states: NDArray[np.float64]
    inputs: NDArray[np.float64]
    outcome: Outcome
    model: str
    controller: str
    stop_impacts: int = 0
    footholds: tuple[float, ...] = (0.0,)
    footholds_xy: tuple[tuple[float, float], ...] = ()
    state_labels: tuple[str, ...] = ()
    decided_time: float | None = None
    extras: Push3DExtras | None = None
    physics: PhysicalChecks | None = None

    @property
    def cops(self) -> NDArray[np.float64]:
        """CoP applied over each control period [m]."""
        return self.inputs[:, 0]

    @property
    def torques(self) -> NDArray[np.float64]:
        """Hip (flywheel) torque applied over each control period [N m] (pitch on the plane)."""
        return self.inputs[:, self.inputs.shape[1] // 2]

    @property
    def peak_hip_torque(self) -> float:
        """Largest abs(hip torque) held during the run [N m] (pitch on the plane)."""
        return float(np.abs(self.torques).max()) if self.torques.size else 0.0

    def strategy_used(self) -> Strategy:
        """Return the strategy the run used, whatever its outcome (the one definition).

        ``step`` if a foot landed, else ``hip`` if the hip torque exceeded
        :data:`HIP_TORQUE_THRESHOLD`, else ``ankle`` (a 3-D humanoid's: its ``extras``' steps
        and hip law's torque).
        """
        extras = self.extras
        if extras is not None:
            return strategy_used(extras.steps, extras.peak_hip_torque)
        return strategy_used(len(self.footholds) - 1, self.peak_hip_torque)

    @property
    def recovered(self) -> bool:
        """True when the body came to rest standing."""
        return self.outcome is Outcome.RECOVERED

    @property
    def final_state(self) -> NDArray[np.float64]:
        """The last state."""
        return self.states[-1]

    def to_dict(self) -> dict[str, object]:
        """JSON summary (the ``simulate`` contract); trajectories are not included."""
        final = self.final_state
        labels = self.state_labels or _LEGACY_LABELS.get(len(final), ())
        values = dict(zip(labels, (float(v) for v in final), strict=True))
        # The keys of the first releases first, in their order; the rest by label.
        order = [key for key in _FIRST_KEYS if key in values]
        order += [key for key in labels if key not in order]
        final_state = {key: values[key] for key in order}
        xy: dict[str, object] = (
            {"footholds_xy": [list(p) for p in self.footholds_xy]} if self.footholds_xy else {}
        )
        physics: dict[str, object] = (
            {} if self.physics is None else {"physics": self.physics.to_dict()}
        )
        return (
            {
                "recovered": self.recovered,
                "outcome": self.outcome.value,
                "model": self.model,
                "controller": self.controller,
                "duration": float(self.time[-1]),
                "final_state": final_state,
                # simulate() always runs at least one control tick, so cops is never empty.
                "peak_cop": {"min": float(self.cops.min()), "max": float(self.cops.max())},
                "max_excursion": float(np.abs(self.states[:, 0]).max()),
                "peak_torque": float(np.abs(self.torques).max()),
                "stop_impacts": self.stop_impacts,
                "footholds": list(self.footholds),
            }
            | xy
            | physics
        )


def strategy_used(steps: int, peak_hip_torque: float) -> Strategy:
    """Return the strategy a run used (the one definition).

    ``step`` if a foot landed (``steps`` > 0), else ``hip`` if the largest abs(hip torque) [N m]
    exceeded :data:`HIP_TORQUE_THRESHOLD`, else ``ankle``.

    Raises
    ------
    InvalidParameterError
        If ``steps`` is not an int >= 0 or ``peak_hip_torque`` not a number >= 0.
    """
    if not (isinstance(steps, int | np.integer) and steps >= 0):
        raise InvalidParameterError(f"steps must be an int >= 0, got {steps!r:.40}")
    non_negative_float("peak_hip_torque", peak_hip_torque, "N m")
    if steps > 0:
        return Strategy.STEP
    if peak_hip_torque > HIP_TORQUE_THRESHOLD:
        return Strategy.HIP
    return Strategy.ANKLE


def judge(outcome: Outcome, checks: PhysicalChecks | None) -> Outcome:
    """Return ``outcome``, or ``slipped`` for a recovered run whose checks it violated.

    A run that came to rest while a loaded foot slid farther than the checks' ``slip_limit``,
    or with a torque above its limit, did not recover as the model claims it would: it is
    ``slipped`` (a fall or an undecided run stays what it is).

    Raises
    ------
    ParameterTypeError
        If ``outcome`` is not an Outcome or ``checks`` neither PhysicalChecks nor None.
    """
    require_type("outcome", outcome, Outcome)
    if checks is not None:
        require_type("checks", checks, PhysicalChecks)
    if outcome is Outcome.RECOVERED and checks is not None and checks.violations():
        return Outcome.SLIPPED
    return outcome
