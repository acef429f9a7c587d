r"""The ``step`` verdict: a state is captured by at most ``max_steps`` steps.

A support's regions C_1 ... C_{max_steps} of :mod:`pushrecovery.surfaces.n_step`
((S1): touchdowns every ``min_step_time`` from ``min_step_time`` on, the hip's box included;
from double support, one set per foot that may lift first) are those of its stance feet: each
is built once per body for the stance ankle at the origin with yaw 0 and turned and moved to
the feet (:class:`StepRegions`), so a new support costs tens of µs at any pose and yaw. A state
needs the smallest N whose region holds its capture point ξ strictly; its step margin is the
largest signed distance of ξ to any of them (positive exactly when some plan of at most
``max_steps`` steps captures it: the margin agrees with the verdict everywhere).

On a line (the sagittal model, or one axis of a measured trial) the regions are intervals:
with the support [s⁻, s⁺] before the first step, the stance ankle q_0, landing feet
[δ⁻, δ⁺] about their ankles, (S2) along ±x gives

.. math:: C_N = [a_1 (q_0 + \delta^-) + (1 - a_1) s^- - a - l\,s_N,\
          a_1 (q_0 + \delta^+) + (1 - a_1) s^+ + a + l\,s_N], \qquad
          s_N = \sum_{k=1}^{N} \beta^k,

β = a_1 = e^{−ωΔt_s}, a the corrected Eq. (15) offset and l = ``max_step_length``; on the
sagittal line s^± = δ^± and q_0 = 0: [δ⁻ − a − l s_N, δ⁺ + a + l s_N].

Over 400 lines on purpose: one concept, the step verdict and its plan, on the line and on the
plane; the regions themselves are :mod:`pushrecovery.surfaces.n_step`'s.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    finite_vector,
    require_type,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture.plan import CapturePlan, _plan, plan_loads
from pushrecovery.surfaces.capture.region import MAX_CAPTURE_POINT, MAX_POSITION
from pushrecovery.surfaces.cmp import cmp_offset
from pushrecovery.surfaces.cop import CaptureInterval
from pushrecovery.surfaces.n_step import (
    StepOption,
    _capturability_distance,
    landing_foot,
    step_options,
    viable_region,
)

__all__ = [
    "LineSteps",
    "StepRegions",
    "line_steps",
    "sagittal_step_interval",
]

FloatArray = NDArray[np.float64]


def _line_step_bounds(
    lower: FloatArray | float,
    upper: FloatArray | float,
    ankle: FloatArray | float,
    params: BodyParams,
    steps: int,
    *,
    hip: bool = True,
) -> tuple[FloatArray, FloatArray]:
    """C_N on a line (module docstring) for supports [lower, upper] and stance ankles [m]."""
    beta, grows = _growth(params, hip)
    grow = float(grows[steps]) if steps < len(grows) else _grow(params, hip, steps)
    first = beta if steps > 0 else 0.0
    low = first * (np.asarray(ankle) + params.heel) + (1.0 - first) * np.asarray(lower) - grow
    high = first * (np.asarray(ankle) + params.toe) + (1.0 - first) * np.asarray(upper) + grow
    return np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)


def _grow(params: BodyParams, hip: bool, steps: int) -> float:
    """Return the growth l s_N (+ the hip's share) of C_N over the stance foot [m]."""
    return _capturability_distance(
        steps,
        params.omega,
        params.min_step_time,
        params.max_step_length,
        0.0,
        cmp_offset(params) if hip else 0.0,
    )


@functools.lru_cache(maxsize=128)
def _growth(params: BodyParams, hip: bool) -> tuple[float, FloatArray]:
    """e^{−ωΔt_s} and the growths of C_0..C_{max_steps}, once per body (the verdict's hot path)."""
    beta = math.exp(-params.omega * params.min_step_time)
    grows = np.array([_grow(params, hip, n) for n in range(params.max_steps + 1)])
    grows.flags.writeable = False
    return beta, grows


#: Up to this many states, the levels N are tested all at once (a (levels, states) array).
_LEVELS_AT_ONCE = 4096


@dataclass(frozen=True, slots=True)
class LineSteps:
    """Step verdicts on a line, one per state (:func:`line_steps`).

    Attributes
    ----------
    steps : ndarray of int64
        Smallest N <= max_steps whose interval holds ξ strictly; 0 if none.
    margin : ndarray
        Signed distance of ξ to C_{max_steps} [m] (the intervals are nested).
    step_length : ndarray
        Recommended first step, the middle of its range, landing ankle minus stance ankle [m]
        (NaN without steps).
    shortest, longest : ndarray
        The first steps along its direction that still capture with ``steps`` steps [m].
    """

    steps: NDArray[np.int64]
    margin: FloatArray
    step_length: FloatArray
    shortest: FloatArray
    longest: FloatArray


def line_steps(
    capture: ArrayLike,
    lower: ArrayLike,
    upper: ArrayLike,
    ankle: ArrayLike,
    params: BodyParams,
) -> LineSteps:
    """N-step verdicts and first steps on a line, vectorised (module docstring) [m].

    The range of first steps is (S3) on the line: q_1 − q_0 in T ξ − T[−a, a] − (T − 1)[s⁻, s⁺]
    − V_{N−1} − q_0, V_{N−1} = [δ⁻ − l s_{N−1}, δ⁺ + l s_{N−1}], T = e^{ωΔt_s}, within ±l; the
    recommended first step is its middle (the most robust, as :func:`_sagittal_plan`).

    Raises
    ------
    ParameterTypeError
        If ``params`` is not a :class:`~pushrecovery.params.BodyParams`.
    InvalidParameterError
        Values that are not finite, shapes that do not broadcast, a ``lower`` above its
        ``upper``, or positions so large that
        the intervals or the first steps overflow.
    """
    require_type("params", params, BodyParams)
    given = {"capture": capture, "lower": lower, "upper": upper, "ankle": ankle}
    arrays = [finite_array(name, value) for name, value in given.items()]
    try:
        capture, lower, upper, ankle = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(str(a.shape) for a in arrays)
        raise InvalidParameterError(
            f"capture, lower, upper and ankle must broadcast, got shapes {shapes}"
        ) from None
    if np.any(lower > upper):
        raise InvalidParameterError(
            "lower must be <= upper (the support's back and front edges on the line) [m], got "
            f"{int(np.count_nonzero(lower > upper))} pair(s) the other way round"
        )
    with np.errstate(over="ignore", invalid="ignore"):  # reported below, as one error
        found = _line_steps(capture, lower, upper, ankle, params)
    stepping = found.steps > 0
    if not (
        np.isfinite(found.margin).all()
        and np.isfinite(found.step_length[stepping]).all()
        and np.isfinite(found.shortest[stepping]).all()
        and np.isfinite(found.longest[stepping]).all()
    ):
        raise InvalidParameterError(
            "positions are too large: the step intervals on the line overflow"
        )
    return found


def _line_steps(
    capture: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    ankle: FloatArray,
    params: BodyParams,
) -> LineSteps:
    """:func:`line_steps` of checked, broadcast arrays."""
    top = params.max_steps
    if capture.size <= _LEVELS_AT_ONCE:
        # C_N = base ∓ grow_N for N >= 1, as _line_step_bounds computes it, all N at once.
        beta, grows = _growth(params, True)
        base_low = beta * (ankle + params.heel) + (1.0 - beta) * lower
        base_high = beta * (ankle + params.toe) + (1.0 - beta) * upper
        level = grows[1:].reshape((top,) + (1,) * capture.ndim)
        low, high = base_low - level, base_high + level
        inside = (capture > low) & (capture < high)
        steps = np.where(inside.any(axis=0), inside.argmax(axis=0) + 1, 0).astype(np.int64)
        margin = np.minimum(capture - low[-1], high[-1] - capture)
    else:
        steps = np.zeros(capture.shape, dtype=np.int64)
        for n in range(top, 0, -1):
            low, high = _line_step_bounds(lower, upper, ankle, params, n)
            inside = (capture > low) & (capture < high)
            steps[inside] = n
            if n == top:
                margin = np.minimum(capture - low, high - capture)
    length = np.full(capture.shape, np.nan)
    shortest, longest = length.copy(), length.copy()
    reach, hip = params.max_step_length, cmp_offset(params)
    scale = math.exp(params.omega * params.min_step_time)
    _, without_hip = _growth(params, False)
    for n in np.unique(steps[steps > 0]):
        rows = steps == n
        more = float(without_hip[int(n) - 1])
        xi = capture[rows]
        first = scale * xi - scale * hip - (scale - 1.0) * upper[rows] - params.toe - more
        last = scale * xi + scale * hip - (scale - 1.0) * lower[rows] - params.heel + more
        first = np.maximum(first - ankle[rows], -reach)
        last = np.minimum(last - ankle[rows], reach)
        length[rows] = 0.5 * (first + last)  # the most robust first step: the middle
        forward = length[rows] >= 0.0
        shortest[rows] = np.where(forward, np.maximum(first, 0.0), np.maximum(-last, 0.0))
        longest[rows] = np.where(forward, last, -first)
    return LineSteps(steps, margin, length, shortest, longest)


def sagittal_step_interval(params: BodyParams, steps: int | None = None) -> CaptureInterval:
    """C_N on the sagittal line (module docstring) [m]; N defaults to ``max_steps``."""
    require_type("params", params, BodyParams)
    count = params.max_steps if steps is None else whole_number("steps", steps, 1, 10**6)
    low, high = _line_step_bounds(params.heel, params.toe, 0.0, params, count)
    return CaptureInterval(float(low), float(high))


def _sagittal_plan(
    xi: float, params: BodyParams, steps: int, com: float | None = None
) -> CapturePlan:
    """Return :func:`_line_plan` with its loads (:func:`plan_loads`; the CoM at ``com`` [m])."""
    plan = _line_plan(xi, params, steps)
    if com is None:
        return plan.with_loads(plan_loads(plan, params))
    velocity = (params.omega * (xi - com), 0.0)
    return plan.with_loads(plan_loads(plan, params, (com, 0.0), velocity))


def _line_plan(xi: float, params: BodyParams, steps: int) -> CapturePlan:
    """Return the plan of :func:`~pushrecovery.surfaces.capture.plan.capture_plan`, sagittal.

    Step by step: the first foothold is the middle of the interval of first footholds ((S3)
    on the line: T ξ − T[−a, a] − (T − 1)(q_0 + [δ⁻, δ⁺]) − V_{N−1}, within q_0 ± l), the most
    robust one; the CoP and the hip's share put every term of T ξ − q_1 at the same fraction of
    its half-width from its centre, which gives the capture point at touchdown; then the same
    from the new foot, N − 1 steps, without the hip. Footholds (x, 0), touchdowns every Δt_s.
    """
    interval = sagittal_step_interval(params, steps)
    margin = interval.half_width - abs(xi - interval.centre)
    scale = math.exp(params.omega * params.min_step_time)
    middle, half = 0.5 * (params.heel + params.toe), 0.5 * (params.toe - params.heel)
    reach = params.max_step_length
    footholds, cops = np.zeros((steps, 2)), np.zeros((steps + 1, 2))
    ankle, capture, hip, share_hip = 0.0, xi, cmp_offset(params), 0.0
    for k in range(steps):
        more = _capturability_distance(
            steps - 1 - k, params.omega, params.min_step_time, reach, 0.0
        )
        low = scale * capture - scale * hip - (scale - 1.0) * (ankle + params.toe)
        low -= params.toe + more
        high = scale * capture + scale * hip - (scale - 1.0) * (ankle + params.heel)
        high -= params.heel - more
        foothold = 0.5 * (max(low, ankle - reach) + min(high, ankle + reach))
        # Split T ξ − q over T[−a, a] + (T − 1)(q_0 + [δ⁻, δ⁺]) + V_{N−1}, equally deep.
        target = scale * capture - foothold
        centre = (scale - 1.0) * (ankle + middle) + middle
        width = scale * hip + (scale - 1.0) * half + half + more
        share = max(-1.0, min(1.0, (target - centre) / width)) if width > 0.0 else 0.0
        if k == 0:
            share_hip = share * hip
        cops[k, 0] = ankle + middle + share * half
        footholds[k, 0] = foothold
        capture = foothold + middle + share * (half + more)
        ankle, hip = foothold, 0.0
    cops[steps, 0] = capture  # the last CoP holds the capture point, in the last foot
    return CapturePlan(
        steps,
        tuple(Stance.LEFT if k % 2 == 0 else Stance.RIGHT for k in range(steps)),
        footholds,
        params.min_step_time * np.arange(1, steps + 1, dtype=np.float64),
        cops,
        np.array([share_hip, 0.0]),
        margin,
    )


@dataclass(frozen=True, slots=True, eq=False)
class _Canonical:
    """The regions of one stance foot at the origin with yaw 0, built once per body and side.

    ``tables`` (2, M, E, 7) and ``counts`` (2, M), ``discs`` (2, M, 4): index 0 the right
    stance foot (the left one swings), 1 the left, as :func:`step_options` orders them from
    double support; E the longest of both. ``nested[k]``: every C_N of side k lies in C_{N+1}.
    """

    polygons: tuple[tuple[ConvexPolygon, ...], tuple[ConvexPolygon, ...]]
    options: tuple[StepOption, StepOption]
    tables: FloatArray
    counts: NDArray[np.int64]
    discs: FloatArray
    nested: tuple[bool, bool]


#: ``outer`` of one region alone (its margin is the largest); read-only as every ``outer``
#: (one compiled signature).
_ONE_OUTER = np.ones(1, dtype=np.bool_)
_ONE_OUTER.flags.writeable = False
#: Index of each stance foot in the canonical arrays (:class:`_Canonical`).
_SIDE = {Stance.RIGHT: 0, Stance.LEFT: 1}


@functools.lru_cache(maxsize=16)
def _canonical(params: BodyParams) -> _Canonical:
    """Build both stance feet's regions at the origin (the Minkowski sums, once per body)."""
    times = [
        tuple(params.min_step_time * (k + 1) for k in range(n))
        for n in range(1, 1 + params.max_steps)
    ]
    polygons, options, nested = [], [], []
    for stance in (Stance.RIGHT, Stance.LEFT):
        swing = Stance.LEFT if stance is Stance.RIGHT else Stance.RIGHT
        option = StepOption(swing, landing_foot(params, stance, 0.0), np.zeros(2), 0.0)
        side = tuple(viable_region(params, option, t) for t in times)
        polygons.append(side)
        options.append(option)
        nested.append(
            all(
                float(outer.signed_distance(*inner.vertices.T).min()) >= -1e-12
                for inner, outer in itertools.pairwise(side)
            )
        )
    longest = max(len(p.offsets) for side in polygons for p in side)
    tables = np.empty((2, params.max_steps, longest, 7))
    counts = np.empty((2, params.max_steps), dtype=np.int64)
    discs = np.empty((2, params.max_steps, 4))
    for k, side in enumerate(polygons):
        for m, polygon in enumerate(side):
            edges = polygon.edge_table
            tables[k, m, : len(edges)] = edges
            tables[k, m, len(edges) :] = edges[-1]
            counts[k, m] = len(edges)
            centre = np.array(polygon.centroid)
            inner = float(np.min(polygon.offsets - polygon.normals @ centre))
            around = float(np.max(np.hypot(*(polygon.vertices - centre).T)))
            # Shrunk and grown by 1e-12 relative: rounding never moves a verdict across an edge.
            discs[k, m] = (*centre, (inner * (1.0 - 1e-12)) ** 2, (around * (1.0 + 1e-12)) ** 2)
    for array in (tables, counts, discs):
        array.flags.writeable = False
    return _Canonical(
        (polygons[0], polygons[1]),
        (options[0], options[1]),
        tables,
        counts,
        discs,
        (nested[0], nested[1]),
    )


@dataclass(frozen=True, slots=True, eq=False)
class _Layout:
    """The rows of one stance's regions before placement (:func:`_layout`), all read-only.

    ``tables``, ``counts`` and ``discs`` are the canonical arrays of its stance feet (both from
    double support); ``rows`` of at most ``longest`` edges, level m of side k at row m K + k.
    """

    stances: tuple[Stance, ...]
    tables: FloatArray
    counts: NDArray[np.int64]
    discs: FloatArray
    rows: int
    longest: int
    row_counts: NDArray[np.int64]
    steps: tuple[int, ...]
    steps_array: NDArray[np.int64]
    outer: NDArray[np.bool_]


@functools.lru_cache(maxsize=48)
def _layout(params: BodyParams, stance: Stance) -> _Layout:
    """Return the canonical rows a support of ``stance`` places (kept: a support costs less)."""
    canonical = _canonical(params)
    stances: tuple[Stance, ...]
    if stance is Stance.DOUBLE:
        stances = (Stance.RIGHT, Stance.LEFT)  # the left foot lifts first
        tables, counts, discs = canonical.tables, canonical.counts, canonical.discs
        nested = canonical.nested[0] and canonical.nested[1]
    else:
        stances = (stance,)
        k = _SIDE[stance]
        tables, counts = canonical.tables[k : k + 1], canonical.counts[k : k + 1]
        discs, nested = canonical.discs[k : k + 1], canonical.nested[k]
    rows = np.ascontiguousarray(counts.T).reshape(-1)
    steps = tuple(n for n in range(1, params.max_steps + 1) for _ in stances)
    array = np.array(steps, dtype=np.int64)
    outer = np.array([not nested or n == params.max_steps for n in steps])
    rows.flags.writeable = array.flags.writeable = outer.flags.writeable = False
    return _Layout(
        stances, tables, counts, discs, len(steps), int(counts.max()), rows, steps, array, outer
    )


@dataclass(frozen=True, slots=True, eq=False)
class StepRegions:
    """The N-step regions of one support, N = 1 ... max_steps, ready for verdicts.

    Each single-support region is a rigid transform of the same region for the stance foot
    at the origin with yaw 0 (rotating every term of (S1) by the stance yaw and moving the
    ankle rotates and moves the sum): those are built once per body (the Minkowski sums) and
    a support only rotates and moves their edge tables (``kernels.placement``, tens of µs).
    From double support the regions are those of both single supports (the first step lifts
    one foot, the other is the stance). The polygons and options are built when first asked.

    Attributes
    ----------
    params : BodyParams
        The body.
    support : Support
        The support.
    steps : tuple of int
        N of each region, ascending; from double support both lifting feet for each N (the
        left foot first).
    steps_array : ndarray of int64, shape (R,)
        ``steps`` as an array (compiled tests).
    table : ndarray, shape (R, E, 7)
        The regions' edge tables (rows of ``ConvexPolygon.edge_table``), padded to the
        longest by repeating a row (compiled tests).
    counts : ndarray of int64, shape (R,)
        Edges of each region.
    discs : ndarray, shape (R, 4)
        (c_x, c_y, r_in², r_out²): discs inside and around each region about its centroid.
    outer : ndarray of bool, shape (R,)
        Regions whose union is the union of all: the max_steps ones when every C_N lies in
        C_{N+1} (checked vertex by vertex), else all.
    polygons : tuple of ConvexPolygon
        C_N, by row.
    options : tuple of StepOption
        The first landing foot of each row.
    """

    params: BodyParams
    support: Support
    steps: tuple[int, ...]
    steps_array: NDArray[np.int64]
    table: FloatArray
    counts: NDArray[np.int64]
    discs: FloatArray
    outer: NDArray[np.bool_]
    _stances: tuple[tuple[Stance, float, float, float], ...]  # (stance, x, y, yaw) per side
    _built: dict[str, tuple[object, ...]] = field(default_factory=dict, repr=False)

    @classmethod
    def of(cls, params: BodyParams, support: Support) -> StepRegions:
        """Return the regions of ``support`` (kept: asking again costs a look-up)."""
        return _regions(params, support)

    @property
    def polygons(self) -> tuple[ConvexPolygon, ...]:
        """C_N of each row [m] (built on first use)."""
        found = self._built.get("polygons")
        if found is None:
            canonical = _canonical(self.params)
            per_side = [
                [p.transformed(x, y, yaw) for p in canonical.polygons[_SIDE[stance]]]
                for stance, x, y, yaw in self._stances
            ]
            found = self._built["polygons"] = tuple(
                side[m] for m in range(self.params.max_steps) for side in per_side
            )
        return found  # type: ignore[return-value]

    @property
    def options(self) -> tuple[StepOption, ...]:
        """The first landing foot of each row (built on first use)."""
        found = self._built.get("options")
        if found is None:
            per_side = step_options(self.params, self.support)
            found = self._built["options"] = tuple(
                option for _ in range(self.params.max_steps) for option in per_side
            )
        return found  # type: ignore[return-value]

    def locate(self, px: float, py: float) -> tuple[int, float]:
        """Return (steps needed, 0 beyond max_steps; step margin [m]) of one capture point."""
        from pushrecovery.kernels.plane_codes import locate_steps

        found, margin = locate_steps(
            self.table, self.counts, self.steps_array, self.outer, float(px), float(py)
        )
        return int(found), float(margin)

    def margins(self, px: FloatArray, py: FloatArray) -> FloatArray:
        """Step margins of many capture points: the largest signed distance to a region [m]."""
        best = np.full(np.shape(px), -np.inf)
        for polygon, outer in zip(self.polygons, self.outer, strict=True):
            if outer:
                np.maximum(best, polygon.signed_distance(px, py), out=best)
        return best

    def plan(
        self,
        px: float,
        py: float,
        steps: int,
        *,
        landing_yaw: float | None = None,
        com: tuple[float, float] | FloatArray | None = None,
    ) -> CapturePlan:
        """Return the plan of ``steps`` steps for ξ = (px, py).

        From double support the foot on the capture point's side of the other ankle steps
        when its regions capture ξ (a side step, not a crossover), else the other one. The
        plan is made in the stance foot's frame (ankle at the origin, yaw 0: its terms are
        kept from plan to plan) and turned and moved back. The plan says whether it crosses
        over (``crossover``, :class:`~pushrecovery.surfaces.capture.plan.CapturePlan`).

        ``landing_yaw`` [rad], in [−π, π], is the world yaw of every landing foot (default:
        the stance foot's); the foot is chosen, and ``steps`` given, by the regions of the
        stance's yaw, while the plan and its ``margin`` are those of the landing yaw
        (:func:`~pushrecovery.surfaces.capture.plan.capture_plan`). With the CoM position
        ``com`` [m], world frame, the plan's loads include the ground forces.
        """
        from pushrecovery.kernels.plane_codes import locate_steps

        px, py = finite_float("px", px, "m"), finite_float("py", py, "m")
        steps = whole_number("steps", steps, 1, self.params.max_steps)
        if landing_yaw is not None:
            landing_yaw = bounded_float("landing_yaw", landing_yaw, -math.pi, math.pi, "rad")
        if com is not None:
            com = finite_vector("com", com, 2, unit="m")

        sides = len(self._stances)
        first = (steps - 1) * sides
        margins = []
        for k in range(sides):
            row = slice(first + k, first + k + 1)
            margins.append(
                float(
                    locate_steps(
                        self.table[row], self.counts[row], self.steps_array[row],
                        _ONE_OUTER, float(px), float(py),
                    )[1]
                )
            )  # fmt: skip

        def preference(k: int) -> tuple[bool, float]:
            stance, x, y, yaw = self._stances[k]
            lateral = -math.sin(yaw) * (px - x) + math.cos(yaw) * (py - y)
            # The swing foot is the other one: a left swing steps to the stance's left.
            outward = lateral >= 0.0 if stance is Stance.RIGHT else lateral <= 0.0
            return margins[k] > 0.0 and outward, margins[k]

        k = 0 if sides == 1 else max(range(sides), key=preference)
        stance, x, y, yaw = self._stances[k]
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = px - x, py - y
        lx, ly = c * dx + s * dy, -s * dx + c * dy
        local = np.array([lx, ly])
        if not (abs(lx) <= MAX_CAPTURE_POINT and abs(ly) <= MAX_CAPTURE_POINT):
            raise InvalidParameterError(
                f"(px, py) must lie within ±{MAX_CAPTURE_POINT:g} m of the stance ankle, got "
                f"({px!r}, {py!r}) (ankle ({x!r}, {y!r}))"
            )
        option = _canonical(self.params).options[_SIDE[stance]]
        turned = None if landing_yaw is None else math.remainder(landing_yaw - yaw, math.tau)
        local_com = velocity = None
        if com is not None:
            gx, gy = float(com[0]) - x, float(com[1]) - y
            local_com = finite_vector("com", (c * gx + s * gy, -s * gx + c * gy), 2, MAX_POSITION,
                                      "m")  # fmt: skip
            velocity = self.params.omega * (local - local_com)
        # capture_plan's own steps, its arguments checked here (a loop's tick pays them once).
        step_time = self.params.min_step_time
        plan = _plan(
            local,
            self.params,
            option,
            steps,
            tuple(step_time + step_time * n for n in range(steps)),
            True,
            margins[k] if not turned else None,
            option.yaw if turned is None else turned,
        )
        turn = np.array([[c, s], [-s, c]])  # row vectors times this: turned by the yaw
        shift = np.array([x, y])
        return CapturePlan(
            plan.steps,
            plan.swings,
            plan.footholds @ turn + shift,
            plan.touchdowns,
            plan.cops @ turn + shift,
            plan.hip @ turn,
            plan.margin,
            shift,
            yaw,
            yaw if landing_yaw is None else landing_yaw,
            plan_loads(plan, self.params, local_com, velocity),
        )


@functools.lru_cache(maxsize=32)
def _regions(params: BodyParams, support: Support) -> StepRegions:
    """Place both stance feet's canonical regions at the support's feet."""
    from pushrecovery.kernels.placement import place_tables

    layout = _layout(params, support.stance)
    poses = [support.left if stance is Stance.LEFT else support.right for stance in layout.stances]
    placed = np.array([(math.cos(p.yaw), math.sin(p.yaw), p.x, p.y) for p in poses])
    table = np.empty((layout.rows, layout.longest, 7))
    circles = np.empty((layout.rows, 4))
    place_tables(layout.tables, layout.counts, layout.discs, placed, table, circles)
    return StepRegions(
        params,
        support,
        layout.steps,
        layout.steps_array,
        table,
        layout.row_counts,
        circles,
        layout.outer,
        tuple(
            (stance, pose.x, pose.y, pose.yaw)
            for stance, pose in zip(layout.stances, poses, strict=True)
        ),
    )
