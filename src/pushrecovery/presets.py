"""Built-in presets and loading a body: presets, TOML parameter files and overrides.

:func:`load_params` is the one way a body enters the library from outside (the CLI's
``--preset``, ``--params`` and flags); everything it returns is a validated
:class:`~pushrecovery.params.BodyParams`. Where the body stands is not part of it: a file's
``[feet]`` table (the stance and the foot poses on the ground plane) is read by
:func:`load_support`, into a :class:`~pushrecovery.ground.support.Support`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from pushrecovery.arguments import require_type
from pushrecovery.errors import InputFileError, InvalidParameterError, ParameterTypeError
from pushrecovery.params import FIELD_NAMES, BodyParams

if TYPE_CHECKING:
    from pushrecovery.ground.support import FootPose, Support

__all__ = ["PRESETS", "load_params", "load_support"]


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
        units (optionally under a ``[body]`` table). Its ``[feet]`` table is checked here and
        read by :func:`load_support`.
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
    from_file: dict[str, Any] = _read_toml(_toml_path(file)) if file is not None else {}
    if "feet" in from_file:  # where the body stands, not the body: load_support's
        _feet_values(from_file.pop("feet"))
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


def load_support(
    params: BodyParams,
    file: str | Path | None = None,
    overrides: Mapping[str, Any] | None = None,
) -> Support:
    """Build the feet on the ground from a TOML file's ``[feet]`` table, then overrides.

    The table (every key optional; a file without it: both feet at their default poses)::

        [feet]
        stance = "left"                      # double (default), left or right
        left = {x = 0.0, y = 0.1, yaw = 0.0}   # ankle x, y [m]; yaw [rad] in [-pi, pi], default 0
        right = {x = 0.05, y = -0.1}

    A pose not given is the default one
    (:meth:`~pushrecovery.ground.support.Support.from_params`: x = 0, y = ±stance_width/2,
    yaw 0); poses are world frame, x forward, y left.

    Parameters
    ----------
    params : BodyParams
        The body whose feet stand there (its sole, stance width and legs).
    file : str or Path, optional
        TOML parameter file (:func:`load_params`' file).
    overrides : mapping, optional
        ``stance`` (str), ``left`` and ``right``
        (:class:`~pushrecovery.ground.support.FootPose`) that win over the file; ``None``
        values are ignored.

    Returns
    -------
    Support
        The stance and foot poses, with this body's soles.

    Raises
    ------
    InvalidParameterError
        An unknown key, a value of the wrong type or out of range (a yaw outside [−π, π] rad),
        a pose without x or y, an unknown stance, or feet that overlap or stand farther apart
        than two legs in double support.
    InputFileError
        Missing, unreadable or malformed TOML file.
    """
    from pushrecovery.arguments import require_type
    from pushrecovery.ground.support import FootPose, Support

    require_type("params", params, BodyParams)
    values = _feet_values(_read_toml(_toml_path(file)).get("feet", {})) if file is not None else {}
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ParameterTypeError(
            f"overrides must be a mapping of stance, left and right, got {type(overrides).__name__}"
        )
    for key, value in (overrides or {}).items():
        if key not in _FEET_KEYS:
            raise InvalidParameterError(
                f"unknown support override {key!r}; known: {', '.join(_FEET_KEYS)}"
            )
        if value is not None:
            if key != "stance":
                require_type(key, value, FootPose)
            values[key] = value
    return Support.from_params(
        params,
        values.get("stance", "double"),
        left=values.get("left"),
        right=values.get("right"),
    )


#: The keys of ``[feet]`` and of each foot's pose in it.
_FEET_KEYS = ("stance", "left", "right")
_POSE_KEYS = ("x", "y", "yaw")


def _feet_values(table: Any) -> dict[str, Any]:
    """``[feet]`` as ``stance`` (str) and ``left``/``right`` poses, or a one-line error."""
    from pushrecovery.ground.support import Stance

    if not isinstance(table, dict):
        raise InvalidParameterError(
            f"[feet] must be a table of stance, left and right, got {table!r:.40}"
        )
    unknown = sorted(set(table) - set(_FEET_KEYS))
    if unknown:
        raise InvalidParameterError(
            f"unknown key {unknown[0]!r} in [feet]; known keys: {', '.join(_FEET_KEYS)}"
        )
    values: dict[str, Any] = {}
    if "stance" in table:
        stance = table["stance"]
        if not isinstance(stance, str) or stance not in {s.value for s in Stance}:
            raise InvalidParameterError(
                f"[feet] stance must be one of {[s.value for s in Stance]}, got {stance!r:.40}"
            )
        values["stance"] = stance
    for side in ("left", "right"):
        if side in table:
            values[side] = _pose_value(side, table[side])
    return values


def _pose_value(side: str, pose: Any) -> FootPose:
    """One foot's ``{x, y[, yaw]}`` in ``[feet]`` as a FootPose, or a one-line error."""
    from pushrecovery.ground.support import FootPose

    name = f"[feet] {side}"
    if not isinstance(pose, dict):
        raise InvalidParameterError(
            f"{name} must be a table {{x = ..., y = ..., yaw = ...}} [m, m, rad], got {pose!r:.40}"
        )
    unknown = sorted(set(pose) - set(_POSE_KEYS))
    if unknown:
        raise InvalidParameterError(
            f"unknown key {unknown[0]!r} in {name}; known keys: {', '.join(_POSE_KEYS)}"
        )
    missing = [key for key in ("x", "y") if key not in pose]
    if missing:
        raise InvalidParameterError(f"{name} needs {missing[0]} [m] (x and y; yaw [rad] optional)")
    for key, value in pose.items():
        if isinstance(value, bool) or not isinstance(value, int | float):
            unit = "rad" if key == "yaw" else "m"
            raise InvalidParameterError(
                f"{name}.{key} must be a number [{unit}], got {value!r:.40}"
            )
    try:
        return FootPose(float(pose["x"]), float(pose["y"]), float(pose.get("yaw", 0.0)))
    except InvalidParameterError as error:
        raise InvalidParameterError(f"{name}: {error}") from None


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


def _toml_path(file: object) -> Path:
    """``file`` as a Path, or raise naming it unless it is a str or a path."""
    require_type("file", file, (str, os.PathLike))
    return Path(file)  # type: ignore[arg-type]


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
    except ValueError as exc:  # an integer of thousands of digits
        raise InputFileError(f"unreadable TOML in {path}: {str(exc).splitlines()[0]}") from None
    except RecursionError:
        raise InputFileError(f"malformed TOML in {path}: nested too deeply") from None
    body = data.pop("body", None)
    if body is not None:
        if not isinstance(body, dict):
            raise InputFileError(f"[body] in {path} must be a table")
        data.update(body)
    return data
