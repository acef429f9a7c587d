"""Every public function (``__all__`` of the library's modules), one hostile value at a time.

A function whose required arguments all have a valid example below is called with them, then
with each argument replaced by each hostile value: it must return finite numbers or raise the
project's own error (issue 16). Two exceptions are documented: ``capture_point`` does not
check the states (one comparison per tick; a NaN state gives a NaN ξ), and the functions of
measured frames in :data:`NAN_IS_MISSING` read NaN as a missing frame, so a NaN argument gives
NaN where it is missing (any other hostile value still gives a finite result or a named error).
"""

from __future__ import annotations

import importlib
import inspect
import math
import os
import pkgutil
import tempfile
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import pushrecovery
from pushrecovery import load_params
from pushrecovery.analysis.base_polygon import FootModel, base_from_params
from pushrecovery.analysis.c3d import write_c3d
from pushrecovery.analysis.readers import read_recording
from pushrecovery.analysis.recording import Recording, fixed_feet
from pushrecovery.analysis.trial.events import Onset, TrialEvents
from pushrecovery.control.mpc import MPCSettings
from pushrecovery.errors import PushRecoveryError
from pushrecovery.ground import Support, rectangle
from pushrecovery.ground.minkowski import minkowski_sum, regular_polygon
from pushrecovery.sim.result import Outcome
from pushrecovery.surfaces.classify import classify, strategy_region
from pushrecovery.surfaces.n_step import step_options
from pushrecovery.surfaces.probability import StateGaussian

P = load_params()
FOOT = rectangle(-0.05, 0.15, 0.1)
OPTION = step_options(P, Support.from_params(P, "left"))[0]
TIME = np.linspace(0.0, 2.0, 201)
#: A horizontal ground reaction force [N] that crosses zero at 0, 1 and 2 s (zero points).
FORCE = 5.0 * np.sin(np.pi * TIME)
SWAY = 0.01 * np.sin(2.0 * np.pi * 0.5 * TIME)
TERMS = [(1.0, FOOT), (0.5, regular_polygon(0.1, 6))]
FOLDER = tempfile.mkdtemp(prefix="sweep-")


def _trial_csv() -> str:
    """A quiet-standing trial for the analysis readers (a temporary CSV, SI units)."""
    path = os.path.join(FOLDER, "trial.csv")
    rows = "\n".join(
        f"{t:.3f},{0.02 + x:.6f},{0.5 * x:.6f}" for t, x in zip(TIME, SWAY, strict=True)
    )
    with open(path, "w") as handle:
        handle.write("time,com_ap,com_ml\n" + rows + "\n")
    return path


def _trial_c3d() -> str:
    """The same trial as a C3D file: a CoM marker at 100 Hz, no plates (the project's writer)."""
    path = os.path.join(FOLDER, "trial.c3d")
    com = np.column_stack([0.02 + SWAY, 0.5 * SWAY, np.full(len(TIME), 1.0)])
    write_c3d(path, point_rate=100.0, markers={"CentreOfMass": com}, analog_rate=100.0, plates=[])
    return path


TRIAL = _trial_csv()
VALID: dict[str, Any] = {
    "params": P, "support": Support.from_params(P), "x": 0.01, "xdot": 0.1, "y": 0.0,
    "settings": MPCSettings(), "ydot": 0.0, "omega": P.omega, "dt": 0.01, "t": 0.1, "x0": 0.01,
    "xdot0": 0.1, "cop": 0.0,
    "theta": 0.05, "theta_rate": 0.1, "mass": 72.0, "length": 1.0, "gravity": 9.81,
    "heel": -0.05, "toe": 0.15, "direction": 1.0, "v0": 1.0, "capture": np.array([0.05]),
    "velocity": 0.1, "duration": 0.5, "steps": 1, "swing_time": 0.2, "tolerance": 1e-3,
    "torque": 0.0, "states": np.zeros((3, 4)), "state": np.zeros(4),
    # The ground plane, steps and plans.
    "polygon": FOOT, "window": rectangle(-0.1, 0.1, 0.3), "option": OPTION,
    "touchdowns": (0.2,), "touchdown": 0.2, "xi": np.array([0.4, 0.05]), "hip": True,
    "heading": 0.3, "origin": (0.0, 0.0), "direction_angle": 0.3, "width": 0.1,
    "points": np.array([[0.0, 0.0], [0.2, 0.0], [0.0, 0.1]]), "radius": 0.1, "sides": 8,
    "terms": TERMS, "step_time": 0.2, "reach": 1.0,
    "plan": classify(0.0, 2.0, P).plan, "position": (0.0, 0.0), "elapsed": 0.1,
    "spin_up": 0.2, "lower": -0.05, "upper": 0.15, "ankle": 0.0,
    "region": strategy_region("ankle", P), "strategy": "hip", "backend": "analytic",
    # The hip.
    "switch_time": 0.1, "capture_point": 0.02, "torque_max": 50.0, "inertia": 10.0,
    "angle_max": 0.5, "weight": 700.0, "speed": 0.01, "theta0": 0.1, "thetadot0": 0.2,
    # The optional dependencies (an installed extra's module).
    "extra": "sim", "module": "mujoco",
    # A person's body (de Leva), and a recording's checks.
    "height": 1.75, "sex": "female", "recording": read_recording(TRIAL),
    # Measured data.
    "path": TRIAL, "com": np.array([0.01, 0.02]), "anchor": np.array([0.02]),
    "n": 10, "ankle_ap": 0.0, "ankle_ml": 0.1, "stance_width": 0.2, "contact_height": 0.05,
    "foot_width": 0.1, "feet": fixed_feet(10, 0.0, 0.1, -0.05, 0.15, 0.2), "time": TIME,
    "force": FORCE, "rate": 100.0, "cutoff": 6.0, "max_gap": 0.1, "ap_axis": "x",
    "missing": np.zeros(10, dtype=bool), "valid": np.ones(10, dtype=bool),
    "source": TIME, "outcome_of": lambda v: Outcome.RECOVERED if abs(v) < 1.0 else Outcome.FELL,
    "guess": 0.5, "max_velocity": 4.0, "horizon": 1.0,
    # Events of measured trials.
    "signal": SWAY, "vertical_force": np.full(len(TIME), 700.0), "windows": [(0.0, 1.0)],
    "events": [],
}  # fmt: skip
#: Arguments whose example depends on the function (the same name, another meaning).
OVERRIDES: dict[str, dict[str, Any]] = {
    "pushrecovery.analysis.signals.lowpass": {"values": np.sin(TIME)},
    "pushrecovery.analysis.signals.repair_gaps": {"values": np.sin(TIME), "name": "com_ap"},
    "pushrecovery.analysis.margins.direction_margins": {
        "velocity": np.array([0.1, -0.1]), "lower": np.full(2, -0.05), "upper": np.full(2, 0.15),
        "ankle": np.zeros(2),
    },
    "pushrecovery.analysis.readers.c3d_files.read_c3d_recording": {"path": _trial_c3d()},
    # A posturography export: the CoP alone.
    "pushrecovery.analysis.sway_recording.recording_sway": {"recording": Recording(
        time=np.arange(0.0, 10.0, 0.01), force_time=np.arange(0.0, 10.0, 0.01),
        cop=0.01 * np.sin(np.outer(np.arange(0.0, 10.0, 0.01), [1.0, 2.0])),
    )},
    # The 2-D base of support and margins (issue 18): three frames of stated feet.
    **{f"pushrecovery.analysis.base_polygon.{name}": {
        "model": FootModel(), "foot": fixed_feet(3, 0.0, 0.1, -0.05, 0.15, 0.2)[0],
        "vertices": np.tile([[-0.05, -0.15], [0.15, -0.15], [0.15, 0.15]], (3, 1, 1)),
    } for name in ("foot_soles", "base_from_feet", "base_from_vertices", "base_from_params")},
    **{f"pushrecovery.analysis.margins.plane.{name}": {
        "base": base_from_params(P, 3), "com": np.zeros((3, 2)), "velocity": np.ones((3, 2)),
        "points": np.zeros((3, 2)), "cop": np.zeros((3, 2)), "cop_velocity": np.ones((3, 2)),
        "xcom": np.full((3, 2), 0.05),
    } for name in ("margins_2d", "signed_distance", "time_to_boundary_cop",
                   "time_to_boundary_xcom", "phase_supports")},
    "pushrecovery.analysis.signals.resample": {
        "values": np.column_stack([np.sin(TIME), np.cos(TIME)]), "target": TIME[::2]
    },
    "pushrecovery.analysis.signals.smooth_and_differentiate": {"values": np.sin(TIME)},
    "pushrecovery.analysis.zero_point.com_from_force": {"cop": 0.02 + SWAY},
    "pushrecovery.analysis.steps_measured.foot_events_from_force": {"foot": "left"},
    "pushrecovery.analysis.steps_measured.foot_events_from_markers": {
        "foot": fixed_feet(len(TIME), 0.0, 0.1, -0.05, 0.15, 0.2)[0]
    },
    "pushrecovery.analysis.steps_measured.measured_steps": {
        "feet": fixed_feet(len(TIME), 0.0, 0.1, -0.05, 0.15, 0.2)
    },
    "pushrecovery.ground.minkowski.decompose": {
        "point": np.array([0.05, 0.01]), "offset": np.zeros(2),
        "total": minkowski_sum(TERMS, (0.0, 0.0)),
    },
    "pushrecovery.sim.batched.ankle_pd_pushes": {
        "model": "lipm", "bodies": [P], "x0": [0.0], "xdot": [0.1], "duration": 1.0
    },
    "pushrecovery.sim.batched.recovery_pushes": {
        "bodies": [P], "x0": [0.0], "xdot": [0.1], "duration": 0.2
    },
    "pushrecovery.sim.result.strategy_used": {"peak_hip_torque": 2.0},
    "pushrecovery.sim.push.direction_sign": {"direction": "forward"},
    "pushrecovery.sim.push.push_direction": {"azimuth": 90.0},
    "pushrecovery.surfaces.step.impact.plan_impacts": {"velocity": (2.0, 0.0)},
    "pushrecovery.control.base.controller_class": {"name": "ankle-pd"},
    "pushrecovery.control.base.make_controller": {"name": "ankle-pd"},
    "pushrecovery.sim.registry.make_plant": {"name": "pendulum"},
    "pushrecovery.sim.registry.make_plant3d": {"name": "biped3d"},
    "pushrecovery.sim.many.run_many": {
        "model": "pendulum", "controller": "ankle-pd", "bodies": [P], "x0": [0.0], "xdot": [0.1],
        "duration": 0.2,
    },
    "pushrecovery.ground.user_polygon.convex_polygon": {
        "name": "foot_polygon", "vertices": [[-0.05, -0.05], [0.15, -0.05], [0.15, 0.05]]
    },
    "pushrecovery.models.flywheel.bang_bang_switch_time": {"target": 0.0},
    "pushrecovery.models.stepping.solve_step_angle": {"target": 0.3},
    "pushrecovery.models.flywheel.flywheel_propagate": {
        "states": np.zeros(4), "inputs": np.zeros((5, 2))
    },
    "pushrecovery.models.flywheel.plane.plane_propagate": {
        "states": np.zeros(8), "inputs": np.zeros((5, 4))
    },
    "pushrecovery.sim.critical.predicted_critical_velocity": {"direction": "forward"},
    "pushrecovery.sim.validation.corrected_critical_velocity": {
        "cop_margin": 0.0, "push_duration": 0.01
    },
    "pushrecovery.sim.critical.find_critical_velocity": {"direction": "forward"},
    "pushrecovery.sim.critical.bisect_critical": {  # a body that stands below 5 N s
        "stands": lambda impulse: (impulse < 5.0, "ankle"), "low": 0.0, "high": 10.0,
        "tolerance": 0.1,
    },
    "pushrecovery.sim.physical_checks.joint_group": {"name": "left_knee_joint"},
    "pushrecovery.sim.result.judge": {"outcome": Outcome.RECOVERED, "checks": None},
    # Probabilities of uncertain states (issue 37).
    "pushrecovery.ground.gaussian.covariance_2d": {"name": "cov", "cov": np.eye(2) * 1e-3},
    **{f"pushrecovery.ground.gaussian.{name}": {
        "mean": np.array([0.05, 0.0]), "cov": np.eye(2) * 1e-3,
        "polygons": [FOOT, FOOT.transformed(0.05, 0.02, 0.3)],
    } for name in ("gaussian_mass", "gaussian_union_mass", "maximal", "union_terms")},
    **{f"pushrecovery.surfaces.probability.{name}": {
        "mean": np.array([0.0, 0.3]), "cov": np.eye(2) * 1e-3,
        "state": StateGaussian(np.array([0.0, 0.3]), np.eye(2) * 1e-3),
    } for name in ("verdicts.ankle_probability", "verdicts.verdict_probabilities",
                   "verdicts.verdict_probability_table", "inputs.check_states",
                   "margins.margin_quantiles")},
    "pushrecovery.surfaces.probability.latency.delayed_capture_point": {
        "mean": np.array([0.05]), "cov": np.array([[1e-3]]), "latency": 0.02,
        "cop": np.array([0.0]),
    },
    **{f"pushrecovery.surfaces.probability.scores.{name}": {
        "predicted": np.array([0.1, 0.8]), "happened": np.array([False, True]),
    } for name in ("brier_score", "reliability")},
    "pushrecovery.surfaces.n_step.hip_box": {"yaw": 0.3},
    "pushrecovery.surfaces.n_step.reach_polygon": {"side": "left", "yaw": 0.3},
    "pushrecovery.surfaces.probability.latency.latency_growth": {"tau": 0.02},
    "pushrecovery.surfaces.probability.latency.latency_nodes": {"latency": (0.01, 0.03)},
    "pushrecovery.analysis.trial.events.c3d_events": {"events": TrialEvents(
        Onset(0.5, "force", None), (), ()
    )},
    # Posturography: 10 s of CoP (ap, ml) [m] at 100 Hz (the spectrum needs >= 1 / 0.15 Hz).
    **{f"pushrecovery.analysis.posturography.{name}": {
        "cop": 0.01 * np.column_stack([np.sin(np.arange(1000) / 20), np.cos(np.arange(1000) / 13)]),
        "series": 0.01 * np.sin(np.arange(1000) / 20),
    } for name in ("path_length", "mean_velocity", "mean_distance", "rms_distance",
                   "mean_frequency", "prediction_ellipse", "sway_spectrum", "sway_measures",
                   "quiet_standing")},
}  # fmt: skip
#: Public functions the sweep leaves to their own tests, and why.
NOT_SWEPT = {
    "pushrecovery.control.base.register": "a class decorator: registering changes the registry",
    "pushrecovery.sim.critical.critical_push": "a bisection of simulations: test_hostile.py",
    "pushrecovery.sim.validation.confusion_matrix": "MuJoCo runs: test_hostile.py via the CLI",
    "pushrecovery.sim.simulate.simulate": "plant and controller objects: test_simulate.py",
    "pushrecovery.sim.simulate.check_run": "plant and controller objects: test_simulate.py",
    "pushrecovery.sim.critical.pushed_state": "a plant object: test_simulate.py",
    "pushrecovery.analysis.output.write_analysis": "an analysis object: test_cli_analyze.py",
    "pushrecovery.analysis.trial.pipeline.analyze": "a recording object: test_cli_analyze.py",
    "pushrecovery.analysis.trial.settings.body_for": "a recording object: test_cli_analyze.py",
    "pushrecovery.surfaces.capture.lp.plane.support_function_lp": "an LP per call: tests only",
    "pushrecovery.surfaces.capture.lp.steps.step_lp": "an LP per call: tests only",
    "pushrecovery.presets.load_params": "no required argument: test_api_hostile.py",
    "pushrecovery.analysis.output.json_safe": "any value in, a JSON value out: test_cli_analyze.py",
    "pushrecovery.surfaces.probability.regions.cumulative_masses": "checked arguments only",
    "pushrecovery.analysis.trial.risk.frame_risk": "an analysis' margins: test_trial_risk.py",
    "pushrecovery.control.delay.reaction_delay": "a controller object: test_delay.py",
    "pushrecovery.surfaces.probability.regions.region_middle": "of regions the module built",
}
HOSTILE: list[Any] = [math.nan, math.inf, -1e300, 0.0, None, "x", [1.0, 2.0], np.zeros((2, 2))]
#: Floors above the library's functions: they draw, write or run campaigns. And below them: the
#: compiled kernels, called with checked arguments only (docs/architecture.md); the whole-body
#: controller's parts, which take MuJoCo models and observations (as sim.mujoco).
SKIPPED = (
    "cli", "plots", "report", "sim.mujoco", "experiments", "campaign", "analysis.c3d", "kernels",
    "control.wbc",
)  # fmt: skip
#: (function, argument) pairs documented as unchecked.
UNCHECKED = {("pushrecovery.surfaces.cop.capture_point", "x"),
             ("pushrecovery.surfaces.cop.capture_point", "xdot")}  # fmt: skip
#: Functions of measured frames whose docstrings make NaN a missing frame: a NaN argument may
#: give NaN (where that frame is missing), and nothing else may.
NAN_IS_MISSING = {"pushrecovery.analysis.margins.time_to_leave"}


def _public() -> dict[str, Callable[..., Any]]:
    found = {}
    for info in pkgutil.walk_packages(pushrecovery.__path__, "pushrecovery."):
        name = info.name
        short = name.removeprefix("pushrecovery.")
        if any(part.startswith("_") for part in name.split(".")) or short.startswith(SKIPPED):
            continue
        module = importlib.import_module(name)
        for attribute in getattr(module, "__all__", []):
            function = getattr(module, attribute, None)
            if inspect.isfunction(function) and function.__module__ == name:
                found[f"{name}.{attribute}"] = function
    return found


def _examples(name: str, function: Callable[..., Any]) -> dict[str, Any] | None:
    """Valid values of the required arguments, or None when one has no example here."""
    names = [
        p.name
        for p in inspect.signature(function).parameters.values()
        if p.default is p.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]
    known = {**VALID, **OVERRIDES.get(name, {})}
    return {n: known[n] for n in names} if all(n in known for n in names) else None


PUBLIC = _public()
CASES = {name: f for name, f in sorted(PUBLIC.items()) if name not in NOT_SWEPT}


def test_every_public_function_is_swept_or_says_why() -> None:
    missing = sorted(name for name, f in CASES.items() if _examples(name, f) is None)
    assert missing == []
    assert set(NOT_SWEPT) <= set(PUBLIC)  # no stale entries
    assert len(CASES) >= 110  # 110 when this was written (53 in its first version)


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_arguments_give_a_result_or_a_named_error(name: str) -> None:
    function = CASES[name]
    base = _examples(name, function)
    if base is None:
        pytest.fail(f"no valid example for the arguments of {name}")
    function(**base)  # the example itself is valid
    for argument in base:
        for value in HOSTILE:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    result = function(**{**base, argument: value})
                except PushRecoveryError:
                    continue
            if (name, argument) in UNCHECKED:
                continue
            if name in NAN_IS_MISSING and isinstance(value, float) and math.isnan(value):
                continue
            if isinstance(result, float):
                assert math.isfinite(result), (argument, value, result)
            if isinstance(result, np.ndarray) and result.dtype.kind == "f":
                assert np.isfinite(result).all(), (argument, value, result)
