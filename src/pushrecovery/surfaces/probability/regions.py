"""The verdict regions of a body and support, and a Gaussian's cumulative masses on them.

Level 0 is the CoP region (ankle), 1 the CMP region (hip), 1 + k the k-step regions; on the
line intervals, on the plane convex polygons (two per k from double support). The verdict is
the first level whose region holds ξ, so P(level <= L) is the mass of the union of levels
0 … L (docs/uncertainty.md).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.special import ndtr

from pushrecovery.arguments import finite_array, require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.ground.gaussian import covariance_2d, gaussian_union_mass, maximal
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_region
from pushrecovery.surfaces.cop import cop_region
from pushrecovery.surfaces.plane import cmp_polygon
from pushrecovery.surfaces.step.regions import StepRegions, sagittal_step_interval

__all__ = ["Level", "cumulative_masses", "region_middle", "verdict_regions"]

FloatArray = NDArray[np.float64]

#: A level's regions: intervals (lower, upper) on the line, convex polygons on the plane.
Level = list[tuple[float, float]] | list[ConvexPolygon]


def verdict_regions(params: BodyParams, support: Support | None) -> list[Level]:
    """Return the regions of each level: CoP, CMP, then 1 … max_steps steps."""
    require_type("params", params, BodyParams)
    if support is not None:
        require_type("support", support, Support)
    if support is None:
        intervals = [cop_region(params), cmp_region(params)] + [
            sagittal_step_interval(params, n) for n in range(1, params.max_steps + 1)
        ]
        return [[(i.lower, i.upper)] for i in intervals]
    steps = StepRegions.of(params, support)
    per_n: list[Level] = [
        [p for p, n in zip(steps.polygons, steps.steps, strict=True) if n == count]
        for count in range(1, params.max_steps + 1)
    ]
    return [[support.polygon], [cmp_polygon(support, params)], *per_n]


def _check_levels(name: str, levels: object) -> None:
    """Raise naming ``name`` unless ``levels`` are non-empty lists of regions of one kind.

    Polygons, or (lower, upper) pairs [m] with lower <= upper: what :func:`strategy_levels`
    returns.
    """
    groups = levels if isinstance(levels, list) else None
    regions = [r for g in groups or () if isinstance(g, list | tuple) for r in g]
    if not groups or not regions or len(groups) != sum(isinstance(g, list | tuple) for g in groups):
        raise ParameterTypeError(f"{name} must be a non-empty list of lists of regions")
    if all(isinstance(r, ConvexPolygon) for r in regions):
        return
    pairs = [r for r in regions if isinstance(r, tuple) and len(r) == 2]
    if len(pairs) != len(regions) or not all(
        isinstance(v, float | int) and math.isfinite(v) for r in pairs for v in r
    ):
        raise ParameterTypeError(
            f"{name} must hold polygons or finite (lower, upper) pairs [m], not a mix"
        )
    if any(low > high for low, high in pairs):
        raise InvalidParameterError(f"{name} must have lower <= upper in every interval [m]")


def region_middle(level: Level) -> FloatArray:
    """Return the middle of a level's first region [m]: an interval's, a polygon's centroid."""
    _check_levels("level", [level])
    region = level[0]
    if isinstance(region, ConvexPolygon):
        return np.array(region.centroid)
    return np.array([0.5 * (region[0] + region[1])])


def cumulative_masses(mean: FloatArray, cov: FloatArray, regions: list[Level]) -> FloatArray:
    """Return P(ξ in the union of levels 0 … L) per state (rows) and level L (columns).

    ``mean`` (n, d) [m] and ``cov`` (d, d) or (n, d, d) [m²] of ξ; d = 1 on the line.
    """
    _check_levels("regions", regions)
    mean = finite_array("mean", mean)
    if mean.ndim != 2:
        raise InvalidParameterError(f"mean must be of shape (n, d), got shape {mean.shape}")
    if not isinstance(regions[0][0], ConvexPolygon):
        cov = finite_array("cov", cov)
        if cov.shape not in ((1, 1), (len(mean), 1, 1)) or np.any(cov < 0.0):
            raise InvalidParameterError(
                f"cov must be a variance >= 0 [m²] of shape (1, 1) or (n, 1, 1) on the line, "
                f"got shape {cov.shape}"
            )
    cumulative = np.empty((len(mean), len(regions)))
    if isinstance(regions[0][0], ConvexPolygon):
        sigma = covariance_2d("cov", cov)
        kept: list[ConvexPolygon] = []
        last = None
        for level, group in enumerate(regions):
            # Only the polygons no other one contains count (nested levels change nothing);
            # once the union holds all the mass but rounding, larger unions hold it too.
            kept = maximal([*kept, *group])
            if level and (kept == last or np.all(cumulative[:, level - 1] >= 1.0 - 1e-15)):
                cumulative[:, level] = cumulative[:, level - 1]
            else:
                cumulative[:, level] = gaussian_union_mass(mean, sigma, kept)
            last = kept
    else:
        sd = np.sqrt(np.maximum(np.broadcast_to(cov, (len(mean), 1, 1))[:, 0, 0], 0.0))
        for level in range(len(regions)):
            pieces = [r for group in regions[: level + 1] for r in group]
            cumulative[:, level] = _interval_union_mass(mean[:, 0], sd, pieces)  # type: ignore[arg-type]
    return np.maximum.accumulate(np.clip(cumulative, 0.0, 1.0), axis=1)


def _interval_union_mass(
    mu: FloatArray, sd: FloatArray, pieces: list[tuple[float, float]]
) -> FloatArray:
    """P(ξ in a union of intervals) of 1-D Gaussians (a zero deviation: strictly inside)."""
    merged: list[list[float]] = []
    for low, high in sorted(pieces):
        if merged and low <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], high)
        else:
            merged.append([low, high])
    total = np.zeros(len(mu))
    exact = sd == 0.0
    safe = np.where(exact, 1.0, sd)
    for low, high in merged:
        total += np.where(
            exact, (low < mu) & (mu < high), ndtr((high - mu) / safe) - ndtr((low - mu) / safe)
        )
    return total
