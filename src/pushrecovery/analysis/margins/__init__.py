r"""Per-frame balance margins of measured states, in one horizontal direction.

The decision surfaces of the paper are stated for a foot [δ⁻, δ⁺] around the ankle. A measured
base of support may be wider (both feet on the floor) and moves with the feet, so here the
region edges are arrays (one value per frame), in the lab frame:

- capture point (Hof's extrapolated CoM), ξ = x + ẋ/ω, Eq. (4);
- CoP margin, min(ξ − lower, upper − ξ): Hof's margin of stability, positive when the ankle
  strategy alone recovers (Eq. 4);
- CMP margin, the CoP margin plus the hip strategy's reach a (1 − e^{−ω T_max})², corrected
  Eq. (15) (errata E11);
- step: the N-step intervals of :func:`pushrecovery.surfaces.step.regions.line_steps` (at
  most ``max_steps`` steps, touchdowns every ``min_step_time``) from the measured base and
  the stance ankle, landing on the single foot's own edges;
- time to leave: with the CoP (or the CMP) held where it is, ξ − p grows as e^{ωt}
  (ξ̇ = ω (ξ − p), the LIPM), so a capture point inside (lower, upper) reaches the edge on its
  side after

  .. math:: t = \frac{1}{\omega} \ln \frac{\text{edge} - p}{\xi - p},

  0 when it is already outside and +inf when ξ = p.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, float_array, require_type, sample_array
from pushrecovery.errors import InvalidParameterError
from pushrecovery.params import OMEGA_MAX, OMEGA_MIN, BodyParams
from pushrecovery.surfaces.classify import STRATEGY_CODES, Strategy
from pushrecovery.surfaces.cmp import cmp_offset
from pushrecovery.surfaces.cop import capture_point
from pushrecovery.surfaces.step.regions import line_steps

__all__ = ["DirectionMargins", "direction_margins", "time_to_leave"]

FloatArray = NDArray[np.float64]

_ANKLE, _HIP, _STEP, _FALL = (STRATEGY_CODES.index(s) for s in Strategy)


@dataclass(frozen=True, slots=True)
class DirectionMargins:
    """Margins of n frames in one direction; arrays of shape (n,), NaN where invalid.

    Attributes
    ----------
    capture_point : ndarray
        ξ = x + ẋ/ω, lab frame [m].
    cop, cmp, step : ndarray
        Margins to the CoP region, the CMP region and the region of ``max_steps`` steps [m]
        (:func:`~pushrecovery.surfaces.step.regions.line_steps`; > 0 when steps capture).
    strategy : ndarray of int8
        Codes into :data:`~pushrecovery.surfaces.classify.STRATEGY_CODES`, −1 where invalid.
    time_to_leave_cop, time_to_leave_cmp : ndarray
        Time until ξ leaves the CoP (CMP) region with the CoP (CMP) held [s].
    step_length : ndarray
        First step of the plan, stance ankle to landing ankle, signed along the axis [m],
        where a step is needed.
    step_shortest, step_longest : ndarray
        First step lengths that still capture with ``steps`` steps, unsigned [m].
    steps : ndarray of int64
        Steps needed (0 for ankle and hip, N for step, −1 for fall and invalid frames).
    """

    capture_point: FloatArray
    cop: FloatArray
    cmp: FloatArray
    step: FloatArray
    strategy: NDArray[np.int8]
    time_to_leave_cop: FloatArray
    time_to_leave_cmp: FloatArray
    step_length: FloatArray
    step_shortest: FloatArray
    step_longest: FloatArray
    steps: NDArray[np.int64]


def time_to_leave(
    capture: FloatArray, anchor: FloatArray, lower: FloatArray, upper: FloatArray, omega: float
) -> FloatArray:
    """Time until the capture point leaves (lower, upper) with the CoP/CMP held at ``anchor``.

    Parameters
    ----------
    capture : ndarray
        Capture points ξ [m].
    anchor : ndarray
        Where the CoP (or CMP) stays [m]; clipped into [lower, upper] (a measured CoP a hair
        beyond an edge of the measured base is on it).
    lower, upper : ndarray
        Region edges [m].
    omega : float
        sqrt(g / L) [1/s].

    Returns
    -------
    ndarray
        Time [s] (module docstring): 0 outside the region, +inf when ξ equals the anchor, NaN
        where an input is NaN (a missing frame).

    Raises
    ------
    InvalidParameterError
        Values that are not numbers or are infinite, shapes that do not broadcast, a
        ``lower`` above ``upper``, or ``omega`` outside [0.1, 100] 1/s
        (:data:`~pushrecovery.params.OMEGA_MIN`, :data:`~pushrecovery.params.OMEGA_MAX`).
    """
    capture, anchor, lower, upper = _frames(
        capture=capture, anchor=anchor, lower=lower, upper=upper
    )
    with np.errstate(invalid="ignore"):
        inverted = lower > upper
    if inverted.any():
        raise InvalidParameterError("lower must be <= upper (an empty or inverted region)")
    omega = bounded_float("omega", omega, OMEGA_MIN, OMEGA_MAX, "1/s")
    return _time_to_leave(capture, anchor, lower, upper, omega)


def _frames(**arrays: FloatArray) -> list[FloatArray]:
    """Return the arrays as floats, NaN where missing, refusing infinities; shapes broadcast."""
    checked = []
    for name, value in arrays.items():
        array = float_array(name, value)
        if np.isinf(array).any():
            raise InvalidParameterError(f"{name} must be finite or NaN (missing), got infinities")
        checked.append(array)
    try:
        np.broadcast_shapes(*(a.shape for a in checked))
    except ValueError:
        shapes = ", ".join(f"{n} {a.shape}" for n, a in zip(arrays, checked, strict=True))
        raise InvalidParameterError(f"the arrays' shapes must broadcast, got {shapes}") from None
    return checked


def _time_to_leave(
    capture: FloatArray, anchor: FloatArray, lower: FloatArray, upper: FloatArray, omega: float
) -> FloatArray:
    """:func:`time_to_leave` of checked arguments."""
    anchor = np.clip(anchor, lower, upper)
    ahead = capture - anchor
    edge = np.where(ahead > 0.0, upper, lower) - anchor
    # A ξ a subnormal away from the anchor overflows the ratio: +inf, as for ξ on it.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = edge / ahead
        time = np.where(ratio > 1.0, np.log(ratio) / omega, 0.0)
    time = np.where(ahead == 0.0, np.inf, time)
    inside = (capture > lower) & (capture < upper)
    time = np.where(inside, time, 0.0)
    missing = ~(np.isfinite(capture) & np.isfinite(anchor) & np.isfinite(lower + upper))
    return np.where(missing, np.nan, time)


def direction_margins(
    com: FloatArray,
    velocity: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    ankle: FloatArray,
    params: BodyParams,
    *,
    cop: FloatArray | None = None,
    cmp: FloatArray | None = None,
) -> DirectionMargins:
    """Margins, strategy and step of each frame (module docstring).

    Parameters
    ----------
    com, velocity : ndarray, shape (n,)
        CoM position, lab frame [m], and velocity [m/s] along the axis; NaN where missing.
    lower, upper : ndarray, shape (n,)
        Base of support along the axis, lab frame [m].
    ankle : ndarray, shape (n,)
        Stance ankle (the pivot of the stepping model), lab frame [m].
    params : BodyParams
        The body; ``heel`` and ``toe`` are the single foot's edges relative to its ankle along
        this axis (the foot a step lands on), ``com_height`` sets ω.
    cop : ndarray, optional
        Measured CoP [m] for the time to leave the CoP region; default: none (NaN times).
    cmp : ndarray, optional
        Measured CMP [m] for the time to leave the CMP region; default the CoP.

    Returns
    -------
    DirectionMargins

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        Arrays that are not of shape (n,) and one n, or with infinite values.
    """
    require_type("params", params, BodyParams)
    given = {"com": com, "velocity": velocity, "lower": lower, "upper": upper, "ankle": ankle}
    if cop is not None:
        given["cop"] = cop
    if cmp is not None:
        given["cmp"] = cmp
    checked = {name: sample_array(name, value, values="nan") for name, value in given.items()}
    lengths = {name: len(array) for name, array in checked.items()}
    if len(set(lengths.values())) > 1:
        raise InvalidParameterError(f"the arrays must have one length, got {lengths}")
    com, velocity, lower, upper, ankle = (
        checked[n] for n in ("com", "velocity", "lower", "upper", "ankle")
    )
    cop, cmp = checked.get("cop"), checked.get("cmp")
    omega = params.omega
    capture = capture_point(com, velocity, omega)
    cop_margin = np.minimum(capture - lower, upper - capture)
    reach = cmp_offset(params)
    cmp_margin = cop_margin + reach
    valid = np.isfinite(cop_margin)
    known = valid & np.isfinite(ankle)
    plan = line_steps(
        np.where(known, capture, 0.0),
        np.where(known, lower, 0.0),
        np.where(known, upper, 0.0),
        np.where(known, ankle, 0.0),
        params,
    )
    feasible = known & (plan.steps > 0)
    strategy = np.full(len(com), _FALL, dtype=np.int8)
    strategy[feasible] = _STEP
    strategy[cmp_margin > 0.0] = _HIP
    strategy[cop_margin > 0.0] = _ANKLE
    strategy[~valid] = -1
    stepping = strategy == _STEP
    nan = np.full(len(com), np.nan)
    cop_anchor = nan if cop is None else cop
    cmp_anchor = cop_anchor if cmp is None else cmp
    return DirectionMargins(
        capture_point=capture,
        cop=cop_margin,
        cmp=cmp_margin,
        step=np.where(known, plan.margin, np.where(valid, -np.inf, np.nan)),
        strategy=strategy,
        time_to_leave_cop=_time_to_leave(capture, cop_anchor, lower, upper, omega),
        time_to_leave_cmp=_time_to_leave(capture, cmp_anchor, lower - reach, upper + reach, omega),
        step_length=np.where(stepping, plan.step_length, np.nan),
        step_shortest=np.where(stepping, plan.shortest, np.nan),
        step_longest=np.where(stepping, plan.longest, np.nan),
        steps=np.where(stepping, plan.steps, np.where(strategy == _FALL, -1, 0)).astype(np.int64)
        * (strategy >= 0)
        - (strategy < 0),
    )
