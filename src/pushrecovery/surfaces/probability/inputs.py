"""The uncertain inputs of the verdict probabilities: a Gaussian state estimate, checked."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import finite_array
from pushrecovery.errors import InvalidParameterError

__all__ = ["MAX_STATE", "StateGaussian", "check_states"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class StateGaussian:
    """A CoM state known up to a Gaussian error.

    Attributes
    ----------
    mean : ndarray, shape (2,) or (4,)
        (x, ẋ) on the sagittal line, or (x, y, ẋ, ẏ) on the ground plane [m, m/s]: the CoM
        relative to the stance ankle (line) or in the ground frame (plane), x forward, y left.
    cov : ndarray, shape (2, 2) or (4, 4)
        Its covariance [m², m²/s, m²/s²], symmetric positive semi-definite (zero: known exactly).
    """

    mean: FloatArray
    cov: FloatArray

    def __post_init__(self) -> None:
        means, cov = check_states(self.mean, self.cov)
        if len(means) != 1 or np.ndim(self.mean) != 1 or cov.ndim != 2:
            raise InvalidParameterError(
                "a StateGaussian is one state: mean of shape (2,) or (4,) and its (d, d) cov, "
                f"got {np.shape(self.mean)} and {cov.shape}"
            )
        mean = means[0].copy()
        cov = cov.copy()
        for name, array in (("mean", mean), ("cov", cov)):
            array.flags.writeable = False
            object.__setattr__(self, name, array)

    @property
    def plane(self) -> bool:
        """True for a state on the ground plane (4 numbers)."""
        return len(self.mean) == 4


#: Largest magnitude of a position [m] or velocity [m/s] in a state's mean: a foot pose's bound
#: (:data:`~pushrecovery.ground.support.MAX_POSE`).
MAX_STATE = 1e6


def check_states(mean: ArrayLike, cov: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Return states' means (n, d) and covariances (d, d) or (n, d, d), checked.

    d = 2 ((x, ẋ) [m, m/s]) or 4 ((x, y, ẋ, ẏ)); the covariances [m², m²/s, m²/s²] finite,
    symmetric and positive semi-definite (to 1e-12 of their largest entry).

    Raises
    ------
    InvalidParameterError
        Other shapes, non-finite values, a mean beyond ±:data:`MAX_STATE`, an asymmetric or
        indefinite covariance.
    """
    means = np.atleast_2d(finite_array("mean", mean))
    if means.ndim != 2 or means.shape[1] not in (2, 4):
        raise InvalidParameterError(
            f"mean must be states (x, xdot) or (x, y, xdot, ydot): shape (n, 2) or (n, 4), "
            f"got {np.shape(mean)}"
        )
    if means.size and float(np.max(np.abs(means))) > MAX_STATE:
        raise InvalidParameterError(
            f"mean must have positions [m] and velocities [m/s] within ±{MAX_STATE:g} (beyond, "
            "the capture point's distances overflow)"
        )
    d = means.shape[1]
    covs = finite_array("cov", cov)
    if covs.shape not in ((d, d), (len(means), d, d)):
        raise InvalidParameterError(
            f"cov must have shape ({d}, {d}) or ({len(means)}, {d}, {d}), got {covs.shape}"
        )
    if covs.shape == (2, 2):  # one state's (x, xdot): the checks in closed form (a loop's tick)
        (a, b), (c, e) = covs.tolist()
        scale = max(abs(a), abs(b), abs(c), abs(e))
        if abs(b - c) > 1e-12 * scale:
            raise InvalidParameterError("cov must be symmetric (a covariance matrix)")
        half, mid = math.hypot(0.5 * (a - e), 0.5 * (b + c)), 0.5 * (a + e)
        if mid - half < -1e-12 * scale:
            raise InvalidParameterError(
                "cov must be positive semi-definite (a covariance), got an eigenvalue "
                f"{mid - half:.3g}"
            )
        return means, covs
    scale = np.max(np.abs(covs), axis=(-2, -1), keepdims=True)
    if np.any(np.abs(covs - np.swapaxes(covs, -1, -2)) > 1e-12 * scale):
        raise InvalidParameterError("cov must be symmetric (a covariance matrix)")
    smallest = np.linalg.eigvalsh(0.5 * (covs + np.swapaxes(covs, -1, -2)))[..., 0]
    if np.any(smallest < -1e-12 * scale[..., 0, 0]):
        raise InvalidParameterError(
            "cov must be positive semi-definite (a covariance), got an eigenvalue "
            f"{float(np.min(smallest)):.3g}"
        )
    return means, covs
