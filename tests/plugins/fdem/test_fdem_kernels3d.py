"""fdem's 3D kernels (rigid polyhedra, face-pair contacts, exact rotations) against closed forms: a block at rest
on a base (reaction and penetration), sliding down an incline at ``g (sin theta - mu cos theta)`` and held below
the friction angle, tipping over an edge once the sideways load passes ``b / h`` of its weight and landing on its
side (corner contacts), and the torque-free precession of a symmetric top. Units are the kernels' own: g = 1, unit weight 1 a volume."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_fdem import kernels3d as k3
from masonryfw_fdem import scene3d as s3

KN = 1e4  # normal stiffness per area: a unit cube of weight 1 sinks 1e-4
RECLIP_SHARE = {o.name: o.default for o in mf.get_solver("fdem").options}["reclip_ratio"]
BUFFER = 0.05
MIN_COS = np.cos(np.radians(30.0))


def block_on_base(size=(1.0, 1.0, 1.0), base=(8.0, 8.0)):
    """A free box of ``size`` standing centred on a fixed base slab 0.5 thick."""
    bx, by = base
    sx, sy, sz = size
    poly = mfp.boxes(np.array([[-bx / 2, -by / 2, -0.5], [-sx / 2, -sy / 2, 0.0]]),
                     np.array([[bx / 2, by / 2, 0.0], [sx / 2, sy / 2, sz]]))
    return s3.bodies_of(poly, np.array([0.0, 1.0]), np.array([True, False]), np.zeros(2, bool), np.zeros((2, 6)))


def run(bodies, load, friction, steps, dt=1e-3, damping=0.0, dashpot=0.2, ramp=0.0, edge_contacts=True):
    """``steps`` steps from rest under ``load`` (block, 6; ramped in over ``ramp``) on joints of ``friction``, face
    pairs found again whenever the kernel asks (and edge contacts unless told not to); returns the motion, the last
    pairs and the wrench on the supports."""
    motion = s3.at_rest(bodies)
    law = k3.ContactLaw3(KN, 0.5 * KN, 1e-12, dashpot, RECLIP_SHARE, BUFFER)
    loading = k3.Loading3(load, ramp, 0.0, 0.0, 0.0, 0.0)
    stepping = k3.Stepping3(dt, damping, 0.5 * BUFFER)
    pairs, wrench, left = None, np.zeros((bodies.pos0.shape[0], 6)), steps
    while left > 0:
        faces, corners, edges = s3.contacts(bodies, motion, BUFFER, 0.2, MIN_COS)
        if not edge_contacts:
            edges = edges[:0]
        pairs = s3.new_pairs(bodies, faces, np.tile([friction, 0.0, 0.0], (len(faces), 1)), np.zeros(len(faces)),
                             corners, np.full(len(corners), friction), edges, np.full(len(edges), friction), pairs)
        done, rebuild, *_ = k3.advance3(left, bodies, pairs, law, motion, loading, stepping, wrench)
        left -= done
        motion.pos_detect[:] = motion.pos
        motion.quat_detect[:] = motion.quat
    return motion, pairs, wrench


def rotation_of(q):
    """The rotation matrix of a unit quaternion (w, x, y, z), written out here as the reference."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def weight_load(bodies, tilt=0.0, sideways=0.0):
    """The blocks' weight, turned ``tilt`` radians about y (an incline), plus ``sideways`` of it along x."""
    load = np.zeros((bodies.pos0.shape[0], 6))
    load[:, 0] = bodies.mass * (np.sin(tilt) + sideways)
    load[:, 2] = -bodies.mass * np.cos(tilt)
    return load


def test_a_block_at_rest_presses_its_weight_into_the_base_with_the_closed_form_penetration():
    bodies = block_on_base()
    motion, pairs, wrench = run(bodies, weight_load(bodies), 0.6, 4000, damping=0.8)
    assert wrench[0, 2] == pytest.approx(-1.0, rel=1e-9)  # the block's whole weight on the support
    assert np.count_nonzero(pairs.held[0] == 1) == 4  # the four corners of its base
    assert pairs.normal[0][pairs.held[0] == 1] == pytest.approx(np.full(4, 0.25), rel=1e-9)
    assert 0.0 - (motion.pos[1, 2] - 0.5) == pytest.approx(1.0 / KN, rel=1e-6)  # W / (kn A)
    assert np.abs(motion.pos[1, :2]).max() < 1e-12


def pair_wrench(bodies, pairs, motion):
    """Every face pair's force and moments (:func:`.kernels3d.pair_forces3`) at ``motion``, histories kept."""
    world = s3.world_vertices(bodies, motion)
    n_face = bodies.face_offs.size - 1
    normal, centre = np.empty((n_face, 3)), np.empty((n_face, 3))
    k3.face_frames3(world, bodies, normal, centre)
    force, energy = np.empty((len(pairs.faces), 9)), np.empty((len(pairs.faces), 3))
    law = k3.ContactLaw3(KN, 0.5 * KN, 1e-12, 0.0, RECLIP_SHARE, BUFFER)
    k3.pair_forces3(bodies, pairs, law, motion, world, normal, centre, force, energy, 1e-3, False)
    return force


@pytest.mark.parametrize("turn", [False, True])
def test_a_pairs_reused_overlap_carries_the_forces_of_a_fresh_clip_to_its_tolerance(turn):
    """A block at rest slid (or turned about z) by less than ``reclip_ratio`` of its radius against its base: the
    pair keeps its overlap as clipped at rest, its points on the base; its forces are those of the overlap clipped
    afresh, the moments within the weight times the move (the points' lever arms moved by that much)."""
    bodies = block_on_base()
    motion, pairs, _ = run(bodies, weight_load(bodies), 0.6, 4000, damping=0.8)
    move = 0.5 * RECLIP_SHARE * bodies.radius.min()
    if turn:
        k3.turn(motion.quat[1], 0.0, 0.0, move / bodies.radius[1])
    else:
        motion.pos[1, :2] += move / np.sqrt(2.0)
    assert (pairs.clipped == 4).all()
    reused = pair_wrench(bodies, pairs, motion)
    fresh = pair_wrench(bodies, pairs._replace(clipped=np.full_like(pairs.clipped, -1)), motion)
    weight = bodies.mass[1]
    assert np.abs(reused[:, :3] - fresh[:, :3]).max() <= 1e-9 * weight
    assert np.abs(reused[:, 3:] - fresh[:, 3:]).max() <= 1.01 * weight * move
    assert abs(reused[:, 2].sum() - weight) <= 1e-6 * weight


@pytest.mark.parametrize("tilt_deg", [25.0, 35.0])
def test_a_block_slides_down_an_incline_at_the_coulomb_acceleration(tilt_deg):
    """On an incline steeper than the friction angle the block accelerates at ``g (sin theta - mu cos theta)``
    (no damping), measured between 0.5 and 1.5 time units (the normal force builds up over the first hundredth)."""
    bodies, mu, dt = block_on_base(), 0.3, 1e-3
    theta = np.radians(tilt_deg)
    early, _, _ = run(bodies, weight_load(bodies, theta), mu, 500, dt=dt)
    late, _, _ = run(bodies, weight_load(bodies, theta), mu, 1500, dt=dt)
    acceleration = (late.vel[1, 0] - early.vel[1, 0]) / (1000 * dt)
    assert acceleration == pytest.approx(np.sin(theta) - mu * np.cos(theta), rel=2e-3)
    assert abs(late.vel[1, 1]) < 1e-9 * late.vel[1, 0]
    assert np.abs(late.omega[1]).max() < 1e-6


def test_a_block_holds_on_an_incline_below_the_friction_angle():
    """Below the friction angle the block moves by the give of its springs, then stays (no creep)."""
    bodies = block_on_base()
    early, _, _ = run(bodies, weight_load(bodies, np.radians(15.0)), 0.3, 1500, damping=0.3)
    late, _, _ = run(bodies, weight_load(bodies, np.radians(15.0)), 0.3, 3000, damping=0.3)
    assert abs(late.pos[1, 0]) < 1e-3
    assert abs(late.pos[1, 0] - early.pos[1, 0]) < 1e-8
    assert abs(late.vel[1, 0]) < 1e-8


@pytest.mark.parametrize(("share", "tips"), [(0.9, False), (1.1, True)])
def test_a_slender_block_tips_over_its_edge_once_the_sideways_load_passes_b_over_h(share, tips):
    """A block b wide and h high under a sideways load lambda W (friction high enough not to slide) stays while
    lambda < b / h and turns about its edge beyond."""
    b, h = 0.5, 1.5
    bodies = block_on_base((b, 1.0, h))
    motion, _, _ = run(bodies, weight_load(bodies, sideways=share * b / h), 0.9, 4000, damping=0.3, ramp=1.0)
    angle = k3.rotation_angle(motion.quat[1], np.array([1.0, 0.0, 0.0, 0.0]))
    assert (angle > 0.05) == tips, angle
    if not tips:
        assert angle < 5e-3 and abs(motion.pos[1, 0]) < 1e-3
    else:
        assert motion.omega[1, 1] > 0.0 and abs(motion.omega[1, 0]) + abs(motion.omega[1, 2]) < 1e-6


def lowest_vertex(bodies, motion, block):
    """The height of ``block``'s lowest vertex at ``motion``."""
    vertices = bodies.vertices[bodies.vertex_offs[block]:bodies.vertex_offs[block + 1]]
    return min(k3.rotate(motion.quat[block], *v)[2] for v in vertices) + motion.pos[block, 2]


def test_a_toppling_block_lands_on_its_side_and_never_passes_through_the_base():
    """A block b wide and h high pushed over its edge (sideways 1.2 b / h of its weight, friction 0.9) turns past
    ``max_contact_angle`` (its base no longer faces the ground: the face pair is gone) on the corner contacts of
    its edge, then lies on its side: turned 90 degrees, its centroid b / 2 high. Without corner contacts it sank
    into the base from 40 degrees and fell through it (0.40 below the surface at 64 degrees)."""
    b, h = 0.5, 1.5
    bodies = block_on_base((b, 1.0, h))
    load = weight_load(bodies, sideways=1.2 * b / h)
    falling, _, _ = run(bodies, load, 0.9, 3500, ramp=0.2)
    fallen, pairs, _ = run(bodies, load, 0.9, 8000, damping=0.0, ramp=0.2)
    rest = np.array([1.0, 0.0, 0.0, 0.0])
    assert 50.0 < np.degrees(k3.rotation_angle(falling.quat[1], rest)) < 85.0  # on its edge, past the contact angle
    assert lowest_vertex(bodies, falling, 1) > -1e-3
    assert np.degrees(k3.rotation_angle(fallen.quat[1], rest)) == pytest.approx(90.0, abs=0.5)
    assert fallen.pos[1, 2] == pytest.approx(b / 2, abs=1e-3)
    assert lowest_vertex(bodies, fallen, 1) > -1e-3
    assert len(pairs.faces) == 1 and len(pairs.corners) == 0  # lying on its side: a face pair again


def crossed_ridges(gap):
    """Two beams 0.6 x 0.6 x 4 across each other, each turned 45 degrees about its length: a fixed one along x,
    its ridge at z = 0, and a free one along y above it, its lower ridge ``gap`` higher. Their only touch is ridge
    across ridge: no vertex of either is ever inside the other, and no faces face each other."""
    half = 0.3 * np.sqrt(2.0)
    poly = mfp.boxes(np.array([[-2.0, -0.3, -0.3], [-0.3, -2.0, -0.3]]), np.array([[2.0, 0.3, 0.3], [0.3, 2.0, 0.3]]))
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    about_x = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    about_y = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    owner = np.repeat(np.arange(2), poly.block_node_count)
    vertices = np.where((owner == 0)[:, None], poly.vertices @ about_x.T - [0.0, 0.0, half],
                        poly.vertices @ about_y.T + [0.0, 0.0, half + gap])
    return s3.bodies_of(poly._replace(vertices=vertices), np.array([0.0, 1.0]), np.array([True, False]),
                        np.zeros(2, bool), np.zeros((2, 6)))


def test_a_beam_dropped_ridge_on_ridge_across_another_rests_on_the_crossing():
    """A ridge that lands across another meets it at one point, inside both edges: an edge contact. The beam comes
    to rest there, its ridge sunk by its weight over the point's stiffness (``W / (kn A)``, A the smaller corner
    area), not turned. Without edge contacts it fell straight through the fixed beam (2 s of free fall)."""
    bodies = crossed_ridges(gap=0.02)
    load = weight_load(bodies)
    weight = bodies.mass[1]
    rested, pairs, wrench = run(bodies, load, 0.6, 2000)
    half = 0.3 * np.sqrt(2.0)
    sunk = weight / (KN * bodies.corner_area.min())
    assert rested.pos[1, 2] - half == pytest.approx(-sunk, rel=1e-3)  # measured: 5.5e-7
    assert wrench[0, 2] == pytest.approx(-weight, rel=1e-4) and np.abs(wrench[0, :2]).max() < 1e-9 * weight
    assert np.degrees(k3.rotation_angle(rested.quat[1], np.array([1.0, 0.0, 0.0, 0.0]))) < 1e-6
    assert np.abs(rested.pos[1, :2]).max() < 1e-9
    assert len(pairs.faces) == 0 and len(pairs.corners) == 0 and len(pairs.edges) == 1
    fallen, _, _ = run(bodies, load, 0.6, 2000, edge_contacts=False)
    assert fallen.pos[1, 2] < -1.0


def test_a_free_symmetric_top_keeps_its_angular_momentum_and_precesses_at_l_over_i1():
    """No contact, no load: the angular momentum stays (world frame) and the symmetry axis turns about it at
    ``|L| / I1`` (I1 the inertia about a transverse axis)."""
    poly = mfp.boxes(np.array([[-0.5, -0.5, -1.0]]), np.array([[0.5, 0.5, 1.0]]))
    bodies = s3.bodies_of(poly, np.array([1.0]), np.array([False]), np.zeros(1, bool), np.zeros((1, 6)))
    motion = s3.at_rest(bodies)
    motion.omega[0] = (0.6, 0.0, 2.0)
    pairs = s3.new_pairs(bodies, np.zeros((0, 2), dtype=np.int64), np.zeros((0, 3)), np.zeros(0),
                         np.zeros((0, 3), dtype=np.int64), np.zeros(0), np.zeros((0, 4), dtype=np.int64), np.zeros(0))
    momentum = bodies.inertia[0] @ motion.omega[0]
    steps, dt = 20000, 1e-4
    k3.advance3(steps, bodies, pairs, k3.ContactLaw3(KN, KN, 0.0, 0.0, RECLIP_SHARE, BUFFER), motion,
                k3.Loading3(np.zeros((1, 6)), 0.0, 0.0, 0.0, 0.0, 0.0), k3.Stepping3(dt, 0.0, 1e9), np.zeros((1, 6)))
    r = rotation_of(motion.quat[0])
    after = r @ bodies.inertia[0] @ r.T @ motion.omega[0]
    assert np.linalg.norm(after - momentum) < 1e-3 * np.linalg.norm(momentum)
    axis, along = r[:, 2], momentum / np.linalg.norm(momentum)
    across0 = np.array([0.0, 0.0, 1.0]) - along[2] * along
    across = axis - (axis @ along) * along
    turned = np.arctan2(np.cross(across0, across) @ along, across0 @ across)
    expected = np.linalg.norm(momentum) / bodies.inertia[0][0, 0] * steps * dt
    assert np.mod(turned, 2 * np.pi) == pytest.approx(np.mod(expected, 2 * np.pi), abs=2e-3)


def test_a_block_with_a_non_convex_face_is_refused_by_name():
    """The clipping takes convex faces: an L-shaped prism (its two L faces non-convex) is refused naming the block,
    a box beside it is not."""
    x = np.array([0.0, 2.0, 2.0, 1.0, 1.0, 0.0, 3.0, 4.0, 4.0, 3.0])
    y = np.array([0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 0.0, 0.0, 1.0, 1.0])
    poly = mfp.prisms(x, y, np.array([6, 4]), np.array([0.5, 0.5]))
    with pytest.raises(mf.ModelError, match="block 0: face .* is not convex"):
        s3.bodies_of(poly, np.ones(2), np.zeros(2, bool), np.zeros(2, bool), np.zeros((2, 6)))
    box = mfp.boxes(np.array([[3.0, 0.0, -0.25]]), np.array([[4.0, 1.0, 0.25]]))
    assert s3.bodies_of(box, np.ones(1), np.zeros(1, bool), np.zeros(1, bool), np.zeros((1, 6))).mass[0] == 0.5
