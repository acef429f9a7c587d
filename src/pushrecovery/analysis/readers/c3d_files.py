"""Measured trials from C3D files: markers, feet and the plates' combined CoP."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pushrecovery.analysis.recording import LOADED, Foot, Recording
from pushrecovery.analysis.signals import resample
from pushrecovery.arguments import input_file, input_path
from pushrecovery.errors import InputFileError, ParameterTypeError

if TYPE_CHECKING:
    from pushrecovery.analysis.c3d import ForcePlate
from pushrecovery.analysis.readers.common import (
    COM_MARKER,
    FOOT_MARKERS,
    STANDING_PERCENTILE,
    FloatArray,
    body_rotation,
)

__all__ = [
    "read_c3d_recording",
]


def _labels(name: str, value: object, size: int) -> None:
    """Raise naming ``name`` unless ``value`` is a list of labels (None: the default).

    ``size`` 4: exactly four, a foot's name and its heel, toe and ankle markers.
    """
    if value is None and size == 1:
        return
    ok = isinstance(value, list | tuple) and all(isinstance(v, str) for v in value)
    if not ok or (size == 4 and len(value) != 4):  # type: ignore[arg-type]
        what = "(name, heel, toe, ankle) labels" if size == 4 else "a list of marker labels"
        raise ParameterTypeError(f"{name} must be {what}, got {str(value)[:60]!r}")


def read_c3d_recording(
    path: str | Path,
    *,
    ap_axis: str = "x",
    com_markers: Sequence[str] | None = None,
    feet: Sequence[tuple[str, str, str, str]] | None = None,
) -> Recording:
    """Read a C3D trial: markers, force plates, subject mass.

    Parameters
    ----------
    path : str or Path
        The file.
    ap_axis : str
        Lab axis pointing forward: ``x``, ``-x``, ``y``, ``-y``, ``z`` or ``-z``; it must be
        horizontal (the file's ``POINT:Y_SCREEN`` names the up axis, default +z).
    com_markers : sequence of str, optional
        Markers whose mean is the CoM; default ``CentreOfMass`` when the file has it, else the
        CoM comes from the force plates.
    feet : sequence of (name, heel, toe, ankle), optional
        Foot marker labels; default the Plug-in Gait feet (:data:`FOOT_MARKERS`) present in
        the file.

    Returns
    -------
    Recording
        At the marker rate when the CoM comes from markers, else at the force-plate rate.

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a str or path, ``ap_axis`` not a str, ``com_markers`` not labels
        or ``feet`` not (name, heel, toe, ankle) labels.
    InputFileError
        A missing or malformed file, or markers it does not have.
    """
    from pushrecovery.analysis.c3d import read_c3d

    path = input_path("path", path)
    body_rotation(ap_axis)  # a bad axis name fails before the file is read
    _labels("com_markers", com_markers, 1)
    if feet is not None:
        if not isinstance(feet, list | tuple) or not feet:
            raise ParameterTypeError("feet must be a list of (name, heel, toe, ankle) labels")
        for foot in feet:
            _labels("each of feet", foot, 4)
    input_file("path", path)
    content = read_c3d(path, threshold=LOADED)
    rotation = body_rotation(ap_axis, content.up)
    markers = {name: values @ rotation.T for name, values in content.markers.items()}
    notes: list[str] = []
    if com_markers is None:
        com_markers = [COM_MARKER] if COM_MARKER in markers else []
    missing = [name for name in com_markers if name not in markers]
    if missing:
        raise InputFileError(
            f"{path}: no marker {missing[0]!r}; markers: {', '.join(markers) or '(none)'}"
        )
    com = np.mean([markers[name] for name in com_markers], axis=0) if com_markers else None
    foot_sets = FOOT_MARKERS if feet is None else tuple(feet)
    found_feet = []
    for name, heel, toe, ankle in foot_sets:
        labels = (heel, toe, ankle)
        if all(label in markers for label in labels):
            found_feet.append(Foot(name, *(markers[label] for label in labels)))
        elif feet is not None:
            absent = next(label for label in labels if label not in markers)
            raise InputFileError(
                f"{path}: no marker {absent!r} for foot {name!r}; markers: {', '.join(markers)}"
            )
    com_height = None
    if com is not None and found_feet:
        ankle_height = np.nanmean([foot.ankle[:, 2] for foot in found_feet], axis=0)
        height = com[:, 2] - ankle_height
        if np.isfinite(height).any():
            # Standing height: a step or a crouch lowers the CoM for part of a trial.
            com_height = float(np.nanpercentile(height, STANDING_PERCENTILE))
    force = cop = force_time = None
    plates: tuple[tuple[FloatArray, FloatArray], ...] = ()
    if content.plates:
        force_time = content.analog_time
        total = np.sum([plate.force for plate in content.plates], axis=0)
        force = total @ rotation.T
        cop = _combined_cop(content.plates) @ rotation.T
        cop = cop[:, :2]
        if len(content.plates) > 1:
            notes.append(f"{len(content.plates)} force plates: forces summed, CoPs combined")
            plates = tuple(
                ((plate.force @ rotation.T)[:, 2], (plate.cop @ rotation.T)[:, :2])
                for plate in content.plates
            )
    if com is None and force is None:
        raise InputFileError(
            f"{path}: neither a CoM marker ({COM_MARKER!r} or --com-marker) nor force plates"
        )
    time = content.point_time
    if com is None:
        assert force_time is not None
        if found_feet:
            found_feet = [_resampled(foot, time, force_time) for foot in found_feet]
            notes.append("CoM from the force plates: foot markers resampled to their rate")
        time = force_time
    return Recording(
        time=time,
        com=com,
        feet=tuple(found_feet),
        force_time=force_time,
        force=force,
        cop=cop,
        mass=content.mass,
        com_height=com_height,
        source=str(path),
        notes=notes,
        plates=plates,
    )


def _resampled(foot: Foot, source: FloatArray, target: FloatArray) -> Foot:
    """Resample a foot's markers to other times (:func:`~.signals.resample`)."""
    return Foot(
        foot.name,
        resample(source, foot.heel, target),
        resample(source, foot.toe, target),
        resample(source, foot.ankle, target),
    )


def _combined_cop(plates: Sequence[ForcePlate]) -> FloatArray:
    """CoP of several plates at one height: the vertical-force-weighted mean of their CoPs."""
    weights = []
    points = []
    for plate in plates:
        vertical = plate.force[:, 2]
        cop = plate.cop
        loaded = np.isfinite(cop).all(axis=1) & (vertical > 0.0)
        weights.append(np.where(loaded, vertical, 0.0))
        points.append(np.where(loaded[:, None], cop, 0.0))
    weight = np.sum(weights, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        combined = np.sum([w[:, None] * p for w, p in zip(weights, points, strict=True)], axis=0)
        combined = combined / weight[:, None]
    return np.where((weight > 0.0)[:, None], combined, np.nan)
