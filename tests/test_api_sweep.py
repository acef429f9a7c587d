"""Every public function (``__all__`` of the library's modules), one hostile value at a time.

A function whose required arguments all have a valid example below is called with them, then
with each argument replaced by each hostile value: it must return finite numbers or raise the
project's own error (issue 16). The only exception is documented: ``capture_point`` does not
check the states (one comparison per tick; a NaN state gives a NaN ξ).
"""

from __future__ import annotations

import importlib
import inspect
import math
import pkgutil
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import pushrecovery
from pushrecovery import load_params
from pushrecovery.errors import PushRecoveryError
from pushrecovery.ground import Support

P = load_params()
VALID: dict[str, Any] = {
    "params": P, "support": Support.from_params(P), "x": 0.01, "xdot": 0.1, "y": 0.0,
    "ydot": 0.0, "omega": P.omega, "dt": 0.01, "t": 0.1, "x0": 0.01, "xdot0": 0.1, "cop": 0.0,
    "theta": 0.05, "theta_rate": 0.1, "mass": 72.0, "length": 1.0, "gravity": 9.81,
    "heel": -0.05, "toe": 0.15, "direction": 1.0, "v0": 1.0, "capture": np.array([0.05]),
    "velocity": 0.1, "duration": 0.5, "steps": 1, "swing_time": 0.2, "tolerance": 1e-3,
    "torque": 0.0, "states": np.zeros((3, 4)), "state": np.zeros(4),
}  # fmt: skip
HOSTILE: list[Any] = [math.nan, math.inf, -1e300, 0.0, None, "x", [1.0, 2.0], np.zeros((2, 2))]
#: Floors above the library's functions: they draw, write or run campaigns.
SKIPPED = ("cli", "plots", "report", "sim.mujoco", "experiments", "campaign", "analysis.c3d")
#: (function, argument) pairs documented as unchecked.
UNCHECKED = {("pushrecovery.surfaces.cop.capture_point", "x"),
             ("pushrecovery.surfaces.cop.capture_point", "xdot")}  # fmt: skip


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


def _required(function: Callable[..., Any]) -> list[str] | None:
    """The required arguments' names, or None when one has no valid example here."""
    names = [
        p.name
        for p in inspect.signature(function).parameters.values()
        if p.default is p.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]
    return names if all(n in VALID for n in names) else None


CASES = {name: function for name, function in sorted(_public().items()) if _required(function)}


def test_the_sweep_covers_the_core() -> None:
    assert len(CASES) >= 50  # 53 when this was written


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_arguments_give_a_result_or_a_named_error(name: str) -> None:
    function = CASES[name]
    names = _required(function) or []
    base = {n: VALID[n] for n in names}
    for argument in names:
        for value in HOSTILE:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    result = function(**{**base, argument: value})
                except PushRecoveryError:
                    continue
            if (name, argument) in UNCHECKED:
                continue
            if isinstance(result, float):
                assert math.isfinite(result), (argument, value, result)
            if isinstance(result, np.ndarray) and result.dtype.kind == "f":
                assert np.isfinite(result).all(), (argument, value, result)
