"""The contact law is written twice (rigid blocks in kernels.py, nodes in deformable.py: one shared numba
function cost 30-55 % of the contact loop's speed, docs/fdem.md). The two copies are pinned to each other:
on random contact states of two blocks (penetration, sliding, bonds breaking or holding, dashpots), every
end's normal and shear force, spring energy, bond and history, the dissipation, and the nodal forces summed
per block equal the rigid law's, to round-off.

By design the two apply a contact end's force at different points: the rigid law at the point midway
between the two faces, the nodal law at each block's own face (shared between its two nodes); so the
moments differ by the force times half the gap, and each law reads the relative velocity at its own
points. The blocks here translate (no spin), where the velocities agree exactly.
"""
from __future__ import annotations

import numpy as np
import pytest

from masonryfw_fdem import deformable, kernels

N_ACC = kernels.N_ACC


def squares(rng):
    """Two unit squares, B on A, B shifted, turned a little and pressed in; centroid-relative vertices."""
    lx = np.array([-0.5, 0.5, 0.5, -0.5] * 2)
    ly = np.array([-0.5, -0.5, 0.5, 0.5] * 2)
    offs = np.array([0, 4, 8])
    pos = np.array([[0.0, 0.0, 0.0],
                    [rng.uniform(-0.4, 0.4), 1.0 - rng.uniform(2e-4, 1.5e-3), rng.uniform(-3e-3, 3e-3)]])
    return lx, ly, offs, pos


def compare_once(seed) -> dict:
    """One random state through both laws; asserts they agree, returns which branches it went through."""
    rng = np.random.default_rng(seed)
    lx, ly, offs, pos = squares(rng)
    driven = np.zeros(2, dtype=np.bool_)
    faces = kernels.detect_face_pairs(pos, lx, ly, offs, driven, 0.05, 0.1, np.cos(np.radians(40)))
    assert faces.shape[0] >= 1
    n_face = faces.shape[0]
    props = np.column_stack([rng.uniform(0.2, 0.8, n_face), rng.uniform(0.0, 0.5, n_face) * (seed % 2),
                             rng.uniform(0.0, 0.5, n_face) * (seed % 2), np.full(n_face, -1.0)])
    vel = rng.normal(scale=0.01, size=(2, 3))
    vel[:, 2] = 0.0  # translation: the same relative velocity at the mid-plane point and on each face
    mass = rng.uniform(0.5, 2.0, 2)
    kn, kt, min_half, damping, dt = 1e3, 5e2, 1e-3, rng.uniform(0.0, 0.3), 1e-4
    history = {"shear": rng.normal(scale=0.5, size=(n_face, 2)), "bonded": rng.integers(0, 2, (n_face, 2)),
               "normal": np.zeros((n_face, 2)), "energy": rng.uniform(0.0, 1e-3, (n_face, 2))}

    vx, vy = np.empty(8), np.empty(8)
    kernels.place_vertices(pos, lx, ly, offs, vx, vy)
    rigid = {k: v.copy() for k, v in history.items()}
    force, acc = np.zeros((2, 3)), np.zeros(N_ACC)
    bodies = kernels.Bodies(pos, np.ones(2), lx, ly, offs, np.repeat(mass[:, None], 3, axis=1), 1.0 / mass,
                            np.ones((2, 3), np.bool_), driven, driven, np.zeros((2, 3)))
    law = kernels.ContactLaw(kn, kt, min_half, damping)
    pairs = kernels.Pairs(faces, props, rigid["shear"], rigid["bonded"], rigid["normal"], rigid["energy"],
                          np.zeros((n_face, 4)))
    motion = kernels.Motion(pos, vel, pos.copy(), np.ones(2, dtype=np.int64), np.zeros(2, np.int64), acc)
    stored = kernels.contact_forces(bodies, pairs, law, motion, vx, vy, force, dt, True, 0.0)

    # the same state on nodes: each vertex moves with its block's rigid velocity; node inverse masses chosen
    # so that the nodal dashpot's mass (half the sum over the four nodes of a pair) is the blocks' reduced mass
    owner = np.repeat([0, 1], 4)
    node_vel = np.column_stack([vel[owner, 0] - vel[owner, 2] * (vy - pos[owner, 1]),
                                vel[owner, 1] + vel[owner, 2] * (vx - pos[owner, 0])])
    nodal = {k: v.copy() for k, v in history.items()}
    node_force, node_acc = np.zeros((8, 2)), np.zeros(N_ACC)
    mesh = deformable.Mesh(vx, vy, owner, np.zeros((0, 3), np.int64), np.zeros((0, 3)), np.zeros((0, 3)),
                           np.zeros(0), np.zeros(0), np.zeros(0), 1.0 / (1.0 / mass[owner]), 1.0 / mass[owner],
                           np.zeros(8, np.bool_), np.zeros(0, np.bool_))
    node_pairs = kernels.Pairs(faces, props, nodal["shear"], nodal["bonded"], nodal["normal"], nodal["energy"],
                               np.zeros((0, 4)))
    node_motion = deformable.NodeMotion(vx, vy, node_vel, vx.copy(), vy.copy(), node_acc)
    node_stored = deformable.node_contact_forces(offs, mesh, node_pairs, law, node_motion, node_force, dt, True)

    block_force = np.zeros((2, 2))
    np.add.at(block_force[:, 0], owner, node_force[:, 0])
    np.add.at(block_force[:, 1], owner, node_force[:, 1])
    assert np.abs(force[:, :2]).max() > 0  # something pushes
    assert np.abs(block_force - force[:, :2]).max() <= 1e-12 * np.abs(force[:, :2]).max()
    assert node_stored == pytest.approx(stored, rel=1e-12, abs=1e-15)
    for name in history:
        np.testing.assert_allclose(nodal[name], rigid[name], rtol=1e-12, atol=1e-15, err_msg=name)
    np.testing.assert_allclose(node_acc, acc, rtol=1e-12, atol=1e-18)
    return {"slides": acc[kernels.DISSIPATED_FRICTION] > 0, "bond breaks": (rigid["bonded"] < history["bonded"]).any(),
            "bond holds": rigid["bonded"].any(), "end opens": (rigid["normal"] == 0).any(),
            "dashpot": acc[kernels.DISSIPATED_DAMPING] != 0}


@pytest.mark.slow  # 24 s: both modes on one wall
def test_the_rigid_and_the_nodal_contact_law_agree_to_round_off():
    seen = [compare_once(seed) for seed in range(200)]
    for branch in seen[0]:
        assert any(s[branch] for s in seen), f"no random state went through: {branch}"
