"""Write a C3D file that third-party readers understand: markers and type-2 force plates."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.analysis.c3d.forceplate import _channels, plate_frame
from pushrecovery.arguments import positive_float
from pushrecovery.errors import InvalidParameterError
from pushrecovery.extras import require

FloatArray = NDArray[np.float64]


_WRITE_LABELS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
_WRITE_UNITS = ("N", "N", "N", "Nmm", "Nmm", "Nmm")


# --- Writing --------------------------------------------------------------------------------
def write_c3d(
    path: str | Path,
    *,
    point_rate: float,
    markers: Mapping[str, ArrayLike],
    analog_rate: float,
    plates: Sequence[tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike]],
    mass: float | None = None,
) -> None:
    """Write markers and force plates (lab frame, SI) as a C3D file that other readers agree on.

    Parameters
    ----------
    path : str or Path
        The file to write (overwritten).
    point_rate : float
        Marker frame rate [Hz], > 0.
    markers : mapping of str to array_like, shape (n_points, 3)
        Label -> position [m], lab frame; NaN rows are gaps (written with residual −1).
    analog_rate : float
        Analog rate [Hz], an integer multiple k of ``point_rate``.
    plates : sequence of (force, cop, free_moment, corners)
        Per plate: force on the subject (n, 3) [N], CoP (n, 3) [m] on the top surface (lab),
        free moment (n,) [N m] on the subject about up, corners (4, 3) [m]; n = k · n_points.
        Corners in the spec's order are clockwise seen from above (z-down plate); corners
        listed anticlockwise (the quadrants of a z-up frame) are written as corners 1, 4, 3, 2,
        the same rectangle in the spec's order, so that other readers agree. A NaN CoP (an
        unloaded plate) is written at the plate centre, a NaN free moment as 0.
    mass : float, optional
        Subject mass [kg], > 0, stored as PROCESSING:Bodymass.

    Raises
    ------
    InvalidParameterError
        On inconsistent sizes or rates, non-finite forces, degenerate corners.
    """
    rate = positive_float("point_rate", point_rate, "Hz")
    a_rate = positive_float("analog_rate", analog_rate, "Hz")
    ratio = a_rate / rate
    per_frame = round(ratio)
    if per_frame < 1 or abs(ratio - per_frame) > 1e-9 * ratio:
        raise InvalidParameterError(
            f"analog_rate must be an integer multiple of point_rate, got {a_rate:g} / {rate:g} Hz"
        )
    labels = list(markers)
    positions = [_marker(label, markers[label]) for label in labels]
    lengths = {len(p) for p in positions}
    if len(lengths) > 1:
        raise InvalidParameterError(f"markers differ in length: {sorted(lengths)}")
    plate_data = [_plate_channels(i, plate) for i, plate in enumerate(plates)]
    samples = {len(channels) for channels, _ in plate_data}
    if len(samples) > 1:
        raise InvalidParameterError(f"plates differ in length: {sorted(samples)}")
    if positions:
        n_points = len(positions[0])
    elif plate_data:
        n_points = len(plate_data[0][0]) // per_frame
    else:
        raise InvalidParameterError("nothing to write: no markers and no plates")
    if n_points == 0:
        raise InvalidParameterError("nothing to write: zero frames")
    if samples and samples != {n_points * per_frame}:
        raise InvalidParameterError(
            f"plates must have {per_frame} samples per marker frame: {n_points * per_frame} "
            f"samples for {n_points} frames, got {samples.pop()}"
        )
    weight = None if mass is None else positive_float("mass", mass, "kg")
    if any(not isinstance(label, str) or not label.strip() for label in labels):
        raise InvalidParameterError("marker labels must be non-empty strings")

    require("analysis", "ezc3d", "writing a C3D file")
    import ezc3d

    c3d = ezc3d.c3d()
    point = c3d["parameters"]["POINT"]
    point["RATE"]["value"] = np.array([rate])
    point["UNITS"]["value"] = ["mm"]
    point["LABELS"]["value"] = tuple(labels)
    data = np.zeros((4, len(labels), n_points))
    data[3] = 1.0
    residuals = np.zeros((1, len(labels), n_points))
    for j, xyz in enumerate(positions):
        gap = np.logical_not(np.all(np.isfinite(xyz), axis=1))
        data[:3, j] = np.where(gap[:, None], 0.0, xyz * 1000.0).T
        residuals[0, j, gap] = -1.0
    c3d["data"]["points"] = data
    c3d["data"]["meta_points"]["residuals"] = residuals

    analog = c3d["parameters"]["ANALOG"]
    analog["RATE"]["value"] = np.array([a_rate])
    n_plates = len(plate_data)
    c3d["data"]["analogs"] = np.zeros((1, 0, n_points * per_frame))  # ezc3d checks the rates
    if n_plates:
        analog["LABELS"]["value"] = tuple(
            f"{name}{i + 1}" for i in range(n_plates) for name in _WRITE_LABELS
        )
        analog["UNITS"]["value"] = list(_WRITE_UNITS) * n_plates
        c3d["data"]["analogs"] = np.concatenate([ch for ch, _ in plate_data], axis=1).T[None]
        fp = c3d["parameters"]["FORCE_PLATFORM"]
        fp["USED"]["value"] = np.array([n_plates])
        fp["TYPE"]["value"] = np.full(n_plates, 2)
        fp["CORNERS"]["value"] = np.stack([corners.T * 1000.0 for _, corners in plate_data], -1)
        fp["ORIGIN"]["value"] = np.zeros((3, n_plates))
        fp["CHANNEL"]["value"] = np.arange(1, 6 * n_plates + 1).reshape(n_plates, 6).T
    if weight is not None:
        c3d.add_parameter("PROCESSING", "Bodymass", np.array([weight]))
    c3d.write(str(path))


def _plate_channels(index: int, plate: Sequence[ArrayLike]) -> tuple[FloatArray, FloatArray]:
    """Type-2 channels (n, 6) [N, N mm] of one plate to write, and its corners [m]."""
    try:
        force_in, cop_in, moment_in, corners_in = plate
    except (TypeError, ValueError):
        raise InvalidParameterError(
            f"plate {index + 1} must be (force, cop, free_moment, corners)"
        ) from None
    force = _channels(force_in, 3, f"plate {index + 1} force")
    if not np.isfinite(force).all():
        raise InvalidParameterError(f"plate {index + 1} force must be finite")
    cop = _channels(cop_in, 3, f"plate {index + 1} cop")
    free = np.asarray(moment_in, dtype=np.float64).reshape(-1)
    if not (len(cop) == len(force) == len(free)):
        raise InvalidParameterError(
            f"plate {index + 1}: force, cop and free_moment differ in length: "
            f"{len(force)}, {len(cop)}, {len(free)}"
        )
    corners = np.asarray(corners_in, dtype=np.float64)
    rotation, centre = plate_frame(corners)
    if np.linalg.det(rotation) < 0.0:
        # Anticlockwise seen from above (the quadrants of a z-up frame): the same rectangle in
        # the spec's order for a z-down plate keeps corner 1 and swaps the axes.
        corners = corners[[0, 3, 2, 1]]
        rotation, centre = plate_frame(corners)
    on_plate = -(force @ rotation)  # force on the plate, plate frame
    local = (np.where(np.isfinite(cop), cop, centre) - centre) @ rotation
    cx, cy = local[:, 0], local[:, 1]
    tz = np.nan_to_num(free, nan=0.0)
    fx, fy, fz = on_plate.T
    moment = np.column_stack([cy * fz, -cx * fz, cx * fy - cy * fx + tz])  # c × F + Tz ẑ
    return np.column_stack([on_plate, moment * 1000.0]), corners


def _marker(label: str, values: ArrayLike) -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        raise InvalidParameterError(f"marker {label!r} must be (n, 3), got shape {array.shape}")
    if np.isinf(array).any():
        raise InvalidParameterError(f"marker {label!r} has infinite coordinates")
    return array


# --- Small checks ----------------------------------------------------------------------------
