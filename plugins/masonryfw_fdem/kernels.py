"""Numba kernels of the rigid-block mode: contact detection, contact forces, time stepping.

Everything here works on flat float64/int64 arrays in non-dimensional units
(lengths over the characteristic length, forces over the total weight, time over
``sqrt(length / g)``), see :mod:`.scene`.

Contact model ("face pairs"): two blocks touch through a pair of nearly
anti-parallel edges, one of each block. The pair's common normal ``n`` is the
bisector of the two outward edge normals (from block A into block B), its
tangent ``t = (n_y, -n_x)``. The two edges are projected on ``t``; their overlap
``[s_lo, s_hi]`` carries two contact points, one at each end (end 0 at
``s_lo``, end 1 at ``s_hi``), each with the tributary length ``(s_hi - s_lo) / 2``
(the stiffness of an end is the contact stiffness per unit length times that length,
so the force grows with the overlap as in a potential-based, area-proportional
contact). An overlap shorter than ``2 min_half`` carries nothing: two blocks that
meet corner to corner, as the builder's aligned support ends and unit corners do,
are not in contact until their faces really overlap (the limit analysis, with its
fixed interface list, makes the same choice).
The gap at an end is the distance along ``n`` between the two edges' lines there
(negative = penetration). A block that rocks about a corner keeps a single
penetrating end at that corner, so this reduces to vertex-to-edge contact; on
flat faces it gives exactly the two interface ends of the limit analysis.
Geometry is recomputed from the current positions every step (large displacements);
the pair list itself is rebuilt only when some block has moved more than half the
detection buffer since the last detection.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

# Indices into the scalar state vector ``acc`` (accumulators carried between chunks).
TIME, SETTLEMENT, WORK_GRAVITY, WORK_SUPPORT, DISSIPATED_DAMPING, DISSIPATED_FRICTION, RELEASED = range(7)
N_ACC = 7


class Bodies(NamedTuple):
    """The blocks as the kernels see them (fixed for a run): rest positions (block, 3), radius, the
    polygons (``lx``, ``ly`` about the centroid, ``offs``), masses (block, 3) and their inverses (block,
    translation; 0 for supports), free components (block, 3), support flags and settlement directions."""

    pos0: np.ndarray
    radius: np.ndarray
    lx: np.ndarray
    ly: np.ndarray
    offs: np.ndarray
    mass: np.ndarray
    inv_mass: np.ndarray
    free: np.ndarray
    driven: np.ndarray
    moving: np.ndarray
    direction: np.ndarray


class Pairs(NamedTuple):
    """The face pairs (face, 4: block A, its edge, block B, its edge) with their properties (face, 4) and
    histories: tangential spring force, bond, normal force, spring energy (face, 2 ends) and each pair's
    forces (face, 4, kept while both blocks sleep)."""

    faces: np.ndarray
    props: np.ndarray
    shear: np.ndarray
    bonded: np.ndarray
    normal: np.ndarray
    energy: np.ndarray
    face_force: np.ndarray


class ContactLaw(NamedTuple):
    """Normal and tangential stiffness per unit length, the shortest contact's half length, the normal
    dashpot as a share of critical."""

    kn: float
    kt: float
    min_half: float
    damping: float


class EndLaw(NamedTuple):
    """The contact law of one face pair's ends (:func:`contact_end`), per unit of an end's share of the overlap:
    the normal and shear spring stiffnesses, the normal dashpot, the friction coefficient, the cohesion and
    tensile strength (bonded ends)."""

    knp: float
    ktp: float
    dashpot: float
    mu: float
    coh: float
    ten: float


class Motion(NamedTuple):
    """What the steps change: positions and velocities (block, 3), positions at the last detection,
    the active (integrated) and calm (slow steps in a row) counters, the accumulators ``acc``."""

    pos: np.ndarray
    vel: np.ndarray
    pos_detect: np.ndarray
    active: np.ndarray
    calm: np.ndarray
    acc: np.ndarray


class Loading(NamedTuple):
    """The loads (block or node, components) with the smooth ramp of the first ``load_ramp``, the added
    load ramped in from ``added_start`` over ``added_time``, and the settlement: ``rate`` ramped in over
    ``rate_ramp`` from ``start``, up to ``target`` (0: none)."""

    load: np.ndarray
    load_ramp: float
    added: np.ndarray
    added_start: float
    added_time: float
    rate: float
    rate_ramp: float
    start: float
    target: float


class Stepping(NamedTuple):
    """The time step, Cundall's local damping, the motion that asks for a new detection, and sleeping:
    the speed and the number of steps below it that put a block to sleep, the unbalanced share that wakes
    it."""

    dt: float
    damping: float
    half_buffer: float
    sleep_speed: float
    sleep_steps: int
    wake_force: float


class Report(NamedTuple):
    """What a chunk of steps ends with: the steps done, whether the pair list must be rebuilt, the kinetic
    and stored energy, the unbalanced-force ratio (the support wrenches go to the caller's array)."""

    steps: int
    rebuild: bool
    kinetic: float
    stored: float
    unbalanced: float

# error_model="numpy": float division by zero gives inf/nan instead of a checked branch (3x faster).
# Lengths are sqrt(x * x + y * y), not np.hypot: libm's hypot guards against overflow, which lengths of
# order one (non-dimensional) never reach, and it made a step of the 2,432-block wall 1.3x slower.
jit = njit(cache=True, error_model="numpy")
pjit = njit(cache=True, error_model="numpy", parallel=True)


@pjit
def place_vertices(pos, lx, ly, offs, vx, vy):
    """Current positions ``vx, vy`` of all nodes (one sine and cosine per block; blocks in parallel)."""
    for b in prange(offs.size - 1):
        c = np.cos(pos[b, 2])
        s = np.sin(pos[b, 2])
        for k in range(offs[b], offs[b + 1]):
            vx[k] = pos[b, 0] + c * lx[k] - s * ly[k]
            vy[k] = pos[b, 1] + s * lx[k] + c * ly[k]


@jit
def next_node(k, b, offs):
    return k + 1 if k + 1 < offs[b + 1] else offs[b]


@jit
def face_geometry(vx, vy, offs, a, ea, b, eb):
    """Frame, overlap and end gaps of the face pair (edge ``ea`` of ``a``, edge ``eb`` of ``b``).

    Returns ``nx, ny, ox, oy, s_lo, s_hi, gap_lo, gap_hi, h_lo, h_hi, cos_angle`` where
    ``h`` is the mid-plane height of each end (contact point ``o + s t + h n``).
    """
    ka, kb = next_node(ea, a, offs), next_node(eb, b, offs)
    ax0, ay0, ax1, ay1 = vx[ea], vy[ea], vx[ka], vy[ka]
    bx0, by0, bx1, by1 = vx[eb], vy[eb], vx[kb], vy[kb]
    la = np.sqrt((ax1 - ax0) ** 2 + (ay1 - ay0) ** 2)
    lb = np.sqrt((bx1 - bx0) ** 2 + (by1 - by0) ** 2)
    inv_a, inv_b = 1.0 / la, 1.0 / lb
    nax, nay = (ay1 - ay0) * inv_a, -(ax1 - ax0) * inv_a
    nbx, nby = (by1 - by0) * inv_b, -(bx1 - bx0) * inv_b
    cos_angle = nax * nbx + nay * nby
    nx, ny = nax - nbx, nay - nby
    nn = np.sqrt(nx * nx + ny * ny)
    if cos_angle > -0.1:  # faces at more than ~84 degrees: never a face pair
        return 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 1e300, 1e300, 0.0, 0.0, cos_angle
    nx, ny = nx / nn, ny / nn
    tx, ty = ny, -nx
    ox = 0.25 * (ax0 + ax1 + bx0 + bx1)
    oy = 0.25 * (ay0 + ay1 + by0 + by1)
    sa0 = (ax0 - ox) * tx + (ay0 - oy) * ty
    sa1 = (ax1 - ox) * tx + (ay1 - oy) * ty
    sb0 = (bx0 - ox) * tx + (by0 - oy) * ty
    sb1 = (bx1 - ox) * tx + (by1 - oy) * ty
    ha0 = (ax0 - ox) * nx + (ay0 - oy) * ny
    ha1 = (ax1 - ox) * nx + (ay1 - oy) * ny
    hb0 = (bx0 - ox) * nx + (by0 - oy) * ny
    hb1 = (bx1 - ox) * nx + (by1 - oy) * ny
    s_lo = max(min(sa0, sa1), min(sb0, sb1))
    s_hi = min(max(sa0, sa1), max(sb0, sb1))
    if s_hi < s_lo:  # no overlap: evaluate both ends at the middle of the gap between the edges
        mid = 0.5 * (s_lo + s_hi)
        e_lo, e_hi = mid, mid
    else:
        e_lo, e_hi = s_lo, s_hi
    slope_a = (ha1 - ha0) / (sa1 - sa0)
    slope_b = (hb1 - hb0) / (sb1 - sb0)
    ka_lo = ha0 + slope_a * (e_lo - sa0)
    ka_hi = ha0 + slope_a * (e_hi - sa0)
    kb_lo = hb0 + slope_b * (e_lo - sb0)
    kb_hi = hb0 + slope_b * (e_hi - sb0)
    return (nx, ny, ox, oy, s_lo, s_hi, kb_lo - ka_lo, kb_hi - ka_hi,
            0.5 * (ka_lo + kb_lo), 0.5 * (ka_hi + kb_hi), cos_angle)


@jit
def block_boxes(vx, vy, offs, margin):
    n = offs.size - 1
    box = np.empty((n, 4))
    for b in range(n):
        x0 = y0 = 1e300
        x1 = y1 = -1e300
        for k in range(offs[b], offs[b + 1]):
            x, y = vx[k], vy[k]
            x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
        box[b, 0], box[b, 1], box[b, 2], box[b, 3] = x0 - margin, x1 + margin, y0 - margin, y1 + margin
    return box


@jit
def candidate_block_pairs(box, driven):
    """Block pairs whose boxes overlap: sort by left edge, sweep (no all-pairs loop).

    Pairs of two driven blocks (supports) are left out: nothing acts between them.
    """
    order = np.argsort(box[:, 0])
    n = order.size
    out = []
    for i in range(n):
        p = order[i]
        for j in range(i + 1, n):
            q = order[j]
            if box[q, 0] > box[p, 1]:
                break
            if box[q, 2] > box[p, 3] or box[p, 2] > box[q, 3]:
                continue
            if driven[p] and driven[q]:
                continue
            out.append((min(p, q), max(p, q)))
    pairs = np.empty((len(out), 2), dtype=np.int64)
    for i in range(len(out)):
        pairs[i, 0], pairs[i, 1] = out[i]
    return pairs


@jit
def inside(vx, vy, offs, b, px, py):
    """Whether the point (px, py) lies inside block ``b``'s polygon (even-odd crossings of a ray along +x)."""
    crossings = 0
    for k in range(offs[b], offs[b + 1]):
        j = next_node(k, b, offs)
        if (vy[k] > py) != (vy[j] > py):
            x = vx[k] + (py - vy[k]) * (vx[j] - vx[k]) / (vy[j] - vy[k])
            if x > px:
                crossings += 1
    return crossings % 2 == 1


@jit
def penetrates(vx, vy, offs, a, b, g, shallow):
    """Whether each end of the face pair ``g`` (:func:`face_geometry`) whose gap is below ``-shallow`` is a true
    penetration: the point of block ``a``'s edge there inside block ``b``. Two faces at an angle whose lines cross
    (a unit's edge along an arch's extrados and a voussoir's chord two chords away) have a "gap" of tens of
    millimetres that no block overlap makes: counted, it kicked the unit out by as much."""
    nx, ny, ox, oy = g[0], g[1], g[2], g[3]
    tx, ty = ny, -nx
    mid = 0.5 * (g[4] + g[5])
    for end in range(2):
        gap = g[6 + end]
        if gap >= -shallow:
            continue
        s = g[4 + end] if g[5] >= g[4] else mid
        h = g[8 + end] - 0.5 * gap  # the edge of a: the mid-plane height less half the gap (kb - ka)
        if not inside(vx, vy, offs, b, ox + s * tx + h * nx, oy + s * ty + h * ny):
            return False
    return True


@jit
def detect_face_pairs(pos, lx, ly, offs, driven, buffer, max_penetration, min_cos):
    """Face pairs of every candidate block pair: edges anti-parallel within the angle
    ``acos(min_cos)``, overlapping (or within ``buffer`` of it) along the tangent, with
    end gaps between ``-max_penetration`` and ``buffer``, an end deeper than a tenth of the buffer only where
    it is inside the other block (:func:`penetrates`). Returns (k, 4) ``a, ea, b, eb``."""
    vx = np.empty(lx.size)
    vy = np.empty(lx.size)
    place_vertices(pos, lx, ly, offs, vx, vy)
    pairs = candidate_block_pairs(block_boxes(vx, vy, offs, buffer), driven)
    out = []
    for i in range(pairs.shape[0]):
        a, b = pairs[i, 0], pairs[i, 1]
        for ea in range(offs[a], offs[a + 1]):
            for eb in range(offs[b], offs[b + 1]):
                g = face_geometry(vx, vy, offs, a, ea, b, eb)
                if g[10] > -min_cos:
                    continue
                if g[5] - g[4] < -buffer:
                    continue
                gap_min = min(g[6], g[7])
                if gap_min < -max_penetration or gap_min > buffer:
                    continue
                if gap_min < -0.1 * buffer and not penetrates(vx, vy, offs, a, b, g, 0.1 * buffer):
                    continue
                out.append((a, ea, b, eb))
    faces = np.empty((len(out), 4), dtype=np.int64)
    for i in range(len(out)):
        faces[i, 0], faces[i, 1], faces[i, 2], faces[i, 3] = out[i]
    return faces


@jit
def face_keys(faces, n_node):
    """One int64 per face pair (its two edges), to carry contact history across rebuilds."""
    return faces[:, 1] * n_node + faces[:, 3]


@jit
def carry_history(old_keys, old_shear, old_bonded, old_energy, new_keys, new_shear, new_bonded, new_energy):
    """Copy shear forces, bond states and spring energies of face pairs present before and after
    a rebuild; returns the spring energy of the pairs the rebuild dropped."""
    order = np.argsort(new_keys)
    sorted_keys = new_keys[order]
    dropped = 0.0
    for o in range(old_keys.size):
        j = np.searchsorted(sorted_keys, old_keys[o])
        if j < sorted_keys.size and sorted_keys[j] == old_keys[o]:
            i = order[j]
            for e in range(2):
                new_shear[i, e] = old_shear[o, e]
                new_bonded[i, e] = old_bonded[o, e]
                new_energy[i, e] = old_energy[o, e]
        else:
            dropped += old_energy[o, 0] + old_energy[o, 1]
    return dropped


@jit
def wake_sleepers(bodies, pairs, law, motion, vx, vy, wake_speed):
    """Wake every sleeping block with a contact end shared with an active block that moves
    faster than ``wake_speed`` or has lost half its compression (the sleeper's support goes).

    Runs before the force loop: a block woken inside it would miss the forces of the pairs
    with other sleepers already skipped, move for one step without them, and the energy of
    those springs would change with its motion, made from nothing (the energy leak of the
    first version: 3.7 % on the small test wall, ~20 % on Facade 3).
    """
    offs, faces, normal, driven = bodies.offs, pairs.faces, pairs.normal, bodies.driven
    pos, vel, active, calm = motion.pos, motion.vel, motion.active, motion.calm
    kn, min_half = law.kn, law.min_half
    for f in range(faces.shape[0]):
        a, ea, b, eb = faces[f, 0], faces[f, 1], faces[f, 2], faces[f, 3]
        if active[a] == active[b]:
            continue
        sleeper = a if not active[a] else b
        if driven[sleeper]:
            continue
        g = face_geometry(vx, vy, offs, a, ea, b, eb)
        nx, ny, ox, oy, s_lo, s_hi = g[0], g[1], g[2], g[3], g[4], g[5]
        half = 0.5 * (s_hi - s_lo)
        if half <= min_half:
            continue
        for e in range(2):
            s = s_lo if e == 0 else s_hi
            h = g[8] if e == 0 else g[9]
            px = ox + s * ny + h * nx
            py = oy - s * nx + h * ny
            dvx = (vel[b, 0] - vel[b, 2] * (py - pos[b, 1])) - (vel[a, 0] - vel[a, 2] * (py - pos[a, 1]))
            dvy = (vel[b, 1] + vel[b, 2] * (px - pos[b, 0])) - (vel[a, 1] + vel[a, 2] * (px - pos[a, 0]))
            fn_elastic = -kn * half * (g[6] if e == 0 else g[7])
            losing = normal[f, e] > 0.0 and fn_elastic < 0.5 * normal[f, e]
            if losing or dvx * dvx + dvy * dvy > wake_speed * wake_speed:
                active[sleeper] = 1
                calm[sleeper] = 0
                break


@jit
def face_law(law, g, props_f, m_inv):
    """Half the overlap of a face pair (frame ``g``: :func:`face_geometry`) and the :class:`EndLaw` of each of
    its two ends: the stiffnesses per length times that half, the dashpot of ``contact_damping`` on the pair's
    inverse mass ``m_inv``, the interface's friction and its cohesion and tension per length times the half."""
    kn, kt, _, contact_damping = law
    half = 0.5 * (g[5] - g[4])
    knp = kn * half
    ktp = kt * half
    dashpot = 2.0 * contact_damping * np.sqrt(knp / m_inv) if m_inv > 0.0 else 0.0
    return half, EndLaw(knp, ktp, dashpot, props_f[0], props_f[1] * half, props_f[2] * half)


@jit
def end_point(g, e):
    """The contact point ``o + s t + h n`` of end ``e`` (0: low, 1: high) of a face pair (:func:`face_geometry`)
    and its gap."""
    nx, ny, ox, oy = g[0], g[1], g[2], g[3]
    tx, ty = ny, -nx
    s = g[4] if e == 0 else g[5]
    gap = g[6] if e == 0 else g[7]
    h = g[8] if e == 0 else g[9]
    return ox + s * tx + h * nx, oy + s * ty + h * ny, gap


@jit
def release_face(f, energy, shear, bonded, normal, update_history):
    """A face pair whose faces slid apart: the contact (and any bond) is gone. Returns the spring energy its two
    ends held (released; 0 unless the history is updated)."""
    held_0 = held_1 = 0.0
    if update_history:
        held_0, held_1 = energy[f, 0], energy[f, 1]
        for e in range(2):
            energy[f, e] = 0.0
            shear[f, e] = 0.0
            bonded[f, e] = 0
    normal[f, 0] = normal[f, 1] = 0.0
    return held_0, held_1


@jit
def contact_end(fn_elastic, opening_rate, slip_rate, ft, bonded, law, dt, update_history):
    """The contact law at one end of a face pair, for rigid blocks and for nodes alike.

    In: the elastic normal force ``-kn gap`` (compression positive), the opening and sliding rates of the two
    faces there, the shear spring force ``ft`` and ``bonded`` (1 while the end keeps its cohesion and tensile
    strength), the face pair's :class:`EndLaw`. A bond breaks in tension beyond ``ten`` or at the first
    slip; a dry end that opens carries nothing; the dashpot keeps a dry end's normal force compressive; the
    shear trial is capped by Coulomb's ``mu fn (+ coh while bonded)``.

    Returns ``(open, fn, ft, bonded, spring, friction_1, friction_2, damping)``: whether the end carries no
    force, its normal and shear forces and bond, the energy its springs store, and the energy dissipated by
    friction (two terms, each added on its own: the sums are the same bit for bit as written inline) and by
    the dashpot (``damping``, subtracted). With ``update_history`` False nothing of the history changes.
    """
    knp, ktp, dashpot, mu, coh, ten = law
    friction_1 = 0.0
    friction_2 = 0.0
    damping = 0.0
    if bonded and fn_elastic < -ten and update_history:
        bonded = 0
        friction_1 = 0.5 * fn_elastic * fn_elastic / knp
    if not bonded and fn_elastic <= 0.0:  # open dry end: no force at all
        if update_history:
            friction_2 = 0.5 * ft * ft / ktp
            ft = 0.0
        return True, 0.0, ft, bonded, 0.0, friction_1, friction_2, damping
    fn = fn_elastic - dashpot * opening_rate
    if not bonded and fn < 0.0:
        fn = 0.0
    if update_history:
        damping = (fn - fn_elastic) * opening_rate * dt
        slip = slip_rate * dt
        trial = ft - ktp * slip
        cap = mu * max(fn, 0.0) + (coh if bonded else 0.0)
        if abs(trial) > cap:
            if bonded:  # brittle: the bond is lost at the first violation
                bonded = 0
                if fn < 0.0:
                    friction_1 = 0.5 * fn_elastic * fn_elastic / knp
                    fn = 0.0
                    fn_elastic = 0.0
                cap = mu * fn
            # friction work on the plastic part of the slip increment
            friction_2 = cap * (abs(trial) - cap) / ktp
            ft = cap if trial > 0.0 else -cap
        else:
            ft = trial
    spring = 0.5 * fn_elastic * fn_elastic / knp + 0.5 * ft * ft / ktp
    return False, fn, ft, bonded, spring, friction_1, friction_2, damping


@pjit
def contact_forces(bodies, pairs, law, motion, vx, vy, force, dt, update_history, wake_speed):
    """Add the contact forces of every face pair to ``force`` (block, 3), the vertices at ``vx``, ``vy``.

    Each pair's forces go to ``face_force`` (face, 4) first: the force on B (x, y), its moment on B
    and on A (A gets minus the force), the pairs in parallel with numba's threads; then into
    ``force`` in face order: the same sums, bit for bit, with any number of threads.

    ``props`` (face, 4): friction, cohesion and tensile strength per unit length
    (already times the thickness), and the model interface (post-processing only). ``shear`` (face, 2) is the
    tangential spring force on block B along ``t``, ``normal`` (face, 2) the
    normal force (compression positive), ``bonded`` (face, 2) 1 while the end
    still has its cohesion/tension. Friction (and bond-breaking) dissipation goes
    to ``acc[DISSIPATED_FRICTION]``; the spring energy a face pair still holds
    when its two faces slide apart (a corner sliding off an edge) to ``acc[RELEASED]``.
    ``energy`` (face, 2) keeps the spring energy of every end (for what a rebuild drops). Returns the elastic energy stored in the springs.
    With ``update_history`` False only the forces and energy are evaluated.

    Normal contact damping: a dashpot ``contact_damping`` times critical for the
    reduced mass of the two blocks (``inv_mass``: 0 for driven blocks) acts on
    the normal relative velocity; the total normal force stays compressive on
    dry ends. It damps the contact chatter (a block landing on a plane) without
    touching sliding, which has no normal relative velocity.

    Sleeping: a pair of two inactive blocks (asleep, or supports standing still) is
    skipped, its forces (kept in ``face_force``) and spring energy frozen, still acting on both; :func:`wake_sleepers` runs first, so
    every block integrated in this step gets all its contact forces. A loaded end sliding
    or opening faster than ``wake_speed`` resets both blocks' calm counters: nothing
    touched by a moving block falls asleep.
    """
    offs, inv_mass = bodies.offs, bodies.inv_mass
    faces, props, shear, bonded, normal, energy, face_force = pairs
    pos, vel, active, calm, acc = motion.pos, motion.vel, motion.active, motion.calm, motion.acc
    min_half = law[2]
    if wake_speed > 0.0:
        wake_sleepers(bodies, pairs, law, motion, vx, vy, wake_speed)
    stored = 0.0
    d_friction = 0.0
    d_damping = 0.0
    released = 0.0
    for f in prange(faces.shape[0]):
        a, ea, b, eb = faces[f, 0], faces[f, 1], faces[f, 2], faces[f, 3]
        if not active[a] and not active[b]:  # frozen: its forces and spring energy as they were
            stored += energy[f, 0] + energy[f, 1]
            continue
        fbx = fby = mb = ma = 0.0
        g = face_geometry(vx, vy, offs, a, ea, b, eb)
        nx, ny = g[0], g[1]
        tx, ty = ny, -nx
        half, end_law = face_law(law, g, props[f], inv_mass[a] + inv_mass[b])
        if half <= min_half:
            held = release_face(f, energy, shear, bonded, normal, update_history)
            for e in range(2):
                released += held[e]
            face_force[f, 0] = face_force[f, 1] = face_force[f, 2] = face_force[f, 3] = 0.0
            continue
        for e in range(2):
            px, py, gap = end_point(g, e)
            dvx = (vel[b, 0] - vel[b, 2] * (py - pos[b, 1])) - (vel[a, 0] - vel[a, 2] * (py - pos[a, 1]))
            dvy = (vel[b, 1] + vel[b, 2] * (px - pos[b, 0])) - (vel[a, 1] + vel[a, 2] * (px - pos[a, 0]))
            is_open, fn, ft, bond, spring, friction_1, friction_2, damping = contact_end(
                -end_law.knp * gap, dvx * nx + dvy * ny, dvx * tx + dvy * ty, shear[f, e], bonded[f, e], end_law, dt,
                update_history)
            if friction_1 != 0.0:  # each term on its own, as the law adds them (numba: one reduction a branch)
                d_friction += friction_1
            if friction_2 != 0.0:
                d_friction += friction_2
            if damping != 0.0:
                d_damping -= damping
            shear[f, e] = ft
            bonded[f, e] = bond
            if is_open:
                normal[f, e] = 0.0
                energy[f, e] = 0.0
                continue
            if wake_speed > 0.0 and dvx * dvx + dvy * dvy > wake_speed * wake_speed:
                calm[a] = calm[b] = 0  # touched by something moving: neither may fall asleep
            stored += spring
            if update_history:
                energy[f, e] = spring
            normal[f, e] = fn
            fx = fn * nx + ft * tx
            fy = fn * ny + ft * ty
            fbx += fx
            fby += fy
            mb += (px - pos[b, 0]) * fy - (py - pos[b, 1]) * fx
            ma -= (px - pos[a, 0]) * fy - (py - pos[a, 1]) * fx
        face_force[f, 0] = fbx
        face_force[f, 1] = fby
        face_force[f, 2] = mb
        face_force[f, 3] = ma
    acc[DISSIPATED_FRICTION] += d_friction
    acc[DISSIPATED_DAMPING] += d_damping
    acc[RELEASED] += released
    for f in range(faces.shape[0]):  # in face order: the same sums with any number of threads
        a, b = faces[f, 0], faces[f, 2]
        force[b, 0] += face_force[f, 0]
        force[b, 1] += face_force[f, 1]
        force[b, 2] += face_force[f, 2]
        force[a, 0] -= face_force[f, 0]
        force[a, 1] -= face_force[f, 1]
        force[a, 2] += face_force[f, 3]
    return stored


@jit
def unbalanced_beyond(i, force, bodies, loading, load_share, added_share, share):
    """Whether block ``i``'s unbalanced force (translation, plus the moment over its radius) exceeds
    ``share`` of its applied load (translation)."""
    unbalanced = 0.0
    applied = 0.0
    for d in range(3):
        if not bodies.free[i, d]:
            continue
        load_d = load_share * loading.load[i, d] + added_share * loading.added[i, d]
        if d < 2:
            unbalanced += abs(force[i, d] + load_d)
            applied += abs(load_d)
        else:
            unbalanced += abs(force[i, d] + load_d) / bodies.radius[i]
    return unbalanced > share * applied


@jit
def settlement_rate(time, rate, ramp_time, start_time):
    """Smooth velocity ramp (half cosine over ``ramp_time``) from ``start_time`` on."""
    if rate == 0.0 or time <= start_time:
        return 0.0
    return rate * smooth_share(time - start_time, ramp_time)


@jit
def smooth_share(tau, duration):
    """0 before ``tau = 0``, a half cosine up to 1 over ``duration``, then 1 (1 at once if duration <= 0)."""
    if tau <= 0.0:
        return 0.0 if duration > 0.0 else 1.0
    if tau >= duration:
        return 1.0
    return 0.5 * (1.0 - np.cos(np.pi * tau / duration))


@pjit
def integrate_velocities(bodies, motion, loading, stepping, force, load_share, added_share, rate_now, sleeping):
    """The velocity update of every block (in parallel): driven blocks follow the support's motion, free
    ones the unbalanced force with Cundall's local damping; a sleeper wakes when :func:`unbalanced_beyond`.
    Returns the work of the supports, the work of the loads and the damping's dissipation in the step."""
    mass, free, driven, direction = bodies.mass, bodies.free, bodies.driven, bodies.direction
    vel, active, calm = motion.vel, motion.active, motion.calm
    load, added_load = loading.load, loading.added
    dt, damping = stepping.dt, stepping.damping
    work_support = 0.0
    work_gravity = 0.0
    damped = 0.0
    for i in prange(force.shape[0]):
        if driven[i]:
            for d in range(3):
                v = rate_now * direction[i, d]
                work_support -= force[i, d] * v * dt
                vel[i, d] = v
            continue
        if not active[i]:
            if not sleeping or not unbalanced_beyond(i, force, bodies, loading, load_share, added_share,
                                                     stepping.wake_force):
                continue
            active[i] = 1  # loaded out of its equilibrium: awake from this step on
            calm[i] = 0
        for d in range(3):
            if not free[i, d]:
                vel[i, d] = 0.0
                continue
            applied = load_share * load[i, d] + added_share * added_load[i, d]
            f = force[i, d] + applied
            v_old = vel[i, d]
            damp = 0.0
            if v_old > 0.0:
                damp = -damping * abs(f)
            elif v_old < 0.0:
                damp = damping * abs(f)
            v_new = v_old + dt * (f + damp) / mass[i, d]
            vel[i, d] = v_new
            work_gravity += applied * v_new * dt
            damped -= damp * v_new * dt
    return work_support, work_gravity, damped


@pjit
def move_blocks(bodies, motion, stepping, settlement, sleeping):
    """The position update of every block (in parallel); a block slow for ``sleep_steps`` steps falls asleep
    and its kinetic energy, returned, is dissipated."""
    pos0, mass, driven, radius, direction = bodies.pos0, bodies.mass, bodies.driven, bodies.radius, bodies.direction
    pos, vel, active, calm = motion.pos, motion.vel, motion.active, motion.calm
    dt, sleep_speed, sleep_steps = stepping.dt, stepping.sleep_speed, stepping.sleep_steps
    dissipated = 0.0
    for i in prange(pos.shape[0]):
        if driven[i]:
            for d in range(3):
                pos[i, d] = pos0[i, d] + settlement * direction[i, d]
        elif active[i]:
            for d in range(3):
                pos[i, d] += dt * vel[i, d]
            if sleeping:
                speed = np.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2) + abs(vel[i, 2]) * radius[i]
                calm[i] = calm[i] + 1 if speed < sleep_speed else 0
                if calm[i] >= sleep_steps:
                    active[i] = 0
                    for d in range(3):
                        dissipated += 0.5 * mass[i, d] * vel[i, d] * vel[i, d]
                        vel[i, d] = 0.0
    return dissipated


@pjit
def farthest_move(pos, pos_detect, radius):
    """The largest motion of a block since the last detection (centroid plus rotation times radius)."""
    moved = np.empty(pos.shape[0])
    for i in prange(pos.shape[0]):
        dx, dy = pos[i, 0] - pos_detect[i, 0], pos[i, 1] - pos_detect[i, 1]
        moved[i] = np.sqrt(dx * dx + dy * dy) + abs(pos[i, 2] - pos_detect[i, 2]) * radius[i]
    return moved.max()


@jit
def advance(n_steps, bodies, pairs, law, motion, loading, stepping, wrench):
    """Up to ``n_steps`` explicit central-difference steps; returns the fields of a :class:`Report`.

    Local non-viscous damping (Cundall): each free component of the unbalanced
    force is reduced by ``damping * |F|`` against its velocity. Driven blocks
    (supports) follow ``pos0 + settlement * direction``. The loads grow with a smooth
    ramp over ``load_ramp`` from time 0 (applied at once if 0); the added load comes on
    top of them with a smooth ramp from ``added_start`` over ``added_time`` (the steps
    of a load-factor search, :func:`smooth_share`). Stops early when some
    block has moved more than ``half_buffer`` since the last detection (the pair
    list must be rebuilt) or the settlement reached ``target``.

    Sleeping (``sleep_speed`` > 0, settlement phase only), as rigid-body engines do: a
    free block slower than ``sleep_speed`` (centroid speed plus spin times radius) for
    ``sleep_steps`` steps in a row stops being integrated until a contact wakes it
    (see :func:`contact_forces`) or its unbalanced force (translation, and the moment over its
    radius) exceeds ``wake_force`` times its load: a neighbour creeping below the sleep speed
    still loads it more and more, and it must follow. Moving supports are active while they move.

    ``wrench`` (block, 3) receives the force and moment (about its centroid) the wall exerts on every
    support block (0 for the others); ``motion.acc`` carries the accumulators.
    """
    pos, vel, active, acc = motion.pos, motion.vel, motion.active, motion.acc
    lx, ly, offs, driven, free, mass = bodies.lx, bodies.ly, bodies.offs, bodies.driven, bodies.free, bodies.mass
    load, added_load = loading.load, loading.added
    dt = stepping.dt
    n_block = pos.shape[0]
    force = np.zeros((n_block, 3))
    vx = np.empty(lx.size)
    vy = np.empty(lx.size)
    steps = 0
    rebuild = False
    load_norm = 0.0
    for i in range(n_block):
        load_norm += abs(load[i, 0] + added_load[i, 0]) + abs(load[i, 1] + added_load[i, 1])
    for _ in range(n_steps):
        force[:, :] = 0.0
        place_vertices(pos, lx, ly, offs, vx, vy)
        time = acc[TIME]
        added_share = smooth_share(time - loading.added_start, loading.added_time)
        rate_now = settlement_rate(time + 0.5 * dt, loading.rate, loading.rate_ramp, loading.start)
        sleeping = stepping.sleep_speed > 0.0 and rate_now > 0.0
        for i in range(n_block):
            if driven[i]:
                active[i] = 1 if (bodies.moving[i] and rate_now != 0.0) else 0
        contact_forces(bodies, pairs, law, motion, vx, vy, force, dt, True,
                       stepping.sleep_speed if sleeping else 0.0)
        load_share = smooth_share(time, loading.load_ramp)
        work_support, work_gravity, damped = integrate_velocities(
            bodies, motion, loading, stepping, force, load_share, added_share, rate_now, sleeping)
        acc[WORK_SUPPORT] += work_support
        acc[WORK_GRAVITY] += work_gravity
        acc[DISSIPATED_DAMPING] += damped
        acc[SETTLEMENT] += rate_now * dt
        acc[DISSIPATED_DAMPING] += move_blocks(bodies, motion, stepping, acc[SETTLEMENT], sleeping)
        acc[TIME] = time + dt
        steps += 1
        if farthest_move(pos, motion.pos_detect, bodies.radius) > stepping.half_buffer:
            rebuild = True
            break
        if loading.target > 0.0 and acc[SETTLEMENT] >= loading.target:
            break
    # state at the end of the chunk (forces at the current positions, history untouched)
    force[:, :] = 0.0
    place_vertices(pos, lx, ly, offs, vx, vy)
    stored = contact_forces(bodies, pairs, law, motion, vx, vy, force, dt, False, 0.0)
    kinetic = 0.0
    unbalanced = 0.0
    for i in range(n_block):
        for d in range(3):
            wrench[i, d] = force[i, d] if driven[i] else 0.0
        if not driven[i]:
            for d in range(3):
                if free[i, d]:
                    kinetic += 0.5 * mass[i, d] * vel[i, d] * vel[i, d]
                    if d < 2:
                        unbalanced += abs(force[i, d] + load[i, d] + added_load[i, d])
    return steps, rebuild, kinetic, stored, unbalanced / load_norm if load_norm > 0.0 else 0.0


@jit
def face_frames(pos, lx, ly, offs, faces):
    """(face, 11) :func:`face_geometry` of every face pair (for post-processing)."""
    vx = np.empty(lx.size)
    vy = np.empty(lx.size)
    place_vertices(pos, lx, ly, offs, vx, vy)
    out = np.empty((faces.shape[0], 11))
    for f in range(faces.shape[0]):
        g = face_geometry(vx, vy, offs, faces[f, 0], faces[f, 1], faces[f, 2], faces[f, 3])
        for j in range(11):
            out[f, j] = g[j]
    return out
