"""Force plates of types 1-4: the wrench on the subject, its CoP and free moment (pure numpy).

Conventions: docs/c3d.md.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import non_negative_float
from pushrecovery.errors import InvalidParameterError

FloatArray = NDArray[np.float64]


def plate_frame(
    corners: ArrayLike, up: ArrayLike = (0.0, 0.0, 1.0)
) -> tuple[FloatArray, FloatArray]:
    """Rotation plate -> lab and the top-surface centre of a force plate, from its corners.

    Parameters
    ----------
    corners : array_like, shape (4, 3)
        Corners in the lab frame, in C3D order: the (+x, +y), (−x, +y), (−x, −y), (+x, −y)
        quadrants of the plate frame. Any length unit; ``centre`` comes out in it.
    up : array_like, shape (3,)
        The lab's up direction (default +z); only its sign relative to the plate's normal is
        used.

    Returns
    -------
    rotation : ndarray, shape (3, 3)
        Columns x̂, ŷ, ẑ of the plate frame in lab coordinates (lab = rotation @ plate).
        x̂ ∝ (c1 − c2) + (c4 − c3); ŷ ∝ (c1 − c4) + (c2 − c3) made orthogonal to x̂ (for corners
        listed crossed, where these vanish, x̂ ∝ c1 − c2 and ŷ ∝ c1 − c4 as in ezc3d);
        ẑ = ±x̂ × ŷ, the sign chosen so that ẑ points down (into the plate). For corners
        listed anticlockwise seen from above (BioWare) ẑ = −x̂ × ŷ and ``det(rotation) = −1``;
        a plate on a wall (normal ⟂ up) keeps the right-handed ẑ = x̂ × ŷ.
    centre : ndarray, shape (3,)
        Mean of the corners: the centre of the top surface.

    Raises
    ------
    InvalidParameterError
        If ``corners`` is not (4, 3), not finite, or degenerate (no area).
    """
    points = np.asarray(corners, dtype=np.float64)
    if points.shape != (4, 3) or not np.isfinite(points).all():
        raise InvalidParameterError(
            f"corners must be a finite (4, 3) array, got shape {np.shape(points)}"
        )
    c1, c2, c3, c4 = points
    size = float(np.abs(points - points.mean(axis=0)).max())
    x_axis = (c1 - c2) + (c4 - c3)  # the +x corners minus the -x corners
    y_axis = (c1 - c4) + (c2 - c3)
    normal = np.cross(x_axis, y_axis)
    if np.linalg.norm(normal) <= 1e-6 * size**2:
        # Corners listed crossed (kistler_DJ_2plates.c3d's second plate): trust corner 1 and
        # its two neighbours, as ezc3d does.
        x_axis, y_axis = c1 - c2, c1 - c4
        normal = np.cross(x_axis, y_axis)
    if size == 0.0 or np.linalg.norm(normal) <= 1e-6 * size**2:
        raise InvalidParameterError("corners must span a plate (they are collinear or equal)")
    x_hat = x_axis / np.linalg.norm(x_axis)
    normal /= np.linalg.norm(normal)
    y_hat = np.cross(normal, x_hat)  # in-plane, ⟂ x̂, on ŷ's side
    z_hat = -normal if float(np.dot(normal, np.asarray(up, dtype=np.float64))) > 0.0 else normal
    return np.column_stack([x_hat, y_hat, z_hat]), points.mean(axis=0)


def wrench_type2(channels: ArrayLike, origin: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Force and moment about the top-surface centre from type-2 channels (plate frame, SI).

    Parameters
    ----------
    channels : array_like, shape (n, 6)
        Fx, Fy, Fz [N] and Mx, My, Mz [N m] about the transducer origin, plate frame.
    origin : array_like, shape (3,)
        ``FORCE_PLATFORM:ORIGIN`` [m]: the vector from the transducer origin to the centre of
        the top surface (z < 0 in the z-down frame). Stored with z > 0, it is the vector the
        other way round (the manufacturer's sheet) and is negated.

    Returns
    -------
    force : ndarray, shape (n, 3)
        [N], same sign convention as the channels.
    moment : ndarray, shape (n, 3)
        About the top-surface centre [N m]: M + F × origin.
    """
    data = _channels(channels, 6)
    vector = _vector3("origin", origin)
    if vector[2] > 0.0:
        vector = -vector
    force = data[:, :3]
    return force, data[:, 3:] + np.cross(force, vector)


def wrench_type3(channels: ArrayLike, origin: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Force and moment about the top-surface centre from Kistler's 8 channels (plate frame).

    Kistler's formulas with a = abs(origin x), b = abs(origin y), az0 = −abs(origin z):
    F = (fx12 + fx34, fy14 + fy23, fz1 + fz2 + fz3 + fz4),
    Mx = b (fz1 + fz2 − fz3 − fz4) + Fy az0, My = a (−fz1 + fz2 + fz3 − fz4) − Fx az0,
    Mz = b (−fx12 + fx34) + a (fy14 − fy23). Sensor 1 sits at (+a, +b), 2 at (−a, +b),
    3 at (−a, −b), 4 at (+a, −b), the sensor plane abs(az0) below the top surface.

    Parameters
    ----------
    channels : array_like, shape (n, 8)
        fx12, fx34, fy14, fy23, fz1, fz2, fz3, fz4 [N].
    origin : array_like, shape (3,)
        ``FORCE_PLATFORM:ORIGIN`` (a, b, az0) [m]; signs are ignored (files differ).

    Returns
    -------
    force : ndarray, shape (n, 3)
        [N], the force on the plate for raw Kistler channels (Fz > 0 under load).
    moment : ndarray, shape (n, 3)
        About the top-surface centre [N m].
    """
    data = _channels(channels, 8)
    a, b, depth = np.abs(_vector3("origin", origin))
    az0 = -depth
    fx12, fx34, fy14, fy23, fz1, fz2, fz3, fz4 = data.T
    fx, fy = fx12 + fx34, fy14 + fy23
    force = np.column_stack([fx, fy, fz1 + fz2 + fz3 + fz4])
    moment = np.column_stack(
        [
            b * (fz1 + fz2 - fz3 - fz4) + fy * az0,
            a * (-fz1 + fz2 + fz3 - fz4) - fx * az0,
            b * (-fx12 + fx34) + a * (fy14 - fy23),
        ]
    )
    return force, moment


def wrench_type4(
    channels: ArrayLike, origin: ArrayLike, cal_matrix: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Type 4: :func:`wrench_type2` of the channels calibrated by ``cal_matrix`` (6 × 6).

    Parameters
    ----------
    channels : array_like, shape (n, 6)
        Raw channels, in units that ``cal_matrix`` turns into N and N m.
    origin : array_like, shape (3,)
        As in :func:`wrench_type2` [m].
    cal_matrix : array_like, shape (6, 6)
        Calibrated = ``cal_matrix @ raw`` for each sample (the C3D parameter's first index is
        the row, as ezc3d reads it).
    """
    matrix = np.asarray(cal_matrix, dtype=np.float64)
    if matrix.shape != (6, 6) or not np.isfinite(matrix).all():
        raise InvalidParameterError(
            f"cal_matrix must be a finite (6, 6) array, got shape {matrix.shape}"
        )
    return wrench_type2(_channels(channels, 6) @ matrix.T, origin)


def plate_cop_in_plate_frame(
    force: ArrayLike,
    moment: ArrayLike,
    *,
    threshold: float = 20.0,
    cop_poly: ArrayLike | None = None,
) -> tuple[FloatArray, FloatArray]:
    """CoP and free moment in the plate frame from the wrench about the top-surface centre.

    The force acts at c = (cx, cy, 0) on the top surface with a free moment Tz about the
    plate's z axis only, so M = c × F + (0, 0, Tz): cx = −My/Fz, cy = Mx/Fz and
    Tz = Mz − cx Fy + cy Fx. With ``cop_poly`` the CoP is first corrected by Kistler's
    polynomial (:func:`kistler_cop_correction`) and Tz taken about the corrected CoP, as ezc3d
    does.

    Parameters
    ----------
    force : array_like, shape (n, 3)
        Force on the plate [N], z-down plate frame (Fz > 0 under load).
    moment : array_like, shape (n, 3)
        Moment of that force about the top-surface centre [N m] (:func:`wrench_type2` ...).
    threshold : float
        Smallest Fz [N] with a defined CoP, >= 0.
    cop_poly : array_like, shape (12,), optional
        ``FORCE_PLATFORM:FPCOPPOLY`` of this plate (Kistler's coefficients, for the CoP in mm).

    Returns
    -------
    cop : ndarray, shape (n, 3)
        (cx, cy, 0) relative to the plate centre [m]; NaN where Fz < ``threshold``.
    free_moment : ndarray, shape (n,)
        Tz [N m] about the z-down axis (for the force on the plate); NaN where ``cop`` is. For
        the subject about the upward normal this is the same number.
    """
    limit = non_negative_float("threshold", threshold, "N")
    f = _channels(force, 3, "force")
    m = _channels(moment, 3, "moment")
    if f.shape != m.shape:
        raise InvalidParameterError(f"force and moment differ in shape: {f.shape}, {m.shape}")
    loaded = f[:, 2] >= limit
    fz = np.where(loaded, f[:, 2], np.nan)  # NaN, not inf, where the plate is unloaded
    cx = -m[:, 1] / fz
    cy = m[:, 0] / fz
    if cop_poly is not None:  # Kistler's coefficients are for millimetres
        corrected = kistler_cop_correction(np.column_stack([cx, cy]) * 1000.0, cop_poly)
        cx, cy = corrected[:, 0] / 1000.0, corrected[:, 1] / 1000.0
    cop = np.column_stack([cx, cy, np.where(loaded, 0.0, np.nan)])
    return cop, m[:, 2] - cx * f[:, 1] + cy * f[:, 0]


def kistler_cop_correction(cop_mm: ArrayLike, coefficients: ArrayLike) -> FloatArray:
    """Kistler's CoP correction polynomial (``FORCE_PLATFORM:FPCOPPOLY``) applied to a CoP.

    With (ax, ay) the measured CoP [mm] relative to the plate centre in Kistler's plate frame
    (the plate frame here: sensor 1 at (+a, +b), z down) and the coefficients P1x ... P6x,
    P1y ... P6y in that order::

        Δx = (P1x ay⁴ + P2x ay² + P3x) ax³ + (P4x ay⁴ + P5x ay² + P6x) ax
        Δy = (P1y ax⁴ + P2y ax² + P3y) ay³ + (P4y ax⁴ + P5y ax² + P6y) ay
        corrected = (ax − Δx, ay − Δy)

    Source: Kistler's manual of the 9281E/9287C plates, section 8.4.3 "COP Correction
    Algorithm for Force Plates" (it lists the coefficients per plate model); ezc3d applies the
    same to type-3 plates (pyomeca/ezc3d#253, PR #297). docs/c3d.md has the details.

    Parameters
    ----------
    cop_mm : array_like, shape (n, 2) or (n, 3)
        Measured CoP (ax, ay[, az]) [mm], plate frame; a third column is returned unchanged.
        NaN rows stay NaN.
    coefficients : array_like, shape (12,)
        P1x, ..., P6x, P1y, ..., P6y (units making Δx, Δy millimetres).

    Returns
    -------
    ndarray, same shape as ``cop_mm``
        The corrected CoP [mm].

    Raises
    ------
    InvalidParameterError
        If ``coefficients`` are not 12 finite numbers or ``cop_mm`` is not (n, 2) or (n, 3).
    """
    values = np.asarray(coefficients, dtype=np.float64).reshape(-1)
    if values.shape != (12,) or not np.isfinite(values).all():
        raise InvalidParameterError(
            "FORCE_PLATFORM:FPCOPPOLY must hold 12 finite coefficients per plate "
            f"(P1x..P6x, P1y..P6y), got {values.size}"
        )
    cop = np.array(cop_mm, dtype=np.float64)
    if cop.ndim != 2 or cop.shape[1] not in (2, 3):
        raise InvalidParameterError(f"cop_mm must be (n, 2) or (n, 3), got shape {cop.shape}")
    ax, ay = cop[:, 0].copy(), cop[:, 1].copy()
    px, py = values[:6], values[6:]
    dx = (px[0] * ay**4 + px[1] * ay**2 + px[2]) * ax**3 + (
        px[3] * ay**4 + px[4] * ay**2 + px[5]
    ) * ax
    dy = (py[0] * ax**4 + py[1] * ax**2 + py[2]) * ay**3 + (
        py[3] * ax**4 + py[4] * ax**2 + py[5]
    ) * ay
    cop[:, 0] = ax - dx
    cop[:, 1] = ay - dy
    return cop


# --- Reading --------------------------------------------------------------------------------


def _load_sign(force: FloatArray) -> float:
    """+1 if the channels give the force on the plate (summed Fz >= 0), else −1 (Vicon)."""
    return -1.0 if float(np.sum(force[:, 2])) < 0.0 else 1.0


def _channels(values: ArrayLike, width: int, name: str = "channels") -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != width:
        raise InvalidParameterError(f"{name} must be (n, {width}), got shape {array.shape}")
    return array


def _vector3(name: str, values: ArrayLike) -> FloatArray:
    array = np.asarray(values, dtype=np.float64).reshape(-1)
    if array.shape != (3,) or not np.isfinite(array).all():
        raise InvalidParameterError(f"{name} must be 3 finite numbers, got {values!r}")
    return array
