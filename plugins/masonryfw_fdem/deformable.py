"""The ``deformable`` mode: every block a fan of constant-strain triangles (CST), joints as in
the rigid mode.

Mesh: each block is split into a fan of triangles from an extra node at its centroid (a
non-convex block that its centroid does not see whole: into the constrained Delaunay
triangles of its own nodes, its centroid node left massless and out of every element), so
its boundary nodes are exactly the model's polygon nodes (same indices as ``Scene.lx``),
and the rigid mode's face-pair detection and contact law apply unchanged to the current
boundary. Nodes ``0 .. n_polygon_node - 1`` are the polygon nodes, followed by one
centroid node per block.

Elements: plane stress, total Lagrangian with the Green-Lagrange strain and a Saint
Venant-Kirchhoff law (``S = D E``), so that rigid rotations of a block (rocking) carry no
spurious strain; for small displacements this is the linear CST, ``f = -t A B^T D B u``.
Masses are lumped (a third of each triangle's mass at each of its nodes; the mass-weighted
mean of the nodes is then the polygon's centroid exactly).

Non-dimensional units as in :mod:`.scene`; the elastic constant of a block becomes
``E t length / W`` (force per unit non-dimensional strain and length).
Contact forces act at points of the current boundary edges and are shared between an edge's
two nodes by linear interpolation (velocities are interpolated the same way).
Support blocks stay rigid: their nodes follow ``pos0 + settlement * direction`` (finite rotation).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .kernels import (
    DISSIPATED_DAMPING,
    DISSIPATED_FRICTION,
    RELEASED,
    SETTLEMENT,
    TIME,
    WORK_GRAVITY,
    WORK_SUPPORT,
    contact_end,
    end_point,
    face_geometry,
    face_law,
    next_node,
    release_face,
    settlement_rate,
    smooth_share,
)
from .scene import Scene

jit = njit(cache=True, error_model="numpy")
# the element loop has no nan/inf logic: fastmath (fused multiply-adds) makes it ~25 % faster
fast_jit = njit(cache=True, error_model="numpy", fastmath=True, boundscheck=False)


class Mesh(NamedTuple):
    """Flat non-dimensional arrays of the triangulated blocks (what the kernels take)."""

    x0: np.ndarray  # (node,) reference coordinates
    y0: np.ndarray
    node_block: np.ndarray  # (node,) owning block
    triangles: np.ndarray  # (tri, 3) node indices, counter-clockwise
    grad_x: np.ndarray  # (tri, 3) dN_i/dX in the reference configuration
    grad_y: np.ndarray  # (tri, 3) dN_i/dY
    area0: np.ndarray  # (tri,) reference area
    young: np.ndarray  # (tri,) E t length / W
    poisson: np.ndarray  # (tri,)
    mass: np.ndarray  # (node,) lumped
    inv_mass: np.ndarray  # (node,) 0 on driven nodes
    driven: np.ndarray  # (node,) bool: node of a support block
    active_tri: np.ndarray  # (tri,) bool: element of a free block (support blocks are rigid)


def fan_triangles(offs: np.ndarray) -> np.ndarray:
    """(tri, 3): centroid node, polygon node k, next polygon node, for every edge of every block."""
    n_poly = int(offs[-1])
    counts = np.diff(offs)
    block = np.repeat(np.arange(counts.size), counts)
    k = np.arange(n_poly)
    nxt = k + 1
    nxt[offs[1:] - 1] = offs[:-1]
    return np.stack((n_poly + block, k, nxt), axis=1).astype(np.int64)


#: A fan triangle thinner than this share of its block's area makes the block triangulated instead.
FAN_MIN_SHARE = 1e-3


def block_triangles(x0: np.ndarray, y0: np.ndarray, offs: np.ndarray) -> np.ndarray:
    """(tri, 3) counter-clockwise elements of every block: the fan from its centroid node where every
    fan triangle is positive (convex blocks, and star-shaped ones seen from their centroid), else the
    constrained Delaunay triangulation of its polygon nodes (its centroid node is then left out)."""
    fan = fan_triangles(offs)
    px, py = x0[fan], y0[fan]
    area = 0.5 * ((px[:, 1] - px[:, 0]) * (py[:, 2] - py[:, 0]) - (px[:, 2] - px[:, 0]) * (py[:, 1] - py[:, 0]))
    counts = np.diff(offs)
    block = np.repeat(np.arange(counts.size), counts)
    block_area = np.bincount(block, weights=area, minlength=counts.size)
    thin = area <= FAN_MIN_SHARE * block_area[block]
    bad = np.unique(block[thin])
    if bad.size == 0:
        return fan
    n_poly = int(offs[-1])
    triangles, _ = mfp.triangulated(x0[:n_poly], y0[:n_poly], counts, bad)
    return np.concatenate((fan[~np.isin(block, bad)], triangles))


def shape_gradients(x: np.ndarray, y: np.ndarray, triangles: np.ndarray):
    """Constant shape-function gradients (tri, 3) and signed areas (tri,) of linear triangles."""
    px, py = x[triangles], y[triangles]
    j, k = [1, 2, 0], [2, 0, 1]
    area = 0.5 * ((px[:, 1] - px[:, 0]) * (py[:, 2] - py[:, 0]) - (px[:, 2] - px[:, 0]) * (py[:, 1] - py[:, 0]))
    grad_x = (py[:, j] - py[:, k]) / (2.0 * area[:, None])
    grad_y = (px[:, k] - px[:, j]) / (2.0 * area[:, None])
    return grad_x, grad_y, area


def elastic_constants(model, n_block: int) -> tuple[np.ndarray, np.ndarray]:
    """``block_young_modulus`` and ``block_poisson_ratio`` [Pa, 1], checked."""
    for name in ("block_young_modulus", "block_poisson_ratio"):
        if name not in model:
            raise mf.ModelError(f"{name}: missing; the fdem deformable mode needs the blocks' elastic constants "
                                "(material young_modulus / poisson_ratio in the wall spec)")
    young = model.block_young_modulus.values.astype(float)
    nu = model.block_poisson_ratio.values.astype(float)
    bad = np.flatnonzero(~(young > 0))
    if bad.size:
        raise mf.ModelError(f"block(s) {mfp.listed(bad)}: block_young_modulus must be positive")
    bad = np.flatnonzero(~((nu > -1.0) & (nu < 0.5)))
    if bad.size:
        raise mf.ModelError(f"block(s) {mfp.listed(bad)}: block_poisson_ratio must be in (-1, 0.5)")
    return np.broadcast_to(young, (n_block,)), np.broadcast_to(nu, (n_block,))


def build_mesh(model, scene: Scene) -> Mesh:
    """The fan mesh of every block of ``model`` (see the module docstring)."""
    n_block = scene.driven.size
    counts = np.diff(scene.offs)
    owner = np.repeat(np.arange(n_block), counts)
    x0 = np.concatenate((scene.pos0[owner, 0] + scene.lx, scene.pos0[:, 0]))
    y0 = np.concatenate((scene.pos0[owner, 1] + scene.ly, scene.pos0[:, 1]))
    node_block = np.concatenate((owner, np.arange(n_block)))
    triangles = block_triangles(x0, y0, scene.offs)
    tri_block = node_block[triangles[:, 1]]
    grad_x, grad_y, area0 = shape_gradients(x0, y0, triangles)
    block_area = np.bincount(tri_block, weights=area0, minlength=n_block)
    young, nu = elastic_constants(model, n_block)
    thickness = model.block_thickness.values
    young_scaled = young * thickness * scene.scales.length / scene.scales.force
    mass_share = scene.mass[:, 0]
    tri_mass = mass_share[tri_block] * area0 / block_area[tri_block]
    mass = np.bincount(triangles.ravel(), weights=np.repeat(tri_mass / 3.0, 3), minlength=x0.size)
    driven = scene.driven[node_block]
    return Mesh(x0=x0, y0=y0, node_block=node_block, triangles=triangles, grad_x=grad_x, grad_y=grad_y,
                area0=area0, young=young_scaled[tri_block], poisson=nu[tri_block], mass=mass,
                inv_mass=np.where(driven | (mass <= 0), 0.0, 1.0 / np.where(mass > 0, mass, 1.0)), driven=driven,
                active_tri=~scene.driven[tri_block])


def check_supported(scene: Scene) -> None:
    """The deformable mode moves nodes, not blocks: a held component of a free block, or a moment
    load, has no nodal meaning here."""
    held = np.flatnonzero(~scene.driven & ~scene.free.all(axis=1))
    if held.size:
        raise mf.ModelError(f"block(s) {mfp.listed(held)}: block_fixed holds a component of a free block; "
                            "the fdem deformable mode does not support it (make the block a support)")
    moment = np.flatnonzero((scene.dead[:, 2] != 0) | (scene.live[:, 2] != 0))
    if moment.size:
        raise mf.ModelError(f"block(s) {mfp.listed(moment)}: dead_load / live_load has a moment component; "
                            "the fdem deformable mode takes only forces (applied in proportion to the nodal masses)")


def nodal_load(mesh: Mesh, scene: Scene, load: np.ndarray) -> np.ndarray:
    """(node, 2): each free block's force load shared among its nodes in proportion to their masses."""
    block_mass = np.bincount(mesh.node_block, weights=mesh.mass, minlength=scene.driven.size)
    share = mesh.mass / block_mass[mesh.node_block]
    return np.where(mesh.driven[:, None], 0.0, load[mesh.node_block, :2] * share[:, None])


def critical_time_step(mesh: Mesh, scene: Scene, kn: float) -> float:
    """2 / omega_max with omega^2 bounded by the stiffest element (Courant: omega = 2 c_p / h_min,
    c_p^2 = E / (rho (1 - nu^2)), h the triangle's smallest altitude) plus the contact springs
    all round a boundary node (kn times the length of its two edges over 2, on its lumped mass)."""
    free_tri = mesh.active_tri
    px, py = mesh.x0[mesh.triangles], mesh.y0[mesh.triangles]
    sides = np.hypot(px - np.roll(px, -1, axis=1), py - np.roll(py, -1, axis=1))
    altitude = 2.0 * np.abs(mesh.area0) / sides.max(axis=1)
    tri_block = mesh.node_block[mesh.triangles[:, 0]]
    block_area = np.bincount(tri_block, weights=mesh.area0, minlength=scene.driven.size)
    density = scene.mass[tri_block, 0] / block_area[tri_block]
    wave = mesh.young / (density * (1.0 - mesh.poisson**2))
    omega_element = (4.0 * wave / altitude**2)[free_tri].max(initial=0.0)
    n_poly = scene.lx.size
    following = np.arange(n_poly) + 1
    following[scene.offs[1:] - 1] = scene.offs[:-1]
    edge = np.hypot(mesh.x0[following] - mesh.x0[:n_poly], mesh.y0[following] - mesh.y0[:n_poly])  # polygon edges
    tributary = 0.5 * (edge + edge[prev_edge(scene.offs)])
    free_poly = ~mesh.driven[:n_poly]
    omega_contact = (kn * tributary / mesh.mass[:n_poly])[free_poly].max(initial=0.0)
    omega = np.sqrt(omega_element + omega_contact)
    return 2.0 / omega if omega > 0 else np.inf


def prev_edge(offs: np.ndarray) -> np.ndarray:
    """Index of the edge ending at each polygon node (edge k runs from node k to the next)."""
    idx = np.arange(int(offs[-1])) - 1
    idx[offs[:-1]] = offs[1:] - 1
    return idx


@jit
def element_constants(triangles, grad_x, grad_y, area0, young, poisson, active_tri):
    """The active elements and their constants packed for :func:`cst_element_forces`.

    Returns ``(active triangles (n, 3), constants (n, 8))`` with the constants of an element
    contiguous in one row: ``dN/dX`` of its 3 nodes, ``dN/dY`` of its 3 nodes,
    ``A0 E t / (1 - nu^2)`` and ``nu``. The element loop then reads one cache line per element
    and does no division (measured: 1.2-1.5x the throughput of seven separate arrays).
    """
    keep = np.flatnonzero(active_tri)
    tri = np.empty((keep.size, 3), dtype=np.int64)
    constants = np.empty((keep.size, 8))
    for i in range(keep.size):
        e = keep[i]
        for j in range(3):
            tri[i, j] = triangles[e, j]
            constants[i, j] = grad_x[e, j]
            constants[i, 3 + j] = grad_y[e, j]
        constants[i, 6] = area0[e] * young[e] / (1.0 - poisson[e] * poisson[e])
        constants[i, 7] = poisson[e]
    return tri, constants


@fast_jit
def cst_element_forces(x, y, triangles, constants, force):
    """Add the internal forces of the CSTs (packed by :func:`element_constants`) to ``force``
    (node, 2); returns the strain energy.

    Deformation gradient ``F = sum_i x_i grad N_i``, Green strain ``E = (F^T F - I) / 2``,
    plane-stress ``S = D E``, first Piola ``P = F S``, nodal force ``-A0 P grad N_i``.
    """
    energy = 0.0
    for e in range(triangles.shape[0]):
        n0, n1, n2 = triangles[e, 0], triangles[e, 1], triangles[e, 2]
        bx0, bx1, bx2 = constants[e, 0], constants[e, 1], constants[e, 2]
        by0, by1, by2 = constants[e, 3], constants[e, 4], constants[e, 5]
        stiffness, nu = constants[e, 6], constants[e, 7]
        x0, x1, x2, y0, y1, y2 = x[n0], x[n1], x[n2], y[n0], y[n1], y[n2]
        f11 = x0 * bx0 + x1 * bx1 + x2 * bx2
        f12 = x0 * by0 + x1 * by1 + x2 * by2
        f21 = y0 * bx0 + y1 * bx1 + y2 * bx2
        f22 = y0 * by0 + y1 * by1 + y2 * by2
        e11 = 0.5 * (f11 * f11 + f21 * f21 - 1.0)
        e22 = 0.5 * (f12 * f12 + f22 * f22 - 1.0)
        e12 = 0.5 * (f11 * f12 + f21 * f22)
        s11 = stiffness * (e11 + nu * e22)  # A0 times the second Piola-Kirchhoff stress
        s22 = stiffness * (e22 + nu * e11)
        s12 = stiffness * (1.0 - nu) * e12
        energy += s11 * e11 + s22 * e22 + 2.0 * s12 * e12
        p11 = f11 * s11 + f12 * s12
        p12 = f11 * s12 + f12 * s22
        p21 = f21 * s11 + f22 * s12
        p22 = f21 * s12 + f22 * s22
        force[n0, 0] -= p11 * bx0 + p12 * by0
        force[n0, 1] -= p21 * bx0 + p22 * by0
        force[n1, 0] -= p11 * bx1 + p12 * by1
        force[n1, 1] -= p21 * bx1 + p22 * by1
        force[n2, 0] -= p11 * bx2 + p12 * by2
        force[n2, 1] -= p21 * bx2 + p22 * by2
    return 0.5 * energy


@jit
def edge_weight(x, y, k0, k1, px, py):
    """Share of node ``k1`` in the point of edge k0-k1 nearest to (px, py), clipped to the edge."""
    ex, ey = x[k1] - x[k0], y[k1] - y[k0]
    w = ((px - x[k0]) * ex + (py - y[k0]) * ey) / (ex * ex + ey * ey)
    return min(max(w, 0.0), 1.0)


class NodeMotion(NamedTuple):
    """What the steps change: node positions and velocities (node, 2), positions at the last detection,
    the accumulators ``acc`` (:mod:`.kernels`)."""

    x: np.ndarray
    y: np.ndarray
    vel: np.ndarray
    x_detect: np.ndarray
    y_detect: np.ndarray
    acc: np.ndarray


@jit
def node_contact_forces(offs, mesh, pairs, law, motion, force, dt, update_history):
    """The rigid mode's face-pair contact law (see :func:`.kernels.contact_forces`) on the current
    boundary nodes: the force at each contact end goes to the two nodes of each edge by linear
    interpolation, and the relative velocity is interpolated from them. Returns the spring energy."""
    faces, props, shear, bonded, normal, energy = pairs.faces, pairs.props, pairs.shear, pairs.bonded, \
        pairs.normal, pairs.energy
    x, y, vel, acc = motion.x, motion.y, motion.vel, motion.acc
    min_half = law[2]
    inv_mass = mesh.inv_mass
    stored = 0.0
    for f in range(faces.shape[0]):
        a, ea, b, eb = faces[f, 0], faces[f, 1], faces[f, 2], faces[f, 3]
        ka, kb = next_node(ea, a, offs), next_node(eb, b, offs)
        g = face_geometry(x, y, offs, a, ea, b, eb)
        nx, ny = g[0], g[1]
        tx, ty = ny, -nx
        half, end_law = face_law(law, g, props[f], 0.5 * (inv_mass[ea] + inv_mass[ka] + inv_mass[eb] + inv_mass[kb]))
        if half <= min_half:
            held = release_face(f, energy, shear, bonded, normal, update_history)
            for e in range(2):
                acc[RELEASED] += held[e]
            continue
        for e in range(2):
            px, py, gap = end_point(g, e)
            wa = edge_weight(x, y, ea, ka, px, py)
            wb = edge_weight(x, y, eb, kb, px, py)
            dvx = ((1.0 - wb) * vel[eb, 0] + wb * vel[kb, 0]) - ((1.0 - wa) * vel[ea, 0] + wa * vel[ka, 0])
            dvy = ((1.0 - wb) * vel[eb, 1] + wb * vel[kb, 1]) - ((1.0 - wa) * vel[ea, 1] + wa * vel[ka, 1])
            is_open, fn, ft, bond, spring, friction_1, friction_2, damping = contact_end(
                -end_law.knp * gap, dvx * nx + dvy * ny, dvx * tx + dvy * ty, shear[f, e], bonded[f, e], end_law, dt,
                update_history)
            acc[DISSIPATED_FRICTION] += friction_1
            acc[DISSIPATED_FRICTION] += friction_2
            acc[DISSIPATED_DAMPING] -= damping
            shear[f, e] = ft
            bonded[f, e] = bond
            if is_open:
                normal[f, e] = 0.0
                energy[f, e] = 0.0
                continue
            stored += spring
            if update_history:
                energy[f, e] = spring
            normal[f, e] = fn
            fx = fn * nx + ft * tx
            fy = fn * ny + ft * ty
            force[eb, 0] += (1.0 - wb) * fx
            force[eb, 1] += (1.0 - wb) * fy
            force[kb, 0] += wb * fx
            force[kb, 1] += wb * fy
            force[ea, 0] -= (1.0 - wa) * fx
            force[ea, 1] -= (1.0 - wa) * fy
            force[ka, 0] -= wa * fx
            force[ka, 1] -= wa * fy
    return stored


@jit
def driven_motion(settlement, rate, bodies, mesh, driven_nodes, motion):
    """Positions and velocities of the support nodes: rigid motion ``pos0 + settlement * direction``."""
    x0, y0, node_block, pos0, direction = mesh.x0, mesh.y0, mesh.node_block, bodies.pos0, bodies.direction
    x, y, vel = motion.x, motion.y, motion.vel
    for k in driven_nodes:
        b = node_block[k]
        theta = settlement * direction[b, 2]
        c, s = np.cos(theta), np.sin(theta)
        rx, ry = x0[k] - pos0[b, 0], y0[k] - pos0[b, 1]
        qx, qy = c * rx - s * ry, s * rx + c * ry
        x[k] = pos0[b, 0] + settlement * direction[b, 0] + qx
        y[k] = pos0[b, 1] + settlement * direction[b, 1] + qy
        vel[k, 0] = rate * (direction[b, 0] - direction[b, 2] * qy)
        vel[k, 1] = rate * (direction[b, 1] + direction[b, 2] * qx)


@jit
def advance(n_steps, bodies, mesh, pairs, law, motion, loading, stepping, wrench):
    """Up to ``n_steps`` central-difference steps of the nodes (see :func:`.kernels.advance` for the
    damping, the loads (per node here), the supports, the stop conditions, ``wrench`` and what it returns;
    stored energy = strain + springs)."""
    x, y, vel, acc = motion.x, motion.y, motion.vel, motion.acc
    driven, inv_mass, node_block = mesh.driven, mesh.inv_mass, mesh.node_block
    load, added_load = loading.load, loading.added
    pos0, direction = bodies.pos0, bodies.direction
    dt, damping = stepping.dt, stepping.damping
    n_node = x.size
    force = np.zeros((n_node, 2))
    elements, constants = element_constants(mesh.triangles, mesh.grad_x, mesh.grad_y, mesh.area0, mesh.young,
                                            mesh.poisson, mesh.active_tri)
    driven_nodes = np.flatnonzero(driven)
    steps = 0
    rebuild = False
    load_norm = 0.0
    for k in range(n_node):
        load_norm += abs(load[k, 0] + added_load[k, 0]) + abs(load[k, 1] + added_load[k, 1])
    limit = stepping.half_buffer * stepping.half_buffer
    for _ in range(n_steps):
        time = acc[TIME]
        added_share = smooth_share(time - loading.added_start, loading.added_time)
        rate_now = settlement_rate(time + 0.5 * dt, loading.rate, loading.rate_ramp, loading.start)
        driven_motion(acc[SETTLEMENT], rate_now, bodies, mesh, driven_nodes, motion)
        cst_element_forces(x, y, elements, constants, force)
        node_contact_forces(bodies.offs, mesh, pairs, law, motion, force, dt, True)
        load_share = smooth_share(time, loading.load_ramp)
        # one pass over the nodes: velocity, position, distance since the detection; the force
        # buffer is cleared behind it for the next step
        moved = 0.0
        work_gravity = 0.0
        damping_work = 0.0
        for k in range(n_node):
            if driven[k]:
                continue
            for d in range(2):
                applied = load_share * load[k, d] + added_share * added_load[k, d]
                f = force[k, d] + applied
                force[k, d] = 0.0
                v_old = vel[k, d]
                damp = -damping * abs(f) * np.sign(v_old)  # branch-free (0 at rest)
                v_new = v_old + dt * (f + damp) * inv_mass[k]
                vel[k, d] = v_new
                work_gravity += applied * v_new
                damping_work -= damp * v_new
            x[k] += dt * vel[k, 0]
            y[k] += dt * vel[k, 1]
            dx, dy = x[k] - motion.x_detect[k], y[k] - motion.y_detect[k]
            moved = max(moved, dx * dx + dy * dy)
        acc[WORK_GRAVITY] += work_gravity * dt
        acc[DISSIPATED_DAMPING] += damping_work * dt
        for k in driven_nodes:
            acc[WORK_SUPPORT] -= (force[k, 0] * vel[k, 0] + force[k, 1] * vel[k, 1]) * dt
            force[k, 0] = force[k, 1] = 0.0
        acc[SETTLEMENT] += rate_now * dt
        driven_motion(acc[SETTLEMENT], rate_now, bodies, mesh, driven_nodes, motion)
        for k in driven_nodes:
            dx, dy = x[k] - motion.x_detect[k], y[k] - motion.y_detect[k]
            moved = max(moved, dx * dx + dy * dy)
        acc[TIME] = time + dt
        steps += 1
        if moved > limit:
            rebuild = True
            break
        if loading.target > 0.0 and acc[SETTLEMENT] >= loading.target:
            break
    force[:, :] = 0.0
    strain = cst_element_forces(x, y, elements, constants, force)
    springs = node_contact_forces(bodies.offs, mesh, pairs, law, motion, force, dt, False)
    kinetic = 0.0
    unbalanced = 0.0
    wrench[:, :] = 0.0
    for k in range(n_node):
        if driven[k]:  # the wall's force on the support block, and its moment about the block's centroid
            b = node_block[k]
            cx = pos0[b, 0] + acc[SETTLEMENT] * direction[b, 0]
            cy = pos0[b, 1] + acc[SETTLEMENT] * direction[b, 1]
            wrench[b, 0] += force[k, 0]
            wrench[b, 1] += force[k, 1]
            wrench[b, 2] += (x[k] - cx) * force[k, 1] - (y[k] - cy) * force[k, 0]
        if not driven[k]:
            kinetic += 0.5 * mesh.mass[k] * (vel[k, 0] * vel[k, 0] + vel[k, 1] * vel[k, 1])
            unbalanced += (abs(force[k, 0] + load[k, 0] + added_load[k, 0])
                           + abs(force[k, 1] + load[k, 1] + added_load[k, 1]))
    return steps, rebuild, kinetic, strain + springs, unbalanced / load_norm if load_norm > 0.0 else 0.0


def rigid_fit(mesh: Mesh, x: np.ndarray, y: np.ndarray, n_block: int) -> np.ndarray:
    """(block, 3) centroid and rotation of the rigid motion nearest (least squares, mass-weighted)
    to each block's nodes: mean translation of the centroid, best-fit rotation about it."""
    m, owner = mesh.mass, mesh.node_block
    total = np.bincount(owner, weights=m, minlength=n_block)
    cx0 = np.bincount(owner, weights=m * mesh.x0, minlength=n_block) / total
    cy0 = np.bincount(owner, weights=m * mesh.y0, minlength=n_block) / total
    cx = np.bincount(owner, weights=m * x, minlength=n_block) / total
    cy = np.bincount(owner, weights=m * y, minlength=n_block) / total
    rx, ry = mesh.x0 - cx0[owner], mesh.y0 - cy0[owner]
    qx, qy = x - cx[owner], y - cy[owner]
    sin_sum = np.bincount(owner, weights=m * (rx * qy - ry * qx), minlength=n_block)
    cos_sum = np.bincount(owner, weights=m * (rx * qx + ry * qy), minlength=n_block)
    return np.stack((cx, cy, np.arctan2(sin_sum, cos_sum)), axis=1)
