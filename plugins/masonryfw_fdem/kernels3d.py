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
penetration). A point keeps its history (shear spring, bond) from step to step as the two ends of a 2D face pair
keep theirs: it is the last step's point nearest to it in block A's frame (within a tenth of the pair's overlap
size, each old point taken once). Names by the edges a vertex lies on would not do: aligned blocks have faces
whose edges coincide, and round-off then picks either edge from one step to the next. A block that rocks about
an edge keeps its points along that edge, a corner on a face the point at that corner; faces up to
``acos(min_cos)`` apart still pair. A block turned further (a pier toppling over its edge) has no face pair with
what it leans on: its vertices inside the other, convex, block are corner contacts (:func:`corner_forces3`), and
where an edge of it crosses an edge of the other with no vertex inside (two ridges across each other) the pair of
edges is an edge contact (:func:`edge_forces3`), so it does not pass through. A pair's overlap is clipped again only once its blocks have moved against each other by
``ContactLaw3.reclip`` of the smaller one's radius (:func:`pair_forces3`).

Rotations are integrated exactly: a block's orientation is a unit quaternion, turned each step by the rotation
of its angular velocity over the step (``exp``), its inertia turned with it (no small-rotation shortcut).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import prange

from .kernels import (
    DISSIPATED_DAMPING,
    DISSIPATED_FRICTION,
    SETTLEMENT,
    TIME,
    WORK_GRAVITY,
    WORK_SUPPORT,
    jit,
    pjit,
    settlement_rate,
    smooth_share,
)

#: The most vertices a face may have (a face pair's overlap has at most the sum of its faces').
MAX_FACE_VERTICES = 32
#: A vertex within this share of a clipping edge's length of its line is on it (inside), and vertices that close
#: are one. The faces of aligned blocks have edges that coincide; moved by the elastic settling (of order the
#: penetration, 1e-4 of a unit) and twisted by as little, two such edges cross somewhere along their length, and
#: that crossing, a contact point, jumps along the edge from step to step and takes the springs' histories with
#: it. 1e-9 (round-off only) left the drawn corner 100,000 steps from rest and the house's toothed corners
#: creeping; 1e-4 brings the drawn corner to rest in 6,000 (measured 2026-12-02).
ON_LINE = 1e-4


#: Two edges cross (an edge contact) only if the sine of their angle is at least this (5.7 degrees): nearer
#: parallel they meet along a line (the face pairs' and corners' business), and the point where they cross, ill
#: conditioned, runs along them with the round-off.
EDGE_SINE = 0.1


class Bodies3(NamedTuple):
    """The blocks as the 3D kernels see them (fixed for a run): rest centroids (block, 3), radius, vertices about
    the centroid in the rest frame (vertex, 3) block after block (``vertex_offs``), faces block after block
    (``block_faces``) as vertex lists (``face_offs``, ``face_vertices``: global vertex numbers, counter-clockwise
    seen from outside) and their blocks, masses (block,), inertia tensors about the centroid in the rest frame (block, 3, 3) and their
    inverses, support flags and settlement motions (block, 6: translation, then rotation vector, per unit t); the area a
    corner contact of each block's vertices takes (:func:`corner_forces3`) and whether the block is convex (only a
    convex block's inside is the inside of all its faces' planes); its edges block after block (``block_edges``;
    edge, 2: global vertex numbers) with the two faces each one joins (``edge_faces``), for the edge contacts."""

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
    corner_area: np.ndarray
    convex: np.ndarray
    edges: np.ndarray
    edge_faces: np.ndarray
    block_edges: np.ndarray


class Pairs3(NamedTuple):
    """The face pairs (pair, 2: face of A, face of B), their properties (pair, 3: friction coefficient, cohesion
    and tensile strength per area) and their points' histories (pair, point): whether each slot holds a point
    (1; 0: none; -1 in every slot of a pair that never had one), its place in block A's frame (pair, point, 3),
    its shear spring force (pair, point, 3), bond and normal force; and the overlap as last clipped: its point
    count (pair; -1: to clip), the points' tributary areas (pair, point) and B's pose in A's frame then (pair, 7:
    B's centroid, the relative orientation), which :func:`pair_forces3` reuses while B has moved less than
    :attr:`ContactLaw3.reclip` in A's frame. And the corner contacts (corner, 3: a vertex, its block B, the block A
    it may enter; :func:`detect_corners3`) with their friction coefficients and shear springs (corner, 3), and the
    edge contacts (edge contact, 4: an edge, its block B, an edge of A, A; :func:`detect_edges3`) with theirs."""

    faces: np.ndarray
    props: np.ndarray
    held: np.ndarray
    points: np.ndarray
    shear: np.ndarray
    bonded: np.ndarray
    normal: np.ndarray
    clipped: np.ndarray
    area: np.ndarray
    pose: np.ndarray
    corners: np.ndarray
    corner_friction: np.ndarray
    corner_shear: np.ndarray
    edges: np.ndarray
    edge_friction: np.ndarray
    edge_shear: np.ndarray


class ContactLaw3(NamedTuple):
    """Normal and tangential stiffness per area, the smallest overlap area that carries, the normal dashpot as a
    share of critical, and the motion of a pair's B in A's frame (a share of the smaller block's radius) after
    which the pair's overlap is clipped again (below it, its points stay where they were in A's frame); a corner
    contact's vertex must be this much farther from the entered block's other faces than from the face it entered
    (a vertex at an edge of A is a neighbour's, not a corner entering: :func:`corner_forces3`)."""

    kn: float
    kt: float
    min_area: float
    damping: float
    reclip: float
    margin: float


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
def quat_of_rotation(rx, ry, rz):
    """The unit quaternion ``(w, x, y, z)`` of the rotation vector ``(rx, ry, rz)`` (its angle is its length)."""
    angle = np.sqrt(rx * rx + ry * ry + rz * rz)
    if angle < 1e-300:
        return 1.0, 0.0, 0.0, 0.0
    s = np.sin(0.5 * angle) / angle
    return np.cos(0.5 * angle), s * rx, s * ry, s * rz


@jit
def rotate(q, vx, vy, vz):
    """The vector ``v`` turned by the unit quaternion ``q`` (``q v q*``)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty, vy + w * ty + z * tx - x * tz, vz + w * tz + x * ty - y * tx)


@jit
def rotate_back(q, vx, vy, vz):
    """The vector ``v`` turned by the inverse of the unit quaternion ``q`` (its conjugate)."""
    return rotate((q[0], -q[1], -q[2], -q[3]), vx, vy, vz)


@jit
def turn(q, rx, ry, rz):
    """``q`` turned in place by the rotation vector ``(rx, ry, rz)`` (world frame), normalised."""
    a0, a1, a2, a3 = quat_of_rotation(rx, ry, rz)
    b0, b1, b2, b3 = q[0], q[1], q[2], q[3]
    w = a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3
    x = a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2
    y = a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1
    z = a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0
    norm = np.sqrt(w * w + x * x + y * y + z * z)
    q[0], q[1], q[2], q[3] = w / norm, x / norm, y / norm, z / norm


@jit
def rotation_angle(q, p):
    """The angle of the rotation from ``p`` to ``q``."""
    dot = abs(q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] * p[3])
    return 2.0 * np.arccos(min(dot, 1.0))


@pjit
def place_vertices3(pos, quat, bodies, world):
    """Every vertex's position (vertex, 3) at the centroids ``pos`` and orientations ``quat``."""
    offs, local = bodies.vertex_offs, bodies.vertices
    for b in prange(pos.shape[0]):
        for k in range(offs[b], offs[b + 1]):
            x, y, z = rotate(quat[b], local[k, 0], local[k, 1], local[k, 2])
            world[k, 0], world[k, 1], world[k, 2] = pos[b, 0] + x, pos[b, 1] + y, pos[b, 2] + z


# ------------------------------------------------------------------------------------------ face geometry

@pjit
def face_frames3(world, bodies, normal, centre):
    """Every face's unit outward normal (Newell's) and vertex mean, into ``normal`` and ``centre`` (face, 3)."""
    face_offs, face_vertices = bodies.face_offs, bodies.face_vertices
    for f in prange(face_offs.size - 1):
        nx = ny = nz = 0.0
        cx = cy = cz = 0.0
        start, stop = face_offs[f], face_offs[f + 1]
        for k in range(start, stop):
            p = face_vertices[k]
            q = face_vertices[k + 1 if k + 1 < stop else start]
            nx += (world[p, 1] - world[q, 1]) * (world[p, 2] + world[q, 2])
            ny += (world[p, 2] - world[q, 2]) * (world[p, 0] + world[q, 0])
            nz += (world[p, 0] - world[q, 0]) * (world[p, 1] + world[q, 1])
            cx += world[p, 0]
            cy += world[p, 1]
            cz += world[p, 2]
        norm = np.sqrt(nx * nx + ny * ny + nz * nz)
        count = stop - start
        normal[f, 0], normal[f, 1], normal[f, 2] = nx / norm, ny / norm, nz / norm
        centre[f, 0], centre[f, 1], centre[f, 2] = cx / count, cy / count, cz / count


class Scratch(NamedTuple):
    """The work arrays of one face pair's points, made once per thread: the two projected faces, the clipped
    polygon and its next version, each with the line from every vertex on."""

    ax: np.ndarray
    ay: np.ndarray
    bx: np.ndarray
    by: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    cline: np.ndarray
    nx: np.ndarray
    ny: np.ndarray
    nline: np.ndarray


@jit
def scratch(most):
    return Scratch(np.empty(most), np.empty(most), np.empty(most), np.empty(most), np.empty(2 * most),
                   np.empty(2 * most), np.empty(2 * most, dtype=np.int64), np.empty(2 * most), np.empty(2 * most),
                   np.empty(2 * most, dtype=np.int64))


@jit
def clip_convex(w, na, nb):
    """The overlap of the convex polygons ``w.a`` (``na`` vertices) and ``w.b`` (``nb``), both counter-clockwise:
    ``a`` clipped by every edge of ``b`` (Sutherland-Hodgman), into ``w.cx``, ``w.cy``. Lines are numbered
    ``a``'s edges first (edge ``i`` from vertex ``i``), then ``b``'s; ``w.cline[k]`` is the line from vertex
    ``k`` to the next. Returns the vertex count."""
    cx, cy, cline, nx, ny, nline = w.cx, w.cy, w.cline, w.nx, w.ny, w.nline
    n = na
    for i in range(na):
        cx[i], cy[i], cline[i] = w.ax[i], w.ay[i], i
    for j in range(nb):
        if n == 0:
            break
        x0, y0 = w.bx[j], w.by[j]
        j1 = j + 1 if j + 1 < nb else 0
        ex, ey = w.bx[j1] - x0, w.by[j1] - y0
        near = ON_LINE * np.sqrt(ex * ex + ey * ey)
        on_line = near * np.sqrt(ex * ex + ey * ey)  # sp of a vertex ``near`` the clip line: on it, inside
        m = 0
        for k in range(n):
            k1 = k + 1 if k + 1 < n else 0
            sp = ex * (cy[k] - y0) - ey * (cx[k] - x0)
            sq = ex * (cy[k1] - y0) - ey * (cx[k1] - x0)
            if sp >= -on_line:
                nx[m], ny[m], nline[m] = cx[k], cy[k], cline[k]
                m += 1
            if ((sp < -on_line and sq > on_line) or (sp > on_line and sq < -on_line)) and m < nx.size:
                s = sp / (sp - sq)
                nx[m] = cx[k] + s * (cx[k1] - cx[k])
                ny[m] = cy[k] + s * (cy[k1] - cy[k])
                nline[m] = na + j if sp >= 0.0 else cline[k]
                m += 1
        n = 0
        for k in range(m):  # vertices that coincide (a corner of a on an edge of b) are one
            previous = n - 1 if n > 0 else -1
            if previous >= 0 and abs(nx[k] - cx[previous]) + abs(ny[k] - cy[previous]) <= near:
                continue
            cx[n], cy[n], cline[n] = nx[k], ny[k], nline[k]
            n += 1
        if n > 1 and abs(cx[n - 1] - cx[0]) + abs(cy[n - 1] - cy[0]) <= near:
            n -= 1
    return n


@jit
def face_pair_points(world, bodies, normal, centre, fa, fb, w, px, py, pz, gap, area):
    """The contact points of the face pair ``fa`` (block A), ``fb`` (block B) at the vertices ``world`` (their
    faces' ``normal`` and ``centre``): positions, gaps along the pair's normal (negative: penetration) and
    tributary areas. Returns the point count (0: the projections do not overlap) and the normal."""
    face_offs, face_vertices = bodies.face_offs, bodies.face_vertices
    nx, ny, nz = normal[fa, 0] - normal[fb, 0], normal[fa, 1] - normal[fb, 1], normal[fa, 2] - normal[fb, 2]
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    if norm < 1e-12:
        return 0, nx, ny, nz
    nx, ny, nz = nx / norm, ny / norm, nz / norm
    if abs(nx) < 0.9:  # t1 normal to n and to x, t2 = n x t1
        t1x, t1y, t1z = 0.0, -nz, ny
    else:
        t1x, t1y, t1z = nz, 0.0, -nx
    size = np.sqrt(t1x * t1x + t1y * t1y + t1z * t1z)
    t1x, t1y, t1z = t1x / size, t1y / size, t1z / size
    t2x, t2y, t2z = ny * t1z - nz * t1y, nz * t1x - nx * t1z, nx * t1y - ny * t1x
    sa, sb = face_offs[fa + 1] - face_offs[fa], face_offs[fb + 1] - face_offs[fb]
    ox = (centre[fa, 0] * sa + centre[fb, 0] * sb) / (sa + sb)
    oy = (centre[fa, 1] * sa + centre[fb, 1] * sb) / (sa + sb)
    oz = (centre[fa, 2] * sa + centre[fb, 2] * sb) / (sa + sb)
    for k in range(sa):
        v = face_vertices[face_offs[fa] + k]
        dx, dy, dz = world[v, 0] - ox, world[v, 1] - oy, world[v, 2] - oz
        w.ax[k], w.ay[k] = dx * t1x + dy * t1y + dz * t1z, dx * t2x + dy * t2y + dz * t2z
    for k in range(sb):  # b's vertices in reverse: counter-clockwise about n
        v = face_vertices[face_offs[fb + 1] - 1 - k]
        dx, dy, dz = world[v, 0] - ox, world[v, 1] - oy, world[v, 2] - oz
        w.bx[k], w.by[k] = dx * t1x + dy * t1y + dz * t1z, dx * t2x + dy * t2y + dz * t2z
    count = clip_convex(w, sa, sb)
    if count < 3:
        return 0, nx, ny, nz
    mx = my = 0.0
    for k in range(count):
        mx += w.cx[k]
        my += w.cy[k]
        area[k] = 0.0
    mx, my = mx / count, my / count
    for k in range(count):
        k1 = k + 1 if k + 1 < count else 0
        half_triangle = 0.25 * abs((w.cx[k] - mx) * (w.cy[k1] - my) - (w.cy[k] - my) * (w.cx[k1] - mx))
        area[k] += half_triangle
        area[k1] += half_triangle
    cos_a = normal[fa, 0] * nx + normal[fa, 1] * ny + normal[fa, 2] * nz
    cos_b = normal[fb, 0] * nx + normal[fb, 1] * ny + normal[fb, 2] * nz
    for k in range(count):
        wx = ox + w.cx[k] * t1x + w.cy[k] * t2x
        wy = oy + w.cx[k] * t1y + w.cy[k] * t2y
        wz = oz + w.cx[k] * t1z + w.cy[k] * t2z
        gap[k], px[k], py[k], pz[k] = mid_surface(normal, centre, fa, fb, cos_a, cos_b, nx, ny, nz, wx, wy, wz)
    return count, nx, ny, nz


@jit
def mid_surface(normal, centre, fa, fb, cos_a, cos_b, nx, ny, nz, wx, wy, wz):
    """The gap along the pair's normal ``n`` between the planes of faces ``fa`` and ``fb`` at the point ``w`` (its
    ``cos`` with each face's normal), and the point moved along ``n`` to midway between them."""
    h_a = (normal[fa, 0] * (centre[fa, 0] - wx) + normal[fa, 1] * (centre[fa, 1] - wy)
           + normal[fa, 2] * (centre[fa, 2] - wz)) / cos_a
    h_b = (normal[fb, 0] * (centre[fb, 0] - wx) + normal[fb, 1] * (centre[fb, 1] - wy)
           + normal[fb, 2] * (centre[fb, 2] - wz)) / cos_b
    mid = 0.5 * (h_a + h_b)
    return h_b - h_a, wx + mid * nx, wy + mid * ny, wz + mid * nz


@jit
def relative_pose(pos, quat, a, b, out):
    """B's centroid in A's frame and B's orientation relative to A's (``conj(q_a) q_b``), into ``out`` (7)."""
    out[0], out[1], out[2] = rotate_back(quat[a], pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], pos[b, 2] - pos[a, 2])
    a0, a1, a2, a3 = quat[a, 0], -quat[a, 1], -quat[a, 2], -quat[a, 3]
    b0, b1, b2, b3 = quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3]
    out[3] = a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3
    out[4] = a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2
    out[5] = a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1
    out[6] = a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0


@jit
def pose_change(now, then, radius):
    """How far B's faces have moved in A's frame between the poses ``then`` and ``now`` (:func:`relative_pose`):
    its centroid's move plus its turn's angle times its ``radius``."""
    dx, dy, dz = now[0] - then[0], now[1] - then[1], now[2] - then[2]
    return np.sqrt(dx * dx + dy * dy + dz * dz) + rotation_angle(now[3:], then[3:]) * radius


@jit
def carried_points(world, bodies, normal, centre, fa, fb, pos, quat, a, local, count, px, py, pz, gap):
    """The contact points of a face pair whose overlap is reused: its ``count`` points ``local`` (A's frame, as
    last clipped) carried by A, each moved to the mid-surface between the faces' planes as they are now, with
    its gap along the pair's normal (:func:`face_pair_points`' measure). Returns the normal."""
    nx, ny, nz = normal[fa, 0] - normal[fb, 0], normal[fa, 1] - normal[fb, 1], normal[fa, 2] - normal[fb, 2]
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    nx, ny, nz = nx / norm, ny / norm, nz / norm
    cos_a = normal[fa, 0] * nx + normal[fa, 1] * ny + normal[fa, 2] * nz
    cos_b = normal[fb, 0] * nx + normal[fb, 1] * ny + normal[fb, 2] * nz
    for k in range(count):
        x, y, z = rotate(quat[a], local[k, 0], local[k, 1], local[k, 2])
        gap[k], px[k], py[k], pz[k] = mid_surface(normal, centre, fa, fb, cos_a, cos_b, nx, ny, nz, pos[a, 0] + x,
                                                  pos[a, 1] + y, pos[a, 2] + z)
    return nx, ny, nz


# ---------------------------------------------------------------------------------------- contact law

@jit
def contact_point(fn_elastic, opening_rate, sx, sy, sz, fx, fy, fz, bonded, knp, ktp, dashpot, mu, coh, ten, dt,
                  update_history):
    """The contact law at one point, the 2D law (:func:`.kernels.contact_end`) with a shear force vector ``f``
    and the slip velocity vector ``s`` (in the contact plane): a bond breaks in tension beyond ``ten`` or at
    the first slip; a dry point that opens carries nothing; the dashpot keeps a dry point's normal force
    compressive; the shear trial is capped by Coulomb's ``mu fn (+ coh while bonded)`` on its length. Returns
    ``(open, fn, fx, fy, fz, bonded, spring, friction, damping)``."""
    friction = 0.0
    damping = 0.0
    if bonded and fn_elastic < -ten and update_history:
        bonded = 0
        friction += 0.5 * fn_elastic * fn_elastic / knp
    if not bonded and fn_elastic <= 0.0:
        if update_history:
            friction += 0.5 * (fx * fx + fy * fy + fz * fz) / ktp
            fx = fy = fz = 0.0
        return True, 0.0, fx, fy, fz, bonded, 0.0, friction, damping
    fn = fn_elastic - dashpot * opening_rate
    if not bonded and fn < 0.0:
        fn = 0.0
    if update_history:
        damping = (fn - fn_elastic) * opening_rate * dt
        fx, fy, fz = fx - ktp * dt * sx, fy - ktp * dt * sy, fz - ktp * dt * sz
        size = np.sqrt(fx * fx + fy * fy + fz * fz)
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
            share = cap / size
            fx, fy, fz = fx * share, fy * share, fz * share
    spring = 0.5 * fn_elastic * fn_elastic / knp + 0.5 * (fx * fx + fy * fy + fz * fz) / ktp
    return False, fn, fx, fy, fz, bonded, spring, friction, damping


#: Face pairs a thread takes at a time in the contact pass (its work arrays made once for them).
PAIR_BLOCK = 64
#: A point takes over the history of the last step's point nearest to it within this share of the square root
#: of its pair's overlap area.
MATCH_SHARE = 0.1


@pjit
def pair_forces3(bodies, pairs, law, motion, world, normal, centre, pair_force, pair_energy, dt, update_history):
    """Every face pair's force and moments, in parallel: ``pair_force`` (pair, 9) the force on B and the
    moments on B and on A about their centroids (A takes the opposite force), ``pair_energy`` (pair, 3) its
    stored spring energy, friction and dashpot dissipation."""
    faces, props, held, points, shear, bonded = pairs.faces, pairs.props, pairs.held, pairs.points, pairs.shear, \
        pairs.bonded
    normal_force, clipped, clipped_area, pose = pairs.normal, pairs.clipped, pairs.area, pairs.pose
    pos, vel, omega, quat = motion.pos, motion.vel, motion.omega, motion.quat
    most = held.shape[1]
    n_pair = faces.shape[0]
    for chunk in prange((n_pair + PAIR_BLOCK - 1) // PAIR_BLOCK):
        w = scratch(most)
        px, py, pz = np.empty(most), np.empty(most), np.empty(most)
        gap, area = np.empty(most), np.empty(most)
        old_held = np.empty(most, dtype=np.int64)
        old_points = np.empty((most, 3))
        old_shear = np.empty((most, 3))
        old_bonded = np.empty(most, dtype=np.int64)
        pose_now = np.empty(7)
        for f in range(chunk * PAIR_BLOCK, min(n_pair, (chunk + 1) * PAIR_BLOCK)):
            fa, fb = faces[f, 0], faces[f, 1]
            a, b = bodies.face_block[fa], bodies.face_block[fb]
            relative_pose(pos, quat, a, b, pose_now)
            reused = clipped[f] >= 0 and pose_change(pose_now, pose[f], bodies.radius[b]) <= law.reclip * min(
                bodies.radius[a], bodies.radius[b])
            if reused:  # the overlap as last clipped, its points carried by A: each keeps its own history
                count = clipped[f]
                nx, ny, nz = carried_points(world, bodies, normal, centre, fa, fb, pos, quat, a, points[f], count,
                                            px, py, pz, gap)
                for k in range(count):
                    area[k] = clipped_area[f, k]
            else:
                count, nx, ny, nz = face_pair_points(world, bodies, normal, centre, fa, fb, w, px, py, pz, gap,
                                                     area)
                total = 0.0
                for k in range(count):
                    total += area[k]
                if total <= law.min_area:
                    count = 0
                if update_history:
                    clipped[f] = count
                    for k in range(count):
                        clipped_area[f, k] = area[k]
                    for d in range(7):
                        pose[f, d] = pose_now[d]
            fresh = held[f, 0] == -1
            if not reused:  # the points as they were, for the new ones to take their histories by place
                for k in range(most):
                    old_held[k], old_bonded[k] = held[f, k], bonded[f, k]
                    for d in range(3):
                        old_points[k, d], old_shear[k, d] = points[f, k, d], shear[f, k, d]
            total = 0.0
            for k in range(count):
                total += area[k]
            reach = (MATCH_SHARE * MATCH_SHARE) * total
            m_inv = (0.0 if bodies.driven[a] else 1.0 / bodies.mass[a]) + (0.0 if bodies.driven[b] else
                                                                              1.0 / bodies.mass[b])
            fbx = fby = fbz = mbx = mby = mbz = max_ = may = maz = 0.0
            stored = friction_sum = damping_sum = 0.0
            for k in range(count):
                if reused:  # each point its own slot's history (read before the slot is written)
                    lx, ly, lz = points[f, k, 0], points[f, k, 1], points[f, k, 2]
                    fx, fy, fz = shear[f, k, 0], shear[f, k, 1], shear[f, k, 2]
                    bond = bonded[f, k]
                else:
                    lx, ly, lz = rotate_back(quat[a], px[k] - pos[a, 0], py[k] - pos[a, 1], pz[k] - pos[a, 2])
                    fx = fy = fz = 0.0
                    bond = old_bonded[0] if fresh else 0  # a new pair's points start as its joint is
                    nearest, best = -1, reach
                    for j in range(most):
                        if old_held[j] == 1:
                            dx, dy, dz = old_points[j, 0] - lx, old_points[j, 1] - ly, old_points[j, 2] - lz
                            d2 = dx * dx + dy * dy + dz * dz
                            if d2 < best:
                                nearest, best = j, d2
                    if nearest >= 0:
                        old_held[nearest] = 0  # taken
                        fx, fy, fz = old_shear[nearest, 0], old_shear[nearest, 1], old_shear[nearest, 2]
                        bond = old_bonded[nearest]
                size = np.sqrt(fx * fx + fy * fy + fz * fz)  # the spring kept in the turned plane, its length kept
                along = fx * nx + fy * ny + fz * nz
                fx, fy, fz = fx - along * nx, fy - along * ny, fz - along * nz
                turned_size = np.sqrt(fx * fx + fy * fy + fz * fz)
                if turned_size > 0.0:
                    fx, fy, fz = fx * size / turned_size, fy * size / turned_size, fz * size / turned_size
                rax, ray, raz = px[k] - pos[a, 0], py[k] - pos[a, 1], pz[k] - pos[a, 2]
                rbx, rby, rbz = px[k] - pos[b, 0], py[k] - pos[b, 1], pz[k] - pos[b, 2]
                dvx = (vel[b, 0] + omega[b, 1] * rbz - omega[b, 2] * rby) - (vel[a, 0] + omega[a, 1] * raz
                                                                           - omega[a, 2] * ray)
                dvy = (vel[b, 1] + omega[b, 2] * rbx - omega[b, 0] * rbz) - (vel[a, 1] + omega[a, 2] * rax
                                                                           - omega[a, 0] * raz)
                dvz = (vel[b, 2] + omega[b, 0] * rby - omega[b, 1] * rbx) - (vel[a, 2] + omega[a, 0] * ray
                                                                           - omega[a, 1] * rax)
                opening = dvx * nx + dvy * ny + dvz * nz
                knp, ktp = law.kn * area[k], law.kt * area[k]
                dashpot = 2.0 * law.damping * np.sqrt(knp / m_inv) if m_inv > 0.0 else 0.0
                is_open, fn, fx, fy, fz, bond, spring, friction, damping = contact_point(
                    -knp * gap[k], opening, dvx - opening * nx, dvy - opening * ny, dvz - opening * nz, fx, fy, fz,
                    bond, knp, ktp, dashpot, props[f, 0], props[f, 1] * area[k], props[f, 2] * area[k], dt,
                    update_history)
                friction_sum += friction
                damping_sum += damping
                if update_history:
                    held[f, k] = 1
                    points[f, k, 0], points[f, k, 1], points[f, k, 2] = lx, ly, lz
                    bonded[f, k] = bond
                    shear[f, k, 0], shear[f, k, 1], shear[f, k, 2] = fx, fy, fz
                    normal_force[f, k] = fn
                if is_open:
                    continue
                stored += spring
                gx, gy, gz = fn * nx + fx, fn * ny + fy, fn * nz + fz  # on B; A takes the opposite
                fbx += gx
                fby += gy
                fbz += gz
                mbx += rby * gz - rbz * gy
                mby += rbz * gx - rbx * gz
                mbz += rbx * gy - rby * gx
                max_ -= ray * gz - raz * gy
                may -= raz * gx - rax * gz
                maz -= rax * gy - ray * gx
            if update_history:
                for k in range(count, most):
                    held[f, k] = 0
                    bonded[f, k] = 0
                    normal_force[f, k] = 0.0
                    shear[f, k, 0] = shear[f, k, 1] = shear[f, k, 2] = 0.0
            pair_force[f, 0], pair_force[f, 1], pair_force[f, 2] = fbx, fby, fbz
            pair_force[f, 3], pair_force[f, 4], pair_force[f, 5] = mbx, mby, mbz
            pair_force[f, 6], pair_force[f, 7], pair_force[f, 8] = max_, may, maz
            pair_energy[f, 0], pair_energy[f, 1], pair_energy[f, 2] = stored, friction_sum, damping_sum


@jit
def corner_depth(world, bodies, normal, centre, v, a):
    """How far the vertex ``v`` is outside the convex block ``a``: the largest signed distance of ``v`` from
    ``a``'s faces' planes (negative: inside), that face, and the next largest (how far the nearest other face is)."""
    depth, second, face = -np.inf, -np.inf, -1
    for f in range(bodies.block_faces[a], bodies.block_faces[a + 1]):
        d = (normal[f, 0] * (world[v, 0] - centre[f, 0]) + normal[f, 1] * (world[v, 1] - centre[f, 1])
             + normal[f, 2] * (world[v, 2] - centre[f, 2]))
        if d > depth:
            depth, second, face = d, depth, f
        elif d > second:
            second = d
    return depth, face, second


@jit
def point_contact(bodies, law, motion, force, a, b, px, py, pz, nx, ny, nz, depth, shear, c, mu, area, dt,
                  update_history):
    """One dry contact point of B on A at ``p``: B pushed out along ``n`` (out of A) by the contact law for the
    penetration ``-depth`` over ``area``, its shear spring in ``shear[c]``. Adds the wrench to both blocks (the
    friction and dashpot dissipation to the accumulators when ``update_history``); returns the stored energy."""
    pos, vel, omega = motion.pos, motion.vel, motion.omega
    rax, ray, raz = px - pos[a, 0], py - pos[a, 1], pz - pos[a, 2]
    rbx, rby, rbz = px - pos[b, 0], py - pos[b, 1], pz - pos[b, 2]
    dvx = (vel[b, 0] + omega[b, 1] * rbz - omega[b, 2] * rby) - (vel[a, 0] + omega[a, 1] * raz - omega[a, 2] * ray)
    dvy = (vel[b, 1] + omega[b, 2] * rbx - omega[b, 0] * rbz) - (vel[a, 1] + omega[a, 2] * rax - omega[a, 0] * raz)
    dvz = (vel[b, 2] + omega[b, 0] * rby - omega[b, 1] * rbx) - (vel[a, 2] + omega[a, 0] * ray - omega[a, 1] * rax)
    opening = dvx * nx + dvy * ny + dvz * nz
    fx, fy, fz = shear[c, 0], shear[c, 1], shear[c, 2]
    along = fx * nx + fy * ny + fz * nz  # the spring kept in the contact plane
    fx, fy, fz = fx - along * nx, fy - along * ny, fz - along * nz
    knp, ktp = law.kn * area, law.kt * area
    m_inv = (0.0 if bodies.driven[a] else 1.0 / bodies.mass[a]) + (0.0 if bodies.driven[b] else 1.0 / bodies.mass[b])
    dashpot = 2.0 * law.damping * np.sqrt(knp / m_inv) if m_inv > 0.0 else 0.0
    is_open, fn, fx, fy, fz, _, spring, friction, damping = contact_point(
        -knp * depth, opening, dvx - opening * nx, dvy - opening * ny, dvz - opening * nz, fx, fy, fz, 0, knp,
        ktp, dashpot, mu, 0.0, 0.0, dt, update_history)
    if update_history:
        shear[c, 0], shear[c, 1], shear[c, 2] = fx, fy, fz
        motion.acc[DISSIPATED_FRICTION] += friction
        motion.acc[DISSIPATED_DAMPING] -= damping
    if is_open:
        return 0.0
    gx, gy, gz = fn * nx + fx, fn * ny + fy, fn * nz + fz  # on B; A takes the opposite
    force[b, 0] += gx
    force[b, 1] += gy
    force[b, 2] += gz
    force[b, 3] += rby * gz - rbz * gy
    force[b, 4] += rbz * gx - rbx * gz
    force[b, 5] += rbx * gy - rby * gx
    force[a, 0] -= gx
    force[a, 1] -= gy
    force[a, 2] -= gz
    force[a, 3] -= ray * gz - raz * gy
    force[a, 4] -= raz * gx - rax * gz
    force[a, 5] -= rax * gy - ray * gx
    return spring


@jit
def corner_forces3(bodies, pairs, law, motion, world, normal, centre, force, dt, margin, update_history):
    """Add the forces of the corner contacts to ``force``: a vertex of B inside the convex block A through one
    face (the others farther than ``margin``) is pushed out along that face's normal by the contact law at one
    point (dry: no cohesion, no tension), its area the vertex's share of B's surface (``corner_area``). Returns
    the stored spring energy; adds the friction and dashpot dissipation when ``update_history``."""
    stored = 0.0
    for c in range(pairs.corners.shape[0]):
        v, b, a = pairs.corners[c, 0], pairs.corners[c, 1], pairs.corners[c, 2]
        depth, face, second = corner_depth(world, bodies, normal, centre, v, a)
        if depth >= 0.0 or second > depth - margin:
            if update_history:
                pairs.corner_shear[c, 0] = pairs.corner_shear[c, 1] = pairs.corner_shear[c, 2] = 0.0
            continue
        stored += point_contact(bodies, law, motion, force, a, b, world[v, 0], world[v, 1], world[v, 2],
                                normal[face, 0], normal[face, 1], normal[face, 2], depth, pairs.corner_shear, c,
                                pairs.corner_friction[c], bodies.corner_area[b], dt, update_history)
    return stored


@jit
def between_normals(n1, n2, nx, ny, nz):
    """Whether ``n`` (normal to the edge the faces of normals ``n1`` and ``n2`` share) lies between them: in the
    edge's cone of outward normals (to 1e-9)."""
    c1x, c1y, c1z = n1[1] * nz - n1[2] * ny, n1[2] * nx - n1[0] * nz, n1[0] * ny - n1[1] * nx
    c2x, c2y, c2z = ny * n2[2] - nz * n2[1], nz * n2[0] - nx * n2[2], nx * n2[1] - ny * n2[0]
    return (c1x * c2x + c1y * c2y + c1z * c2z >= -1e-9
            and nx * (n1[0] + n2[0]) + ny * (n1[1] + n2[1]) + nz * (n1[2] + n2[2]) > 0.0)


@jit
def edge_crossing(world, bodies, normal, pos, eb, ea, a, margin):
    """Where edge ``eb`` of B passes edge ``ea`` of the convex block A: the signed distance between them along their
    common normal ``n`` (out of A; negative: B's edge is inside A), ``n`` and the mid-point of their closest points.
    ``valid`` only where the closest points are inside both edges, farther than ``margin`` from their ends (a
    vertex on or near the other's edge is a neighbour's touch, as for :func:`corner_forces3`: without it, the kit's
    corner building had six such touches, units' corners on the edges of the ground segments beside theirs, which
    took 3.6 % of its weight off its interfaces at 10 mm), and ``n`` is an
    outward normal of A at ``ea`` and ``-n`` one of B at ``eb`` (the edges' cones of normals: then no face of
    either block is nearer)."""
    p0, p1 = bodies.edges[eb, 0], bodies.edges[eb, 1]
    q0, q1 = bodies.edges[ea, 0], bodies.edges[ea, 1]
    ux, uy, uz = world[p1, 0] - world[p0, 0], world[p1, 1] - world[p0, 1], world[p1, 2] - world[p0, 2]
    wx, wy, wz = world[q1, 0] - world[q0, 0], world[q1, 1] - world[q0, 1], world[q1, 2] - world[q0, 2]
    nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    size = np.sqrt(nx * nx + ny * ny + nz * nz)
    uu, ww, uw = ux * ux + uy * uy + uz * uz, wx * wx + wy * wy + wz * wz, ux * wx + uy * wy + uz * wz
    if size <= EDGE_SINE * np.sqrt(uu * ww):  # (nearly) parallel: a line, the face pairs' and corners' business
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    rx, ry, rz = world[p0, 0] - world[q0, 0], world[p0, 1] - world[q0, 1], world[p0, 2] - world[q0, 2]
    ur, wr = ux * rx + uy * ry + uz * rz, wx * rx + wy * ry + wz * rz
    den = uu * ww - uw * uw
    s = (uw * wr - ww * ur) / den
    t = (uu * wr - uw * ur) / den
    reach_s, reach_t = margin / np.sqrt(uu), margin / np.sqrt(ww)
    if not (reach_s < s < 1.0 - reach_s and reach_t < t < 1.0 - reach_t):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    nx, ny, nz = nx / size, ny / size, nz / size
    qx, qy, qz = world[q0, 0] + t * wx, world[q0, 1] + t * wy, world[q0, 2] + t * wz
    if nx * (qx - pos[a, 0]) + ny * (qy - pos[a, 1]) + nz * (qz - pos[a, 2]) < 0.0:
        nx, ny, nz = -nx, -ny, -nz
    fa0, fa1 = bodies.edge_faces[ea, 0], bodies.edge_faces[ea, 1]
    fb0, fb1 = bodies.edge_faces[eb, 0], bodies.edge_faces[eb, 1]
    if not (between_normals(normal[fa0], normal[fa1], nx, ny, nz)
            and between_normals(normal[fb0], normal[fb1], -nx, -ny, -nz)):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    px, py, pz = world[p0, 0] + s * ux, world[p0, 1] + s * uy, world[p0, 2] + s * uz
    depth = (px - qx) * nx + (py - qy) * ny + (pz - qz) * nz
    return True, depth, nx, ny, nz, 0.5 * (px + qx), 0.5 * (py + qy), 0.5 * (pz + qz)


@jit
def edge_forces3(bodies, pairs, law, motion, world, normal, force, dt, update_history):
    """Add the forces of the edge contacts to ``force``: where an edge of B has gone into the convex block A past
    one of A's edges (:func:`edge_crossing`), B is pushed out along their common normal at the mid-point of their
    closest points by the contact law at one point (dry), its area the smaller of the two blocks' corner areas.
    Returns the stored spring energy; adds the friction and dashpot dissipation when ``update_history``."""
    stored = 0.0
    for c in range(pairs.edges.shape[0]):
        eb, b, ea, a = pairs.edges[c, 0], pairs.edges[c, 1], pairs.edges[c, 2], pairs.edges[c, 3]
        valid, depth, nx, ny, nz, px, py, pz = edge_crossing(world, bodies, normal, motion.pos, eb, ea, a,
                                                             law.margin)
        if not valid or depth >= 0.0:
            if update_history:
                pairs.edge_shear[c, 0] = pairs.edge_shear[c, 1] = pairs.edge_shear[c, 2] = 0.0
            continue
        stored += point_contact(bodies, law, motion, force, a, b, px, py, pz, nx, ny, nz, depth, pairs.edge_shear,
                                c, pairs.edge_friction[c], min(bodies.corner_area[a], bodies.corner_area[b]), dt,
                                update_history)
    return stored


@jit
def contact_forces3(bodies, pairs, law, motion, world, normal, centre, pair_force, pair_energy, force, dt,
                    update_history):
    """Add the contact forces and moments (block, 6) of every face pair to ``force`` (:func:`pair_forces3`, then
    summed in pair order: the same sums on any number of threads). Returns the stored spring energy, and adds
    the friction and dashpot dissipation to the accumulators when ``update_history``."""
    face_frames3(world, bodies, normal, centre)
    pair_forces3(bodies, pairs, law, motion, world, normal, centre, pair_force, pair_energy, dt, update_history)
    stored = 0.0
    for f in range(pairs.faces.shape[0]):
        a, b = bodies.face_block[pairs.faces[f, 0]], bodies.face_block[pairs.faces[f, 1]]
        for d in range(3):
            force[b, d] += pair_force[f, d]
            force[a, d] -= pair_force[f, d]
            force[b, 3 + d] += pair_force[f, 3 + d]
            force[a, 3 + d] += pair_force[f, 6 + d]
        stored += pair_energy[f, 0]
        if update_history:
            motion.acc[DISSIPATED_FRICTION] += pair_energy[f, 1]
            motion.acc[DISSIPATED_DAMPING] -= pair_energy[f, 2]
    return (stored + corner_forces3(bodies, pairs, law, motion, world, normal, centre, force, dt, law.margin,
                                    update_history)
            + edge_forces3(bodies, pairs, law, motion, world, normal, force, dt, update_history))


# ----------------------------------------------------------------------------------------- time steps

@jit
def damped(f, v, damping):
    """Cundall's local damping: ``f`` reduced by ``damping |f|`` against the velocity ``v``."""
    if v > 0.0:
        return f - damping * abs(f)
    if v < 0.0:
        return f + damping * abs(f)
    return f


@pjit
def step_blocks(bodies, motion, loading, stepping, force, load_share, rate_now, settlement):
    """One velocity and position update of every block, in parallel: driven blocks follow their settlement
    motion, free ones their unbalanced force and moment (Euler's equations in the block's frame, so its
    inertia turns with it), each world component damped (Cundall). Returns the work of the supports and of the
    loads, and the damping's dissipation."""
    pos, quat, vel, omega = motion.pos, motion.quat, motion.vel, motion.omega
    dt, damping = stepping.dt, stepping.damping
    load, direction = loading.load, bodies.direction
    work_support = 0.0
    work_load = 0.0
    dissipated = 0.0
    for i in prange(pos.shape[0]):
        if bodies.driven[i]:
            for d in range(3):
                v = rate_now * direction[i, d]
                w = rate_now * direction[i, 3 + d]
                work_support -= (force[i, d] * v + force[i, 3 + d] * w) * dt
                vel[i, d] = v
                omega[i, d] = w
                pos[i, d] = bodies.pos0[i, d] + settlement * direction[i, d]
            q0, q1, q2, q3 = quat_of_rotation(settlement * direction[i, 3], settlement * direction[i, 4],
                                              settlement * direction[i, 5])
            quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3] = q0, q1, q2, q3
            continue
        for d in range(3):
            applied = load_share * load[i, d]
            total = damped(force[i, d] + applied, vel[i, d], damping)
            dissipated += (force[i, d] + applied - total) * vel[i, d] * dt
            vel[i, d] += dt * total / bodies.mass[i]
            work_load += applied * vel[i, d] * dt
        mx = damped(force[i, 3] + load_share * load[i, 3], omega[i, 0], damping)
        my = damped(force[i, 4] + load_share * load[i, 4], omega[i, 1], damping)
        mz = damped(force[i, 5] + load_share * load[i, 5], omega[i, 2], damping)
        for d in range(3):
            applied = load_share * load[i, 3 + d]
            dissipated += (force[i, 3 + d] + applied - (mx, my, mz)[d]) * omega[i, d] * dt
            work_load += applied * omega[i, d] * dt
        wx, wy, wz = rotate_back(quat[i], omega[i, 0], omega[i, 1], omega[i, 2])  # in the block's frame
        tx, ty, tz = rotate_back(quat[i], mx, my, mz)
        inertia, inverse = bodies.inertia[i], bodies.inv_inertia[i]
        lx = inertia[0, 0] * wx + inertia[0, 1] * wy + inertia[0, 2] * wz
        ly = inertia[1, 0] * wx + inertia[1, 1] * wy + inertia[1, 2] * wz
        lz = inertia[2, 0] * wx + inertia[2, 1] * wy + inertia[2, 2] * wz
        rx, ry, rz = tx - (wy * lz - wz * ly), ty - (wz * lx - wx * lz), tz - (wx * ly - wy * lx)
        ax = inverse[0, 0] * rx + inverse[0, 1] * ry + inverse[0, 2] * rz
        ay = inverse[1, 0] * rx + inverse[1, 1] * ry + inverse[1, 2] * rz
        az = inverse[2, 0] * rx + inverse[2, 1] * ry + inverse[2, 2] * rz
        gx, gy, gz = rotate(quat[i], ax, ay, az)
        omega[i, 0] += dt * gx
        omega[i, 1] += dt * gy
        omega[i, 2] += dt * gz
        for d in range(3):
            pos[i, d] += dt * vel[i, d]
        turn(quat[i], dt * omega[i, 0], dt * omega[i, 1], dt * omega[i, 2])
    return work_support, work_load, dissipated


@pjit
def farthest_move3(motion, radius, moved):
    """The largest motion of a block since the last detection (centroid, plus rotation angle times radius)."""
    for i in prange(motion.pos.shape[0]):
        dx = motion.pos[i, 0] - motion.pos_detect[i, 0]
        dy = motion.pos[i, 1] - motion.pos_detect[i, 1]
        dz = motion.pos[i, 2] - motion.pos_detect[i, 2]
        moved[i] = np.sqrt(dx * dx + dy * dy + dz * dz) + rotation_angle(motion.quat[i],
                                                                           motion.quat_detect[i]) * radius[i]
    return moved.max()


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
    n_face = bodies.face_offs.size - 1
    normal, centre = np.empty((n_face, 3)), np.empty((n_face, 3))
    pair_force = np.empty((pairs.faces.shape[0], 9))
    pair_energy = np.empty((pairs.faces.shape[0], 3))
    moved = np.empty(n_block)
    dt = stepping.dt
    steps = 0
    rebuild = False
    for _ in range(n_steps):
        force[:, :] = 0.0
        place_vertices3(motion.pos, motion.quat, bodies, world)
        time = acc[TIME]
        rate_now = settlement_rate(time + 0.5 * dt, loading.rate, loading.rate_ramp, loading.start)
        contact_forces3(bodies, pairs, law, motion, world, normal, centre, pair_force, pair_energy, force, dt, True)
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
        if farthest_move3(motion, bodies.radius, moved) > stepping.half_buffer:
            rebuild = True
            break
        if loading.target > 0.0 and acc[SETTLEMENT] >= loading.target:
            break
    force[:, :] = 0.0
    place_vertices3(motion.pos, motion.quat, bodies, world)
    stored = contact_forces3(bodies, pairs, law, motion, world, normal, centre, pair_force, pair_energy, force, dt,
                             False)
    kinetic = 0.0
    unbalanced = 0.0
    load_norm = 0.0
    for i in range(n_block):
        for d in range(6):
            wrench[i, d] = force[i, d] if bodies.driven[i] else 0.0
        if bodies.driven[i]:
            continue
        wx, wy, wz = rotate_back(motion.quat[i], motion.omega[i, 0], motion.omega[i, 1], motion.omega[i, 2])
        inertia = bodies.inertia[i]
        spin = (wx * (inertia[0, 0] * wx + inertia[0, 1] * wy + inertia[0, 2] * wz)
                + wy * (inertia[1, 0] * wx + inertia[1, 1] * wy + inertia[1, 2] * wz)
                + wz * (inertia[2, 0] * wx + inertia[2, 1] * wy + inertia[2, 2] * wz))
        kinetic += 0.5 * bodies.mass[i] * (motion.vel[i, 0] ** 2 + motion.vel[i, 1] ** 2 + motion.vel[i, 2] ** 2) \
            + 0.5 * spin
        for d in range(3):
            unbalanced += abs(force[i, d] + loading.load[i, d])
            load_norm += abs(loading.load[i, d])
    return steps, rebuild, kinetic, stored, unbalanced / load_norm if load_norm > 0.0 else 0.0


# ------------------------------------------------------------------------------------------- detection

@jit
def detect_face_pairs3(bodies, world, block_pairs, buffer, max_penetration, min_cos):
    """Face pairs of the candidate block pairs ``(k, 2)``: faces anti-parallel within ``acos(min_cos)`` whose
    projections overlap, with gaps between ``-max_penetration`` and ``buffer``. Returns (pair, 2) faces."""
    first_face = bodies.block_faces
    n_face = bodies.face_offs.size - 1
    normal, centre = np.empty((n_face, 3)), np.empty((n_face, 3))
    face_frames3(world, bodies, normal, centre)
    most = 2 * MAX_FACE_VERTICES
    w = scratch(most)
    px, py, pz = np.empty(most), np.empty(most), np.empty(most)
    gap, area = np.empty(most), np.empty(most)
    out = []
    for i in range(block_pairs.shape[0]):
        a, b = block_pairs[i, 0], block_pairs[i, 1]
        for fa in range(first_face[a], first_face[a + 1]):
            for fb in range(first_face[b], first_face[b + 1]):
                if normal[fa] @ normal[fb] > -min_cos:
                    continue
                count, _, _, _ = face_pair_points(world, bodies, normal, centre, fa, fb, w, px, py, pz, gap, area)
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


@jit
def detect_corners3(bodies, world, block_pairs, joined, buffer, max_penetration, margin):
    """Corner contacts (corner, 3: vertex, its block, the other block) of the candidate block pairs ``(k, 2)`` that
    have no face pair (``joined[i]`` false): each vertex of one block within ``buffer`` outside the other,
    convex, block (or inside it by less than ``max_penetration``) through one of its faces (the others farther than
    ``margin``: :func:`corner_forces3`)."""
    n_face = bodies.face_offs.size - 1
    normal, centre = np.empty((n_face, 3)), np.empty((n_face, 3))
    face_frames3(world, bodies, normal, centre)
    out = []
    for i in range(block_pairs.shape[0]):
        if joined[i]:
            continue
        for side in range(2):
            b, a = block_pairs[i, side], block_pairs[i, 1 - side]
            if not bodies.convex[a] or (bodies.driven[a] and bodies.driven[b]):
                continue
            for v in range(bodies.vertex_offs[b], bodies.vertex_offs[b + 1]):
                depth, _, second = corner_depth(world, bodies, normal, centre, v, a)
                if -max_penetration < depth < buffer and second <= depth - margin:
                    out.append((v, b, a))
    corners = np.empty((len(out), 3), dtype=np.int64)
    for i in range(len(out)):
        corners[i, 0], corners[i, 1], corners[i, 2] = out[i]
    return corners


@jit
def detect_edges3(bodies, world, pos, block_pairs, joined, buffer, max_penetration, margin):
    """Edge contacts (edge contact, 4: an edge of B, B, an edge of A, A) of the candidate block pairs ``(k, 2)`` that
    have no face pair (``joined[i]`` false), both convex: each pair of their edges that pass within ``buffer`` of
    each other (or into A by less than ``max_penetration``) where :func:`edge_crossing` finds them facing (``pos``:
    the blocks' centroids; ``margin``: its)."""
    n_face = bodies.face_offs.size - 1
    normal, centre = np.empty((n_face, 3)), np.empty((n_face, 3))
    face_frames3(world, bodies, normal, centre)
    out = []
    for i in range(block_pairs.shape[0]):
        b, a = block_pairs[i, 0], block_pairs[i, 1]
        if joined[i] or not (bodies.convex[a] and bodies.convex[b]):
            continue
        for eb in range(bodies.block_edges[b], bodies.block_edges[b + 1]):
            for ea in range(bodies.block_edges[a], bodies.block_edges[a + 1]):
                valid, depth, _, _, _, _, _, _ = edge_crossing(world, bodies, normal, pos, eb, ea, a, margin)
                if valid and -max_penetration < depth < buffer:
                    out.append((eb, b, ea, a))
    edges = np.empty((len(out), 4), dtype=np.int64)
    for i in range(len(out)):
        edges[i, 0], edges[i, 1], edges[i, 2], edges[i, 3] = out[i]
    return edges
