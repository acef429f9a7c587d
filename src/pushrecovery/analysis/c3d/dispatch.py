"""Which code computes a force plate: ezc3d's force-platform module, or this package's formulas.

ezc3d (``ezc3d.c3d(path, extract_forceplat_data=True)``) is used wherever it gives the vendor's
numbers, ours (:mod:`.forceplate`) only where it does not. The rules, their reasons and the
measurements behind them are in docs/c3d.md, "Which code computes a plate".
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from pushrecovery.analysis.c3d.forceplate import plate_frame

Route = Literal["ezc3d", "own"]

#: Largest samples × plates sent through ezc3d: its Python wrapper copies the platform output
#: sample by sample (about 12 µs per sample and plate measured with ezc3d 1.7.2, against well
#: under 1 µs for ours), so a long file would take seconds for the same numbers.
EZC3D_MAX_SAMPLES = 100_000

#: Largest difference between ezc3d's plate frame and ours (elements of the rotation) taken as
#: the same frame: float32 corners of a rotated rectangle differ from a parallelogram by ~1e-8.
FRAME_TOLERANCE = 1e-7


def ezc3d_extracts(
    types: ArrayLike,
    cal_matrix_shape: tuple[int, ...] | None,
    channel_shape: tuple[int, ...],
) -> bool:
    """Whether ezc3d's force-platform module accepts the file at all (else it raises).

    It needs ``FORCE_PLATFORM:CAL_MATRIX`` present unless every plate is of type 2, and for a
    type-4 plate k a 6 × 6 × (≥ k) matrix (an empty or 2-D one is refused, although the C3D
    convention reads an empty one as the identity); and ``FORCE_PLATFORM:CHANNEL`` as a
    channels × plates table (it indexes a 1-D one out of bounds). One refused plate fails the
    whole file.

    Parameters
    ----------
    types : array_like of int
        ``FORCE_PLATFORM:TYPE`` of the plates in use (``USED`` of them).
    cal_matrix_shape : tuple of int or None
        Shape of ``FORCE_PLATFORM:CAL_MATRIX`` as ezc3d returns it; None when it is missing.
    channel_shape : tuple of int
        Shape of ``FORCE_PLATFORM:CHANNEL`` as ezc3d returns it.
    """
    kinds = [int(kind) for kind in np.asarray(types).reshape(-1)]
    needed = max((8 if kind == 3 else 6 for kind in kinds), default=6)
    channel = tuple(channel_shape)
    if len(channel) != 2 or channel[0] < needed or channel[1] < len(kinds):
        return False
    if cal_matrix_shape is None:
        return all(kind == 2 for kind in kinds)
    if 4 not in kinds:
        return True
    last = max(index for index, kind in enumerate(kinds) if kind == 4)
    shape = tuple(cal_matrix_shape)
    return len(shape) == 3 and shape[:2] == (6, 6) and shape[2] > last


def plate_path(
    kind: int,
    origin: ArrayLike,
    corners: ArrayLike,
    *,
    up: ArrayLike = (0.0, 0.0, 1.0),
    default_units: bool = True,
    cop_poly: bool = False,
    point_mm: bool = True,
    extracts: bool = True,
    samples: int = 0,
) -> tuple[Route, str]:
    """Choose who computes one plate: ``"ezc3d"`` where it agrees with the vendor, else ``"own"``.

    ezc3d's results are the vendor's (to rounding, docs/c3d.md) when its plate frame, its
    reading of ``ORIGIN`` and its units are ours; each rule below is a case where they are not.

    Parameters
    ----------
    kind : int
        ``FORCE_PLATFORM:TYPE`` (1-4).
    origin : array_like, shape (3,)
        ``FORCE_PLATFORM:ORIGIN`` as stored (any length unit; only signs matter).
    corners : array_like, shape (4, 3)
        ``FORCE_PLATFORM:CORNERS`` in the lab, in the file's order (any length unit).
    up : array_like, shape (3,)
        The lab's up axis (``POINT:Y_SCREEN``).
    default_units : bool
        Whether every channel is in the C3D default units ezc3d assumes: N, N·(point unit) and
        (point unit); ezc3d never reads ``ANALOG:UNITS``.
    cop_poly : bool
        Whether the file has ``FORCE_PLATFORM:FPCOPPOLY`` (applied by both to type 3 only).
    point_mm : bool
        Whether ``POINT:UNITS`` is mm (or empty): ezc3d evaluates FPCOPPOLY in the point unit,
        Kistler's coefficients are for mm.
    extracts : bool
        :func:`ezc3d_extracts` for the file.
    samples : int
        Analog samples × plates of the file (ezc3d converts all plates at once).

    Returns
    -------
    path : {"ezc3d", "own"}
    reason : str
        Why, in one line.
    """
    if not extracts:
        return "own", "ezc3d's force-platform module refuses the file's CAL_MATRIX or CHANNEL"
    if samples > EZC3D_MAX_SAMPLES:
        return "own", (
            f"{samples} samples × plates: ezc3d's Python wrapper is slow (~12 µs each) "
            "for the same numbers"
        )
    if not default_units:
        return "own", "channel units other than N, N·(point unit): ezc3d ignores ANALOG:UNITS"
    stored = np.asarray(origin, dtype=np.float64).reshape(3)
    theirs = -stored if stored[2] > 0.0 else stored  # ezc3d negates the whole ORIGIN if z > 0
    if kind == 3 and (theirs[0] < 0.0 or theirs[1] < 0.0):
        return "own", "type 3: ezc3d negates the whole ORIGIN when z > 0, a or b < 0 (mirrored CoP)"
    if kind == 3 and cop_poly and not point_mm:
        return "own", "FPCOPPOLY with POINT:UNITS not mm: ezc3d applies it in the point unit"
    rotation, _ = plate_frame(corners, up)
    c1, c2, _, c4 = np.asarray(corners, dtype=np.float64).reshape(4, 3)
    x_axis = c1 - c2
    z_axis = np.cross(x_axis, c1 - c4)  # ezc3d: right-handed from corner 1's two edges
    axes = [x_axis, np.cross(z_axis, x_axis), z_axis]
    norms = [float(np.linalg.norm(axis)) for axis in axes]
    if min(norms) > 0.0:
        frame = np.column_stack([axis / norm for axis, norm in zip(axes, norms, strict=True)])
        if float(np.abs(frame - rotation).max()) <= FRAME_TOLERANCE:
            return "ezc3d", "ezc3d's frame, ORIGIN and units are ours"
    return "own", (
        "corners anticlockwise seen from above (BioWare) or not a parallelogram: "
        "ezc3d's plate frame differs from ours"
    )
