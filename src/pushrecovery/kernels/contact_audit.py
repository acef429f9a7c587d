"""The physical checks' compiled kernel (numba, cached on disk): one physics step, in place.

:func:`audit_step` is :class:`~pushrecovery.sim.mujoco.contact_audit.ContactAudit`'s work at
every physics step of a MuJoCo run, on MuJoCo's own arrays (the definitions of each check are
in :mod:`pushrecovery.sim.physical_checks`). It allocates nothing.
"""

from __future__ import annotations

import math

import numba


@numba.njit(cache=True, nogil=True)
def audit_step(  # type: ignore[no-untyped-def]
    geom, dist, frame, pos, friction, address, dim, efc_force, efc_type, nefc, xpos, xmat,
    cvel, subtree_com, actuator_force, pyramidal, floor, geom_foot, light, threshold,
    lift_steps, h, feet, roots, soles, sole_counts, slip, pending, unloaded, cop, loads,
    moments, limits, torque_use, limit_type,
):  # fmt: skip
    """Audit one physics step: (vertical force [N], depth [m], friction use, slip, foot, limit).

    Contacts (MuJoCo's ``contact`` arrays, ``geom`` (n, 2), ``frame`` (n, 9), ``pos`` (n, 3),
    ``friction`` (n, 5), ``address``, ``dim``; ``efc_force``): a contact of the body with the
    floor (exactly one geom of the world body, ``floor``) has the contact-frame force of
    ``mj_contactForce``: pyramidal, the normal the sum of the 2 (dim − 1) pyramid forces and
    tangent i (f_2i − f_2i+1) μ_i; elliptic, the first dim constraint forces. Its force on the
    body, world z: ± (f_n n_z + f_t1 t1_z + f_t2 t2_z) (+ when the floor is geom1: the normal
    points from geom1 to geom2). Summed per foot (``geom_foot``, −1: no foot) into ``loads``
    [N] and their moments about the world z axis through the origin into ``moments`` (n_feet,
    2) [N m] for the CoP; friction use ‖f_t‖/(μ f_n) of contacts with f_n > ``light`` [N].

    Slip (module docstring of :mod:`~pushrecovery.sim.physical_checks`): a foot carrying at
    least ``threshold`` [N] adds to ``slip`` (n_feet, k, 2) the travel over ``h`` [s] of its
    sole points (``soles`` (n_feet, k, 3) in the foot frame, ``sole_counts`` of them) at the
    velocity of its material point at the CoP p plus the yaw ω_z ẑ × (c − p); the velocity of
    a body point q is v + ω × (q − c_root) (``cvel`` (ω, v), ``subtree_com`` of the body's
    root, ``roots``). A foot below the threshold counts its steps (``unloaded``) and, within
    ``lift_steps`` of its last load, its travel about its last CoP (``cop``) into ``pending``,
    which counts once it is loaded again; after ``lift_steps`` its next load starts a new
    interval. It returns the largest ‖travel‖ of any loaded foot's sole point this step and
    that foot (−1: none loaded).

    Torques: ``torque_use`` (per actuator) keeps the largest ‖actuator_force‖ / ``limits``; a
    joint is on its limit (the last value returned) when one of the first ``nefc`` constraints
    is of ``limit_type``.
    """
    for i in range(torque_use.shape[0]):
        ratio = abs(actuator_force[i]) / limits[i]
        if ratio > torque_use[i]:
            torque_use[i] = ratio
    on_limit = False
    for i in range(nefc):
        if efc_type[i] == limit_type:
            on_limit = True
            break
    count = feet.shape[0]
    for foot in range(count):
        loads[foot] = 0.0
        moments[foot, 0] = 0.0
        moments[foot, 1] = 0.0
    total, depth, use = 0.0, 0.0, 0.0
    for i in range(geom.shape[0]):
        first, second = floor[geom[i, 0]], floor[geom[i, 1]]
        if first == second:
            continue  # not a contact of the body with the floor
        if -dist[i] > depth:
            depth = -dist[i]
        a, k = address[i], dim[i]
        if a < 0:
            continue
        normal, tangent1, tangent2 = efc_force[a], 0.0, 0.0
        if pyramidal and k > 1:
            normal = 0.0
            for j in range(2 * (k - 1)):
                normal += efc_force[a + j]
            tangent1 = (efc_force[a] - efc_force[a + 1]) * friction[i, 0]
            tangent2 = (efc_force[a + 2] - efc_force[a + 3]) * friction[i, 1]
        elif k > 1:
            tangent1, tangent2 = efc_force[a + 1], efc_force[a + 2]
        sign = 1.0 if first else -1.0
        fz = sign * (normal * frame[i, 2] + tangent1 * frame[i, 5] + tangent2 * frame[i, 8])
        total += fz
        if normal > light and friction[i, 0] > 0.0:
            ratio = math.hypot(tangent1, tangent2) / (friction[i, 0] * normal)
            if ratio > use:
                use = ratio
        foot = geom_foot[geom[i, 1] if first else geom[i, 0]]
        if foot >= 0:
            loads[foot] += fz
            moments[foot, 0] += fz * pos[i, 0]
            moments[foot, 1] += fz * pos[i, 1]
    moved, moved_foot = 0.0, -1
    for foot in range(count):
        loaded = loads[foot] >= threshold
        if loaded:
            lifted = unloaded[foot] >= lift_steps
            for j in range(sole_counts[foot]):
                for axis in range(2):
                    if lifted:  # a new stance: its slip counts from here
                        slip[foot, j, axis] = 0.0
                    else:  # a bounce: the travel while unloaded counts
                        slip[foot, j, axis] += pending[foot, j, axis]
                    pending[foot, j, axis] = 0.0
            unloaded[foot] = 0
            cop[foot, 0] = moments[foot, 0] / loads[foot]
            cop[foot, 1] = moments[foot, 1] / loads[foot]
        else:
            unloaded[foot] += 1
            if unloaded[foot] >= lift_steps:
                continue
        body = feet[foot]
        root = roots[body]
        wx, wy, wz = cvel[body, 0], cvel[body, 1], cvel[body, 2]
        # The foot's material point at its CoP p (on the floor, z = 0), relative to the
        # velocity's reference point c_root: v_p = v + ω × (p − c_root).
        rx = cop[foot, 0] - subtree_com[root, 0]
        ry = cop[foot, 1] - subtree_com[root, 1]
        rz = -subtree_com[root, 2]
        vx = cvel[body, 3] + wy * rz - wz * ry
        vy = cvel[body, 4] + wz * rx - wx * rz
        for j in range(sole_counts[foot]):
            # The sole point now (world xy), relative to the CoP, turned by ω_z about it.
            cx = xpos[body, 0]
            cy = xpos[body, 1]
            for axis in range(3):
                cx += xmat[body, axis] * soles[foot, j, axis]
                cy += xmat[body, 3 + axis] * soles[foot, j, axis]
            dx = (vx - wz * (cy - cop[foot, 1])) * h
            dy = (vy + wz * (cx - cop[foot, 0])) * h
            if loaded:
                slip[foot, j, 0] += dx
                slip[foot, j, 1] += dy
                travel = math.hypot(slip[foot, j, 0], slip[foot, j, 1])
                if travel > moved:
                    moved, moved_foot = travel, foot
            else:
                pending[foot, j, 0] += dx
                pending[foot, j, 1] += dy
    return total, depth, use, moved, moved_foot, on_limit
