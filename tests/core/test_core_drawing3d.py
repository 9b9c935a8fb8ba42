"""3D drawings: an OBJ mesh of blocks read, cleaned, checked and stood on ground that follows a profile in plan;
the planar wall drawn in 3D is the planar wall."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.geometry import polyhedra

MATERIAL = {"unit_weight": 20000.0, "friction_angle": 30.0}
UNIT = {"length": 0.24, "height": 0.12}


def write_obj(path, poly: polyhedra.Polyhedra, layers=None, scale=1.0, inward=()) -> None:
    """``poly`` as an OBJ file: one object per block, its faces on its layer's material (``inward``: the blocks
    written with their faces turned in)."""
    lines = ["# written by the tests", "mtllib none.mtl"]
    first = 1
    starts = np.concatenate(([0], np.cumsum(poly.block_node_count)))
    face_starts = np.concatenate(([0], np.cumsum(poly.face_node_count)))
    face = 0
    for b in range(poly.n_block):
        lines.append(f"o block{b}")
        if layers is not None:
            lines.append(f"usemtl {layers[b]}")
        lines += [f"v {x * scale:.12g} {y * scale:.12g} {z * scale:.12g}"
                  for x, y, z in poly.vertices[starts[b]:starts[b + 1]]]
        for _ in range(poly.block_face_count[b]):
            nodes = poly.face_nodes[face_starts[face]:face_starts[face + 1]] + first
            lines.append("f " + " ".join(map(str, nodes[::-1] if b in inward else nodes)))
            face += 1
        first += int(poly.block_node_count[b])
    path.write_text("\n".join(lines) + "\n")


def planar_wall():
    return mf.build({"title": "wall", "wall": {"width": 2.4, "height": 1.2, "thickness": 0.12}, "unit": UNIT,
                     "bond": {"pattern": "running", "first_course": "full"}, "material": MATERIAL,
                     "settlement": {"profile": "gaussian", "width": 0.8, "center": 1.9, "segment": 0.06},
                     "loading": {"type": "settlement"}})


def masonry_of(model) -> polyhedra.Polyhedra:
    """The planar model's masonry stood in the x-z plane, 0.12 m thick about y = 0 (its 3D twin's blocks)."""
    masonry = mfp.masonry_blocks(model.block_role.values)
    counts = model.block_node_count.values
    nodes = np.repeat(masonry, counts)
    return polyhedra.prisms(model.node_x.values[nodes], model.node_y.values[nodes], counts[masonry],
                            np.full(int(masonry.sum()), 0.12))


def drawn_spec(path, **geometry):
    return {"title": "drawn", "space": 3, "geometry": {"mesh": str(path), **geometry}, "material": MATERIAL,
            "settlement": {"profile": "gaussian", "width": 0.8, "center_x": 1.9, "segment": 0.06}}


@pytest.mark.parametrize("unit, scale", [("m", 1.0), ("mm", 1000.0)])
def test_the_planar_wall_drawn_in_3d_is_the_planar_wall(tmp_path, unit, scale):
    """The 2D spec wall's blocks written as an OBJ (in m, and in mm with drawing_unit = "mm", every block's faces
    turned inwards in the second) and built as a 3D drawing: the ground made under it has the 2D segments'
    motions (two cells across its thickness), and alpha and the settlement reaction are the 2D programme's."""
    planar = planar_wall()
    masonry = masonry_of(planar)
    path = tmp_path / "wall.obj"
    write_obj(path, masonry, scale=scale, inward=range(masonry.n_block) if unit == "mm" else ())
    drawn = mf.build(drawn_spec(path, drawing_unit=unit))
    assert mfp.masonry_blocks(drawn.block_role.values).sum() == masonry.n_block
    moving_2d = planar.block_role.values == mfp.flags("block_role")["moving_support"]
    moving_3d = drawn.block_role.values == mfp.flags("block_role")["moving_support"]
    assert moving_3d.sum() == 2 * moving_2d.sum()
    a, b = mf.solve(planar, "la"), mf.solve(drawn, "la")
    assert float(b.collapse_multiplier) == pytest.approx(float(a.collapse_multiplier), rel=1e-7)
    assert float(b.moving_support_reaction) == pytest.approx(float(a.moving_support_reaction), rel=1e-7)
    if unit == "mm":
        assert drawn.attrs["laying_notes"].count("turned outward") == masonry.n_block


def box_obj(path, text_faces: str) -> None:
    path.write_text("o box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n" + text_faces)


CLOSED = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"


@pytest.mark.parametrize("faces, message", [
    (CLOSED.replace("f 4 1 5 8\n", ""), "block 'box' \\(line 10\\): not a closed solid: the edge from"),
    (CLOSED.replace("f 4 1 5 8", "f 8 5 1 4"), "is run the same way by two faces"),
    (CLOSED + "f 1 2 99\n", "line 16: the face names vertex 99, but the file has 8"),
    (CLOSED.replace("f 1 4 3 2", "f 1 4 x 2"), "line 10: 'f 1 4 x 2' is not a face"),
    ("", "no faces \\(f\\) in it"),
])
def test_a_broken_mesh_names_the_block_the_line_and_the_place(tmp_path, faces, message):
    path = tmp_path / "box.obj"
    box_obj(path, faces)
    with pytest.raises(mf.SpecError, match=message):
        mf.build(drawn_spec(path, snap_tolerance=1e-9))


def test_a_bent_face_and_a_missing_file_and_an_unknown_layer_are_refused(tmp_path):
    path = tmp_path / "box.obj"
    box_obj(path, CLOSED)
    text = path.read_text().replace("v 1 1 1", "v 1 1 1.2")
    path.write_text(text)
    with pytest.raises(mf.SpecError, match="block .box. \\(line 10\\): the face at line 11: is not planar \\(vertex \\("):
        mf.build(drawn_spec(path))
    with pytest.raises(mf.SpecError, match="'geometry.mesh' = '.*nowhere.obj': no such file"):
        mf.build(drawn_spec(tmp_path / "nowhere.obj"))
    box_obj(path, CLOSED)
    with pytest.raises(mf.SpecError, match="'geometry.layers.BEAMS': no block of the drawing is on that layer"):
        mf.build(drawn_spec(path, layers={"BEAMS": "lintel"}))


def test_a_house_drawn_in_3d_builds_checks_and_solves_from_a_spec_file(tmp_path):
    """The small toothed corner building (masonryfw.testing) written as OBJ with its lintel on its own layer, read
    back from a spec file next to it: the same masonry volume, the lintel's role from its layer; la solves it."""
    import masonryfw.testing as mt

    building = mt.corner_building()
    masonry = mfp.masonry_blocks(building.block_role.values)
    layers = ["LINTEL" if r == mfp.flags("block_role")["lintel"] else "BRICK"
              for r in building.block_role.values[masonry]]
    write_obj(tmp_path / "corner.obj", polyhedra.subset(mfp.polyhedra_of(building), masonry), layers=layers)
    spec = tmp_path / "corner.toml"
    spec.write_text(mf.dump_toml({**drawn_spec("corner.obj", layers={"LINTEL": "lintel"}),
                                  "settlement": {"profile": "gaussian", "width": 0.6, "axis_angle": 30.0,
                                                 "center_x": 1.4, "center_y": 0.2}}))
    drawn = mf.build(spec)
    assert mf.build(mf.load_spec(spec)).sizes == drawn.sizes  # what a sweep starts from: the mesh found absolutely
    drawn_masonry = mfp.masonry_blocks(drawn.block_role.values)
    assert drawn.block_volume.values[drawn_masonry].sum() == pytest.approx(
        building.block_volume.values[masonry].sum(), rel=1e-12)
    assert (drawn.block_role.values == mfp.flags("block_role")["lintel"]).sum() == layers.count("LINTEL")
    assert 0 < float(mf.solve(drawn, "la").collapse_multiplier) < 1


def test_the_bundled_3d_drawing_is_the_corner_its_generator_describes(tmp_path):
    """``drawn-corner`` (datasets/drawings): the file bundled is what its generator writes, and the model read
    from it holds the corner's masonry (two walls 2.4 and 1.8 m on their outer faces, 0.12 m thick, 1.2 m high,
    less a 0.48 x 0.36 m window) with its one lintel, stands on moving ground, and solves."""
    from importlib import resources

    from masonryfw.datasets.drawings import generate

    generate.write_obj(tmp_path / "corner.obj", *generate.drawn_corner())
    bundled = resources.files("masonryfw.datasets").joinpath("drawings", "drawn-corner.obj").read_text()
    assert bundled == (tmp_path / "corner.obj").read_text()
    model = mf.open_model("drawn-corner")
    masonry = mfp.masonry_blocks(model.block_role.values)
    assert model.block_volume.values[masonry].sum() == pytest.approx(0.12 * (2.4 + 1.8 - 0.12) * 1.2 - 0.12 * 0.48
                                                                     * 0.36, rel=1e-12)
    assert (model.block_role.values == mfp.flags("block_role")["lintel"]).sum() == 1
    assert (model.block_role.values == mfp.flags("block_role")["moving_support"]).sum() > 0
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


def test_a_mesh_that_is_not_text_is_refused_naming_the_file_before_it_is_read_whole(tmp_path):
    """The OBJ is read like every drawing (masonryfw.runtime.inputs.read_text): bounded, UTF-8, a regular file."""
    path = tmp_path / "box.obj"
    path.write_bytes(b"o box\nv 0 0 0\n\xff\xfe not text\n")
    with pytest.raises(mf.MasonryError, match="box.obj.*UTF-8"):
        mf.build(drawn_spec(path))
