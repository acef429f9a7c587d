"""The physical checks' compiled kernel (numba, cached on disk): one physics step, in place.

:func:`audit_step` is :class:`~pushrecovery.sim.mujoco.contact_audit.ContactAudit`'s work at
every physics step of a MuJoCo run, on MuJoCo's own arrays (the definitions of each check are
in :mod:`pushrecovery.sim.physical_checks`). It allocates nothing. The audit's state is packed
into a few arrays (the layouts below) because numba's dispatch costs about 60 ns an argument,
at every physics step.
"""

from __future__ import annotations

from pushrecovery.kernels.jit import hypot, njit

#: ``settings``: the cone is pyramidal (1.0) or elliptic, the light load [N], the load
#: threshold [N], the lift steps, the physics step h [s] and MuJoCo's joint-limit constraint type.
PYRAMIDAL, LIGHT, THRESHOLD, LIFT_STEPS, STEP, LIMIT_TYPE = range(6)
#: ``feet_int`` columns: the foot body, its root body, its sole points, its unloaded steps.
BODY, ROOT, POINTS, UNLOADED = range(4)
#: ``feet_float`` columns: the step's vertical load [N], its moments about the world z axis
#: through the origin [N m] and the last CoP (world xy) [m].
LOAD, MOMENT_X, MOMENT_Y, COP_X, COP_Y = range(5)
#: ``soles`` columns: the sole point in the foot frame [m], the stance interval's slip and a
#: bounce's pending travel (world xy) [m].
SOLE, SLIP, PENDING = 0, 3, 5
#: ``totals``: the run's peak vertical force [N], deepest penetration [m], friction use, largest
#: slip [m] and its foot (−1: none), joint-limit steps and physics steps.
PEAK, DEPTH, USE, MOVED, MOVED_FOOT, LIMIT_STEPS, STEPS = range(7)
#: ``geom_class``: a floor geom (the world body's); a geom of no foot; else the foot's index.
FLOOR, NO_FOOT = -2, -1


@njit(cache=True, nogil=True)
def audit_step(  # type: ignore[no-untyped-def]
    geom, dist, frame, pos, friction, address, dim, efc_force, efc_type, xpos, xmat, cvel,
    subtree_com, actuator_force, settings, geom_class, feet_int, feet_float, soles, actuators,
    totals,
):  # fmt: skip
    """Audit one physics step into ``totals`` (module docstring for the packed layouts).

    Contacts (MuJoCo's ``contact`` arrays, ``geom`` (n, 2), ``frame`` (n, 9), ``pos`` (n, 3),
    ``friction`` (n, 5), ``address``, ``dim``; ``efc_force``): a contact of the body with the
    floor (exactly one geom of class FLOOR in ``geom_class``) has the contact-frame force of
    ``mj_contactForce``: pyramidal, the normal the sum of the 2 (dim − 1) pyramid forces and
    tangent i (f_2i − f_2i+1) μ_i; elliptic, the first dim constraint forces. Its force on the
    body, world z: ± (f_n n_z + f_t1 t1_z + f_t2 t2_z) (+ when the floor is geom1: the normal
    points from geom1 to geom2). Summed per foot (its class) into LOAD [N] and its moments
    about the world z axis through the origin for the CoP; friction use ‖f_t‖/(μ f_n) of
    contacts with f_n > LIGHT [N]. The step's total and deepest penetration raise PEAK, DEPTH.

    Slip (module docstring of :mod:`~pushrecovery.sim.physical_checks`): a foot carrying at
    least THRESHOLD [N] adds to SLIP the travel over h [s] of its sole points at the velocity
    of its material point at the CoP p plus the yaw ω_z ẑ × (c − p); the velocity of a body
    point q is v + ω × (q − c_root) (``cvel`` (ω, v), ``subtree_com`` of the body's ROOT). A
    foot below the threshold counts its UNLOADED steps and, within LIFT_STEPS of its last
    load, its travel about its last CoP into PENDING, which counts once it is loaded again;
    after LIFT_STEPS its next load starts a new interval. The largest ‖slip‖ of any loaded
    foot's sole point raises MOVED (and MOVED_FOOT).

    Torques: each actuator's column 1 of ``actuators`` keeps the largest ‖actuator_force‖ over
    its limit (column 0); LIMIT_STEPS counts the steps with a constraint of LIMIT_TYPE among
    ``efc_type``.
    """
    for i in range(actuators.shape[0]):
        ratio = abs(actuator_force[i]) / actuators[i, 0]
        if ratio > actuators[i, 1]:
            actuators[i, 1] = ratio
    limit_type = int(settings[LIMIT_TYPE])
    for i in range(efc_type.shape[0]):
        if efc_type[i] == limit_type:
            totals[LIMIT_STEPS] += 1.0
            break
    count = feet_int.shape[0]
    for foot in range(count):
        feet_float[foot, LOAD] = 0.0
        feet_float[foot, MOMENT_X] = 0.0
        feet_float[foot, MOMENT_Y] = 0.0
    pyramidal, light = settings[PYRAMIDAL] != 0.0, settings[LIGHT]
    total, depth, use = 0.0, 0.0, 0.0
    for i in range(geom.shape[0]):
        first, second = geom_class[geom[i, 0]] == FLOOR, geom_class[geom[i, 1]] == FLOOR
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
            ratio = hypot(tangent1, tangent2) / (friction[i, 0] * normal)
            if ratio > use:
                use = ratio
        foot = geom_class[geom[i, 1] if first else geom[i, 0]]
        if foot >= 0:
            feet_float[foot, LOAD] += fz
            feet_float[foot, MOMENT_X] += fz * pos[i, 0]
            feet_float[foot, MOMENT_Y] += fz * pos[i, 1]
    if total > totals[PEAK]:
        totals[PEAK] = total
    if depth > totals[DEPTH]:
        totals[DEPTH] = depth
    if use > totals[USE]:
        totals[USE] = use
    threshold, lift_steps, h = settings[THRESHOLD], int(settings[LIFT_STEPS]), settings[STEP]
    moved, moved_foot = 0.0, -1
    for foot in range(count):
        load = feet_float[foot, LOAD]
        loaded = load >= threshold
        points = feet_int[foot, POINTS]
        if loaded:
            lifted = feet_int[foot, UNLOADED] >= lift_steps
            for j in range(points):
                for axis in range(2):
                    if lifted:  # a new stance: its slip counts from here
                        soles[foot, j, SLIP + axis] = 0.0
                    else:  # a bounce: the travel while unloaded counts
                        soles[foot, j, SLIP + axis] += soles[foot, j, PENDING + axis]
                    soles[foot, j, PENDING + axis] = 0.0
            feet_int[foot, UNLOADED] = 0
            feet_float[foot, COP_X] = feet_float[foot, MOMENT_X] / load
            feet_float[foot, COP_Y] = feet_float[foot, MOMENT_Y] / load
        else:
            feet_int[foot, UNLOADED] += 1
            if feet_int[foot, UNLOADED] >= lift_steps:
                continue
        body, root = feet_int[foot, BODY], feet_int[foot, ROOT]
        px, py = feet_float[foot, COP_X], feet_float[foot, COP_Y]
        wx, wy, wz = cvel[body, 0], cvel[body, 1], cvel[body, 2]
        # The foot's material point at its CoP p (on the floor, z = 0), relative to the
        # velocity's reference point c_root: v_p = v + ω × (p − c_root).
        rx = px - subtree_com[root, 0]
        ry = py - subtree_com[root, 1]
        rz = -subtree_com[root, 2]
        vx = cvel[body, 3] + wy * rz - wz * ry
        vy = cvel[body, 4] + wz * rx - wx * rz
        for j in range(points):
            # The sole point now (world xy), relative to the CoP, turned by ω_z about it.
            cx = xpos[body, 0]
            cy = xpos[body, 1]
            for axis in range(3):
                cx += xmat[body, axis] * soles[foot, j, SOLE + axis]
                cy += xmat[body, 3 + axis] * soles[foot, j, SOLE + axis]
            dx = (vx - wz * (cy - py)) * h
            dy = (vy + wz * (cx - px)) * h
            if loaded:
                soles[foot, j, SLIP] += dx
                soles[foot, j, SLIP + 1] += dy
                travel = hypot(soles[foot, j, SLIP], soles[foot, j, SLIP + 1])
                if travel > moved:
                    moved, moved_foot = travel, foot
            else:
                soles[foot, j, PENDING] += dx
                soles[foot, j, PENDING + 1] += dy
    if moved > totals[MOVED]:
        totals[MOVED] = moved
        totals[MOVED_FOOT] = moved_foot
    totals[STEPS] += 1.0
