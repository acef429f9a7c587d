r"""CoP-balancing (ankle strategy) decision surface, Eq. (4) of [Stephens07].

A state (x, ẋ) of the LIPM can be brought to rest with the CoP on the foot if and only if its
capture point ξ = x + ẋ/ω lies strictly between the foot edges:

.. math:: \delta^- < x + \frac{\dot x}{\omega} < \delta^+ .

Derivation (docs/errata.md, E1): ξ obeys ξ̇ = ω (ξ − δ), so with the CoP saturated at δ⁺ a
capture point below δ⁺ moves back and one above it runs away as e^{ωt}; the boundary
ξ = δ± is the stable manifold of the equilibrium with the CoP on the edge, reached only as
t → ∞, hence the strict inequalities.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    MAX_MAGNITUDE,
    finite_array,
    float_array,
    output_array,
    positive_float,
    require_type,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN, BodyParams

__all__ = [
    "CaptureInterval",
    "capture_margin",
    "capture_point",
    "cop_margin",
    "cop_region",
    "critical_velocity",
]

# From this size on, one fused, multithreaded numba pass beats five numpy passes; below it the
# numpy path avoids compiling the kernel at all.
_FUSED_MIN_SIZE = 1 << 15


@dataclass(frozen=True, slots=True)
class CaptureInterval:
    """Open interval (lower, upper) of capture points a strategy can recover [m]."""

    lower: float
    upper: float

    @property
    def centre(self) -> float:
        """Midpoint of the interval [m]."""
        return 0.5 * (self.lower + self.upper)

    @property
    def half_width(self) -> float:
        """Half the interval width [m]."""
        return 0.5 * (self.upper - self.lower)


@overload
def capture_point(x: float, xdot: float, omega: float) -> float: ...


@overload
def capture_point(x: ArrayLike, xdot: ArrayLike, omega: float) -> NDArray[np.float64]: ...


def capture_point(x: ArrayLike, xdot: ArrayLike, omega: float) -> float | NDArray[np.float64]:
    """Capture point ξ = x + ẋ/ω, the middle term of Eq. (4) [m].

    The one definition in the project (controllers, plots, the CLI and the surfaces call it);
    two Python floats give a float without touching numpy (a controller's tick), anything
    else an array.

    Parameters
    ----------
    x : float or array_like
        CoM position relative to the ankle [m], x forward (or one axis of the plane).
    xdot : float or array_like
        CoM velocity [m/s].
    omega : float
        LIPM natural frequency sqrt(g / L) [1/s], > 0.

    Returns
    -------
    float or ndarray
        ξ [m], where the CoP would have to be for the CoM to come to rest over it.

    Raises
    ------
    InvalidParameterError
        If ``omega`` is outside [0.1, 100] 1/s, the sqrt(g/L) of every body
        :data:`~pushrecovery.params.LIMITS` admits (the states are not checked here: a NaN state
        gives a NaN ξ; the margins and verdicts built on it refuse them).
    """
    try:
        valid = OMEGA_MIN <= omega <= OMEGA_MAX  # one comparison: this runs at every tick
    except (TypeError, ValueError):  # text, None, an array
        valid = False
    if not valid:
        raise InvalidParameterError(
            f"omega must be in [{OMEGA_MIN:g}, {OMEGA_MAX:g}] 1/s (sqrt(g/L) of any body), "
            f"got {omega!r}"
        )
    inv = 1.0 / omega  # multiplied, as the compiled kernels do: the same ξ to the bit
    if type(x) is float and type(xdot) is float:
        return x + xdot * inv
    position, velocity = float_array("x", x), float_array("xdot", xdot)
    try:
        return position + velocity * inv
    except ValueError:
        raise InvalidParameterError(
            f"x and xdot must broadcast, got shapes {position.shape} and {velocity.shape}"
        ) from None


def cop_region(params: BodyParams) -> CaptureInterval:
    """Capture-point bounds of CoP balancing, Eq. (4): the foot itself, (δ⁻, δ⁺) [m]."""
    require_type("params", params, BodyParams)
    return CaptureInterval(params.heel, params.toe)


def cop_margin(
    x: ArrayLike,
    xdot: ArrayLike,
    params: BodyParams,
    *,
    out: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Signed margin of the states to the CoP-balancing surface, Eq. (4) [m].

    margin = min(ξ − δ⁻, δ⁺ − ξ): positive inside the region (ankle torque alone recovers),
    zero on the surface, negative outside; its magnitude is the distance of the capture point
    to the nearer foot edge. See :func:`capture_margin` for the arguments.
    """
    region = cop_region(params)  # checks params first
    return capture_margin(x, xdot, params.omega, region, out=out)


def capture_margin(
    x: ArrayLike,
    xdot: ArrayLike,
    omega: float,
    region: CaptureInterval,
    *,
    out: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Signed distance of the capture points to the edges of a capture interval [m].

    margin = min(ξ − lower, upper − ξ) = w − abs(ξ − c), with c the centre and w the half width of
    the interval: positive inside.

    Parameters
    ----------
    x : array_like
        CoM positions relative to the ankle [m].
    xdot : array_like
        CoM velocities [m/s]; broadcast against ``x``.
    omega : float
        sqrt(g / L) [1/s].
    region : CaptureInterval
        Capture-point interval of a strategy [m].
    out : ndarray, optional
        Float64 array of the broadcast shape to write the margins into (saves an allocation).

    Returns
    -------
    ndarray
        Margins [m], float64, of the broadcast shape of ``x`` and ``xdot``.

    Raises
    ------
    ParameterTypeError
        If ``region`` is not a :class:`CaptureInterval`.
    InvalidParameterError
        If a state is NaN or infinite, or ``omega`` is not a finite number > 0.
    """
    require_type("region", region, CaptureInterval)
    x = float_array("x", x)
    xdot = float_array("xdot", xdot)
    inv_omega = 1.0 / positive_float("omega", omega, "1/s")
    if out is not None or x.shape != xdot.shape:
        try:
            shape = np.broadcast_shapes(x.shape, xdot.shape)
        except ValueError:
            raise InvalidParameterError(
                f"x and xdot must broadcast, got shapes {x.shape} and {xdot.shape}"
            ) from None
        if out is not None:
            out = output_array("out", out, shape)
    centre, half = region.centre, region.half_width
    if _fusable(x, xdot, out):
        margin = np.empty_like(x) if out is None else out
        from pushrecovery.kernels.capture_point import capture_margins

        bad = capture_margins(
            x.reshape(-1), xdot.reshape(-1), inv_omega, centre, half, margin.reshape(-1)
        )
    else:
        with np.errstate(over="ignore", invalid="ignore"):  # reported below, as one error
            margin = np.subtract(half, np.abs(x + xdot * inv_omega - centre), out=out)
        # NaN and -inf propagate into the minimum: one reduction, not two isfinite passes.
        bad = 0 if margin.size == 0 or math.isfinite(float(np.min(margin))) else 1
    if bad:
        _raise_non_finite(x, xdot)
    return margin


def _fusable(
    x: NDArray[np.float64], xdot: NDArray[np.float64], out: NDArray[np.float64] | None
) -> bool:
    """Large, same-shape, C-contiguous inputs (and output) take the fused kernel."""
    arrays = (x, xdot) if out is None else (x, xdot, out)
    return (
        x.size >= _FUSED_MIN_SIZE
        and all(a.shape == x.shape and a.flags.c_contiguous for a in arrays)
        and (out is None or out.dtype == np.float64)
    )


def _raise_non_finite(x: NDArray[np.float64], xdot: NDArray[np.float64]) -> None:
    finite_array("x", x)
    finite_array("xdot", xdot)
    raise InvalidParameterError("states are too large: the margin overflows")  # pragma: no cover


def critical_velocity(
    x: ArrayLike,
    direction: ArrayLike,
    params: BodyParams,
    *,
    region: CaptureInterval | None = None,
) -> NDArray[np.float64]:
    """Largest CoM velocity a strategy recovers from position x, Eq. (4) by default [m/s].

    Solving lower < x + ẋ/ω < upper for ẋ: forward (direction +1) ẋ < ω (upper − x),
    backward (direction −1) ẋ > ω (lower − x). Signed like the velocity (negative backward).

    Parameters
    ----------
    x : array_like
        CoM position relative to the ankle [m].
    direction : array_like
        +1 for a forward push, −1 for a backward push.
    params : BodyParams
        Body parameters.
    region : CaptureInterval, optional
        Capture-point interval of the strategy; default the CoP region (Eq. 4).

    Returns
    -------
    ndarray
        Critical velocity [m/s] (the supremum: the boundary itself is not recoverable).

    Raises
    ------
    InvalidParameterError
        If a position is not finite or a direction is not +1 or −1.
    """
    if region is not None:
        require_type("region", region, CaptureInterval)
    region = cop_region(params) if region is None else region
    x = finite_array("x", x, MAX_MAGNITUDE, "m")  # beyond, ω (edge − x) overflows
    direction = finite_array("direction", direction)
    if not np.all(np.abs(direction) == 1.0):
        raise InvalidParameterError("direction must be +1 (forward) or -1 (backward)")
    edge = np.where(direction > 0.0, region.upper, region.lower)
    return params.omega * (edge - x)
