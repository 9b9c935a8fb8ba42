"""3D models (``masonryfw_space = 3``): built, checked, saved and read back, refused where 2D is all there is."""
from __future__ import annotations

import numpy as np
import pytest
from support import cli, refused

import masonryfw as mf
import masonryfw.plugin_api as mfp


@pytest.fixture(scope="module")
def in_3d():
    """Test 12C's spec with ``space = 3``: the wall one block thick in 3D."""
    spec = dict(mf.load_spec(mf.bundled_spec_path("test-12c")))
    return mf.build({**spec, "space": 3}), mf.open_model("test-12c")


def test_a_spec_with_space_3_builds_the_wall_one_block_thick(in_3d):
    model, planar = in_3d
    assert mfp.space(model) == 3 and mfp.space(planar) == 2
    assert model.sizes["block"] == planar.sizes["block"]
    np.testing.assert_allclose(model.block_volume.values, planar.block_area.values * planar.block_thickness.values,
                               rtol=1e-12)
    np.testing.assert_allclose(model.block_centroid_z.values, planar.block_centroid_y.values, atol=1e-12)
    np.testing.assert_allclose(model.block_centroid_y.values, 0.0, atol=1e-12)
    # every planar joint is a rectangle: its length times the thickness
    pairs = {tuple(sorted(p)): a for p, a in zip(model.interface_blocks.values.tolist(), model.interface_area.values)}
    for (a, b), length in zip(planar.interface_blocks.values.tolist(), planar.interface_length.values):
        assert pairs[tuple(sorted((a, b)))] == pytest.approx(length * planar.block_thickness.values[a])
    assert model.dead_load.values[:, 2].sum() == pytest.approx(planar.dead_load.values[:, 1].sum())


def test_a_3d_model_is_saved_and_read_back_unchanged(in_3d, tmp_path):
    model, _ = in_3d
    path = mf.save(model, tmp_path / "wall3d.nc")
    back = mf.open_model(path)
    assert mfp.space(back) == 3
    assert mfp.content_sha256(back) == mfp.content_sha256(model)
    np.testing.assert_array_equal(back.block_volume.values, model.block_volume.values)


def broken(model, change):
    ds = model.copy(deep=True)
    change(ds)
    return [str(p) for p in mf.check(ds, "model")]


def test_the_checks_name_the_face_block_and_interface_at_fault(in_3d):
    model, _ = in_3d
    assert mf.check(model, "model") == []

    def beyond(ds):
        ds.face_nodes.values[5] = 9

    def flipped(ds):
        ds.face_nodes.values[:4] = ds.face_nodes.values[:4][::-1]

    def self_contact(ds):
        ds.interface_blocks.values[3] = [7, 7]

    def miscounted(ds):
        ds.block_face_count.values[0] = 5

    assert broken(model, beyond) == ["face 1: names vertex 9 of block 0, which has 8"]
    assert broken(model, flipped)[0].startswith("block 0: face 0 has an edge no other face of the block runs the "
                                                "other way")
    assert broken(model, self_contact) == ["interface 3: joins blocks [7, 7]: two different blocks of the 74 are "
                                           "needed"]
    assert broken(model, miscounted) == ["variable block_face_count: adds up to 443, but dimension face has 444"]


def test_a_spec_asks_for_space_2_or_3():
    spec = dict(mf.load_spec(mf.bundled_spec_path("test-12c")))
    with pytest.raises(mf.SpecError, match="space: must be 2 .* or 3 .*not 4"):
        mf.build({**spec, "space": 4})


def test_info_describes_a_3d_model(in_3d):
    lines = mf.describe_model(in_3d[0])
    assert "space: 3D" in lines
    assert any(line.startswith("masonry: x 0..1.1 m, y -0.05..0.05 m, z 0..0.6 m") for line in lines)


def test_la_solves_the_3d_model_to_the_planar_answer(in_3d):
    """alpha and the settlement reaction at collapse of the 3D twin against the planar la's."""
    model, planar = in_3d
    ours, theirs = mf.solve(model, "la"), mf.solve(planar, "la")
    assert float(ours.collapse_multiplier) == pytest.approx(float(theirs.collapse_multiplier), rel=1e-7)
    assert float(ours.moving_support_reaction) == pytest.approx(float(theirs.moving_support_reaction), rel=1e-6)
    assert ours.block_displacement.shape == (model.sizes["block"], 3)
    numbers = {n.name: n.value for n in mf.key_numbers(ours)}
    assert numbers["dead_reaction"] == pytest.approx(432.0)


def test_what_handles_2d_only_refuses_a_3d_model_before_it_starts(in_3d):
    model, _ = in_3d
    for solver in ("jmm", "jmm-limit", "la-incremental"):
        with pytest.raises(mf.SolveError, match=f"solver {solver} solves 2D models; 'Test 12C \\(3D twin\\)' is 3D"):
            mf.solve(model, solver)
    result = mf.solve(model, "la")
    with pytest.raises(mf.ModelError, match="the forces plot handles 2D models and results"):
        mf.render([result], "forces")
    with pytest.raises(mf.SolveError, match="non-associative friction is solved on Coulomb's cone"):
        mf.solve(model, "la", {"flow": "nonassociative", "pyramid_sides": 8})


def test_the_command_line_says_so_without_a_traceback(in_3d, tmp_path):
    path = mf.save(in_3d[0], tmp_path / "wall3d.nc")
    refused(cli(["solve", path, "--plugin", "jmm", "-o", tmp_path / "f.nc"], tmp_path), "solver jmm solves 2D models")
    cracks = tmp_path / "cracks.csv"
    cracks.write_text("crack,x,y\nc1,0.5,0.1\nc1,0.6,0.3\n")
    refused(cli(["diagnose", path, "--cracks", cracks, "-o", tmp_path / "d.nc"], tmp_path),
            "masonryfw diagnose handles 2D")


@pytest.mark.parametrize("name", ["test-12c", "panel-5", "facade-2"])
def test_the_comparable_fields_of_a_3d_twin_are_the_planar_ones(name):
    """Interface states, crack indicator and macro-blocks derived at the vertices of the 3D twin's interfaces
    against those derived at the ends of the planar interfaces (the same block pairs)."""
    planar = mf.open_model(name)
    a, b = mf.solve(planar, "la"), mf.solve(mf.checked_model(mfp.twin(planar)), "la")
    index = {tuple(sorted(p)): i for i, p in enumerate(b.interface_blocks.values.tolist())}
    same = np.array([index[tuple(sorted(p))] for p in a.interface_blocks.values.tolist()])
    np.testing.assert_array_equal(b.interface_state.values[same], a.interface_state.values)
    np.testing.assert_allclose(b.crack_indicator.values[same], a.crack_indicator.values, atol=1e-6)
    pairs = np.c_[a.macro_block.values, b.macro_block.values]
    assert len(np.unique(pairs, axis=0)) == len(np.unique(a.macro_block.values)) == len(np.unique(b.macro_block.values))


def test_the_supports_carry_the_masonry_the_house_weighs():
    """The support reactions of la's collapse state hold the masonry up: their sum is its weight and its floor
    loads, upward, and nothing sideways (the masonry's own equilibrium, from the vertex forces)."""
    model = mf.open_model("house-tunnel")
    result = mf.solve(model, "la")
    masonry = mfp.masonry_blocks(model.block_role.values)
    reaction = result.support_reaction.values
    load = -model.dead_load.values[masonry].sum(axis=0)
    np.testing.assert_allclose(reaction.sum(axis=0), load, atol=1e-7 * abs(load[2]))
    assert np.abs(reaction[masonry]).max() == 0.0


def test_a_finite_motion_opens_the_3d_twin_at_its_vertices_as_it_opens_the_plane_at_its_ends():
    """Block motions with finite rotations (to 0.3 rad) of a planar wall and the same motions of its 3D twin
    (x, z in the plane, the rotation about -y): every interface opens and slips as much at its vertices (the
    rotation vector's Rodrigues matrix) as the planar one at its ends (the planar finite motion), and the
    widest crack is the same joint, as wide."""
    from masonryfw.results.semantics3d import padded, vertex_motion

    planar = mf.open_model("panel-5")
    twin = mf.checked_model(mfp.twin(planar))
    u = np.random.default_rng(5).normal(scale=[0.01, 0.01, 0.1], size=(planar.sizes["block"], 3))
    u3 = np.c_[u[:, 0], np.zeros(len(u)), u[:, 1], np.zeros(len(u)), -u[:, 2], np.zeros(len(u))]
    opening, slip = mfp.relative_motion(planar, u, "finite")
    count = twin.interface_node_count.values.astype(np.int64)
    opening_3d, slip_3d = (padded(v, count) for v in vertex_motion(twin, u3, "finite"))
    index = {tuple(sorted(p)): i for i, p in enumerate(twin.interface_blocks.values.tolist())}
    same = np.array([index[tuple(sorted(p))] for p in planar.interface_blocks.values.tolist()])
    scale = np.abs(opening).max()
    np.testing.assert_allclose(np.sort(opening_3d[same], axis=1)[:, [0, -1]],
                               np.sort(opening, axis=1), atol=1e-12 * scale)
    np.testing.assert_allclose(np.abs(slip_3d[same]).max(axis=1), np.abs(slip).max(axis=1), atol=1e-12 * scale)
    a, b = mf.widest_crack(planar, u, "finite"), mf.widest_crack(twin, u3, "finite")
    assert b.width == pytest.approx(a.width, rel=1e-12) and a.width > 0.01
    assert same[a.interface] == b.interface
    assert b.base_gap == pytest.approx(a.base_gap, rel=1e-12)
