"""Numba kernels of rigid polyhedra (3D): face-pair contacts, the contact law at a point, exact rotations, time
steps. The 2D kernels' counterpart (:mod:`.kernels`), in the same non-dimensional units and with the same
accumulators.

Contact model (face pairs, as in 2D): two nearly anti-parallel faces of neighbouring blocks, face ``fa`` of block
A and face ``fb`` of block B. The pair's normal ``n`` bisects their outward normals (from A into B); ``t1``,
``t2`` span the plane normal to it through ``o``, the mean of the two faces' vertices. Both faces are projected
onto that plane and the projection of ``fa`` is clipped by that of ``fb`` (Sutherland-Hodgman, both convex): the
overlap polygon. Each of its vertices is a contact point with a tributary area (half of each triangle of the fan
from the polygon's centre that it bounds, so the points of a face pair share its overlap area and its stiffness
grows with the overlap), and its gap is the distance along ``n`` between the two faces' planes there (negative:
penetration). A vertex is named by the two lines it lies on (edges of ``fa`` or of ``fb``): the name holds while
the faces slide, so a point's history (shear spring, bond) follows it from step to step, as the two ends of a 2D
face pair keep theirs. A block that rocks about an edge keeps its points along that edge, a corner on a face the
point at that corner; faces up to ``acos(min_cos)`` apart still pair, so a rotated block does not pass through.

Rotations are integrated exactly: a block's orientation is a unit quaternion, turned each step by the rotation
of its angular velocity over the step (``exp``), its inertia turned with it (no small-rotation shortcut).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .kernels import (
    DISSIPATED_DAMPING,
    DISSIPATED_FRICTION,
    SETTLEMENT,
    TIME,
    WORK_GRAVITY,
    WORK_SUPPORT,
    jit,
    settlement_rate,
    smooth_share,
)

#: The most vertices a face may have (a face pair's overlap has at most the sum of its faces').
MAX_FACE_VERTICES = 32


class Bodies3(NamedTuple):
    """The blocks as the 3D kernels see them (fixed for a run): rest centroids (block, 3), radius, vertices about
    the centroid in the rest frame (vertex, 3) block after block (``vertex_offs``), faces block after block
    (``block_faces``) as vertex lists (``face_offs``, ``face_vertices``: global vertex numbers, counter-clockwise
    seen from outside) and their blocks, masses (block,), inertia tensors about the centroid in the rest frame (block, 3, 3) and their
    inverses, support flags and settlement motions (block, 6: translation, then rotation vector, per unit t)."""

    pos0: np.ndarray
    radius: np.ndarray
    vertices: np.ndarray
    vertex_offs: np.ndarray
    block_faces: np.ndarray
    face_offs: np.ndarray
    face_vertices: np.ndarray
    face_block: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    inv_inertia: np.ndarray
    driven: np.ndarray
    moving: np.ndarray
    direction: np.ndarray


class Pairs3(NamedTuple):
    """The face pairs (pair, 2: face of A, face of B), their properties (pair, 3: friction coefficient, cohesion
    and tensile strength per area) and their points' histories (pair, point): each point's name (-1: none), shear
    spring force (pair, point, 3), bond and normal force."""

    faces: np.ndarray
    props: np.ndarray
    keys: np.ndarray
    shear: np.ndarray
    bonded: np.ndarray
    normal: np.ndarray


class ContactLaw3(NamedTuple):
    """Normal and tangential stiffness per area, the smallest overlap area that carries, the normal dashpot as a
    share of critical."""

    kn: float
    kt: float
    min_area: float
    damping: float


class Motion3(NamedTuple):
    """What the steps change: centroids (block, 3), orientations (block, 4: unit quaternions ``w, x, y, z``),
    velocities and angular velocities (block, 3, world frame), the centroids and orientations at the last
    detection, the accumulators ``acc`` (:mod:`.kernels`' indices)."""

    pos: np.ndarray
    quat: np.ndarray
    vel: np.ndarray
    omega: np.ndarray
    pos_detect: np.ndarray
    quat_detect: np.ndarray
    acc: np.ndarray


class Loading3(NamedTuple):
    """The loads (block, 6: force and moment about the centroid) with the smooth ramp of the first
    ``load_ramp``, and the settlement: ``rate`` ramped in over ``rate_ramp`` from ``start``, up to ``target``
    (0: none)."""

    load: np.ndarray
    load_ramp: float
    rate: float
    rate_ramp: float
    start: float
    target: float


class Stepping3(NamedTuple):
    """The time step, Cundall's local damping, the motion that asks for a new detection."""

    dt: float
    damping: float
    half_buffer: float


# ----------------------------------------------------------------------------------------------- rotations

@jit
def quat_multiply(a, b):
    """The quaternion product ``a b`` (the rotation ``b`` first, then ``a``)."""
    return np.array([a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                     a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                     a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                     a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]])


@jit
def quat_of_rotation(rx, ry, rz):
    """The unit quaternion of the rotation vector ``(rx, ry, rz)`` (its angle is the vector's length)."""
    angle = np.sqrt(rx * rx + ry * ry + rz * rz)
    if angle < 1e-300:
        return np.array([1.0, 0.0, 0.0, 0.0])
    s = np.sin(0.5 * angle) / angle
    return np.array([np.cos(0.5 * angle), s * rx, s * ry, s * rz])


@jit
def rotation_matrix(q):
    """The rotation matrix of the unit quaternion ``q``."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return np.array([[1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
                     [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
                     [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)]])


@jit
def turned(q, rx, ry, rz):
    """``q`` turned by the rotation vector ``(rx, ry, rz)`` (world frame), normalised."""
    out = quat_multiply(quat_of_rotation(rx, ry, rz), q)
    return out / np.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2 + out[3] ** 2)


@jit
def rotation_angle(q, p):
    """The angle of the rotation from ``p`` to ``q``."""
    dot = abs(q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] * p[3])
    return 2.0 * np.arccos(min(dot, 1.0))


@jit
def place_vertices3(pos, quat, bodies, world):
    """Every vertex's position (vertex, 3) at the centroids ``pos`` and orientations ``quat``."""
    offs, local = bodies.vertex_offs, bodies.vertices
    for b in range(pos.shape[0]):
        r = rotation_matrix(quat[b])
        for k in range(offs[b], offs[b + 1]):
            for d in range(3):
                world[k, d] = pos[b, d] + r[d, 0] * local[k, 0] + r[d, 1] * local[k, 1] + r[d, 2] * local[k, 2]


# ------------------------------------------------------------------------------------------ face geometry

@jit
def face_normal_centre(world, face_offs, face_vertices, f):
    """The unit outward normal (Newell's) and the vertex mean of face ``f``."""
    nx = ny = nz = 0.0
    cx = cy = cz = 0.0
    start, stop = face_offs[f], face_offs[f + 1]
    for k in range(start, stop):
        p = world[face_vertices[k]]
        q = world[face_vertices[k + 1 if k + 1 < stop else start]]
        nx += (p[1] - q[1]) * (p[2] + q[2])
        ny += (p[2] - q[2]) * (p[0] + q[0])
        nz += (p[0] - q[0]) * (p[1] + q[1])
        cx += p[0]
        cy += p[1]
        cz += p[2]
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    count = stop - start
    return np.array([nx / norm, ny / norm, nz / norm]), np.array([cx / count, cy / count, cz / count])


@jit
def plane_axes(n):
    """Two unit vectors ``t1``, ``t2`` with ``t1 x t2 = n``."""
    if abs(n[0]) < 0.9:
        t1 = np.array([0.0, -n[2], n[1]])
    else:
        t1 = np.array([n[2], 0.0, -n[0]])
    t1 /= np.sqrt(t1[0] ** 2 + t1[1] ** 2 + t1[2] ** 2)
    t2 = np.array([n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]])
    return t1, t2


@jit
def clip_convex(ax, ay, bx, by, out_x, out_y, out_line):
    """The overlap of the convex polygons ``a`` and ``b`` (both counter-clockwise), ``a`` clipped by every edge
    of ``b`` (Sutherland-Hodgman). Lines are numbered ``a``'s edges first (edge ``i`` from vertex ``i``), then
    ``b``'s; ``out_line[k]`` is the line from output vertex ``k`` to the next. Returns the vertex count."""
    na, nb = ax.size, bx.size
    cur_x = np.empty(na + nb)
    cur_y = np.empty(na + nb)
    cur_line = np.empty(na + nb, dtype=np.int64)
    n = na
    for i in range(na):
        cur_x[i], cur_y[i], cur_line[i] = ax[i], ay[i], i
    nxt_x = np.empty(na + nb)
    nxt_y = np.empty(na + nb)
    nxt_line = np.empty(na + nb, dtype=np.int64)
    for j in range(nb):
        if n == 0:
            break
        x0, y0 = bx[j], by[j]
        ex, ey = bx[(j + 1) % nb] - x0, by[(j + 1) % nb] - y0
        m = 0
        for k in range(n):
            k1 = (k + 1) % n
            sp = ex * (cur_y[k] - y0) - ey * (cur_x[k] - x0)
            sq = ex * (cur_y[k1] - y0) - ey * (cur_x[k1] - x0)
            if sp >= 0.0:
                nxt_x[m], nxt_y[m], nxt_line[m] = cur_x[k], cur_y[k], cur_line[k]
                m += 1
            if (sp >= 0.0) != (sq >= 0.0) and m < na + nb:
                s = sp / (sp - sq)
                nxt_x[m] = cur_x[k] + s * (cur_x[k1] - cur_x[k])
                nxt_y[m] = cur_y[k] + s * (cur_y[k1] - cur_y[k])
                nxt_line[m] = na + j if sp >= 0.0 else cur_line[k]
                m += 1
        n = m
        for k in range(n):
            cur_x[k], cur_y[k], cur_line[k] = nxt_x[k], nxt_y[k], nxt_line[k]
    for k in range(n):
        out_x[k], out_y[k], out_line[k] = cur_x[k], cur_y[k], cur_line[k]
    return n


@jit
def face_pair_points(world, bodies, fa, fb, px, py, pz, gap, area, key):
    """The contact points of the face pair ``fa`` (block A), ``fb`` (block B) at the vertices ``world``: their
    positions, gaps along the pair's normal (negative: penetration), tributary areas and names. Returns the
    point count (0: the projections do not overlap, or the faces are not anti-parallel) and the normal."""
    face_offs, face_vertices = bodies.face_offs, bodies.face_vertices
    na_, ca = face_normal_centre(world, face_offs, face_vertices, fa)
    nb_, cb = face_normal_centre(world, face_offs, face_vertices, fb)
    n = na_ - nb_
    norm = np.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    if norm < 1e-12:
        return 0, n
    n /= norm
    t1, t2 = plane_axes(n)
    sa, sb = face_offs[fa + 1] - face_offs[fa], face_offs[fb + 1] - face_offs[fb]
    o = (ca * sa + cb * sb) / (sa + sb)
    ax, ay = np.empty(sa), np.empty(sa)
    for k in range(sa):
        d = world[face_vertices[face_offs[fa] + k]] - o
        ax[k], ay[k] = d @ t1, d @ t2
    bx, by = np.empty(sb), np.empty(sb)
    for k in range(sb):  # b's vertices in reverse: counter-clockwise about n
        d = world[face_vertices[face_offs[fb + 1] - 1 - k]] - o
        bx[k], by[k] = d @ t1, d @ t2
    cx, cy = np.empty(sa + sb), np.empty(sa + sb)
    line = np.empty(sa + sb, dtype=np.int64)
    count = clip_convex(ax, ay, bx, by, cx, cy, line)
    if count < 3:
        return 0, n
    mx, my = cx[:count].mean(), cy[:count].mean()
    cos_a, cos_b = na_ @ n, nb_ @ n
    for k in range(count):
        area[k] = 0.0
    for k in range(count):
        k1 = (k + 1) % count
        half_triangle = 0.25 * abs((cx[k] - mx) * (cy[k1] - my) - (cy[k] - my) * (cx[k1] - mx))
        area[k] += half_triangle
        area[k1] += half_triangle
    lines = sa + sb
    for k in range(count):
        w = o + cx[k] * t1 + cy[k] * t2
        h_a = (na_ @ (ca - w)) / cos_a
        h_b = (nb_ @ (cb - w)) / cos_b
        gap[k] = h_b - h_a
        p = w + 0.5 * (h_a + h_b) * n
        px[k], py[k], pz[k] = p[0], p[1], p[2]
        key[k] = line[(k + count - 1) % count] * lines + line[k]
    return count, n


# ---------------------------------------------------------------------------------------- contact law

@jit
def contact_point(fn_elastic, opening_rate, slip, ft, bonded, knp, ktp, dashpot, mu, coh, ten, dt, update_history):
    """The contact law at one point, the 2D law (:func:`.kernels.contact_end`) with a shear force vector ``ft``
    (3, changed in place) and the slip velocity vector ``slip`` (in the contact plane): a bond breaks in
    tension beyond ``ten`` or at the first slip; a dry point that opens carries nothing; the dashpot keeps a dry
    point's normal force compressive; the shear trial is capped by Coulomb's ``mu fn (+ coh while bonded)`` on
    its length. Returns ``(open, fn, bonded, spring, friction, damping)``."""
    friction = 0.0
    damping = 0.0
    if bonded and fn_elastic < -ten and update_history:
        bonded = 0
        friction += 0.5 * fn_elastic * fn_elastic / knp
    if not bonded and fn_elastic <= 0.0:
        if update_history:
            friction += 0.5 * (ft[0] ** 2 + ft[1] ** 2 + ft[2] ** 2) / ktp
            ft[:] = 0.0
        return True, 0.0, bonded, 0.0, friction, damping
    fn = fn_elastic - dashpot * opening_rate
    if not bonded and fn < 0.0:
        fn = 0.0
    if update_history:
        damping = (fn - fn_elastic) * opening_rate * dt
        trial = ft - ktp * dt * slip
        size = np.sqrt(trial[0] ** 2 + trial[1] ** 2 + trial[2] ** 2)
        cap = mu * max(fn, 0.0) + (coh if bonded else 0.0)
        if size > cap:
            if bonded:
                bonded = 0
                if fn < 0.0:
                    friction += 0.5 * fn_elastic * fn_elastic / knp
                    fn = 0.0
                    fn_elastic = 0.0
                cap = mu * fn
            friction += cap * (size - cap) / ktp
            ft[:] = trial * (cap / size)
        else:
            ft[:] = trial
    spring = 0.5 * fn_elastic * fn_elastic / knp + 0.5 * (ft[0] ** 2 + ft[1] ** 2 + ft[2] ** 2) / ktp
    return False, fn, bonded, spring, friction, damping


@jit
def contact_forces3(bodies, pairs, law, motion, world, force, dt, update_history):
    """Add the contact forces and moments (block, 6) of every face pair to ``force``, the vertices at ``world``,
    in pair order (the same sums on any number of threads). Returns the stored spring energy, and adds the
    friction and dashpot dissipation to the accumulators when ``update_history``."""
    faces, props, keys, shear, bonded, normal = pairs
    pos, vel, omega, acc = motion.pos, motion.vel, motion.omega, motion.acc
    inv_mass = np.where(bodies.driven, 0.0, 1.0 / bodies.mass)
    most = keys.shape[1]
    px, py, pz = np.empty(most), np.empty(most), np.empty(most)
    gap, area = np.empty(most), np.empty(most)
    key = np.empty(most, dtype=np.int64)
    old_key = np.empty(most, dtype=np.int64)
    old_shear = np.empty((most, 3))
    old_bonded = np.empty(most, dtype=np.int64)
    ft = np.empty(3)
    stored = 0.0
    for f in range(faces.shape[0]):
        fa, fb = faces[f, 0], faces[f, 1]
        a, b = bodies.face_block[fa], bodies.face_block[fb]
        count, n = face_pair_points(world, bodies, fa, fb, px, py, pz, gap, area, key)
        total = 0.0
        for k in range(count):
            total += area[k]
        if total <= law.min_area:
            count = 0
        for k in range(most):  # the points by name, as they were
            old_key[k], old_bonded[k] = keys[f, k], bonded[f, k]
            for d in range(3):
                old_shear[k, d] = shear[f, k, d]
        m_inv = inv_mass[a] + inv_mass[b]
        for k in range(count):
            ft[:] = 0.0
            bond = old_bonded[0] if old_key[0] == -1 else 0  # a new pair's points start as the joint is
            for j in range(most):
                if old_key[j] == key[k]:
                    ft[:] = old_shear[j]
                    bond = old_bonded[j]
                    break
            tangential = ft[0] * n[0] + ft[1] * n[1] + ft[2] * n[2]  # keep the spring in the turned plane
            size = np.sqrt(ft[0] ** 2 + ft[1] ** 2 + ft[2] ** 2)
            ft -= tangential * n
            turned_size = np.sqrt(ft[0] ** 2 + ft[1] ** 2 + ft[2] ** 2)
            if turned_size > 0.0:
                ft *= size / turned_size
            x = np.array([px[k], py[k], pz[k]])
            ra, rb = x - pos[a], x - pos[b]
            va = vel[a] + np.cross(omega[a], ra)
            vb = vel[b] + np.cross(omega[b], rb)
            dv = vb - va
            opening = dv @ n
            slip = dv - opening * n
            knp, ktp = law.kn * area[k], law.kt * area[k]
            dashpot = 2.0 * law.damping * np.sqrt(knp / m_inv) if m_inv > 0.0 else 0.0
            is_open, fn, bond, spring, friction, damping = contact_point(
                -knp * gap[k], opening, slip, ft, bond, knp, ktp, dashpot, props[f, 0], props[f, 1] * area[k],
                props[f, 2] * area[k], dt, update_history)
            if update_history:
                keys[f, k] = key[k]
                bonded[f, k] = bond
                for d in range(3):
                    shear[f, k, d] = ft[d]
                normal[f, k] = fn
                acc[DISSIPATED_FRICTION] += friction
                acc[DISSIPATED_DAMPING] -= damping
            if is_open:
                continue
            stored += spring
            push = fn * n + ft  # on B; A takes the opposite
            moment_b = np.cross(rb, push)
            moment_a = np.cross(ra, push)
            for d in range(3):
                force[b, d] += push[d]
                force[a, d] -= push[d]
                force[b, 3 + d] += moment_b[d]
                force[a, 3 + d] -= moment_a[d]
        if update_history:
            for k in range(count, most):
                keys[f, k] = -1
                bonded[f, k] = 0
                normal[f, k] = 0.0
                for d in range(3):
                    shear[f, k, d] = 0.0
    return stored


# ----------------------------------------------------------------------------------------- time steps

@jit
def damped(f, v, damping):
    """Cundall's local damping: ``f`` reduced by ``damping |f|`` against the velocity ``v``."""
    if v > 0.0:
        return f - damping * abs(f)
    if v < 0.0:
        return f + damping * abs(f)
    return f


@jit
def step_blocks(bodies, motion, loading, stepping, force, load_share, rate_now, settlement):
    """One velocity and position update of every block: driven blocks follow their settlement motion, free ones
    their unbalanced force and moment (Euler's equations in the world frame, the inertia turned with the
    block), each component damped (Cundall). Returns the work of the supports and of the loads, and the
    damping's dissipation."""
    pos, quat, vel, omega = motion.pos, motion.quat, motion.vel, motion.omega
    dt, damping = stepping.dt, stepping.damping
    load, direction = loading.load, bodies.direction
    work_support = work_load = dissipated = 0.0
    for i in range(pos.shape[0]):
        if bodies.driven[i]:
            for d in range(3):
                v = rate_now * direction[i, d]
                w = rate_now * direction[i, 3 + d]
                work_support -= (force[i, d] * v + force[i, 3 + d] * w) * dt
                vel[i, d] = v
                omega[i, d] = w
                pos[i, d] = bodies.pos0[i, d] + settlement * direction[i, d]
            quat[i] = quat_of_rotation(settlement * direction[i, 3], settlement * direction[i, 4],
                                       settlement * direction[i, 5])
            continue
        r = rotation_matrix(quat[i])
        inertia = r @ bodies.inertia[i] @ r.T
        inv_inertia = r @ bodies.inv_inertia[i] @ r.T
        spin = inertia @ omega[i]
        gyroscopic = np.cross(omega[i], spin)
        for d in range(3):
            applied = load_share * load[i, d]
            total = damped(force[i, d] + applied, vel[i, d], damping)
            dissipated += (force[i, d] + applied - total) * vel[i, d] * dt
            vel[i, d] += dt * total / bodies.mass[i]
            work_load += applied * vel[i, d] * dt
        moment = np.empty(3)
        for d in range(3):
            applied = load_share * load[i, 3 + d]
            moment[d] = damped(force[i, 3 + d] + applied, omega[i, d], damping)
            dissipated += (force[i, 3 + d] + applied - moment[d]) * omega[i, d] * dt
            work_load += applied * omega[i, d] * dt
        omega[i] += dt * (inv_inertia @ (moment - gyroscopic))
        for d in range(3):
            pos[i, d] += dt * vel[i, d]
        quat[i] = turned(quat[i], dt * omega[i, 0], dt * omega[i, 1], dt * omega[i, 2])
    return work_support, work_load, dissipated


@jit
def farthest_move3(motion, radius):
    """The largest motion of a block since the last detection (centroid, plus rotation angle times radius)."""
    most = 0.0
    for i in range(motion.pos.shape[0]):
        d = motion.pos[i] - motion.pos_detect[i]
        moved = np.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2) + rotation_angle(motion.quat[i],
                                                                              motion.quat_detect[i]) * radius[i]
        most = max(most, moved)
    return most


@jit
def advance3(n_steps, bodies, pairs, law, motion, loading, stepping, wrench):
    """Up to ``n_steps`` explicit steps (the 2D :func:`.kernels.advance` in 3D); stops early when a block has
    moved more than ``half_buffer`` since the last detection or the settlement reached ``target``. ``wrench``
    (block, 6) receives the force and moment the masonry exerts on every support block. Returns
    ``(steps, rebuild, kinetic, stored, unbalanced)``."""
    n_block = motion.pos.shape[0]
    acc = motion.acc
    force = np.zeros((n_block, 6))
    world = np.empty_like(bodies.vertices)
    dt = stepping.dt
    steps = 0
    rebuild = False
    for _ in range(n_steps):
        force[:, :] = 0.0
        place_vertices3(motion.pos, motion.quat, bodies, world)
        time = acc[TIME]
        rate_now = settlement_rate(time + 0.5 * dt, loading.rate, loading.rate_ramp, loading.start)
        contact_forces3(bodies, pairs, law, motion, world, force, dt, True)
        load_share = smooth_share(time, loading.load_ramp)
        settlement = acc[SETTLEMENT] + rate_now * dt
        work_support, work_load, dissipated = step_blocks(bodies, motion, loading, stepping, force, load_share,
                                                          rate_now, settlement)
        acc[WORK_SUPPORT] += work_support
        acc[WORK_GRAVITY] += work_load
        acc[DISSIPATED_DAMPING] += dissipated
        acc[SETTLEMENT] = settlement
        acc[TIME] = time + dt
        steps += 1
        if farthest_move3(motion, bodies.radius) > stepping.half_buffer:
            rebuild = True
            break
        if loading.target > 0.0 and acc[SETTLEMENT] >= loading.target:
            break
    force[:, :] = 0.0
    place_vertices3(motion.pos, motion.quat, bodies, world)
    stored = contact_forces3(bodies, pairs, law, motion, world, force, dt, False)
    kinetic = 0.0
    unbalanced = 0.0
    load_norm = 0.0
    for i in range(n_block):
        for d in range(6):
            wrench[i, d] = force[i, d] if bodies.driven[i] else 0.0
        if bodies.driven[i]:
            continue
        r = rotation_matrix(motion.quat[i])
        spin = (r @ bodies.inertia[i] @ r.T) @ motion.omega[i]
        kinetic += 0.5 * bodies.mass[i] * (motion.vel[i] @ motion.vel[i]) + 0.5 * (motion.omega[i] @ spin)
        for d in range(3):
            unbalanced += abs(force[i, d] + loading.load[i, d])
            load_norm += abs(loading.load[i, d])
    return steps, rebuild, kinetic, stored, unbalanced / load_norm if load_norm > 0.0 else 0.0


# ------------------------------------------------------------------------------------------- detection

@jit
def detect_face_pairs3(bodies, world, block_pairs, buffer, max_penetration, min_cos):
    """Face pairs of the candidate block pairs ``(k, 2)``: faces anti-parallel within ``acos(min_cos)`` whose
    projections overlap, with gaps between ``-max_penetration`` and ``buffer``. Returns (pair, 2) faces."""
    face_offs, face_vertices, first_face = bodies.face_offs, bodies.face_vertices, bodies.block_faces
    most = 2 * MAX_FACE_VERTICES
    px, py, pz = np.empty(most), np.empty(most), np.empty(most)
    gap, area = np.empty(most), np.empty(most)
    key = np.empty(most, dtype=np.int64)
    out = []
    for i in range(block_pairs.shape[0]):
        a, b = block_pairs[i, 0], block_pairs[i, 1]
        for fa in range(first_face[a], first_face[a + 1]):
            na_, _ = face_normal_centre(world, face_offs, face_vertices, fa)
            for fb in range(first_face[b], first_face[b + 1]):
                nb_, _ = face_normal_centre(world, face_offs, face_vertices, fb)
                if na_ @ nb_ > -min_cos:
                    continue
                count, _ = face_pair_points(world, bodies, fa, fb, px, py, pz, gap, area, key)
                if count == 0:
                    continue
                least = gap[:count].min()
                if least < -max_penetration or least > buffer:
                    continue
                out.append((fa, fb))
    faces = np.empty((len(out), 2), dtype=np.int64)
    for i in range(len(out)):
        faces[i, 0], faces[i, 1] = out[i]
    return faces
