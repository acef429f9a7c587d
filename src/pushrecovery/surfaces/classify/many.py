"""Vectorised verdicts: :func:`classify_states` for arrays of states, on a line or the plane.

The rules of :func:`pushrecovery.surfaces.classify.classify`, decided for millions of states:
on the line, the four intervals in one compiled pass; on the plane, the support polygon and the
CMP region in one compiled pass, then the N-step regions
(:class:`~pushrecovery.surfaces.step.regions.StepRegions`) only for the states beyond the hip
region, in place (numpy for small arrays), chunk by chunk, so that the extra memory is the
codes themselves.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import broadcast, finite_array, float_array, require_type
from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.polygon import ConvexPolygon
from pushrecovery.ground.support import Support
from pushrecovery.params import BodyParams
from pushrecovery.surfaces.cmp import cmp_margin, cmp_region
from pushrecovery.surfaces.cop import cop_margin, cop_region
from pushrecovery.surfaces.plane import capture_margin_xy, cmp_polygon
from pushrecovery.surfaces.step.regions import StepRegions, sagittal_step_interval
from pushrecovery.surfaces.strategy import STRATEGY_CODES, Strategy

__all__ = ["classify_states"]


def classify_states(
    x: ArrayLike,
    xdot: ArrayLike,
    params: BodyParams,
    *,
    y: ArrayLike | None = None,
    ydot: ArrayLike | None = None,
    support: Support | None = None,
) -> NDArray[np.int8]:
    """Vectorised :func:`classify`: integer codes into :data:`STRATEGY_CODES`.

    The regions decide every state without a plan (module docstring), in chunks, so the extra
    memory stays a few bytes per state. With
    ``y``, ``ydot`` or ``support`` the states are classified on the ground plane.

    Parameters
    ----------
    x, xdot : array_like
        CoM positions [m] and velocities [m/s], broadcast together.
    params : BodyParams
        Body parameters.
    y, ydot : array_like, optional
        Lateral positions [m] and velocities [m/s] (plane).
    support : Support, optional
        Stance and feet (plane; default double support).

    Returns
    -------
    ndarray of int8
        Codes of the broadcast shape.

    Raises
    ------
    InvalidParameterError
        If a state is NaN or infinite.
    """
    if y is not None or ydot is not None or support is not None:
        return _plane_codes(x, xdot, params, y, ydot, support)
    require_type("params", params, BodyParams)
    x, xdot = broadcast(x=float_array("x", x), xdot=float_array("xdot", xdot))
    codes = np.empty(x.shape, dtype=np.int8)
    if x.size == 0:
        return codes
    flat_x, flat_xdot = (np.ascontiguousarray(a).reshape(-1) for a in (x, xdot))
    flat = codes.reshape(-1)  # a view: codes is new and contiguous
    cop, hip = cop_region(params), cmp_region(params)
    step = sagittal_step_interval(params)
    if flat.size >= _CHUNK:
        from pushrecovery.kernels.plane_codes import sagittal_codes

        bad = sagittal_codes(
            flat_x,
            flat_xdot,
            1.0 / params.omega,
            cop.centre,
            cop.half_width,
            hip.centre,
            hip.half_width,
            step.centre,
            step.half_width,
            flat,
        )
        if bad:
            cop_margin(flat_x, flat_xdot, params)  # raises, naming the argument
        return codes
    cop_m, hip_m = cop_margin(flat_x, flat_xdot, params), cmp_margin(flat_x, flat_xdot, params)
    xi = flat_x + flat_xdot / params.omega
    stepping = step.half_width - np.abs(xi - step.centre) > 0.0
    flat[...] = np.where(
        cop_m > 0.0, _ANKLE, np.where(hip_m > 0.0, _HIP, np.where(stepping, _STEP, _FALL))
    )
    return codes


_ANKLE, _HIP, _STEP, _FALL = (STRATEGY_CODES.index(s) for s in Strategy)
#: States per chunk of the vectorised classifier: temporaries stay in the cache.
_CHUNK = 1 << 16
#: States per chunk of the compiled planar classifier: few thread-pool launches, and at most
#: 32 MiB of broadcast copies.
_COMPILED_CHUNK = 1 << 20


def _plane_codes(
    x: ArrayLike,
    xdot: ArrayLike,
    params: BodyParams,
    y: ArrayLike | None,
    ydot: ArrayLike | None,
    support: Support | None,
) -> NDArray[np.int8]:
    """:func:`classify_states` on the ground plane (the rules of :func:`_classify_plane`).

    Chunk by chunk: both margins (the compiled pass for large chunks), then the step test on
    the states beyond the hip region only, on their step lines.
    """
    support = Support.from_params(params) if support is None else support
    # y and ydot not given: on the x axis, at rest sideways.
    given = {"x": x, "y": 0.0 if y is None else y, "xdot": xdot,
             "ydot": 0.0 if ydot is None else ydot}  # fmt: skip
    inputs = [float_array(n, a) for n, a in given.items()]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in inputs))
    except ValueError:
        shapes = ", ".join(str(a.shape) for a in inputs)
        raise InvalidParameterError(f"x, y, xdot and ydot must broadcast, got {shapes}") from None
    size = math.prod(shape)
    codes = np.empty(shape, dtype=np.int8)
    flat_codes = codes.reshape(-1)
    hip_region = cmp_polygon(support, params)
    omega = params.omega
    if size >= _CHUNK:
        _plane_codes_compiled(inputs, shape, flat_codes, params, support, hip_region)
        return codes
    xs, ys, xds, yds = (_chunk(a, shape, slice(0, size)) for a in inputs)
    cop = capture_margin_xy(xs, ys, xds, yds, omega, support.polygon)
    hip = capture_margin_xy(xs, ys, xds, yds, omega, hip_region)
    flat_codes[...] = np.where(cop > 0.0, _ANKLE, np.where(hip > 0.0, _HIP, _FALL))
    beyond = flat_codes == _FALL
    if beyond.any():
        regions = StepRegions.of(params, support)
        px, py = xs[beyond] + xds[beyond] / omega, ys[beyond] + yds[beyond] / omega
        flat_codes[np.flatnonzero(beyond)[regions.margins(px, py) > 0.0]] = _STEP
    return codes


def _plane_codes_compiled(
    inputs: list[NDArray[np.float64]],
    shape: tuple[int, ...],
    flat_codes: NDArray[np.int8],
    params: BodyParams,
    support: Support,
    hip_region: ConvexPolygon,
) -> None:
    """Large arrays: the compiled region test, then the compiled step test, chunk by chunk."""
    from pushrecovery.kernels.plane_codes import padded_edges, plane_codes

    inv = 1.0 / params.omega
    cop_edges = padded_edges(support.polygon.edge_table)
    hip_edges = padded_edges(hip_region.edge_table)
    regions = StepRegions.of(params, support)
    for start in range(0, flat_codes.size, _COMPILED_CHUNK):
        part = slice(start, min(start + _COMPILED_CHUNK, flat_codes.size))
        xs, ys, xds, yds = (_chunk(a, shape, part) for a in inputs)
        chunk = flat_codes[part]
        beyond, bad = plane_codes(xs, ys, xds, yds, inv, cop_edges, hip_edges, chunk)
        if bad:
            for name, array in zip(("x", "y", "xdot", "ydot"), (xs, ys, xds, yds), strict=True):
                finite_array(name, array)
            raise InvalidParameterError("states are too large: the capture point overflows")
        if beyond:
            _mark_plane_steps(xs, ys, xds, yds, chunk, params, regions)


def _mark_plane_steps(
    xs: NDArray[np.float64],
    ys: NDArray[np.float64],
    xds: NDArray[np.float64],
    yds: NDArray[np.float64],
    codes: NDArray[np.int8],
    params: BodyParams,
    regions: StepRegions,
) -> None:
    """Mark ``step`` where the N-step regions hold the states coded ``fall`` (compiled)."""
    from pushrecovery.kernels.plane_codes import mark_regions

    x, y, xdot, ydot = (np.ascontiguousarray(a) for a in (xs, ys, xds, yds))
    outer = regions.outer  # their union is that of all the regions
    tables = (regions.table[outer], regions.counts[outer], regions.discs[outer])
    mark_regions(x, y, xdot, ydot, 1.0 / params.omega, *tables, codes, _FALL, _STEP)


def _chunk(array: NDArray[np.float64], shape: tuple[int, ...], part: slice) -> NDArray[np.float64]:
    """Elements ``part`` of ``array`` broadcast to ``shape`` and flattened (a copy of the part)."""
    if array.shape == shape and array.flags.c_contiguous:
        return array.reshape(-1)[part]
    if array.size == 1:
        return np.full(part.stop - part.start, float(array.reshape(-1)[0]))
    return np.ascontiguousarray(np.broadcast_to(array, shape).flat[part])
