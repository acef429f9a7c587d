"""The whole-body controller's compiled kernels (numba, cached on disk): its QP, in place.

Plain array functions for :mod:`pushrecovery.control.wbc` (the QP's assembly and
least-distance form, :mod:`~pushrecovery.control.wbc.qp` and
:mod:`~pushrecovery.control.wbc.least_distance`; the ankle tasks' rows,
:mod:`~pushrecovery.control.wbc.controller`; the joint guard's rows,
:mod:`~pushrecovery.control.wbc.limits.joint_guard`). Every kernel writes into buffers the
caller allocated once; none allocates more than an index vector.

Over 400 lines on purpose: numba's disk cache is keyed by the file of each function, and the
kernels call one another (``assemble_rows`` runs ``sole_frames``, ``add_rows`` and
``constraints``; ``least_distance`` runs ``transform_rows``; ``balance_point`` runs
``rotation_vector``): one group, one file.

The QP min ½ xᵀ H x + fᵀ x s.t. l ≤ A x ≤ u reaches DAQP in its least-distance form
(Arnström, Bemporad & Axehill 2022; docs/humanoid3d_wbc.md, "The QP"): with H = Rᵀ R,
v = R⁻ᵀ f and u = R x + v, min ½‖u‖² s.t. l + M v ≤ M u ≤ u + M v, M = A R⁻¹,
x = R⁻¹ (u − v). DAQP's own dense update costs ~60 µs at the G1's 47 unknowns; here H is
factored on its *envelope* (row j zero left of ``first[j]``, which the Cholesky factor keeps):
outside the floating base, the waist and a swinging leg H is diagonal, so the factorisation
and M cost little more than reading A.
"""

from __future__ import annotations

import math

import numpy as np

from pushrecovery.kernels.jit import njit

#: Bounds at or beyond this magnitude are infinite for DAQP: never shifted.
INF = 1e30
#: Reassociation and contraction only (no assumption on NaN or infinities): the rounding
#: differs from a strict loop at the 1e-16 level, the results are deterministic.
_FAST = {"reassoc", "contract"}


@njit(cache=True, nogil=True, fastmath=_FAST)
def add_task(hessian, linear, matrix, target, weight):  # type: ignore[no-untyped-def]
    """Add W AᵀA to ``hessian`` and −W Aᵀb to ``linear``, skipping A's zero entries."""
    add_rows(hessian, linear, matrix, target, np.full(matrix.shape[0], weight), matrix.shape[0])


@njit(cache=True, nogil=True, fastmath=_FAST)
def add_rows(hessian, linear, matrix, target, weights, count):  # type: ignore[no-untyped-def]
    """:func:`add_task` of the first ``count`` rows, row r weighted by ``weights[r]``.

    Stacked tasks in one call (each entry of H and f takes its terms in row order, one sum per
    entry: no reduction the compiler could reorder).
    """
    index = np.empty(matrix.shape[1], dtype=np.int64)
    for r in range(count):
        count = 0
        for j in range(matrix.shape[1]):
            if matrix[r, j] != 0.0:
                index[count] = j
                count += 1
        for a in range(count):
            i = index[a]
            scaled = weights[r] * matrix[r, i]
            linear[i] -= scaled * target[r]
            for c in range(count):
                j = index[c]
                hessian[i, j] += scaled * matrix[r, j]


@njit(cache=True, nogil=True, fastmath=_FAST)
def constraints(  # type: ignore[no-untyped-def]
    mass, qfrc_bias, qfrc_passive, jac, jac_dot, local, qvel, contacts, unactuated, actuated,
    gear, ctrl_low, ctrl_high, foot_rows, foot_start, damping, rows, upper, lower, offset,
):  # fmt: skip
    """Write the constraint rows of the QP (``WholeBodyQP``) into ``rows``; return their count.

    Row order: the unactuated rows of the dynamics M q̈ − J_cᵀ w = −h; per foot, six rows
    J_i q̈ = −J̇_i q̇ − k_c J_i q̇ (in contact) or w_i = 0 (swinging); the wrench rows G_i w_i ≤ 0
    of each foot in contact; the motors' (M_a q̈ + h_a − J_aᵀ w)/gear within the ctrl range.
    ``offset`` receives h_a/gear. ``foot_rows`` stacks every foot's G, foot i's rows from
    ``foot_start[i]`` to ``foot_start[i + 1]``.
    """
    nv, size = mass.shape[0], rows.shape[1]
    nf = size - nv
    count = 0
    # Loops, not slices: each slice makes an array view (and its reference count) per row.
    for r in range(unactuated.shape[0]):
        k = unactuated[r]
        for j in range(nv):
            rows[count, j] = mass[k, j]
        for j in range(nf):
            rows[count, nv + j] = -local[j, k]
        upper[count] = lower[count] = qfrc_passive[k] - qfrc_bias[k]
        count += 1
    for i in range(contacts.shape[0]):
        for r in range(6 * i, 6 * i + 6):
            for j in range(size):
                rows[count, j] = 0.0
            if contacts[i]:
                for j in range(nv):
                    rows[count, j] = jac[r, j]
                drift = 0.0
                for j in range(nv):
                    drift += jac[r, j] * qvel[j]
                upper[count] = lower[count] = -jac_dot[r] - damping * drift
            else:
                rows[count, nv + r] = 1.0
                upper[count] = lower[count] = 0.0
            count += 1
    for i in range(contacts.shape[0]):
        if not contacts[i]:
            continue
        for g in range(foot_start[i], foot_start[i + 1]):
            for j in range(size):
                rows[count, j] = 0.0
            for j in range(6):
                rows[count, nv + 6 * i + j] = foot_rows[g, j]
            upper[count], lower[count] = 0.0, -INF
            count += 1
    for r in range(actuated.shape[0]):
        k, scale = actuated[r], gear[r]
        for j in range(nv):
            rows[count, j] = mass[k, j] / scale
        for j in range(nf):
            rows[count, nv + j] = -local[j, k] / scale
        offset[r] = (qfrc_bias[k] - qfrc_passive[k]) / scale
        upper[count] = min(ctrl_high[r] - offset[r], INF)
        lower[count] = max(ctrl_low[r] - offset[r], -INF)
        count += 1
    return count


@njit(cache=True, nogil=True, fastmath=_FAST)
def assemble_rows(  # type: ignore[no-untyped-def]
    matrix, target, weights, tasks, damping, xmat, bodies, dots, qvel, regular, mass, qfrc_bias,
    qfrc_passive, contacts, unactuated, actuated, gear, ctrl_low, ctrl_high, foot_rows,
    foot_start, jac, jac_dot, local, hessian, linear, rows, upper, lower, offset,
):  # fmt: skip
    """Write the whole tick's QP after MuJoCo's calls in one call; return its rows' count.

    :func:`sole_frames`, H = diag(``regular``) and f = 0, :func:`add_rows` of the first
    ``tasks`` rows of the stacked tasks, :func:`constraints`: the kernels the QP otherwise
    calls one by one, in the same order on the same arrays (the same sums, bit for bit),
    without a Python call and its argument checks between them.
    """
    sole_frames(xmat, bodies, jac, dots, qvel, jac_dot, local)
    hessian[:] = 0.0
    for j in range(regular.shape[0]):
        hessian[j, j] = regular[j]
    linear[:] = 0.0
    add_rows(hessian, linear, matrix, target, weights, tasks)
    return constraints(
        mass, qfrc_bias, qfrc_passive, jac, jac_dot, local, qvel, contacts, unactuated,
        actuated, gear, ctrl_low, ctrl_high, foot_rows, foot_start, damping, rows, upper, lower,
        offset,
    )  # fmt: skip


@njit(cache=True, nogil=True)
def commands(product, offset, low, high, ctrl):  # type: ignore[no-untyped-def]
    """Write the motor commands A_a x + h_a/gear, clipped to [low, high], into ``ctrl``.

    ``product`` is A_a x (NumPy's dot: BLAS's sums, kept). Returns whether every command was
    strictly inside (low, high) before the clip (False for a NaN). No fast-math: one add and
    two comparisons per motor, as NumPy's ``+``, ``maximum`` and ``minimum`` round them.
    """
    inside = True
    for r in range(ctrl.shape[0]):
        value = product[r] + offset[r]
        inside = inside and low[r] < value < high[r]
        if value < low[r]:  # np.maximum(value, low): value unless below (NaN kept)
            value = low[r]
        if value > high[r]:  # np.minimum(value, high)
            value = high[r]
        ctrl[r] = value
    return inside


@njit(cache=True, nogil=True, fastmath=_FAST)
def least_distance(  # type: ignore[no-untyped-def]
    hessian, linear, rows, upper, lower, count, factor, first, shift, out_rows, out_upper,
    out_lower,
):  # fmt: skip
    """Factor H = L Lᵀ on its envelope; write M = A L⁻ᵀ, l + M v, u + M v (module docstring).

    ``factor`` receives L, ``first`` each row's first non-zero column, ``shift`` v = L⁻¹ f.
    Only the first ``count`` rows of ``rows`` are read. Returns False when H is not positive
    definite (or not finite).
    """
    n = hessian.shape[0]
    for j in range(n):
        k = 0
        while k < j and hessian[j, k] == 0.0:
            k += 1
        first[j] = k
    for j in range(n):  # row-wise envelope Cholesky: L_jk for first[j] ≤ k ≤ j
        factor[j, : first[j]] = 0.0
        for k in range(first[j], j + 1):
            total = hessian[j, k]
            for p in range(max(first[j], first[k]), k):
                total -= factor[j, p] * factor[k, p]
            if k < j:
                factor[j, k] = total / factor[k, k]
            elif total > 0.0 and math.isfinite(total):
                factor[j, j] = math.sqrt(total)
            else:
                return False
        factor[j, j + 1 :] = 0.0
    _forward(factor, first, linear.reshape(1, n), shift.reshape(1, n), 0)
    transform_rows(factor, first, shift, rows, upper, lower, 0, count, out_rows, out_upper,
                   out_lower)  # fmt: skip
    return True


@njit(cache=True, nogil=True, fastmath=_FAST)
def transform_rows(  # type: ignore[no-untyped-def]
    factor, first, shift, rows, upper, lower, start, stop, out_rows, out_upper, out_lower
):
    """Write rows ``start`` to ``stop`` of M = A L⁻ᵀ, l + M v, u + M v (after the factor)."""
    n = factor.shape[0]
    for r in range(start, stop):
        _forward(factor, first, rows, out_rows, r)
        moved = 0.0
        for j in range(n):
            moved += out_rows[r, j] * shift[j]
        out_upper[r] = upper[r] + moved if upper[r] < INF else upper[r]
        out_lower[r] = lower[r] + moved if lower[r] > -INF else lower[r]


@njit(cache=True, nogil=True, fastmath=_FAST)
def _forward(factor, first, rhs, out, r):  # type: ignore[no-untyped-def]
    """Solve L y = rhs[r] for y (into ``out[r]``), L lower triangular on its envelope ``first``.

    Row r of 2-D arrays, not a row's view: a view per row costs its reference count. A zero
    ``total`` skips its division: 0 / L_jj is that zero, sign included (L_jj > 0, finite), and
    most of A's entries are zeros (the G1's: 78 %).
    """
    for j in range(rhs.shape[1]):
        total = rhs[r, j]
        for k in range(first[j], j):
            total -= factor[j, k] * out[r, k]
        out[r, j] = total / factor[j, j] if total != 0.0 else total


@njit(cache=True, nogil=True, fastmath=_FAST)
def recover(factor, first, shift, solution, x):  # type: ignore[no-untyped-def]
    """Write x = L⁻ᵀ (u − v) for DAQP's ``solution`` u (module docstring)."""
    n = x.shape[0]
    for j in range(n):
        x[j] = solution[j] - shift[j]
    for j in range(n - 1, -1, -1):  # Lᵀ x = y, column j of Lᵀ is row j of L
        x[j] /= factor[j, j]
        for k in range(first[j], j):
            x[k] -= factor[j, k] * x[j]


@njit(cache=True, nogil=True, fastmath=_FAST)
def sole_origins(xpos, xmat, bodies, origins, out):  # type: ignore[no-untyped-def]
    """Write each sole frame's origin x_b + R_b o_b [m] (world) into ``out`` (n, 3)."""
    for i in range(bodies.shape[0]):
        b = bodies[i]
        for r in range(3):
            out[i, r] = xpos[b, r] + (
                xmat[b, 3 * r] * origins[i, 0]
                + xmat[b, 3 * r + 1] * origins[i, 1]
                + xmat[b, 3 * r + 2] * origins[i, 2]
            )


@njit(cache=True, nogil=True, fastmath=_FAST)
def sole_frames(xmat, bodies, jac, dots, qvel, jac_dot, local):  # type: ignore[no-untyped-def]
    """Write J̇ q̇ (from ``dots`` = J̇) and the sole-frame Jacobian Rᵀ J of each foot."""
    nv = jac.shape[1]
    for r in range(jac.shape[0]):
        total = 0.0
        for j in range(nv):
            total += dots[r, j] * qvel[j]
        jac_dot[r] = total
    for i in range(bodies.shape[0]):
        b = bodies[i]
        for block in (6 * i, 6 * i + 3):
            for a in range(3):  # row a of Rᵀ J: Σ_c R[c, a] J[c]
                for j in range(nv):
                    local[block + a, j] = (
                        xmat[b, a] * jac[block, j]
                        + xmat[b, 3 + a] * jac[block + 1, j]
                        + xmat[b, 6 + a] * jac[block + 2, j]
                    )


@njit(cache=True, nogil=True)
def rotation_vector(rot, ref, out):  # type: ignore[no-untyped-def]
    """Write the rotation vector (axis × angle) [rad] of R R₀ᵀ (both row-major, 9) into ``out``.

    No fast-math: the controller's Python formula before, operation for operation.
    """
    trace = (rot[0] * ref[0] + rot[1] * ref[1] + rot[2] * ref[2] + rot[3] * ref[3]
             + rot[4] * ref[4] + rot[5] * ref[5] + rot[6] * ref[6] + rot[7] * ref[7]
             + rot[8] * ref[8])  # fmt: skip
    cosine = 0.5 * (trace - 1.0)
    cosine = cosine if cosine < 1.0 else 1.0  # min(1.0, ·), NaN → 1
    cosine = cosine if cosine > -1.0 else -1.0  # max(-1.0, ·)
    angle = math.acos(cosine)
    scale = 0.5 if angle < 1e-9 else 0.5 * angle / math.sin(angle)
    # (R R₀ᵀ)_21 − (R R₀ᵀ)_12, (R R₀ᵀ)_02 − (R R₀ᵀ)_20, (R R₀ᵀ)_10 − (R R₀ᵀ)_01
    x = rot[6] * ref[3] + rot[7] * ref[4] + rot[8] * ref[5] - (
        rot[3] * ref[6] + rot[4] * ref[7] + rot[5] * ref[8])  # fmt: skip
    y = rot[0] * ref[6] + rot[1] * ref[7] + rot[2] * ref[8] - (
        rot[6] * ref[0] + rot[7] * ref[1] + rot[8] * ref[2])  # fmt: skip
    z = rot[3] * ref[0] + rot[4] * ref[1] + rot[5] * ref[2] - (
        rot[0] * ref[3] + rot[1] * ref[4] + rot[2] * ref[5])  # fmt: skip
    out[0], out[1], out[2] = x * scale, y * scale, z * scale


@njit(cache=True, nogil=True)
def balance_point(  # type: ignore[no-untyped-def]
    xmat, torso, upright, com, vel, omega, gain, rest, normals, offsets, out
):
    """Write the torso's error, the capture point and the DCM law's CoP; return if inside.

    ``out`` receives (e (3) of :func:`rotation_vector` of the torso's ``xmat`` row against
    ``upright``, ξ = c + ċ/ω (2), p = ξ + gain (ξ − ``rest``) (2)) from the CoM ``com`` and
    its velocity ``vel`` (world, rows of MuJoCo's subtree arrays: body 0). Returns whether p is
    strictly inside the polygon n·p ≤ b (``normals``, ``offsets``), finite. No fast-math: the
    rounding of the Python floats of ``capture_point`` and ``ConvexPolygon`` before.
    """
    rotation_vector(xmat[torso], upright, out)
    inv = 1.0 / omega
    xi_x, xi_y = com[0, 0] + vel[0, 0] * inv, com[0, 1] + vel[0, 1] * inv
    cop_x, cop_y = xi_x + gain * (xi_x - rest[0]), xi_y + gain * (xi_y - rest[1])
    out[3], out[4], out[5], out[6] = xi_x, xi_y, cop_x, cop_y
    if not (math.isfinite(cop_x) and math.isfinite(cop_y)):
        return False
    excess = -math.inf
    for e in range(offsets.shape[0]):
        value = normals[e, 0] * cop_x + normals[e, 1] * cop_y - offsets[e]
        if value > excess:
            excess = value
    return excess < 0.0


@njit(cache=True, nogil=True, fastmath=_FAST)
def ankle_targets(  # type: ignore[no-untyped-def]
    xmat, bodies, mass, com, cop, offset, omega2, gravity, error, jacp, jacr, dots, qvel, qpos,
    posture, height, torso_z, gains, upright, stack, targets,
):  # fmt: skip
    """Write the ankle controller's task rows and targets (``WholeBodyController``).

    ``stack`` (≥ nv rows of the QP's size, zeros beyond what is written here) receives the
    tasks' rows in the order of the targets: the CoM's R_i[:2] / m on each foot's force
    columns (2), the torso's J_r (3) and the pelvis's J_z (1) on the q̈ columns (the posture's
    identity rows below are the caller's, constant); ``targets`` receives, in order, the
    CoM's ω² (c − p − δ) − g_xy [m/s²] (2), the torso's α = −k_R e − d_R ω − J̇_r q̇
    [rad/s²] (3), the pelvis's k_z (z_0 − z) − d_z ż − J̇_z q̇ [m/s²] (1) and the posture's
    k_q (q_0 − q) − d_q q̇ [rad/s²] (nv − 6), with ``gains`` = (k_R, d_R, k_z, d_z, k_q, d_q).
    ``jacp``, ``jacr`` and ``dots`` (6, nv: J̇_p, J̇_r) are the torso's. Returns whether |e|
    [rad] and |ω| [rad/s] are both below ``upright``.
    """
    nv = qvel.shape[0]
    for i in range(bodies.shape[0]):
        b = bodies[i]
        for a in range(2):
            for c in range(3):
                stack[a, nv + 6 * i + c] = xmat[b, 3 * a + c] / mass
    stack[2:5, :nv] = jacr
    stack[5, :nv] = jacp[2]
    for a in range(2):
        targets[a] = omega2 * (com[a] - cop[a] - offset[a]) - gravity[a]
    spin2, error2 = 0.0, 0.0
    for a in range(3):
        spin, drift = 0.0, 0.0
        for j in range(nv):
            spin += jacr[a, j] * qvel[j]
            drift += dots[3 + a, j] * qvel[j]
        targets[2 + a] = -gains[0] * error[a] - gains[1] * spin - drift
        spin2 += spin * spin
        error2 += error[a] * error[a]
    rise, drift = 0.0, 0.0
    for j in range(nv):
        rise += jacp[2, j] * qvel[j]
        drift += dots[2, j] * qvel[j]
    targets[5] = gains[2] * (height - torso_z) - gains[3] * rise - drift
    for j in range(nv - 6):
        targets[6 + j] = gains[4] * (posture[j] - qpos[7 + j]) - gains[5] * qvel[6 + j]
    return math.sqrt(error2) < upright and math.sqrt(spin2) < upright


@njit(cache=True, nogil=True)
def guard_rows(qpos, qvel, joints, edges, settings, stack, targets, weights, start):  # type: ignore[no-untyped-def]
    """Write the joint guard's rows (``JointGuard.task_rows``) from row ``start``.

    ``joints`` (n, 2): each joint's qpos and dof address; ``edges`` (n, 2) its (low, high);
    ``settings`` (T, k, d, W). A row: q̈_dof (zeros, 1 at the dof), its target, W. Returns the
    rows' end. No fast-math: ``task_rows``' Python floats, operation for operation (``min(v,
    0.0)`` is v unless 0.0 < v, ``max`` likewise).
    """
    horizon, stiffness, damping, weight = settings[0], settings[1], settings[2], settings[3]
    count = start
    for i in range(joints.shape[0]):
        q, v = qpos[joints[i, 0]], qvel[joints[i, 1]]
        slow, fast = 0.0 if 0.0 < v else v, 0.0 if 0.0 > v else v  # min(v, 0), max(v, 0)
        if q + horizon * slow < edges[i, 0]:
            gap = edges[i, 0] - q
            target = stiffness * (0.0 if 0.0 > gap else gap) - damping * slow
        elif q + horizon * fast > edges[i, 1]:
            gap = edges[i, 1] - q
            target = stiffness * (0.0 if 0.0 < gap else gap) - damping * fast
        else:
            continue
        stack[count] = 0.0
        stack[count, joints[i, 1]] = 1.0
        targets[count], weights[count] = target, weight
        count += 1
    return count
