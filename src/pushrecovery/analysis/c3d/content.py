"""The results of reading a C3D file: markers and force plates in SI units, lab frame."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


# --- Results ---------------------------------------------------------------------------------
# eq=False: the fields are arrays, whose == is elementwise; identity is the honest equality.
@dataclass(frozen=True, slots=True, eq=False)
class ForcePlate:
    """One force plate at the analog rate, lab frame, SI units.

    Parameters
    ----------
    force : ndarray, shape (n, 3)
        Ground reaction force on the subject [N]: minus the force the subject applies to the
        plate; its vertical component is > 0 when someone stands on the plate.
    cop : ndarray, shape (n, 3)
        Centre of pressure on the plate's top surface [m]; NaN where the load (the force on the
        plate along its z-down normal) is below the reader's ``threshold``.
    free_moment : ndarray, shape (n,)
        Moment about the plate's upward normal through the CoP acting on the subject [N m],
        right-hand rule (> 0 turns the subject anticlockwise seen from above); NaN where
        ``cop`` is.
    corners : ndarray, shape (4, 3)
        Plate corners in the file's order (C3D quadrants +x+y, −x+y, −x−y, +x−y) [m].
    computed_by : {"ezc3d", "own"}
        Who computed the plate: ezc3d's force-platform module or this package's formulas
        (:func:`pushrecovery.analysis.c3d.plate_path`; the same numbers to rounding either way).
    """

    force: FloatArray
    cop: FloatArray
    free_moment: FloatArray
    corners: FloatArray
    computed_by: str = "own"


@dataclass(frozen=True, slots=True, eq=False)
class C3DContent:
    """What :func:`read_c3d` found in a file, lab frame, SI units.

    Parameters
    ----------
    point_rate : float or None
        Marker frame rate [Hz]; None when the file has no markers.
    markers : dict of str to ndarray, shape (n_points, 3)
        Label -> position [m]; NaN where the marker is missing (negative residual, or all three
        coordinates exactly 0, which many systems write for gaps).
    analog_rate : float or None
        Analog sample rate [Hz]; None without analog channels.
    plates : tuple of ForcePlate
        The force plates, at the analog rate.
    mass : float or None
        Subject mass [kg] when the file stores it (``PROCESSING:Bodymass``,
        ``SUBJECTS:MASS``/``WEIGHT``, ...), else None.
    point_units : str
        ``POINT:UNITS`` as written in the file, e.g. ``"mm"`` ("" when absent; mm is assumed).
    first_time : float
        Time of the first frame [s]: (header first frame − 1) / point_rate; 0 without markers.
    n_points : int
        Number of marker frames (0 without markers).
    n_analog : int
        Number of analog samples (0 without analog channels).
    up : ndarray, shape (3,)
        The lab's up axis (``POINT:Y_SCREEN``, default +z).
    """

    point_rate: float | None
    markers: dict[str, FloatArray]
    analog_rate: float | None
    plates: tuple[ForcePlate, ...]
    mass: float | None
    point_units: str
    first_time: float
    n_points: int = field(default=0)
    n_analog: int = field(default=0)
    up: FloatArray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))

    @property
    def point_time(self) -> FloatArray:
        """Time of each marker frame [s], shape (n_points,); empty without markers."""
        if self.point_rate is None:
            return np.zeros(0)
        return self.first_time + np.arange(self.n_points) / self.point_rate

    @property
    def analog_time(self) -> FloatArray:
        """Time of each analog sample [s], shape (n_analog,); empty without analogs."""
        if self.analog_rate is None:
            return np.zeros(0)
        return self.first_time + np.arange(self.n_analog) / self.analog_rate
