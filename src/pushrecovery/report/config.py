"""The report's configuration: sections, grids and sizes, filmstrips, figure captions."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

Range = tuple[float, float, float]

#: Section keys and titles, in the page's order.
SECTIONS: Mapping[str, str] = {
    "bounds": "Parameters, bounds and thresholds",
    "map": "Strategy map",
    "plane": "Ground plane",
    "steps": "Steps: capture regions and N-step capturability",
    "figures": "The paper's figures",
    "analytic": "Push campaign on the analytic models",
    "planar": "Push campaign on the planar stepping model: N-step plans",
    "sweep": "Critical push against the hip torque limit",
    "mujoco": "Push campaign in MuJoCo: the hip strategy",
    "biped": "Push campaign in MuJoCo: stepping",
    "critical": "Critical pushes in MuJoCo",
    "filmstrips": "Filmstrips",
    "humanoid3d": "3-D humanoid",
}
#: The sections that need MuJoCo (left out with ``mujoco=False``).
MUJOCO_SECTIONS = ("mujoco", "biped", "critical", "filmstrips", "humanoid3d")
#: Order of computation: the campaigns first (the longest work, on the workers).
_RUN_ORDER = (
    "sweep",
    "analytic",
    "planar",
    "mujoco",
    "biped",
    "bounds",
    "map",
    "plane",
    "steps",
    "figures",
    "critical",
    "filmstrips",
    "humanoid3d",
)
#: Filmstrips: strategy -> (model, controller, caption), as docs/validation.md, "Filmstrips"; the
#: push is the
#: body's own (:func:`~pushrecovery.experiments.pushes.strategy_pushes`: 25, 40 and 80 N s for
#: the paper's body).
FILMSTRIPS: Mapping[str, tuple[str, str, str]] = {
    "ankle": ("foot", "ankle-pd", "ankle strategy: foot + ankle PD"),
    "hip": ("torso", "mpc", "hip strategy: torso + MPC"),
    "step": ("biped", "recovery", "stepping: biped + recovery controller"),
}
#: The 3-D humanoid's filmstrips: key -> (model, azimuth [deg], push as a fraction of the 2-D
#: CoP-region critical impulse at that azimuth, controller: "ankle" (ankles only) or "step"
#: (ankles and steps, 0.2 s swing), caption, frame times [s]; the push at 0.1 s, the run
#: ending 0.1 s after the last frame). An ankle recovery, a lateral capture step (the push of
#: tests/test_wbc_stepping.py), a G1 push.
HUMANOID3D_STRIPS: Mapping[str, tuple[str, float, float, str, str, tuple[float, ...]]] = {
    "biped3d-ankle": ("biped3d", 0.0, 0.6, "ankle", "biped3d, forward push, ankles",
                      (0.1, 0.2, 0.3, 0.45, 0.7, 1.2)),
    "biped3d-step": ("biped3d", 90.0, 1.5, "step", "biped3d, push to the left, a side step",
                     (0.1, 0.2, 0.3, 0.4, 0.6, 1.5)),
    "g1-ankle": ("g1", 90.0, 0.5, "ankle", "Unitree G1, push to the left, ankles",
                 (0.1, 0.2, 0.3, 0.45, 0.7, 1.2)),
}  # fmt: skip
#: Captions of the paper's figures, by file stem.
FIGURE_CAPTIONS: Mapping[str, str] = {
    "fig3a": "Fig. 3(a): open-loop saturated ankle torque on the linear inverted pendulum, "
    "pushed from upright; green runs recover, red fall; the band is Eq. (4).",
    "fig3b": "Fig. 3(b): saturated PD ankle control of the nonlinear pendulum, pushes 15 % "
    "inside and outside Eq. (4).",
    "fig5a": "Fig. 5(a): bang-bang flywheel control (Eqs. 8–13), phase plot against corrected "
    "Eq. (15).",
    "fig5b": "Fig. 5(b): bang-bang flywheel control, flywheel angle and torque against time.",
    "fig6a": "Fig. 6(a): receding-horizon control (Eqs. 16–17), phase plot.",
    "fig6b": "Fig. 6(b): receding-horizon control (Eqs. 16–17), CoP, torque and flywheel "
    "against time.",
    "fig9": "Fig. 9: the stance pendulum, the coordinate jump to the new foot and the impact "
    "(Sec. IV).",
    "fig10": "Fig. 10: optimal step length against the initial CoM velocity (Eq. 21), with the "
    "range of steps that land the capture point on the new foot.",
    "plane": "The capture-point plane in double, left and right support: support polygon "
    "(ankle), CMP region (hip) and pushes from rest coloured by the strategy they need.",
}
#: Push directions of the ground-plane threshold table, in its column order.
PLANE_DIRECTIONS = ("forward", "backward", "left", "right")


@dataclass(frozen=True)
class PushGrid:
    """The pushes of one campaign: starts, pushes and swept body parameters.

    Parameters
    ----------
    x0 : (start, stop, step)
        CoM positions before the push [m]; values off the body's foot are dropped.
    xdot : (start, stop, step)
        Pushes, as the CoM velocity they give [m/s].
    sweeps : mapping of str to (start, stop, step)
        Body parameters to sweep, SI units (the ``sweep`` section needs exactly one).
    """

    x0: Range
    xdot: Range
    sweeps: Mapping[str, Range] = field(default_factory=dict)


@dataclass(frozen=True)
class ReportGrids:
    """Every grid of the report (see :data:`SIZES`).

    Parameters
    ----------
    analytic : PushGrid
        ``stepping`` + ``recovery`` on the analytic backend; also the grid of the ``planar``
        section (``stepping-plane`` + ``recovery-plane``, pushes along x).
    sweep : PushGrid
        ``flywheel`` + ``mpc`` on the analytic backend, sweeping one parameter.
    mujoco : PushGrid
        ``torso`` + ``mpc`` in MuJoCo.
    biped : PushGrid
        ``biped`` + ``recovery`` in MuJoCo.
    critical_x0s : tuple of float
        Starts of the MuJoCo critical-push table [m].
    critical_tolerance : float
        Bracket of the ankle and hip critical pushes [m/s].
    step_tolerance : float
        Bracket of the stepping critical pushes [m/s].
    azimuths3d : tuple of float
        Push azimuths of the 3-D validation's polar plots [deg].
    tolerance3d : float
        Its bisection's final width, as a fraction of the prediction.
    duration3d : float
        Its runs' time after the push [s] (a run not fallen by then stands).
    """

    analytic: PushGrid
    sweep: PushGrid
    mujoco: PushGrid
    biped: PushGrid
    critical_x0s: tuple[float, ...] = (0.0,)
    critical_tolerance: float = 2e-3
    step_tolerance: float = 1e-2
    azimuths3d: tuple[float, ...] = (0.0, 60.0, 120.0, 180.0, 240.0, 300.0)
    tolerance3d: float = 0.05
    duration3d: float = 1.5


#: Grid sizes: ``small`` keeps the whole report near a minute on two cores.
SIZES: Mapping[str, ReportGrids] = {
    "small": ReportGrids(
        analytic=PushGrid((-0.03, 0.12, 0.05), (-3.4, 3.4, 0.2)),
        sweep=PushGrid((0.0, 0.0, 1.0), (-0.6, 1.0, 0.05), {"torque_max": (0.0, 200.0, 50.0)}),
        mujoco=PushGrid((0.0, 0.1, 0.05), (-0.8, 0.9, 0.05)),
        biped=PushGrid((0.0, 0.0, 1.0), (-3.0, 3.0, 0.25)),
    ),
    "full": ReportGrids(
        analytic=PushGrid((-0.04, 0.14, 0.02), (-3.5, 3.5, 0.05)),
        sweep=PushGrid((0.0, 0.1, 0.05), (-1.0, 1.2, 0.02), {"torque_max": (0.0, 300.0, 25.0)}),
        mujoco=PushGrid((-0.03, 0.12, 0.03), (-1.0, 1.0, 0.02)),
        biped=PushGrid((0.0, 0.05, 0.05), (-3.0, 3.0, 0.1)),
        critical_x0s=(-0.03, 0.0, 0.05, 0.1),
        critical_tolerance=1e-3,
        step_tolerance=5e-3,
        azimuths3d=tuple(float(a) for a in range(0, 360, 30)),
        tolerance3d=0.01,
        duration3d=3.0,
    ),
}
