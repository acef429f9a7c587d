r"""The ``step`` verdict: a state is captured by at most ``max_steps`` steps.

A support's regions C_1 ... C_{max_steps} of :mod:`pushrecovery.surfaces.capture_region`
((S1): touchdowns every ``min_step_time`` from ``min_step_time`` on, the hip's box included;
from double support, one set per foot that may lift first) are built once and kept. A state
needs the smallest N whose region holds its capture point ξ strictly; its step margin is the
largest signed distance of ξ to any of them (positive exactly when some plan of at most
``max_steps`` steps captures it: the margin agrees with the verdict everywhere).

On the sagittal line (one foot [heel, toe], no width) the regions are intervals:

.. math:: C_N = [\delta^- - a - l\,s_N,\ \delta^+ + a + l\,s_N], \qquad
          s_N = \sum_{k=1}^{N} \beta^k,\ \beta = e^{-\omega\Delta t_s},

with a the corrected Eq. (15) offset and l = ``max_step_length``: (S2) along ±x.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Stance, Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.capture_region import (
    StepOption,
    StepPlan,
    capturability_distance,
    plan_steps_xy,
    step_options,
    viable_region,
)
from pushrecovery.surfaces.cmp import cmp_offset
from pushrecovery.surfaces.cop import CaptureInterval

__all__ = ["StepRegions", "sagittal_plan", "sagittal_step_interval", "sagittal_steps"]

FloatArray = NDArray[np.float64]


def sagittal_step_interval(params: BodyParams, steps: int | None = None) -> CaptureInterval:
    """C_N on the sagittal line (module docstring) [m]; N defaults to ``max_steps``."""
    count = params.max_steps if steps is None else steps
    grow = capturability_distance(
        count, params.omega, params.min_step_time, params.max_step_length, 0.0, cmp_offset(params)
    )
    return CaptureInterval(params.heel - grow, params.toe + grow)


def sagittal_steps(xi: float, params: BodyParams) -> tuple[int, float]:
    """(smallest N <= max_steps whose interval holds ξ strictly, 0 if none; margin [m]).

    The margin is the signed distance of ξ to C_{max_steps} (the intervals are nested).
    """
    outer = sagittal_step_interval(params)
    margin = outer.half_width - abs(xi - outer.centre)
    if not margin > 0.0:
        return 0, margin
    for steps in range(1, params.max_steps + 1):
        interval = sagittal_step_interval(params, steps)
        if interval.half_width - abs(xi - interval.centre) > 0.0:
            return steps, margin
    return params.max_steps, margin  # pragma: no cover - the last interval is the outer one


def sagittal_plan(xi: float, params: BodyParams, steps: int) -> StepPlan:
    """Return the plan of :func:`~.capture_region.plan_steps_xy` on the sagittal line.

    Every term of (S1) at the same fraction f of its half-width from its centre, f = (ξ −
    c)/half-width of C_N: steps of f l, CoPs at the foot's middle plus f (δ⁺ − δ⁻)/2, the
    hip's share f a. Footholds (x, 0) from the ankle at 0, touchdowns every Δt_s.
    """
    interval = sagittal_step_interval(params, steps)
    share = max(-1.0, min(1.0, (xi - interval.centre) / interval.half_width))
    middle, half = 0.5 * (params.heel + params.toe), 0.5 * (params.toe - params.heel)
    cops = np.zeros((steps + 1, 2))
    footholds = np.zeros((steps, 2))
    footholds[:, 0] = share * params.max_step_length * np.arange(1, steps + 1)
    cops[0, 0] = middle + share * half
    cops[1:, 0] = footholds[:, 0] + middle + share * half
    return StepPlan(
        steps,
        tuple(Stance.LEFT if k % 2 == 0 else Stance.RIGHT for k in range(steps)),
        footholds,
        params.min_step_time * np.arange(1, steps + 1, dtype=np.float64),
        cops,
        np.array([share * cmp_offset(params), 0.0]),
        interval.half_width - abs(xi - interval.centre),
    )


@dataclass(frozen=True, slots=True, eq=False)
class StepRegions:
    """The N-step regions of one support, N = 1 ... max_steps, ready for verdicts.

    Attributes
    ----------
    params : BodyParams
        The body.
    polygons : tuple of ConvexPolygon
        C_N, by ascending N; from double support both lifting feet for each N.
    steps : tuple of int
        N of each polygon.
    options : tuple of StepOption
        The first landing foot of each polygon.
    table : ndarray, shape (R, E, 7)
        The polygons' edge tables, padded to the longest by repeating a row (compiled tests).
    counts : ndarray of int64, shape (R,)
        Edges of each polygon.
    discs : ndarray, shape (R, 4)
        (c_x, c_y, r_in², r_out²): discs inside and around each polygon about its centroid.
    """

    params: BodyParams
    polygons: tuple[ConvexPolygon, ...]
    steps: tuple[int, ...]
    options: tuple[StepOption, ...]
    table: FloatArray
    counts: NDArray[np.int64]
    discs: FloatArray

    @classmethod
    def of(cls, params: BodyParams, support: Support) -> StepRegions:
        """Return the regions of ``support`` (kept: asking again costs a look-up)."""
        return _regions(params, support)

    def locate(self, px: float, py: float) -> tuple[int, float]:
        """Return (steps needed, 0 beyond max_steps; step margin [m]) of one capture point."""
        best = -math.inf
        found = 0
        for polygon, steps in zip(self.polygons, self.steps, strict=True):
            margin = float(polygon.signed_distance(px, py))
            best = max(best, margin)
            if found == 0 and margin > 0.0:
                found = steps
        return found, best

    def margins(self, px: FloatArray, py: FloatArray) -> FloatArray:
        """Step margins of many capture points: the largest signed distance to a region [m]."""
        best = np.full(np.shape(px), -np.inf)
        for polygon in self.polygons:
            np.maximum(best, polygon.signed_distance(px, py), out=best)
        return best

    def plan(self, px: float, py: float, steps: int) -> StepPlan:
        """Return the plan of ``steps`` steps for ξ = (px, py), from the best foot to lift."""
        rows = [i for i, n in enumerate(self.steps) if n == steps]
        row = max(rows, key=lambda i: float(self.polygons[i].signed_distance(px, py)))
        return plan_steps_xy(np.array([px, py]), self.params, self.options[row], steps)


@functools.lru_cache(maxsize=32)
def _regions(params: BodyParams, support: Support) -> StepRegions:
    polygons, steps, options = [], [], []
    for n in range(1, params.max_steps + 1):
        times = tuple(params.min_step_time * (k + 1) for k in range(n))
        for option in step_options(params, support):
            polygons.append(viable_region(params, option, times))
            steps.append(n)
            options.append(option)
    longest = max(len(p.offsets) for p in polygons)
    table = np.empty((len(polygons), longest, 7))
    discs = np.empty((len(polygons), 4))
    for i, polygon in enumerate(polygons):
        edges = polygon.edge_table
        table[i, : len(edges)] = edges
        table[i, len(edges) :] = edges[-1]
        centre = np.array(polygon.centroid)
        inner = float(np.min(polygon.offsets - polygon.normals @ centre))
        outer = float(np.max(np.hypot(*(polygon.vertices - centre).T)))
        # Shrunk and grown by 1e-12 relative: rounding never moves a verdict across an edge.
        discs[i] = (*centre, (inner * (1.0 - 1e-12)) ** 2, (outer * (1.0 + 1e-12)) ** 2)
    counts = np.array([len(p.offsets) for p in polygons], dtype=np.int64)
    return StepRegions(params, tuple(polygons), tuple(steps), tuple(options), table, counts, discs)
