r"""Centre of mass from the ground reaction force: zero-point-to-zero-point integration.

When only force plates were recorded, the horizontal CoM motion follows from Newton's law,
m ẍ = F_x, by double integration. Plain integration drifts: a bias of 1 N in F_x moves a 70 kg
body's CoM by 0.7 m in 10 s. Zatsiorsky & King (1998, J. Biomech. 31:161-164) remove the two
unknown integration constants in every interval between consecutive instants where the
horizontal force is zero (crosses zero, or stays within ``ZERO_FORCE`` = 0.02 % of the body
weight, as a body standing still may never cross). At such an instant the ground reaction
force is vertical; with no change of the body's angular momentum about its CoM the force then
passes through the CoM, so the CoM lies above the CoP: x(t_i) = p(t_i). Between two zero
points t_i < t_j,

.. math:: x(t) = p(t_i) + v_i (t - t_i) + \int_{t_i}^{t} \int_{t_i}^{s} \frac{F_x(u)}{m}
          \,du\,ds,

with v_i chosen so that x(t_j) = p(t_j). Each interval is pinned at both ends, so no error
accumulates from one interval to the next; the velocity is the integral itself,
v(t) = v_i + ∫ F_x/m. Before the first and after the last zero point there is only one pin:
those samples are left missing (reported, never extrapolated).
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import cumulative_trapezoid

from pushrecovery.analysis.signals import _times
from pushrecovery.arguments import bounded_float, non_negative_float, sample_array
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import LIMITS

__all__ = ["ZERO_FORCE", "com_from_force", "zero_points"]

#: Horizontal force counted as zero, as a fraction of the body weight.
ZERO_FORCE = 2e-4
STANDARD_GRAVITY = 9.80665
#: Shortest interval between two zero points [s].
MIN_SPACING = 0.1

FloatArray = NDArray[np.float64]


def zero_points(
    time: FloatArray, force: FloatArray, tolerance: float = 0.0, spacing: float = 0.0
) -> NDArray[np.intp]:
    """Find where the horizontal force is zero: sign changes and runs within ``tolerance``.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sample times [s], finite, strictly increasing.
    force : ndarray, shape (n,)
        Horizontal ground reaction force [N], filtered (noise makes spurious crossings); NaN
        samples never count.
    tolerance : float
        abs(F) up to this counts as zero [N], >= 0: a body standing still may never cross.
    spacing : float
        Shortest time between two zero points [s]: of closer ones only the first is kept (the
        velocity of an interval is a difference quotient over it, noisy when short).

    Returns
    -------
    ndarray of int
        Increasing indices: of each sign change the sample of smaller abs(F), and the first and
        last sample of each run with abs(F) <= tolerance.

    Raises
    ------
    InvalidParameterError
        Times that are not finite and strictly increasing, a force of another shape or length,
        or a negative or non-finite ``tolerance`` or ``spacing``.
    """
    time, force = _time_and_force(time, force)
    tolerance = non_negative_float("tolerance", tolerance, "N")
    spacing = non_negative_float("spacing", spacing, "s")
    return _zero_points(time, force, tolerance, spacing)


def _time_and_force(time: FloatArray, force: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Return checked sample times and a horizontal force of one sample per time."""
    time = _times("time", time)
    force = sample_array("force", force, values="any")
    if len(force) != len(time):
        raise InvalidParameterError(
            f"force must have one sample per time ({len(time)}), got {len(force)}"
        )
    return time, force


def _zero_points(
    time: FloatArray, force: FloatArray, tolerance: float, spacing: float
) -> NDArray[np.intp]:
    """:func:`zero_points` of checked arguments."""
    sign = np.sign(force)
    small = np.abs(force) <= tolerance
    edges = np.diff(np.concatenate(([0], small.astype(np.int8), [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    change = np.flatnonzero(sign[:-1] * sign[1:] < 0.0)
    nearer = np.where(np.abs(force[change]) <= np.abs(force[change + 1]), change, change + 1)
    # A run of near-zero force pins both its ends (the CoM stays above the CoP throughout).
    pins = np.unique(np.concatenate((starts, stops - 1, nearer)))
    if spacing > 0.0 and len(pins) > 1:
        kept = [pins[0]]
        for pin in pins[1:]:
            if time[pin] - time[kept[-1]] >= spacing:
                kept.append(pin)
        pins = np.array(kept, dtype=np.intp)
    return pins


def com_from_force(
    time: FloatArray,
    force: FloatArray,
    cop: FloatArray,
    mass: float,
    *,
    tolerance: float | None = None,
    spacing: float = MIN_SPACING,
) -> tuple[FloatArray, FloatArray]:
    """Horizontal CoM position and velocity by zero-point-to-zero-point integration.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Sample times [s], finite, strictly increasing.
    force : ndarray, shape (n,)
        Horizontal ground reaction force on the body along one axis [N] (positive along the
        axis), low-pass filtered.
    cop : ndarray, shape (n,)
        CoP along the same axis [m], lab frame.
    mass : float
        Body mass [kg], in [0.01, 1e4] (:data:`~pushrecovery.params.LIMITS`).
    tolerance : float, optional
        abs(F) that counts as zero [N]; default ``ZERO_FORCE`` of the body weight (the CoM then
        lies within that fraction of its height of the point above the CoP: 0.2 mm per metre).
    spacing : float
        Shortest interval between zero points [s] (:func:`zero_points`).

    Returns
    -------
    (position, velocity)
        CoM position [m] and velocity [m/s] along the axis, NaN before the first and after
        the last zero point and in any interval with a missing force or CoP at its ends.

    Raises
    ------
    InvalidParameterError
        Fewer than two zero points (nothing can be pinned), a mass outside
        :data:`~pushrecovery.params.LIMITS`, times that are not finite and strictly increasing,
        a force or CoP of another shape or length, or a negative or non-finite ``tolerance``
        or ``spacing``.
    """
    mass = bounded_float("mass", mass, *LIMITS["mass"])
    time, force = _time_and_force(time, force)
    cop = sample_array("cop", cop, values="any")
    if len(cop) != len(time):
        raise InvalidParameterError(
            f"cop must have one sample per time ({len(time)}), got {len(cop)}"
        )
    if tolerance is None:
        tolerance = ZERO_FORCE * mass * STANDARD_GRAVITY
    tolerance = non_negative_float("tolerance", tolerance, "N")
    spacing = non_negative_float("spacing", spacing, "s")
    pins = _zero_points(time, np.where(np.isfinite(force), force, np.nan), tolerance, spacing)
    pins = pins[np.isfinite(cop[pins])]
    if len(pins) < 2:
        raise InvalidParameterError(
            "the horizontal ground reaction force must cross zero at least twice (with a CoP "
            f"measured there) to fix the CoM by zero-point integration; it crosses {len(pins)} "
            "time(s)"
        )
    position = np.full_like(force, np.nan)
    velocity = np.full_like(force, np.nan)
    for first, last in itertools.pairwise(pins):
        span = slice(first, last + 1)
        t, accel = time[span], force[span] / mass
        if not np.isfinite(accel).all():
            continue
        speed = cumulative_trapezoid(accel, t, initial=0.0)
        shift = cumulative_trapezoid(speed, t, initial=0.0)
        duration = t[-1] - t[0]
        start = (cop[last] - cop[first] - shift[-1]) / duration  # x(t_j) = p(t_j)
        position[span] = cop[first] + start * (t - t[0]) + shift
        velocity[span] = start + speed
    return position, velocity
