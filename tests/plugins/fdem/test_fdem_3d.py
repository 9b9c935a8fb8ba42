"""fdem on 3D models against fdem on the plane (a second formulation: polygons with three dofs against polyhedra
with six): a wall's 3D twin settles as the wall does. And what fdem does not do in 3D yet is refused before the
work, by name."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_fdem.scene3d import build_scene3, with_rotation_scaled

#: The twin at the planar run's contact stiffness (3D's default is eight times it: docs/fdem.md, "In 3D").
PLANAR_STIFFNESS = {"penetration_ratio": 1e-4}


@pytest.fixture(scope="module")
def settled():
    planar = mf.open_model("test-12c")
    twin = mf.checked_model(mfp.twin(planar))
    return planar, twin, mf.solve(planar, "fdem"), mf.solve(twin, "fdem", PLANAR_STIFFNESS)


def settlement_records(result):
    at = result.step_phase.values == 1
    return result.step_settlement.values[at], result.step_reaction.values[at]


def test_the_3d_twin_of_test_12c_settles_with_the_planar_reaction_history(settled):
    """Reaction against settlement within 2 % of R0 of the planar run's all the way, the same minimum to 1 %."""
    _, _, planar, twin = settled
    (s2, r2), (s3, r3) = settlement_records(planar), settlement_records(twin)
    r0 = r2[0]
    grid = np.linspace(0.0, min(s2[-1], s3[-1]), 60)
    assert np.abs(np.interp(grid, s3, r3) - np.interp(grid, s2, r2)).max() < 0.02 * r0
    assert r3.min() == pytest.approx(r2.min(), abs=0.01 * r0)
    assert twin.attrs["stood"] == 1 and twin.attrs["stop_reason"] in ("target settlement", "reaction plateau")


def test_the_3d_twin_cracks_where_the_wall_cracks_as_wide(settled):
    """The same cracked joints (F1 >= 0.9, by block pair), the widest crack within 5 %, no motion out of the plane
    beyond 1e-6 of the motion in it."""
    planar_model, twin_model, planar, twin = settled
    pairs = {tuple(sorted(p)) for p in planar_model.interface_blocks.values[mf.cracked_joints(planar)].tolist()}
    found = {tuple(sorted(p)) for p in twin_model.interface_blocks.values[mf.cracked_joints(twin)].tolist()}
    f1 = 2 * len(pairs & found) / (len(pairs) + len(found))
    assert f1 >= 0.9, (sorted(pairs - found), sorted(found - pairs))
    assert twin.step_crack_width_max.values[-1] == pytest.approx(planar.step_crack_width_max.values[-1], rel=0.05)
    motion = twin.block_displacement.values
    assert np.abs(motion[:, 1]).max() <= 1e-6 * np.abs(motion[:, [0, 2]]).max()
    assert np.abs(twin.block_rotation.values[:, [0, 2]]).max() <= 1e-6 * np.abs(twin.block_rotation.values[:, 1]).max()
    assert twin.step_damage_category.values[-1] == planar.step_damage_category.values[-1]
    assert not mf.check(twin, "result")


def test_what_fdem_does_not_do_in_3d_is_refused_by_name(settled):
    _, twin, _, _ = settled
    with pytest.raises(mf.SolveError, match="mode = 'deformable' solves 2D models"):
        mf.solve(twin, "fdem", {"mode": "deformable"})
    held = twin.assign(block_role=twin.block_role.copy(data=np.where(
        mfp.moving_blocks(twin.block_role.values), mfp.ROLE["fixed_support"], twin.block_role.values)))
    tilted = held.assign(live_load=held.dead_load.copy(data=np.c_[-held.dead_load.values[:, 2],
                                                                    np.zeros((held.sizes["block"], 2))]))
    with pytest.raises(mf.SolveError, match="the load-factor search .* solves 2D models"):
        mf.solve(mf.checked_model(tilted.assign(settlement_direction=tilted.settlement_direction * 0)), "fdem")


def test_a_3d_run_keeps_its_snapshots_as_rotation_vectors():
    """Snapshots of a 3D run: the displacement (x, y, z) and the rotation vector of every block at the first
    record past each requested settlement; the last one, taken at the end, is the final state."""
    twin = mf.checked_model(mfp.twin(mf.open_model("test-8c")))
    result = mf.solve(twin, "fdem", {"snapshots": "0.0005,0.002", **PLANAR_STIFFNESS})
    assert result.snapshot_block_displacement.shape == (2, twin.sizes["block"], 3)
    assert result.snapshot_block_rotation.shape == (2, twin.sizes["block"], 3)
    settled = result.snapshot_settlement.values
    assert 0.0005 <= settled[0] < settled[1] and settled[1] >= 0.002
    assert np.abs(result.snapshot_block_rotation.values[:, :, [0, 2]]).max() <= 1e-9 * np.abs(
        result.snapshot_block_rotation.values[:, :, 1]).max()


def test_the_3d_key_numbers_place_the_widest_crack_where_the_plane_does(settled):
    """The widest crack's joint midpoint: (x, y) on the plane, (x, 0, z = y) on its twin (the 3D polygon's
    vertices' mean)."""
    _, _, planar, twin = settled
    flat = {n.name: n.value for n in mf.key_numbers(planar)}
    solid = {n.name: n.value for n in mf.key_numbers(twin)}
    assert solid["crack_x"] == pytest.approx(flat["crack_x"], abs=1e-9)
    assert solid["crack_z"] == pytest.approx(flat["crack_y"], abs=1e-9)
    assert solid["crack_y"] == pytest.approx(0.0, abs=1e-12)
    assert solid["damage_category"] == flat["damage_category"]


def test_the_scaled_rotation_steps_sqrt_3_longer_on_boxes_and_settles_as_the_physical_inertia():
    """A box's corner springs hold its rotation three times as stiffly (per inertia) as its translation (per
    mass), so scaling each box's inertia by 3 makes the time step sqrt(3) longer (a closed form: a box's 6 x 6
    bound); the masses and loads are untouched, and the twin of Test 8C settles with the physical inertia's
    reaction history to 0.5 % of R0, the same category and widest crack to 2 %."""
    twin = mf.checked_model(mfp.twin(mf.open_model("test-8c")))
    physical = build_scene3(twin)
    scaled = with_rotation_scaled(physical)
    assert scaled.critical_time_step(1.0) / physical.critical_time_step(1.0) == pytest.approx(np.sqrt(3.0), rel=1e-9)
    assert np.array_equal(scaled.bodies.mass, physical.bodies.mass) and np.array_equal(scaled.dead, physical.dead)
    runs = [mf.solve(twin, "fdem", {"rotational_inertia": kind, **PLANAR_STIFFNESS}) for kind in ("physical", "scaled")]
    (s1, r1), (s2, r2) = (settlement_records(run) for run in runs)
    grid = np.linspace(0.0, min(s1[-1], s2[-1]), 60)
    assert np.abs(np.interp(grid, s2, r2) - np.interp(grid, s1, r1)).max() < 0.005 * r1[0]
    assert runs[1].attrs["fdem_steps"] < 0.6 * runs[0].attrs["fdem_steps"]
    assert runs[1].step_crack_width_max.values[-1] == pytest.approx(runs[0].step_crack_width_max.values[-1], rel=0.02)
    assert runs[1].step_damage_category.values[-1] == runs[0].step_damage_category.values[-1]
