r"""The per-state step decision in pure Python (``math`` only): the single source of truth.

Every stepping answer of the package comes from the functions below, run either as plain
Python (:func:`pushrecovery.surfaces.step.plan_step`, the thresholds of ``pushrecovery bounds``,
small arrays) or compiled by numba from this very code
(:mod:`pushrecovery.kernels.stepping`: the vectorised :func:`plan_steps
<pushrecovery.surfaces.step.plan_steps>` and :func:`solve_step_angle
<pushrecovery.models.stepping.solve_step_angle>`, and the real-time
:func:`~pushrecovery.surfaces.step.compiled_plan_step`). Hence the rules for this module:

- no import but ``math`` (the bounds path must not load numpy's compiled friends, numba or
  scipy), floats, tuples and ``range`` only, so that numba's nopython mode accepts every line;
- a function calls the others of this module by their global names; the kernels module compiles
  them with those names bound to the compiled versions, and with :data:`prange` bound to
  ``numba.prange``. All compiled code is therefore cached on disk under *this* file's name and
  invalidated by numba whenever this file changes, callees included.

The model is that of :mod:`pushrecovery.models.stepping` (Hofmann's stepping pendulum, Sec. IV)
applied to a leaning stance leg as in :mod:`pushrecovery.surfaces.step`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from numpy import bool_, float64
    from numpy.typing import NDArray

#: Largest step angle: at π/4 the impact absorbs all horizontal velocity (cos 2θ = 0) [rad].
MAX_STEP_ANGLE = 0.25 * math.pi
#: Shortest step that counts as a step, foot to foot [m].
MIN_STEP_LENGTH = 0.05
#: The loop of the array kernels: plain ``range`` here, ``numba.prange`` once compiled.
prange = range

Decision = tuple[float, bool, bool, float, float, float, float, float]


def capture_residual(
    theta: float, energy: float, omega2: float, omega: float, length: float, target: float
) -> tuple[float, float]:
    """ξ⁺(θ) − target [m] and its slope dξ⁺/dθ [m/rad] (stepping module docstring).

    ``energy`` is the upright-equivalent θ̇² = θ̇(θ)² − 2ω²(1 − cos θ) [rad²/s²] (negative for
    falls that start leaning, below the top of the pendulum), ω² = g/L [1/s²].
    """
    s, c = math.sin(theta), math.cos(theta)
    rate = math.sqrt(max(0.0, energy + 2.0 * omega2 * (1.0 - c)))
    c2 = math.cos(2.0 * theta)
    root_c = math.sqrt(c)
    value = length * (-s + rate / omega * c2 / root_c) - target
    if rate == 0.0:
        return value, -1.0
    d_rate = omega2 * s / rate
    slope = length * (
        -c
        + (
            d_rate * c2 / root_c
            - 2.0 * rate * math.sin(2.0 * theta) / root_c
            + 0.5 * rate * c2 * s / (c * root_c)
        )
        / omega
    )
    return value, slope


def step_angle(energy: float, lean: float, target: float, length: float, gravity: float) -> float:
    """Step angle θ in [max(lean, 0), π/4] with ξ⁺(θ) = target, by safeguarded Newton [rad].

    ξ⁺ decreases monotonically in θ, so the bracket [low, high] shrinks around the root and a
    Newton step that leaves it is replaced by bisection; converged when the Newton step or the
    bracket is below 1e-15 rad. Returns the lower end when even an immediate step leaves ξ⁺ at
    or behind the target, and π/4 when the target lies below −L/√2 (unreachable). ``energy`` as
    in :func:`capture_residual`, ``length`` L [m], ``gravity`` g [m/s²], ``target`` [m].
    """
    omega2 = gravity / length
    omega = math.sqrt(omega2)
    top = MAX_STEP_ANGLE
    low = max(0.0, lean)
    if low >= top or capture_residual(low, energy, omega2, omega, length, target)[0] <= 0.0:
        return min(low, top)  # an immediate step already lands at or behind the target
    if -length * math.sqrt(0.5) >= target:
        return top
    high = top
    # Small-angle start for the Eq. (21) root: θ⁴ ≈ v0² / (3.58 g L).
    theta = min(0.5 * (low + top), max(low, (max(energy, 0.0) / omega2 / 3.5833) ** 0.25))
    if theta <= low:
        theta = 0.5 * (low + high)
    for _ in range(100):
        value, slope = capture_residual(theta, energy, omega2, omega, length, target)
        if value > 0.0:  # ξ⁺ decreases with θ: the root lies above
            low = theta
        else:
            high = theta
        step = theta - value / slope if slope < 0.0 else -1.0
        if abs(step - theta) <= 1e-15 * max(1.0, theta):  # converged: Newton stands still
            return min(max(step, low), high)
        if not low < step < high:
            step = 0.5 * (low + high)
        if abs(step - theta) <= 1e-15 * max(1.0, theta) or high - low <= 1e-15:
            return step
        theta = step
    return theta


def decide(
    x: float,
    xdot: float,
    heel: float,
    toe: float,
    height: float,
    gravity: float,
    reach: float,
) -> Decision:
    """Step decision for one CoM state, as documented in :mod:`pushrecovery.surfaces.step`.

    The stance leg l = sqrt(x² + L²) falls from its lean θ0 with the tangential rate θ̇0; three
    roots of ξ⁺(θ) = target in units of l (:func:`step_angle`) give Eq. (21)'s step (target 0)
    and the ends of the range that keeps the post-impact capture point on the new foot (Eq. 4:
    targets toe/l and heel/l), then clipped to the reach, π/4 and a stance leg in compression.

    Parameters
    ----------
    x, xdot : float
        CoM position relative to the stance ankle [m] and velocity [m/s].
    heel, toe : float
        Back and front edge of the new foot relative to its ankle along the step line [m];
        mirrored for backward steps.
    height, gravity, reach : float
        CoM height L [m], g [m/s²] and the longest step, foot to foot [m].

    Returns
    -------
    tuple
        (direction, ready, feasible, theta [rad], step_length [m], shortest [m], longest [m],
        margin [m]): the fields of :class:`~pushrecovery.surfaces.step.StepDecision`.
    """
    direction = 1.0 if x + xdot / math.sqrt(gravity / height) >= 0.5 * (heel + toe) else -1.0
    # Mirror backward steps: positive lean toward the step, heel and toe swapped.
    if direction < 0.0:
        heel, toe = -toe, -heel
    length = math.hypot(x, height)  # the stance leg, ankle to CoM
    lean = math.atan2(direction * x, height)
    lean_rate = direction * xdot * math.cos(lean) / length  # tangential part only
    omega2 = gravity / length
    energy = lean_rate * lean_rate - 2.0 * omega2 * (1.0 - math.cos(lean))  # θ̇² at θ = 0
    ready = lean_rate > 0.0 and (energy > 0.0 or lean > 0.0)
    lowest = max(lean, 0.0)
    # Solve in units of l (ξ⁺/l depends on θ̇/ω_l only): l = 1, g = 1.
    scaled = energy / omega2 if ready else 1.0
    best = step_angle(scaled, lowest, 0.0, 1.0, 1.0)
    low = max(step_angle(scaled, lowest, toe / length, 1.0, 1.0), lean)
    high = step_angle(scaled, lowest, heel / length, 1.0, 1.0)
    # The stance leg stays in compression up to the angle where l θ̇² = g cos θ, i.e.
    # cos θ_c = (l θ̇0² + 2 g) / (3 g) with θ̇0 the upright-equivalent rate.
    cos_limit = (length * (energy if ready else 0.0) + 2.0 * gravity) / (3.0 * gravity)
    reach_angle = math.asin(min(1.0, reach / (2.0 * length)))
    allowed = min(reach_angle, MAX_STEP_ANGLE, math.acos(min(1.0, max(-1.0, cos_limit))))
    # A step needs room: at least MIN_STEP_LENGTH within reach and compression (leaning past
    # the reach, or with a leg about to pull, no step can be placed).
    ready = ready and lowest <= allowed and 2.0 * length * math.sin(allowed) >= MIN_STEP_LENGTH
    high = min(high, allowed)
    in_compression = cos_limit < 1.0 and low <= allowed
    feasible = ready and low < high and in_compression
    theta = math.nan
    if feasible:
        theta = min(max(best, low), high)
    elif ready:  # best effort: the admissible angle nearest Eq. (21)'s
        theta = min(max(best, lowest), max(allowed, lowest))
    shortest = 2.0 * length * math.sin(low) if ready else math.nan
    longest = 2.0 * length * math.sin(high) if feasible else math.nan
    margin = reach - shortest if ready and in_compression else -math.inf
    step_length = direction * 2.0 * length * math.sin(theta)
    return direction, ready, feasible, theta, step_length, shortest, longest, margin


def _capture_below(sin: float, cos: float, energy: float, target: float, strict: bool) -> bool:
    """Whether ξ⁺/l < target (``strict``) or <= target at the angle with this sine and cosine.

    In units l = g = 1 (:func:`capture_residual`): ξ⁺/l = −s + R (c² − s²)/√c with
    R = √(energy + 2 (1 − c)). For θ in [0, π/4], c² − s² = cos 2θ >= 0, so the left side of
    R (c² − s²)/√c < target + s is >= 0: the inequality fails when target + s is negative (or
    zero, strictly) and otherwise holds exactly when its square does,
    R² (c² − s²)² < (target + s)² c. No square root, no trigonometric call.
    """
    room = target + sin
    if room < 0.0 or (strict and room == 0.0):
        return False
    spin = max(0.0, energy + 2.0 * (1.0 - cos))
    squeeze = cos * cos - sin * sin
    left = spin * squeeze * squeeze
    right = room * room * cos
    return left < right if strict else left <= right


def feasible(
    x: float,
    xdot: float,
    heel: float,
    toe: float,
    height: float,
    gravity: float,
    reach: float,
) -> bool:
    """``decide(...)[2]`` (does a single step recover?) without solving for any angle.

    ξ⁺(θ) decreases strictly in θ, so with f = ξ⁺/l on [lowest, π/4] the angles of
    :func:`decide` satisfy θ_toe < θ_heel ⟺ f(lowest) > heel/l, and θ_toe < allowed ⟺
    lowest < allowed and f(allowed) < toe/l; ``feasible`` is ``ready``, the stance leg in
    compression, and both. Every angle involved lies in [0, π/2), where sines order angles, and
    each is known by its sine and cosine (the lean: x/l, L/l; the reach: its half-step over l;
    π/4; the compression limit: its cosine), so no trigonometric function is evaluated: two
    comparisons of ξ⁺ (:func:`_capture_below`, squared) replace three Newton solves. The
    answer can differ from :func:`decide`'s only within rounding of the boundary (f(allowed)
    within ~1e-15 of toe/l). Arguments as in :func:`decide`.
    """
    if x + xdot * math.sqrt(height / gravity) < 0.5 * (heel + toe):
        x, xdot, heel, toe = -x, -xdot, -toe, -heel  # the mirror image: a forward step
    length = math.sqrt(x * x + height * height)  # as hypot, |x| and L being far below 1e150
    inv_length = 1.0 / length  # one division; the rest multiply (divisions are slow)
    lean_cos = height * inv_length
    lean_rate = xdot * lean_cos * inv_length
    energy = lean_rate * lean_rate - 2.0 * gravity * inv_length * (1.0 - lean_cos)
    if not (lean_rate > 0.0 and (energy > 0.0 or x > 0.0)):
        return False
    cos_limit = (length * energy + 2.0 * gravity) * (1.0 / 3.0) / gravity
    if not cos_limit < 1.0:
        return False
    # The lowest angle (the lean, or upright) and the allowed one (reach, π/4, compression),
    # each as (sine, cosine).
    low_sin, low_cos = (x * inv_length, lean_cos) if x > 0.0 else (0.0, 1.0)
    top_sin, top_cos = math.sqrt(0.5), math.sqrt(0.5)
    reach_sin = min(1.0, 0.5 * reach * inv_length)
    if reach_sin < top_sin:
        top_sin, top_cos = reach_sin, math.sqrt(1.0 - reach_sin * reach_sin)
    if cos_limit > top_cos:  # the compression limit comes first (cos_limit > 0 there)
        top_sin, top_cos = math.sqrt(1.0 - cos_limit * cos_limit), cos_limit
    if not (low_sin < top_sin and 2.0 * length * top_sin >= MIN_STEP_LENGTH):
        return False
    scaled = energy * length / gravity  # θ̇² in units of g/l
    if _capture_below(low_sin, low_cos, scaled, heel * inv_length, False):
        return False
    return _capture_below(top_sin, top_cos, scaled, toe * inv_length, True)


def step_line(
    x: float,
    y: float,
    xdot: float,
    ydot: float,
    inv_omega: float,
    ankle_x: float,
    ankle_y: float,
    heading_x: float,
    heading_y: float,
    swing: float,
    foot_x: NDArray[float64],
    foot_y: NDArray[float64],
) -> tuple[float, float, float, float, float, float]:
    """Return the line a planar state steps along, and the state and landing foot on it.

    The line runs from the stance's ankle to ξ = r + ṙ/ω, turned to the heading's side
    (e · heading >= 0) so that the sagittal case keeps its signs (the heading itself when ξ is
    at the ankle); the state is projected on it, s = (r − ankle) · e, ṡ = ṙ · e; the landing
    foot's edges along it are its support function from the foot's vertices (in its frame, any
    sequence), ``swing`` = −1 for the right foot (the left shape mirrored), +1 for the left,
    0 for the one on the side of the step (double support). Positions [m], velocities [m/s],
    1/ω [s], the heading a unit vector.

    Returns
    -------
    tuple
        (e_x, e_y, s [m], ṡ [m/s], heel [m], toe [m]).
    """
    ex = x + xdot * inv_omega - ankle_x
    ey = y + ydot * inv_omega - ankle_y
    norm = math.sqrt(ex * ex + ey * ey)  # hypot is several times slower
    if not norm < math.inf:  # |ξ| beyond 1e154 m: only hypot does not overflow
        norm = math.hypot(ex, ey)
    if norm == 0.0:
        ex, ey = heading_x, heading_y
    else:
        # Turned to the heading's side, in the same multiplication that normalises it.
        scale = (1.0 if ex * heading_x + ey * heading_y >= 0.0 else -1.0) / norm
        ex, ey = ex * scale, ey * scale
    fx = heading_x * ex + heading_y * ey  # the line in the foot's frame
    fy = -heading_y * ex + heading_x * ey
    fy = abs(fy) if swing == 0.0 else swing * fy
    heel, toe = math.inf, -math.inf
    for k in range(len(foot_x)):
        ahead = foot_x[k] * fx + foot_y[k] * fy
        heel = min(heel, ahead)
        toe = max(toe, ahead)
    along = (x - ankle_x) * ex + (y - ankle_y) * ey
    return ex, ey, along, xdot * ex + ydot * ey, heel, toe


def _store(i: int, decision: Decision, values: NDArray[float64], flags: NDArray[bool_]) -> None:
    """Write one decision into column i of the (6, n) floats and (2, n) flags."""
    direction, ready, feasible, theta, step_length, shortest, longest, margin = decision
    values[0, i] = direction
    values[1, i] = theta
    values[2, i] = step_length
    values[3, i] = shortest
    values[4, i] = longest
    values[5, i] = margin
    flags[0, i] = ready
    flags[1, i] = feasible


def decide_each(
    x: NDArray[float64],
    xdot: NDArray[float64],
    heel: NDArray[float64],
    toe: NDArray[float64],
    height: float,
    gravity: float,
    reach: float,
    values: NDArray[float64],
    flags: NDArray[bool_],
) -> None:
    """:func:`decide` for every state of flat arrays, into ``values`` and ``flags`` (_store)."""
    for i in prange(x.shape[0]):
        _store(i, decide(x[i], xdot[i], heel[i], toe[i], height, gravity, reach), values, flags)


def solve_each(
    energy: NDArray[float64],
    lean: NDArray[float64],
    target: NDArray[float64],
    length: float,
    gravity: float,
    out: NDArray[float64],
) -> None:
    """:func:`step_angle` for every element of flat arrays, into ``out`` [rad]."""
    for i in prange(energy.shape[0]):
        out[i] = step_angle(energy[i], lean[i], target[i], length, gravity)
