"""Compiled (numba, cached on disk) polygon geometry: clipping, sums, Chebyshev centres.

And the foothold region of a step in one call. One file on purpose: numba's disk cache is
keyed by the file of each function and does not see changes in the files of the functions it
calls, so kernels that call each other live together. Imported lazily (a plan clips large
regions by tens of half-planes; the real-time foothold query needs the whole pipeline
compiled).
"""

from __future__ import annotations

import math

import numpy as np

from pushrecovery.kernels.jit import hypot, njit


@njit(cache=True, nogil=True)
def clip_loop(points, normals, offsets):  # type: ignore[no-untyped-def]
    """Return the vertices of ``points`` ∩ {p : n_i · p <= b_i} (fewer than 3: empty).

    ``points`` a counter-clockwise convex loop (n, 2); one half-plane after the other, each
    keeping the vertices inside and adding the crossings of the edges that leave or enter.
    """
    size = points.shape[0] + normals.shape[0] + 1
    current = np.empty((size, 2))
    following = np.empty((size, 2))
    count = points.shape[0]
    current[:count] = points
    for k in range(normals.shape[0]):
        nx, ny, b = normals[k, 0], normals[k, 1], offsets[k]
        kept = 0
        for i in range(count):
            j = i + 1 if i + 1 < count else 0
            px, py = current[i, 0], current[i, 1]
            qx, qy = current[j, 0], current[j, 1]
            e = nx * px + ny * py - b
            f = nx * qx + ny * qy - b
            if e <= 0.0:
                following[kept, 0], following[kept, 1] = px, py
                kept += 1
            if (e < 0.0 < f) or (f < 0.0 < e):
                share = e / (e - f)
                following[kept, 0] = px + share * (qx - px)
                following[kept, 1] = py + share * (qy - py)
                kept += 1
        current, following = following, current
        count = kept
        if count < 3:
            return current[:count].copy()
    return current[:count].copy()


@njit(cache=True, nogil=True)
def minkowski_loop(shapes, counts, weights, offset):  # type: ignore[no-untyped-def]
    """Vertices of offset ⊕ Σ_k w_k P_k (shapes stacked (K, M, 2), ``counts`` rows used).

    The compiled twin of :func:`pushrecovery.ground.minkowski.minkowski_sum`: every term's
    edges from its lowest-leftmost vertex, merged by angle; parallel edges add up, repeated and
    collinear vertices are dropped (fewer than 3 vertices: no area).
    """
    total = 0
    for k in range(shapes.shape[0]):
        total += counts[k]
    edges = np.empty((total, 2))
    start = offset.copy()
    e = 0
    for k in range(shapes.shape[0]):
        w, n = weights[k], counts[k]
        if w == 0.0 or n == 0:
            continue
        low = 0
        for i in range(1, n):
            y, ly = w * shapes[k, i, 1], w * shapes[k, low, 1]
            if y < ly or (y == ly and w * shapes[k, i, 0] < w * shapes[k, low, 0]):
                low = i
        start[0] += w * shapes[k, low, 0]
        start[1] += w * shapes[k, low, 1]
        for i in range(n):
            j = (low + i) % n
            m = (j + 1) % n
            dx = w * (shapes[k, m, 0] - shapes[k, j, 0])
            dy = w * (shapes[k, m, 1] - shapes[k, j, 1])
            if dx != 0.0 or dy != 0.0:
                edges[e, 0], edges[e, 1] = dx, dy
                e += 1
    angle = np.empty(e)
    for i in range(e):
        angle[i] = math.atan2(edges[i, 1], edges[i, 0]) % (2.0 * math.pi)
    order = np.argsort(angle, kind="mergesort")  # stable, as minkowski_sum: ties in order
    points = np.empty((e, 2))
    x, y = start[0], start[1]
    count = 0
    i = 0
    while i < e:  # one vertex per group of parallel edges
        points[count, 0], points[count, 1] = x, y
        count += 1
        first = angle[order[i]]
        while i < e and angle[order[i]] - first <= 1e-13:
            x += edges[order[i], 0]
            y += edges[order[i], 1]
            i += 1
    return cleaned_loop(points[:count])


@njit(cache=True, nogil=True)
def cleaned_loop(points):  # type: ignore[no-untyped-def]
    """Drop repeated, then non-turning vertices of a convex loop (as minkowski._cleaned)."""
    n = points.shape[0]
    if n == 0:
        return points
    scale = 1.0
    for i in range(n):
        scale = max(scale, abs(points[i, 0]), abs(points[i, 1]))
    tol = 1e-12 * scale
    kept = np.empty((n, 2))
    m = 0
    for i in range(n):
        j = (i + 1) % n
        if hypot(points[j, 0] - points[i, 0], points[j, 1] - points[i, 1]) > tol:
            kept[m] = points[i]
            m += 1
    loop = kept[:m].copy()
    changed = True
    while changed and loop.shape[0] >= 3:
        n = loop.shape[0]
        keep = np.empty(n, dtype=np.bool_)
        changed = False
        for i in range(n):
            a, b, c = loop[i - 1], loop[i], loop[(i + 1) % n]
            turn = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
            keep[i] = turn > tol * scale
            changed |= not keep[i]
        if changed:
            loop = loop[keep]
    return loop


@njit(cache=True, nogil=True)
def chebyshev_centre(normals, offsets):  # type: ignore[no-untyped-def]
    """(q_x, q_y, r, ok): the largest disc n_i · q + r <= b_i in a convex polygon [m].

    The dual simplex of the LP max r: its dual, min b · y over y >= 0 with Σ y_i n_i = 0 and
    Σ y_i = 1, has a basis of three edges whose normals hold the origin in their hull; (q, r)
    are then the point equidistant from their lines, and an edge violated by it enters the
    basis (the most violated; the ratio test picks the edge that leaves). ``normals`` in
    counter-clockwise order (a ConvexPolygon's). ``ok`` is False when no start is found or the
    iterations do not converge (the caller then solves the LP another way).
    """
    m = normals.shape[0]
    # Start: edge 0, the last edge less than half a turn further round, and the next one.
    base = math.atan2(normals[0, 1], normals[0, 0])
    b = 0
    for k in range(1, m):
        turn = (math.atan2(normals[k, 1], normals[k, 0]) - base) % (2.0 * math.pi)
        if turn < math.pi:
            b = k
    c = b + 1
    if b == 0 or c >= m:
        return 0.0, 0.0, 0.0, False
    basis = np.array([0, b, c])
    matrix = np.empty((3, 3))
    for iteration in range(4 * m + 20):
        for j in range(3):
            matrix[j, 0] = normals[basis[j], 0]
            matrix[j, 1] = normals[basis[j], 1]
            matrix[j, 2] = 1.0
        rhs = np.array([offsets[basis[0]], offsets[basis[1]], offsets[basis[2]]])
        if abs(np.linalg.det(matrix)) < 1e-14:
            return 0.0, 0.0, 0.0, False
        point = np.linalg.solve(matrix, rhs)  # (q_x, q_y, r), equidistant from the three
        worst, enter = -1e-13, -1
        for k in range(m):
            slack = offsets[k] - normals[k, 0] * point[0] - normals[k, 1] * point[1] - point[2]
            if slack < worst:
                worst, enter = slack, k
        if enter < 0:
            return point[0], point[1], point[2], True
        # Ratio test: the dual weights y (Bᵀ y = (0, 0, 1)) and the entering direction u.
        weights = np.linalg.solve(matrix.T, np.array([0.0, 0.0, 1.0]))
        if iteration == 0 and weights.min() < -1e-12:
            return 0.0, 0.0, 0.0, False  # the start is not dual feasible
        column = np.array([normals[enter, 0], normals[enter, 1], 1.0])
        direction = np.linalg.solve(matrix.T, column)
        leave, best = -1, np.inf
        for j in range(3):
            if direction[j] > 1e-15:
                ratio = weights[j] / direction[j]
                if ratio < best:
                    best, leave = ratio, j
        if leave < 0:
            return 0.0, 0.0, 0.0, False
        basis[leave] = enter
    return 0.0, 0.0, 0.0, False


@njit(cache=True, nogil=True)
def foothold_kernel(shapes, counts, weights, offset, window_normals, window_offsets):  # type: ignore[no-untyped-def]
    """Return (vertices, centre_x, centre_y, ok): (S3) clipped to the window, its centre.

    The compiled path of :func:`pushrecovery.surfaces.capture.region.capture_region`, the
    centre the Chebyshev centre (the middle of the centres when the disc can slide). ``ok``
    False: the simplex failed (the caller falls back); fewer than 3 vertices: empty.
    """
    loop = minkowski_loop(shapes, counts, weights, offset)
    empty = np.empty((0, 2))
    if loop.shape[0] < 3:
        return empty, 0.0, 0.0, True
    region = cleaned_loop(clip_loop(loop, window_normals, window_offsets))
    n = region.shape[0]
    if n < 3:
        return empty, 0.0, 0.0, True
    scale = 1.0
    area = 0.0
    for i in range(n):
        j = (i + 1) % n
        area += region[i, 0] * region[j, 1] - region[j, 0] * region[i, 1]
        scale = max(scale, abs(region[i, 0]), abs(region[i, 1]))
    if 0.5 * area <= 1e-12 * scale * scale:
        return empty, 0.0, 0.0, True
    normals = np.empty((n, 2))
    offsets = np.empty(n)
    for i in range(n):
        j = (i + 1) % n
        ex, ey = region[j, 0] - region[i, 0], region[j, 1] - region[i, 1]
        length = hypot(ex, ey)
        normals[i, 0], normals[i, 1] = ey / length, -ex / length
        offsets[i] = normals[i, 0] * region[i, 0] + normals[i, 1] * region[i, 1]
    qx, qy, radius, ok = chebyshev_centre(normals, offsets)
    if not ok:
        return region, 0.0, 0.0, False
    # Held by two parallel edges, the disc can slide: the middle of its centres.
    touching = np.empty(n, dtype=np.int64)
    t = 0
    for i in range(n):
        if offsets[i] - normals[i, 0] * qx - normals[i, 1] * qy - radius < 1e-9 * scale:
            touching[t] = i
            t += 1
    for a in range(t):
        for b in range(a + 1, t):
            i, j = touching[a], touching[b]
            if normals[i, 0] * normals[j, 0] + normals[i, 1] * normals[j, 1] < -1.0 + 1e-9:
                ax, ay = -normals[i, 1], normals[i, 0]
                low, high = -np.inf, np.inf
                for k in range(n):
                    rate = normals[k, 0] * ax + normals[k, 1] * ay
                    if abs(rate) > 1e-12:
                        room = offsets[k] - normals[k, 0] * qx - normals[k, 1] * qy - radius
                        end = room / rate
                        if rate < 0.0:
                            low = max(low, end)
                        else:
                            high = min(high, end)
                middle = 0.5 * (low + high)
                return region, qx + middle * ax, qy + middle * ay, True
    return region, qx, qy, True


@njit(cache=True, nogil=True)
def decompose_loop(point, shapes, counts, weights, offset, total):  # type: ignore[no-untyped-def]
    """Decompose a point in a Minkowski sum: :func:`~pushrecovery.ground.minkowski.decompose`.

    ``shapes`` stacked (K, M, 2) with ``counts`` rows, ``total`` the sum's vertex loop.
    Returns (points (K, 2), share).
    """
    k_count = shapes.shape[0]
    centres = np.zeros((k_count, 2))
    cx, cy = offset[0], offset[1]
    for k in range(k_count):
        n = counts[k]
        for i in range(n):
            centres[k, 0] += shapes[k, i, 0] / n
            centres[k, 1] += shapes[k, i, 1] / n
        cx += weights[k] * centres[k, 0]
        cy += weights[k] * centres[k, 1]
    gx, gy = point[0] - cx, point[1] - cy
    distance = hypot(gx, gy)
    if distance == 0.0:
        return centres, 0.0
    ux, uy = gx / distance, gy / distance
    m = total.shape[0]
    reach, nx, ny = np.inf, 0.0, 0.0
    scale = 1.0
    for i in range(m):
        j = (i + 1) % m
        ex, ey = total[j, 0] - total[i, 0], total[j, 1] - total[i, 1]
        length = hypot(ex, ey)
        ax, ay = ey / length, -ex / length
        rate = ax * ux + ay * uy
        scale = max(scale, abs(total[i, 0]), abs(total[i, 1]))
        if rate > 0.0:
            ratio = (ax * total[i, 0] + ay * total[i, 1] - ax * cx - ay * cy) / rate
            if ratio < reach:
                reach, nx, ny = ratio, ax, ay
    tx, ty = -ny, nx
    bx, by = cx + reach * ux, cy + reach * uy
    faces = np.zeros((k_count, 2))
    lengths = np.zeros(k_count)
    sx, sy = offset[0], offset[1]
    for k in range(k_count):
        w, n = weights[k], counts[k]
        if w == 0.0:
            faces[k] = centres[k]
            continue
        top = -np.inf
        for i in range(n):
            top = max(top, shapes[k, i, 0] * nx + shapes[k, i, 1] * ny)
        low_along, high_along = np.inf, -np.inf
        for i in range(n):
            if shapes[k, i, 0] * nx + shapes[k, i, 1] * ny >= top - 1e-12 * scale / w:
                along = shapes[k, i, 0] * tx + shapes[k, i, 1] * ty
                if along < low_along:
                    low_along = along
                    faces[k, 0], faces[k, 1] = shapes[k, i, 0], shapes[k, i, 1]
                high_along = max(high_along, along)
        lengths[k] = high_along - low_along
        sx += w * faces[k, 0]
        sy += w * faces[k, 1]
    left = (bx - sx) * tx + (by - sy) * ty
    share = distance / reach
    s = min(share, 1.0)
    points = np.empty((k_count, 2))
    for k in range(k_count):
        w = weights[k]
        move = min(max(left, 0.0), w * lengths[k])
        left -= move
        slide = move / w if w != 0.0 else 0.0
        points[k, 0] = (1.0 - s) * centres[k, 0] + s * (faces[k, 0] + slide * tx)
        points[k, 1] = (1.0 - s) * centres[k, 1] + s * (faces[k, 1] + slide * ty)
    return points, share


@njit(cache=True, nogil=True)
def loop_signed_distance(loop, px, py):  # type: ignore[no-untyped-def]
    """Signed distance of (px, py) to a convex counter-clockwise loop [m], + inside.

    As :meth:`pushrecovery.ground.polygon.ConvexPolygon.signed_distance`: inside, the nearest
    edge line; outside, the nearest edge segment.
    """
    n = loop.shape[0]
    excess = -np.inf
    gap2 = np.inf
    for i in range(n):
        j = (i + 1) % n
        ex, ey = loop[j, 0] - loop[i, 0], loop[j, 1] - loop[i, 1]
        length = hypot(ex, ey)
        nx, ny = ey / length, -ex / length
        dx, dy = px - loop[i, 0], py - loop[i, 1]
        e = nx * dx + ny * dy
        excess = max(excess, e)
        along = (dx * ex + dy * ey) / (length * length)
        along = min(max(along, 0.0), 1.0)
        cx, cy = dx - along * ex, dy - along * ey
        gap2 = min(gap2, cx * cx + cy * cy)
    return -excess if excess <= 0.0 else -math.sqrt(gap2)
