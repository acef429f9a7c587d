"""The force plates of a C3D file in the lab frame: through ezc3d where it agrees, else ours.

:func:`read_plates` parses ``FORCE_PLATFORM`` once, asks :func:`.dispatch.plate_path` who
computes each plate, and returns the same :class:`.ForcePlate` either way (docs/c3d.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.c3d.content import ForcePlate
from pushrecovery.analysis.c3d.dispatch import ezc3d_extracts, plate_path
from pushrecovery.analysis.c3d.forceplate import (
    _load_sign,
    plate_cop_in_plate_frame,
    plate_frame,
    wrench_type2,
    wrench_type3,
)
from pushrecovery.analysis.c3d.parameters import (
    _CHANNEL_KINDS,
    _cal_matrix,
    _first_text,
    _lab_up,
    _param,
    _required,
    _unit_scale,
)
from pushrecovery.errors import InputFileError
from pushrecovery.extras import require

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class PlateSetup:
    """One plate as the file describes it (lab frame, SI).

    Parameters
    ----------
    kind : int
        ``FORCE_PLATFORM:TYPE``.
    raw : ndarray, shape (n, channels)
        Its analog channels as ezc3d returns them (scaled, in the file's units).
    scales : ndarray, shape (channels,)
        SI factor of each channel (N, N m, m per unit), from ``ANALOG:UNITS``.
    default_units : bool
        Whether ``scales`` are the C3D defaults (N, N·(point unit), (point unit)).
    origin : ndarray, shape (3,)
        ``FORCE_PLATFORM:ORIGIN`` [m], sign as stored.
    corners : ndarray, shape (4, 3)
        ``FORCE_PLATFORM:CORNERS`` [m], lab frame, the file's order.
    cal_matrix : ndarray, shape (6, 6), or None
        Type 4 only.
    cop_poly : ndarray, shape (12,), or None
        ``FORCE_PLATFORM:FPCOPPOLY`` of a type-3 plate, when the file has it.
    """

    kind: int
    raw: FloatArray
    scales: FloatArray
    default_units: bool
    origin: FloatArray
    corners: FloatArray
    cal_matrix: FloatArray | None
    cop_poly: FloatArray | None


def read_plates(
    file: Path, params: Any, analogs: FloatArray, length: float, threshold: float
) -> tuple[ForcePlate, ...]:
    """Every plate of ``FORCE_PLATFORM`` in the lab frame (``analogs``: channels × samples).

    ``length`` is the point unit [m]; ``threshold`` the smallest load [N] with a CoP.
    """
    setups = plate_setups(file, params, analogs, length)
    if not setups:
        return ()
    up = _lab_up(params)
    fp_types = [setup.kind for setup in setups]
    cal = _param(params, "FORCE_PLATFORM", "CAL_MATRIX")
    channel = _param(params, "FORCE_PLATFORM", "CHANNEL")
    extracts = ezc3d_extracts(fp_types, None if cal is None else np.shape(cal), np.shape(channel))
    paths = [
        plate_path(
            setup.kind,
            setup.origin,
            setup.corners,
            up=up,
            default_units=setup.default_units,
            cop_poly=setup.cop_poly is not None,
            point_mm=length == 1e-3,
            extracts=extracts,
            samples=analogs.shape[1] * len(setups),
        )[0]
        for setup in setups
    ]
    platforms: list[Any] = []
    if "ezc3d" in paths:
        try:
            platforms = _ezc3d_platforms(file)
        except Exception:  # any failure of ezc3d's module: ours gives the same numbers
            platforms = []
        if len(platforms) != len(setups) or any(
            np.shape(platform["force"]) != (3, analogs.shape[1]) for platform in platforms
        ):
            paths = ["own"] * len(setups)
    return tuple(
        ezc3d_plate(setup, platforms[index], up, length, threshold)
        if path == "ezc3d"
        else own_plate(setup, up, threshold)
        for index, (setup, path) in enumerate(zip(setups, paths, strict=True))
    )


def _ezc3d_platforms(file: Path) -> list[Any]:
    """ezc3d's force-platform output for every plate of the file (it parses the file again)."""
    require("analysis", "ezc3d", "reading a C3D file")
    import ezc3d

    return list(ezc3d.c3d(str(file), extract_forceplat_data=True)["data"]["platform"])


def own_plate(setup: PlateSetup, up: FloatArray, threshold: float) -> ForcePlate:
    """One plate through this package's formulas (:mod:`.forceplate`), lab frame, SI.

    Parameters
    ----------
    setup : PlateSetup
    up : ndarray, shape (3,)
        The lab's up axis.
    threshold : float
        Smallest load [N] with a defined CoP and free moment.
    """
    data = setup.raw * setup.scales if setup.kind != 4 else setup.raw
    if setup.kind == 1:
        force = data[:, :3]
        cop = np.column_stack([data[:, 3], data[:, 4], np.zeros(len(data))])
        sign = _load_sign(force)
        force, free = sign * force, sign * data[:, 5]
        unloaded = force[:, 2] < threshold
        cop[unloaded] = np.nan
        free = np.where(unloaded, np.nan, free)
    else:
        if setup.kind == 2:
            force, moment = wrench_type2(data, setup.origin)
        elif setup.kind == 3:
            force, moment = wrench_type3(data, setup.origin)
        else:  # calibrate first: the units are those of the calibrated outputs
            assert setup.cal_matrix is not None
            force, moment = wrench_type2(data @ setup.cal_matrix.T * setup.scales, setup.origin)
        sign = _load_sign(force)
        force, moment = sign * force, sign * moment
        cop, free = plate_cop_in_plate_frame(
            force, moment, threshold=threshold, cop_poly=setup.cop_poly
        )
    rotation, centre = plate_frame(setup.corners, up)
    return _plate(-(force @ rotation.T), centre + cop @ rotation.T, free, setup, "own")


def ezc3d_plate(
    setup: PlateSetup, platform: Any, up: FloatArray, length: float, threshold: float
) -> ForcePlate:
    """One plate from ezc3d's force-platform output, in our units and signs.

    ezc3d gives R·(channels) without choosing action or reaction: ``force`` [N] is the
    channels' force in the lab, ``center_of_pressure`` [point unit] the lab CoP and ``Tz``
    [N·point unit] the free moment along the plate's z axis ẑ (into the plate), with R its
    plate frame, the same as ours where :func:`.dispatch.plate_path` sends a plate here. As in
    :func:`own_plate` the load sign s is that of the summed F·ẑ (+1 for amplifiers, −1 for
    Vicon): force on the subject = −s F, free moment = s Tz·ẑ, both NaN-masked with the CoP
    where s F·ẑ < ``threshold``.

    Parameters
    ----------
    setup : PlateSetup
    platform : mapping
        One element of ``ezc3d.c3d(path, extract_forceplat_data=True)["data"]["platform"]``.
    up : ndarray, shape (3,)
        The lab's up axis.
    length : float
        The point unit [m].
    threshold : float
        Smallest load [N] with a defined CoP and free moment.
    """
    channel_force = np.asarray(platform["force"], dtype=np.float64).T
    rotation, _ = plate_frame(setup.corners, up)
    down = rotation[:, 2]
    load = channel_force @ down
    sign = -1.0 if float(np.sum(load)) < 0.0 else 1.0
    loaded = sign * load >= threshold
    cop = np.asarray(platform["center_of_pressure"], dtype=np.float64).T * length
    moment = np.asarray(platform["Tz"], dtype=np.float64).T @ down * length
    free = np.where(loaded, sign * moment, np.nan)
    cop = np.where(loaded[:, None], cop, np.nan)
    return _plate(-sign * channel_force, cop, free, setup, "ezc3d")


def _plate(
    force: FloatArray, cop: FloatArray, free: FloatArray, setup: PlateSetup, path: str
) -> ForcePlate:
    corners = setup.corners.copy()
    for array in (force, cop, free, corners):
        array.setflags(write=False)
    return ForcePlate(force, cop, free, corners, computed_by=path)


def plate_setups(file: Path, params: Any, analogs: FloatArray, length: float) -> list[PlateSetup]:
    """Parse ``FORCE_PLATFORM`` and each plate's channels (``analogs``: channels × samples).

    Raises
    ------
    InputFileError
        One line naming the file: an unsupported type, missing channels or parameters,
        unknown units, a bad CAL_MATRIX or FPCOPPOLY.
    """
    used = _param(params, "FORCE_PLATFORM", "USED")
    n_plates = int(np.asarray(used).ravel()[0]) if used is not None and np.size(used) else 0
    if n_plates <= 0:
        return []
    types = np.asarray(_required(file, params, "FORCE_PLATFORM", "TYPE")).ravel().astype(int)
    corners = np.asarray(_required(file, params, "FORCE_PLATFORM", "CORNERS"), dtype=np.float64)
    origins = np.asarray(_required(file, params, "FORCE_PLATFORM", "ORIGIN"), dtype=np.float64)
    channel = np.asarray(_required(file, params, "FORCE_PLATFORM", "CHANNEL")).astype(int)
    if channel.ndim == 1:
        channel = channel[:, None]
    if types.size < n_plates or corners.size < 12 * n_plates or origins.size < 3 * n_plates:
        raise InputFileError(
            f"{file}: FORCE_PLATFORM describes fewer plates than FORCE_PLATFORM:USED = {n_plates}"
        )
    corners = corners.reshape(3, 4, -1, order="F") if corners.ndim != 3 else corners
    origins = origins.reshape(3, -1, order="F") if origins.ndim != 2 else origins
    unit_values = _param(params, "ANALOG", "UNITS")
    units = [] if unit_values is None else [str(u) for u in np.atleast_1d(unit_values)]
    point_unit = _first_text(_param(params, "POINT", "UNITS")).strip() or "mm"
    polys = _cop_polys(file, params, n_plates)
    setups = []
    for index in range(n_plates):
        kind = int(types[index])
        if kind not in _CHANNEL_KINDS:
            raise InputFileError(
                f"{file}: force plate {index + 1} has unsupported FORCE_PLATFORM:TYPE {kind} "
                "(supported: 1, 2, 3, 4)"
            )
        kinds = _CHANNEL_KINDS[kind]
        numbers: list[int] = (
            [int(n) for n in channel[: len(kinds), index]] if channel.shape[1] > index else []
        )
        if len(numbers) < len(kinds) or min(numbers) < 1 or max(numbers) > analogs.shape[0]:
            raise InputFileError(
                f"{file}: force plate {index + 1} (type {kind}) needs {len(kinds)} analog "
                f"channels; FORCE_PLATFORM:CHANNEL lists {numbers} of "
                f"{analogs.shape[0]} recorded"
            )
        scales = np.array(
            [
                _unit_scale(file, units, number - 1, what, point_unit, length, kind == 4)
                for number, what in zip(numbers, kinds, strict=True)
            ]
        )
        defaults = np.array([1.0 if what == "F" else length for what in kinds])
        setups.append(
            PlateSetup(
                kind=kind,
                raw=analogs[np.asarray(numbers) - 1].T,
                scales=scales,
                default_units=bool(np.array_equal(scales, defaults)),
                origin=origins[:, index] * length,
                corners=corners[:, :, index].T * length,
                cal_matrix=_cal_matrix(file, params, index) if kind == 4 else None,
                cop_poly=polys[index] if polys is not None and kind == 3 else None,
            )
        )
    return setups


def _cop_polys(file: Path, params: Any, n_plates: int) -> FloatArray | None:
    """``FORCE_PLATFORM:FPCOPPOLY`` as (plates, 12), or None when absent or empty.

    12 values per plate, P1x..P6x then P1y..P6y, in the parameter's storage order (as ezc3d
    reads them); rows of plates that are not of type 3 are ignored.
    """
    value = _param(params, "FORCE_PLATFORM", "FPCOPPOLY")
    if value is None or not np.size(value):
        return None
    try:
        flat = np.asarray(value, dtype=np.float64).ravel(order="F")
    except (TypeError, ValueError):
        raise InputFileError(f"{file}: FORCE_PLATFORM:FPCOPPOLY is not numeric") from None
    if flat.size % 12 or flat.size < 12 * n_plates or not np.isfinite(flat).all():
        raise InputFileError(
            f"{file}: FORCE_PLATFORM:FPCOPPOLY has {flat.size} values; Kistler's CoP "
            f"correction needs 12 finite ones per plate (P1x..P6x, P1y..P6y) for "
            f"{n_plates} plate(s)"
        )
    return flat[: 12 * n_plates].reshape(n_plates, 12)
