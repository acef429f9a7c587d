"""Fuzzing the library: every public function and class, hostile values drawn per annotation.

The callables are read from the ``__all__`` of every module (:func:`public`), their parameters
from their signatures. A case is a callable and a seed: its required arguments start from the
valid examples of ``tests/test_api_sweep.py`` (a hostile draw where there is none), then one
to three parameters, required or optional, are replaced by values drawn for their annotated
type (``float``: NaN, ±inf, 5e-324, ±1e300...; arrays: NaN, empty, ragged, wrong shape;
paths: a FIFO, ``/dev/zero``, a folder, an empty or overlong name...), now and then of another
type. :func:`call` runs it and reports what a user would see: a result (its numbers checked
finite when every input was), the project's error (one line) or anything else (a traceback).
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import functools
import importlib
import inspect
import io
import math
import os
import pkgutil
import random
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import pushrecovery
from pushrecovery.errors import PushRecoveryError

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: Floors the API fuzz leaves to others: the CLI (fuzzed by its command lines) and the
#: compiled kernels (called with checked arguments only, docs/architecture.md).
SKIPPED = ("pushrecovery.cli", "pushrecovery.kernels")
#: Callables whose purpose is a side effect on the process that runs them, and why.
EXCLUDED = {
    "pushrecovery.campaign.watchdog.start": "ends its own process when armed (a worker's)",
    "pushrecovery.campaign.watchdog.arm": "ends its own process at the deadline (a worker's)",
    "pushrecovery.control.base.register": "a class decorator: registering changes the registry",
    "pushrecovery.control.mpc.plan.Plan": "a result the MPC builds at every tick (1 kHz path)",
}
#: Callables that return NaN or an infinity by their documentation (a value that does not
#: exist, a time that never comes), and where.
NAN_DOCUMENTED = {
    "pushrecovery.surfaces.cop.capture_point": "the states unchecked: NaN in, NaN out (per tick)",
    "pushrecovery.surfaces.plane.capture_point_xy": "the states unchecked, as capture_point",
    "pushrecovery.surfaces.step.plan_step": "theta, step_length: NaN where no step is ready",
    "pushrecovery.surfaces.step.plan_steps": "theta, step_length: NaN where no step is ready",
    "pushrecovery.surfaces.plane.plan_step_xy": "the step's plan: NaN where no step is ready",
    "pushrecovery.analysis.margins.plane.margins_2d": "NaN: a missing frame, or no CoP given",
    "pushrecovery.analysis.margins.plane.time_to_boundary_cop": "+inf: the CoP never leaves",
    "pushrecovery.analysis.margins.plane.time_to_boundary_xcom": "+inf: the XCoM never leaves",
    "pushrecovery.analysis.margins.time_to_leave": "NaN: a missing frame",
    "pushrecovery.analysis.posturography.mean_frequency": "NaN: an axis without sway",
    "pushrecovery.surfaces.step.regions.line_steps": "first steps: NaN where no step is taken",
    "pushrecovery.analysis.margins.direction_margins": "NaN: a missing frame, or no step",
    "pushrecovery.sim.many.run_many": "NaN: the measures of an error row (a push that timed out)",
    "pushrecovery.sim.validation.critical_table": "NaN: no correction, no measured force",
    "pushrecovery.experiments.validation3d.step.run_step_validation": "NaN: no run, no step",
    "pushrecovery.experiments.validation3d.run_validation3d": "NaN: no run",
    "pushrecovery.analysis.zero_point.com_from_force": "NaN outside the zero points",
    "pushrecovery.surfaces.probability.scores.brier_score": "NaN: no predictions",
}
#: Floors whose work is minutes of simulation or whole campaigns on valid input: fuzzed only
#: with at least one argument drawn hostile for its type, so that a refusal is what is checked.
HEAVY = (
    "pushrecovery.campaign", "pushrecovery.experiments", "pushrecovery.report",
    "pushrecovery.sim.mujoco", "pushrecovery.sim.critical", "pushrecovery.sim.validation",
    "pushrecovery.plots",
)  # fmt: skip

FLOATS: list[Any] = [
    math.nan, -math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, -5e-324, 1e-300, 1e-12, 1e15,
    1e300, -1e300, 1.7976931348623157e308, -1.0, 1.0, 0.1, 7.0, 10**400 // 10**390, True,
]  # fmt: skip
INTS: list[Any] = [0, -1, 1, 2, 3, 10**9, -(10**9), 10**30, 2**63, True, False, 1.5, math.nan]
STRINGS: list[Any] = ["", "x", "nope", "\x00", "é" * 3, "a" * 5000, "left", "1", " ", "nan"]
BOOLS: list[Any] = [2, -1, "yes", "", None, np.bool_(True), 0.5, [True]]


def _arrays() -> list[Any]:
    return [
        np.array([math.nan]), np.full((3, 2), math.inf), np.zeros(0), np.zeros((0, 2)),
        [[1.0, 2.0], [3.0]], np.array(["a", "b"]), np.zeros((2, 2, 2)), [1e300, -1e300],
        np.array([5e-324, -5e-324]), np.array(1.0), np.ones((4, 3)) * 1e308,
        np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]), np.arange(5.0)[::-1].copy(),
        np.array([1 + 2j]), np.ones(3, dtype=np.int8), [math.nan, 0.0, 1.0],
        np.full(2, -0.0), (0.0,), [[math.nan, 0.0], [1.0, 1.0], [0.0, 1.0]],
    ]  # fmt: skip


def _paths(folder: Path) -> list[Any]:
    fifo = folder / "fifo.csv"
    if not fifo.exists():
        os.mkfifo(fifo)
    loop = folder / "loop.c3d"
    if not loop.is_symlink():
        loop.symlink_to(loop)
    empty = folder / "empty.csv"
    empty.write_bytes(b"")
    return [
        str(fifo), fifo, "/dev/zero", "/dev/null", "", str(folder), "/proc/version/x.png",
        str(folder / ("a" * 300)), str(loop), str(empty), str(folder / "missing.c3d"), 0,
    ]  # fmt: skip


def _others() -> list[Any]:
    return [None, "x", 0, -1.0, math.nan, object(), [], {}, (None,), b"\xff", np.zeros(2)]


def pools(annotation: str, folder: Path) -> list[Any]:
    """Hostile values for a parameter annotated ``annotation`` (a string: PEP 563)."""
    text = annotation.replace(" ", "")
    found: list[Any] = []
    if "Path" in text or "os.PathLike" in text:
        found += _paths(folder)
    if any(k in text for k in ("ArrayLike", "NDArray", "ndarray", "Sequence", "tuple", "list")):
        found += _arrays()
    if "float" in text:
        found += FLOATS
    if "int" in text.replace("Point", "").replace("print", ""):
        found += INTS
    if "bool" in text:
        found += BOOLS
    if "str" in text or "Literal" in text:
        found += STRINGS
    return found or _others()


def public() -> dict[str, Any]:
    """Every function and class in a public module's ``__all__``, by dotted name."""
    found: dict[str, Any] = {}
    for info in pkgutil.walk_packages(pushrecovery.__path__, "pushrecovery."):
        name = info.name
        if any(p.startswith("_") for p in name.split(".")) or name.startswith(SKIPPED):
            continue
        module = importlib.import_module(name)
        for attribute in getattr(module, "__all__", []):
            item = getattr(module, attribute, None)
            if getattr(item, "__module__", None) != name or f"{name}.{attribute}" in EXCLUDED:
                continue
            if attribute.endswith("_unchecked"):  # the checked function's kernel, by its name
                continue
            if inspect.isfunction(item) or (inspect.isclass(item) and _takes_input(item)):
                found[f"{name}.{attribute}"] = item
    return found


def _takes_input(cls: type) -> bool:
    """Whether a class is built from a caller's values: not an error, enum, protocol or
    abstract class, nor a record the library fills (a dataclass without ``__post_init__``)."""
    if issubclass(cls, BaseException | enum.Enum) or getattr(cls, "_is_protocol", False):
        return False
    if inspect.isabstract(cls) or (issubclass(cls, tuple) and hasattr(cls, "_fields")):
        return False  # an abstract class, or a NamedTuple: a record the library fills
    return not (dataclasses.is_dataclass(cls) and "__post_init__" not in vars(cls))


def _parameters(item: Any) -> list[inspect.Parameter]:
    try:
        signature = inspect.signature(item)
    except (TypeError, ValueError):
        return []
    return [
        p for p in signature.parameters.values() if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]


def _examples(name: str) -> dict[str, Any]:
    import test_api_sweep as sweep

    floors = ("pushrecovery.sim.mujoco", "pushrecovery.control.wbc")
    mujoco = _mujoco_examples() if name.startswith(floors) else {}
    return {**sweep.VALID, **mujoco, **sweep.OVERRIDES.get(name, {})}


@functools.cache
def _mujoco_examples() -> dict[str, Any]:
    """Valid MuJoCo objects for the floors that take them: the generated biped3d, standing
    (built once per worker), so that the other parameters' checks are reached too."""
    from pushrecovery.presets import load_params
    from pushrecovery.sim.mujoco.humanoid3d.plant3d import Biped3DPlant

    plant = Biped3DPlant(load_params())
    return {
        "model": plant.model, "data": plant.data, "qpos": plant.qpos.copy(), "feet": plant.feet,
        "torso": plant.torso, "upright": plant.upright, "observation": plant.observation,
        "plant": plant, "name": "torso", "knee": 0.3,
    }  # fmt: skip


def draw(name: str, item: Any, seed: int, folder: Path) -> tuple[dict[str, Any], list[str]]:
    """The arguments of one case, and the names of those drawn hostile."""
    rng = random.Random(seed)
    params = _parameters(item)
    known = _examples(name)
    arguments: dict[str, Any] = {}
    hostile: list[str] = []
    for p in params:
        if p.default is p.empty:
            if p.name in known:
                arguments[p.name] = known[p.name]
            else:
                arguments[p.name] = rng.choice(pools(str(p.annotation), folder))
                hostile.append(p.name)
    if params:
        for p in rng.sample(params, k=min(len(params), rng.choice([1, 1, 1, 2, 3]))):
            pool = pools(str(p.annotation), folder) if rng.random() < 0.75 else _others()
            arguments[p.name] = rng.choice(pool)
            if p.name not in hostile:
                hostile.append(p.name)
        if name.startswith(HEAVY):  # one value no parameter takes: a refusal, not minutes of work
            p = rng.choice(params)
            arguments[p.name] = rng.choice([object(), b"\xff", math.nan])
            hostile.append(p.name)
    return arguments, hostile


def nonfinite(value: Any, depth: int = 0) -> bool:
    """Whether ``value`` holds a NaN or an infinity (numbers, arrays, containers, dataclasses)."""
    if depth > 4:
        return False
    if isinstance(value, bool | int | str | bytes) or value is None:
        return False
    if isinstance(value, float | np.floating):
        return not math.isfinite(value)
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and value.size <= 10**7:
            return not bool(np.isfinite(value).all())
        return False
    if isinstance(value, tuple | list) and len(value) <= 10_000:
        return any(nonfinite(v, depth + 1) for v in value)
    if isinstance(value, dict) and len(value) <= 10_000:
        return any(nonfinite(v, depth + 1) for v in value.values())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return any(
            nonfinite(getattr(value, f.name, None), depth + 1) for f in dataclasses.fields(value)
        )
    return False


def _short(value: Any) -> str:
    text = repr(value)
    if isinstance(value, np.ndarray):
        text = f"array(shape={value.shape}, dtype={value.dtype}, first={value.ravel()[:3]!r})"
    return text if len(text) <= 80 else text[:77] + "..."


#: (callable, parameter) pairs that take a NaN or an infinity by their documentation (an
#: unbounded limit, a missing value), and why: no silent acceptance there.
TAKES_NONFINITE: dict[tuple[str, str], str] = {
    ("pushrecovery.report.markup.percent_within", "value"): "NaN: not computed, an em dash",
    ("pushrecovery.report.markup.percent_within", "resolution"): "NaN: unknown, no ± shown",
    ("pushrecovery.surfaces.n_step.capturability_distance", "steps"): "inf: N = ∞ steps",
    **{(f"pushrecovery.report.markup.{f}", "value"): "NaN: not computed, an em dash; ±inf: ∞"
       for f in ("num", "percent")},
}  # fmt: skip


def certainly_invalid(value: Any, parameter: inspect.Parameter, name: str) -> bool:
    """Whether no documented input of ``parameter`` could be ``value``: a bare ``object()``,
    bytes where no bytes are taken, None where the annotation has no None, a NaN or an
    infinity for a parameter annotated a float (a number, not an array)."""
    text = str(parameter.annotation).replace(" ", "")
    if "Any" in text or text in ("object", "inspect._empty", "_empty"):
        return False
    if type(value) is object:
        return True
    if isinstance(value, bytes) and "bytes" not in text:
        return True
    if value is None and "None" not in text and parameter.default is not None:
        return True
    if (
        isinstance(value, float) and not math.isfinite(value)
        and text in ("float", "float|None") and name not in NAN_DOCUMENTED
        and (name, parameter.name) not in TAKES_NONFINITE
    ):  # fmt: skip
        return True
    return False


def call(name: str, seed: int, folder: Path) -> dict[str, Any]:
    """Run one case; the answer in the CLI campaign's form (``code`` 0 result, 2 refusal)."""
    item = public()[name]
    arguments, hostile = draw(name, item, seed, folder)
    shown = ", ".join(f"{k}={_short(v)}" for k, v in arguments.items())
    reproduction = f"{name}({shown})  # api.draw({name!r}, seed={seed})"
    code, out, err, escaped, accepted = 0, "", "", None, []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            with (
                contextlib.redirect_stdout(io.StringIO()),
                contextlib.redirect_stderr(io.StringIO()),
            ):
                result = item(**arguments)
        except PushRecoveryError as exc:
            code, err = 2, f"pushrecovery: error: {exc}\n"
        except BaseException as exc:  # a traceback the user would see
            code = 1
            tb = inspect.trace()[-1] if inspect.trace() else None
            where = f" | {tb.filename}:{tb.lineno}" if tb else ""
            escaped = f"{type(exc).__name__}: {str(exc)[:300]}{where}"
        else:
            parameters = {p.name: p for p in _parameters(item)}
            accepted = [
                p for p in hostile
                if p in parameters and certainly_invalid(arguments[p], parameters[p], name)
            ]  # fmt: skip
            inputs_finite = not any(nonfinite(v) for v in arguments.values())
            if inputs_finite and nonfinite(result) and name not in NAN_DOCUMENTED:
                out = "nan"  # the campaign's NUMBER pattern
    return {
        "code": code,
        "stdout": out,
        "stderr": err[:20_000],
        "warnings": [f"{w.category.__name__}: {w.message}"[:300] for w in caught],
        "escaped": escaped,
        "call": reproduction,
        "hostile": hostile,
        "accepted": accepted,
    }
