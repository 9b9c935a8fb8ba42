"""Walls from drawings (DXF, CSV, GeoJSON): reading, cleaning, the [geometry] spec and its errors.

References are by hand or from the generator's own geometry (``masonryfw.datasets.drawings.generate``),
written to files here and read back.
"""
from __future__ import annotations

import json
import math

import ezdxf
import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.datasets.drawings import generate
from masonryfw.readers.drawing import read_drawing

ROLE = mfp.flags("block_role")
KIND = mfp.flags("interface_kind")


def spec(drawing: str, **sections) -> dict:
    """A tilt spec of ``drawing`` (in mm) with its lowest block as a fixed base."""
    out = {
        "title": "drawn",
        "geometry": {"dxf" if drawing.endswith(".dxf") else "polygons": drawing, "drawing_unit": "mm"},
        "wall": {"thickness": 0.1},
        "material": {"unit_weight": 12000.0, "friction_angle": 30.0},
        "supports": {"base": {"kind": "fixed", "select": "lowest"}},
        "loading": {"type": "tilt", "direction": 1},
    }
    for key, value in sections.items():
        if value is None:
            out.pop(key, None)
        elif isinstance(value, dict) and isinstance(out.get(key), dict) and key != "supports":
            out[key] = {k: v for k, v in {**out[key], **value}.items() if v is not None}
        else:
            out[key] = value
    return out


def write_spec(folder, drawing, **sections):
    path = folder / "wall.toml"
    path.write_text(mf.dump_toml(spec(drawing, **sections)))
    return path


def two_units_dxf(path, polygons=None, **kwargs):
    """Two 200 x 100 units side by side on a 500 x 50 base, in mm."""
    polygons = polygons or [[(0, 0), (200, 0), (200, 100), (0, 100)], [(200, 0), (400, 0), (400, 100), (200, 100)],
                            [(-50, -50), (450, -50), (450, 0), (-50, 0)]]
    generate.write_dxf(path, polygons, kwargs.pop("layers", ["0"] * len(polygons)), **kwargs)
    return path


# ---------------------------------------------------------------- reading and cleaning

def test_the_lact3_wall_drawing_reads_as_its_generator_drew_it(tmp_path):
    """183 blocks; T-junction marks and the lintel's repeated first vertex cleaned away: all rectangles."""
    polygons, _ = generate.lact3_wall()
    path = tmp_path / "wall.dxf"
    generate.write_dxf(path, polygons, ["0"] * len(polygons), insunits=1)
    drawing = read_drawing(path, "mm")
    assert drawing.block_node_count.size == len(polygons) == 183
    masonry = drawing.block_node_count[:-1]
    assert (masonry == 4).all()  # every unit and the lintel: four corners
    area = mfp.polygon_area_centroid(drawing.node_x, drawing.node_y, drawing.block_node_count)[0]
    assert area[-2] == pytest.approx(0.750 * (500 / 9) * 1e-3)  # the lintel, 750 mm long, one course high
    assert (area > 0).all()


def test_inches_in_the_header_are_refused_unless_the_unit_is_given(tmp_path):
    path = two_units_dxf(tmp_path / "w.dxf", insunits=1)
    with pytest.raises(mf.SpecError, match=r"\$INSUNITS = 1 .*inches.*drawing_unit"):
        read_drawing(path)
    assert read_drawing(path, "cm").node_x.max() == pytest.approx(4.5)


@pytest.mark.parametrize("insunits, scale", [(4, 1e-3), (5, 1e-2), (6, 1.0)])
def test_the_header_unit_is_used_when_it_is_a_length_we_know(tmp_path, insunits, scale):
    path = two_units_dxf(tmp_path / "w.dxf", insunits=insunits)
    assert read_drawing(path).node_x.max() == pytest.approx(450 * scale)


def test_a_polyline_going_on_past_its_start_and_points_around_it(tmp_path):
    """The arch: one voussoir polyline retraces its first edge, 125 POINTs are left out and counted."""
    polygons, layers = generate.lact3_arch()
    path = tmp_path / "arch.dxf"
    generate.write_dxf(path, polygons, layers, points=True)
    drawing = read_drawing(path)
    assert drawing.block_node_count[4] == 4
    assert drawing.ignored == {"POINT": sum(len(p) for p in polygons)}
    assert drawing.block_node_count[-1] == 12  # the base with the springers: non-convex
    assert not mfp.convex_blocks(drawing.node_x, drawing.node_y, drawing.block_node_count)[-1]


def test_arcs_become_chords_within_the_tolerance(tmp_path):
    """Every voussoir vertex lies on the intrados or extrados circle; no chord strays more than 1 mm from its arc."""
    polygons, layers = generate.settling_arch()
    path = tmp_path / "arch.dxf"
    generate.write_dxf(path, polygons, layers)
    drawing = read_drawing(path, chord_tolerance=1.0)
    arch = generate.ARCH
    start = mfp.block_offsets(drawing.block_node_count)
    cx, cy = (c / 1000 for c in arch["centre"])
    for b in range(arch["voussoirs"]):
        x, y = drawing.node_x[start[b]:start[b + 1]], drawing.node_y[start[b]:start[b + 1]]
        r = np.hypot(x - cx, y - cy)
        on_inner, on_outer = np.isclose(r, arch["inner"] / 1000), np.isclose(r, arch["outer"] / 1000)
        assert (on_inner | on_outer).all()
        for ring, radius in ((on_outer, arch["outer"] / 1000), (on_inner, arch["inner"] / 1000)):
            angles = np.sort(np.arctan2(y[ring] - cy, x[ring] - cx))
            sagitta = radius * (1 - np.cos(np.diff(angles) / 2))
            assert sagitta.max() <= 1e-3 + 1e-12 and ring.sum() >= 3  # the arc was divided


def test_arcs_without_a_tolerance_are_refused_naming_the_entity(tmp_path):
    polygons, layers = generate.settling_arch()
    path = tmp_path / "arch.dxf"
    generate.write_dxf(path, polygons, layers)
    with pytest.raises(mf.SpecError, match=r"LWPOLYLINE #\w+ on layer ARCH: has arc segments .*chord_tolerance"):
        read_drawing(path)


def test_an_open_polyline_is_refused_with_its_ends(tmp_path):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(0, 0), (100, 0), (100, 50), (0, 50)], close=False,
                                    dxfattribs={"layer": "WALL"})
    doc.saveas(tmp_path / "open.dxf")
    with pytest.raises(mf.SpecError, match=r"LWPOLYLINE #\w+ on layer WALL: open: it starts at \(0, 0\) m and ends "
                                           r"at \(0, 0.05\) m, 0.05 m apart, more than the snap tolerance"):
        read_drawing(tmp_path / "open.dxf")


def test_a_self_intersecting_outline_is_refused_with_where(tmp_path):
    bow_tie = [(0, 0), (100, 100), (100, 0), (0, 100)]
    path = two_units_dxf(tmp_path / "w.dxf", [bow_tie])
    with pytest.raises(mf.SpecError, match=r"crosses or touches itself \(Self-intersection\[0.05 0.05\]"):
        read_drawing(path)


def test_vertices_a_hair_apart_are_snapped_so_the_blocks_meet(tmp_path):
    """Two units drawn 1e-4 mm apart (CAD round-off): one interface after snapping, as if drawn exactly."""
    gap = 1e-4
    polygons = [[(0, 0), (200, 0), (200, 100), (0, 100)],
                [(200 + gap, 0), (400, 0), (400, 100), (200 + gap, 100)], [(-50, -50), (450, -50), (450, 0), (-50, 0)]]
    path = two_units_dxf(tmp_path / "w.dxf", polygons)
    write_spec(tmp_path, "w.dxf")
    model = mf.build(tmp_path / "wall.toml")
    assert sorted(np.bincount(model.interface_kind.values, minlength=4)[[KIND["head"], KIND["support"]]]) == [1, 2]
    assert read_drawing(path, "mm").node_x[4] == 0.2  # the later vertex moved onto the first drawn


def test_block_references_are_exploded_into_their_blocks(tmp_path):
    """A unit drawn once as a CAD block and inserted twice gives the same model as two polylines."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    unit = doc.blocks.new("UNIT")
    unit.add_lwpolyline([(0, 0), (200, 0), (200, 100), (0, 100)], close=True)
    msp = doc.modelspace()
    msp.add_blockref("UNIT", (0, 0))
    msp.add_blockref("UNIT", (200, 0))
    msp.add_lwpolyline([(-50, -50), (450, -50), (450, 0), (-50, 0)], close=True)
    doc.saveas(tmp_path / "insert.dxf")
    two_units_dxf(tmp_path / "plain.dxf")
    inserted, plain = read_drawing(tmp_path / "insert.dxf"), read_drawing(tmp_path / "plain.dxf")
    np.testing.assert_allclose(np.sort(inserted.node_x), np.sort(plain.node_x))
    np.testing.assert_allclose(np.sort(inserted.node_y), np.sort(plain.node_y))


def test_csv_and_geojson_give_the_model_of_the_dxf(tmp_path):
    polygons, layers = generate.stepped_wall()
    generate.write_dxf(tmp_path / "w.dxf", polygons, layers)
    generate.write_geojson(tmp_path / "w.geojson", polygons, layers)
    with open(tmp_path / "w.csv", "w") as handle:
        handle.write("block,x,y,layer\n")
        for i, (polygon, layer) in enumerate(zip(polygons, layers)):
            handle.writelines(f"b{i},{x},{y},{layer}\n" for x, y in polygon)
    sections = {"supports": {"base": {"kind": "fixed", "layer": "BASE"}, "settling": {"kind": "fixed", "layer": "SETTLE"}}}
    models = []
    for name in ("w.dxf", "w.geojson", "w.csv"):
        write_spec(tmp_path, name, **sections)
        models.append(mf.build(tmp_path / "wall.toml"))
    for other in models[1:]:
        np.testing.assert_allclose(other.node_x.values, models[0].node_x.values)
        np.testing.assert_array_equal(other.interface_blocks.values, models[0].interface_blocks.values)


@pytest.mark.parametrize("text, message", [
    ("block,x\n1,0\n", r"needs the columns block, x, y .*y missing"),
    ("block,x,y\na,0,0\na,1,zero\n", r"row 3: y = 'zero' is not a number"),
    ("block,x,y,layer\na,0,0,A\na,1,0,B\n", r"row 3: block 'a' is on layer 'A' in an earlier row, 'B' here"),
])
def test_a_bad_csv_row_is_named(tmp_path, text, message):
    (tmp_path / "b.csv").write_text(text)
    with pytest.raises(mf.SpecError, match=message):
        read_drawing(tmp_path / "b.csv", "m")


@pytest.mark.parametrize("geometry, message", [
    ({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 0]], [[0.2, 0.1], [0.3, 0.1], [0.3, 0.2]]]},
     r"feature 0: a polygon with 1 hole"),
    ({"type": "MultiPolygon", "coordinates": []}, r"feature 0: a MultiPolygon, not a Polygon"),
])
def test_a_geojson_feature_that_is_no_block_outline_is_named(tmp_path, geometry, message):
    (tmp_path / "b.geojson").write_text(json.dumps({"type": "FeatureCollection",
                                                     "features": [{"type": "Feature", "geometry": geometry}]}))
    with pytest.raises(mf.SpecError, match=message):
        read_drawing(tmp_path / "b.geojson", "m")


# ---------------------------------------------------------------- the [geometry] spec

def test_a_drawing_relative_to_its_spec_builds_a_checked_model(tmp_path):
    two_units_dxf(tmp_path / "w.dxf")
    model = mf.build(write_spec(tmp_path, "w.dxf"))
    assert model.block_role.values.tolist() == [ROLE["unit"], ROLE["unit"], ROLE["fixed_support"]]
    assert model.attrs["source_drawing"] == "w.dxf" and len(model.attrs["source_drawing_sha256"]) == 64
    weight = 12000.0 * 0.2 * 0.1 * 0.1
    np.testing.assert_allclose(mfp.block_loads(model, "live")[:2, 0], [weight, weight])  # tilt: weight towards +x


def test_settlement_loads_as_for_built_walls(tmp_path):
    """The moving support's dead load is W L_m / L_total: the right base carries 300 of the 400 mm of contact."""
    polygons = [[(0, 0), (200, 0), (200, 100), (0, 100)], [(200, 0), (400, 0), (400, 100), (200, 100)],
                [(-50, -50), (100, -50), (100, 0), (-50, 0)], [(100, -50), (450, -50), (450, 0), (100, 0)]]
    two_units_dxf(tmp_path / "w.dxf", polygons, layers=["0", "0", "BASE", "SETTLE"])
    model = mf.build(write_spec(tmp_path, "w.dxf", supports={"base": {"kind": "fixed", "layer": "BASE"},
                                                             "settle": {"kind": "moving", "layer": "SETTLE"}},
                                loading={"type": "settlement", "direction": None}))
    weight = 2 * 12000.0 * 0.2 * 0.1 * 0.1
    assert mf.dead_reaction(model) == pytest.approx(weight * 0.3 / 0.4)
    assert model.block_role.values[-1] == ROLE["moving_support"]


@pytest.mark.parametrize("sections, message", [
    ({"unit": {"length": 0.2, "height": 0.1}}, r"spec key 'unit' does not apply to a wall drawn in \[geometry\]"),
    ({"wall": {"thickness": 0.1, "width": 1.0}}, r"spec key 'wall.width' does not apply"),
    ({"supports": {"base": {"kind": "fixed", "start": 0.0, "end": 1.0}}}, r"'supports.base.start' does not apply"),
    ({"geometry": {"polygons": "w.csv"}}, r"exactly one of 'geometry.dxf' .* not both"),
    ({"geometry": {"drawing_unit": "in"}}, r"'geometry.drawing_unit' = 'in': must be one of 'm', 'cm', 'mm'"),
    ({"geometry": {"layers": {"A": "pier"}}}, r"'geometry.layers.A' = 'pier': must be one of 'unit', 'lintel'"),
    ({"supports": {"base": {"kind": "fixed"}}}, r"'supports.base': choose its blocks with exactly one of select"),
    ({"supports": {"base": {"kind": "fixed", "layer": "SETTLE"}}},
     r"'supports.base.layer' = 'SETTLE': no block of the drawing .* layers: 0"),
    ({"supports": {"base": {"kind": "fixed", "at": [9.0, 9.0]}}}, r"'supports.base.at' = \[9.0, 9.0\]: the point lies in no block"),
    ({"supports": {"base": {"kind": "fixed", "select": "lowest"}, "again": {"kind": "fixed", "at": [0.0, -0.02]}}},
     r"the point lies in no block"),
])
def test_spec_errors_name_the_key(tmp_path, sections, message):
    polygons = [[(0, 0), (200, 0), (200, 100), (0, 100)], [(0, 100), (200, 100), (200, 200), (0, 200)],
                [(-50, -50), (450, -50), (450, 0), (-50, 0)]]
    two_units_dxf(tmp_path / "w.dxf", polygons)
    with pytest.raises(mf.SpecError, match=message):
        mf.build(write_spec(tmp_path, "w.dxf", **sections))


def test_a_selection_that_ties_is_refused_naming_the_blocks(tmp_path):
    polygons = [[(0, 0), (400, 0), (400, 100), (0, 100)], [(-50, -50), (200, -50), (200, 0), (-50, 0)],
                [(200, -50), (450, -50), (450, 0), (200, 0)]]
    two_units_dxf(tmp_path / "w.dxf", polygons)
    with pytest.raises(mf.SpecError, match=r"'supports.base.select' = 'lowest': 2 blocks tie \(LWPOLYLINE"):
        mf.build(write_spec(tmp_path, "w.dxf"))


def test_a_support_that_touches_no_masonry_is_named_with_its_entity(tmp_path):
    polygons = [[(0, 0), (200, 0), (200, 100), (0, 100)], [(-50, -50), (450, -50), (450, 0), (-50, 0)],
                [(1000, 0), (1100, 0), (1100, 100), (1000, 100)]]
    two_units_dxf(tmp_path / "w.dxf", polygons, layers=["0", "0", "FAR"])
    path = write_spec(tmp_path, "w.dxf", supports={"base": {"kind": "fixed", "select": "lowest"},
                                                   "far": {"kind": "fixed", "layer": "FAR"}})
    with pytest.raises(mf.SpecError, match=r"'supports.far': LWPOLYLINE #\w+ on layer FAR touches no masonry"):
        mf.build(path)


def test_overlapping_blocks_are_named_with_their_entities(tmp_path):
    polygons = [[(0, 0), (200, 0), (200, 100), (0, 100)], [(150, 0), (400, 0), (400, 100), (150, 100)],
                [(-50, -50), (450, -50), (450, 0), (-50, 0)]]
    two_units_dxf(tmp_path / "w.dxf", polygons)
    with pytest.raises(mf.ModelError, match=r"block 0 \(LWPOLYLINE #\w+ on layer 0\): overlaps block 1 "
                                            r"\(LWPOLYLINE #\w+ on layer 0\) \(interpenetration 0.05 m\)"):
        mf.build(write_spec(tmp_path, "w.dxf"))


def test_ignored_layers_and_lintels(tmp_path):
    polygons = [[(0, 0), (200, 0), (200, 100), (0, 100)], [(200, 0), (400, 0), (400, 100), (200, 100)],
                [(-50, -50), (450, -50), (450, 0), (-50, 0)], [(600, 600), (700, 600), (700, 700), (600, 700)]]
    two_units_dxf(tmp_path / "w.dxf", polygons, layers=["0", "LINTEL", "0", "NOTES"])
    model = mf.build(write_spec(tmp_path, "w.dxf", geometry={"layers": {"LINTEL": "lintel", "NOTES": "ignore"}}))
    assert model.block_role.values.tolist() == [ROLE["unit"], ROLE["lintel"], ROLE["fixed_support"]]


def test_the_same_drawing_in_m_and_in_mm_gives_the_same_model(tmp_path):
    polygons, layers = generate.stepped_wall()
    generate.write_dxf(tmp_path / "mm.dxf", polygons, layers)
    generate.write_dxf(tmp_path / "m.dxf", [[(x / 1000, y / 1000) for x, y in p] for p in polygons], layers, insunits=6)
    sections = {"supports": {"base": {"kind": "fixed", "layer": "BASE"}, "settling": {"kind": "moving", "layer": "SETTLE"}},
                "loading": {"type": "settlement", "direction": None}}
    in_mm = mf.build(write_spec(tmp_path, "mm.dxf", **sections))
    in_m = mf.build(write_spec(tmp_path, "m.dxf", geometry={"drawing_unit": None}, **sections))
    np.testing.assert_allclose(in_m.node_x.values, in_mm.node_x.values, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(mfp.block_loads(in_m, "dead"), mfp.block_loads(in_mm, "dead"), rtol=1e-12)


@pytest.mark.parametrize("name", mf.DRAWN_NAMES)
def test_every_drawn_example_builds_and_passes_check(name):
    model = mf.open_model(name)
    assert mf.check(model) == []
    assert model.attrs["source_drawing"].split(".")[0] == name


def test_load_spec_makes_the_drawing_path_absolute(tmp_path):
    two_units_dxf(tmp_path / "w.dxf")
    loaded = mf.load_spec(write_spec(tmp_path, "w.dxf"))
    assert loaded["geometry"]["dxf"] == str((tmp_path / "w.dxf").resolve())
    assert mf.build(loaded).sizes["block"] == 3  # a dict without a folder still finds it


def test_the_tilt_angle_of_a_rigid_block_on_a_slope_is_its_friction_angle_or_its_toppling_angle(tmp_path):
    """A single b x h block on a base: alpha = min(mu, b / h) (sliding or toppling), drawn in a DXF."""
    for b, h, mu, expected in ((200, 100, math.tan(math.radians(30)), math.tan(math.radians(30))),
                               (100, 300, 0.9, 1 / 3)):
        polygons = [[(0, 0), (b, 0), (b, h), (0, h)], [(-50, -50), (b + 50, -50), (b + 50, 0), (-50, 0)]]
        two_units_dxf(tmp_path / "one.dxf", polygons)
        model = mf.build(write_spec(tmp_path, "one.dxf", material={"friction": mu, "friction_angle": None}))
        assert float(mf.solve(model, "la").collapse_multiplier) == pytest.approx(expected, rel=1e-9)
