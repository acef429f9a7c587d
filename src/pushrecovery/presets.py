"""Built-in presets and loading a body: presets, TOML parameter files and overrides.

:func:`load_params` is the one way a body enters the library from outside (the CLI's
``--preset``, ``--params`` and flags); everything it returns is a validated
:class:`~pushrecovery.params.BodyParams`.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

from pushrecovery.errors import InputFileError, InvalidParameterError, ParameterTypeError
from pushrecovery.params import FIELD_NAMES, BodyParams

__all__ = ["PRESETS", "load_params"]


#: Largest parameter file [bytes]: a body is a few hundred bytes of TOML.
MAX_TOML_BYTES = 64 * 1024
#: Built-in presets. ``paper``: the flywheel values of Fig. 5(b) (I, τmax, θmax); the body and
#: foot are our documented choice (a 72 kg adult, CoM 1 m above the ankle, 20 cm foot with the
#: ankle 5 cm in front of the heel, 10 cm wide, ankles 20 cm apart; the roll axis of the upper
#: body equal to its pitch axis).
PRESETS: Mapping[str, Mapping[str, Any]] = MappingProxyType(
    {
        "paper": MappingProxyType(
            {
                "mass": 72.0,
                "com_height": 1.0,
                "gravity": 9.81,
                "heel": -0.05,
                "toe": 0.15,
                "flywheel_inertia": 10.0,
                "torque_max": 100.0,
                "flywheel_angle_max": 1.0,
                "leg_length": None,
                "max_step_length": None,
                "foot_width": 0.10,
                "stance_width": 0.20,
                "foot_polygon": None,
                "flywheel_inertia_roll": None,
                "torque_max_roll": None,
                "flywheel_angle_max_roll": None,
                "min_step_time": 0.2,
                "max_steps": None,
                "min_step_width": None,
            }
        )
    }
)


def load_params(
    preset: str = "paper",
    file: str | Path | None = None,
    overrides: Mapping[str, Any] | None = None,
) -> BodyParams:
    """Build parameters from a preset, then a TOML file, then explicit overrides (later wins).

    Parameters
    ----------
    preset : str
        Name of a built-in preset (see :data:`PRESETS`). A TOML file may name its own with a
        top-level ``preset = "..."`` key.
    file : str or Path, optional
        TOML file with any of the field names of :class:`BodyParams` as top-level keys, in SI
        units (optionally under a ``[body]`` table).
    overrides : mapping, optional
        Field values that win over the preset and the file; ``None`` values are ignored.

    Returns
    -------
    BodyParams
        The validated parameter set.

    Raises
    ------
    InvalidParameterError
        Unknown preset or field, or a value out of range.
    InputFileError
        Missing, unreadable or malformed TOML file.
    """
    values: dict[str, Any] = {}
    from_file: dict[str, Any] = _read_toml(Path(file)) if file is not None else {}
    preset = str(from_file.pop("preset", preset))
    if preset not in PRESETS:
        raise InvalidParameterError(
            f"preset must be one of {sorted(PRESETS)}, got preset={preset!r}"
        )
    values.update(PRESETS[preset])
    values.update(from_file)
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ParameterTypeError(
            "overrides must be a mapping of parameter names to values, got "
            f"{type(overrides).__name__}"
        )
    values.update({k: v for k, v in (overrides or {}).items() if v is not None})
    unknown = sorted(set(values) - set(FIELD_NAMES))
    if unknown:
        raise InvalidParameterError(
            f"unknown parameter {unknown[0]!r}; known parameters: {', '.join(FIELD_NAMES)}"
        )
    given = {k for k, v in (overrides or {}).items() if v is not None} | set(from_file)
    # The presets tie the leg to the CoM height and the reach to the leg; keep those ties when
    # only the quantity they follow changes.
    if "com_height" in given and "leg_length" not in given:
        values["leg_length"] = PRESETS[preset].get("leg_length")
    if {"com_height", "leg_length"} & given and "max_step_length" not in given:
        values["max_step_length"] = PRESETS[preset].get("max_step_length")
    if values.get("foot_polygon") is not None:
        from pushrecovery.ground.user_polygon import convex_polygon

        # Validated before its extents become heel, toe and foot_width, so that errors name it.
        polygon = convex_polygon(
            "foot_polygon", _polygon_value(values["foot_polygon"]), contains_origin=True
        )
        values["foot_polygon"] = tuple((float(x), float(y)) for x, y in polygon.vertices)
        clash = sorted({"heel", "toe", "foot_width"} & given)
        if clash:
            raise InvalidParameterError(
                f"give either foot_polygon or {clash[0]}, not both (the polygon sets heel, toe "
                "and foot_width)"
            )
        xs = [x for x, _ in values["foot_polygon"]]
        ys = [y for _, y in values["foot_polygon"]]
        values.update(heel=min(xs), toe=max(xs), foot_width=max(ys) - min(ys))
    for name, value in values.items():
        if name == "foot_polygon":
            continue
        if value is not None and (isinstance(value, bool) or not isinstance(value, int | float)):
            raise InvalidParameterError(f"{name} must be a number, got {value!r}")
    return BodyParams(**values)


def _polygon_value(value: Any) -> tuple[tuple[float, float], ...]:
    """``foot_polygon`` as a tuple of (x, y) pairs of numbers, or a one-line error."""
    if not isinstance(value, list | tuple) or not value:
        raise InvalidParameterError(
            f"foot_polygon must be a list of [x, y] vertices in m, got {value!r:.60}"
        )
    pairs = []
    for index, vertex in enumerate(value):
        if (
            not isinstance(vertex, list | tuple)
            or len(vertex) != 2
            or any(isinstance(c, bool) or not isinstance(c, int | float) for c in vertex)
        ):
            raise InvalidParameterError(
                f"foot_polygon vertex {index} must be a pair of numbers [x, y] in m, "
                f"got {vertex!r:.40}"
            )
        pairs.append((float(vertex[0]), float(vertex[1])))
    return tuple(pairs)


def _read_toml(path: Path) -> dict[str, Any]:
    import stat
    import tomllib  # here, not at the top: 10-20 ms of every start-up without a file

    try:
        # A FIFO or a device would block or never end: only regular files, and small ones.
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            raise InputFileError(f"parameter file {path} is a directory")
        if not stat.S_ISREG(mode):
            raise InputFileError(f"parameter file {path} is not a regular file")
        with path.open("rb") as handle:
            text = handle.read(MAX_TOML_BYTES + 1)
        if len(text) > MAX_TOML_BYTES:
            raise InputFileError(
                f"parameter file {path} is larger than {MAX_TOML_BYTES // 1024} KiB"
            )
        data = tomllib.loads(text.decode("utf-8"))
    except FileNotFoundError:
        raise InputFileError(f"parameter file not found: {path}") from None
    except OSError as exc:
        raise InputFileError(f"cannot read parameter file {path}: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputFileError(f"malformed TOML in {path}: {exc}") from None
    except UnicodeDecodeError:
        raise InputFileError(f"parameter file {path} is not UTF-8 text (TOML)") from None
    except RecursionError:
        raise InputFileError(f"malformed TOML in {path}: nested too deeply") from None
    body = data.pop("body", None)
    if body is not None:
        if not isinstance(body, dict):
            raise InputFileError(f"[body] in {path} must be a table")
        data.update(body)
    return data
