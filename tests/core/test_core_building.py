"""Buildings from a spec's ``[building]`` table: laid once, toothed at the corners, the same wall as in 2D."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

ROLE = mfp.flags("block_role")
MATERIAL = {"unit_weight": 20000.0, "friction_angle": 30.0}
UNIT = {"length": 0.24, "height": 0.12}


def wall(name, start, end, openings=(), height=1.2, thickness=0.12):
    return {"name": name, "start": list(start), "end": list(end), "height": height, "thickness": thickness,
            "openings": [dict(o) for o in openings]}


def house_spec(**settlement):
    """A 2.4 x 1.8 m house of four walls 1.2 m high (ten courses), a door and a window, a floor on two walls,
    over a tunnel whose axis runs at 60 degrees to x."""
    walls = [wall("south", (0, 0), (2.4, 0), [{"x": 0.96, "y": 0.0, "width": 0.48, "height": 0.72}]),
             wall("east", (2.4, 0), (2.4, 1.8), [{"x": 0.6, "y": 0.48, "width": 0.48, "height": 0.36}]),
             wall("north", (2.4, 1.8), (0, 1.8)), wall("west", (0, 1.8), (0, 0))]
    return {"title": "A small house", "building": {"unit": UNIT, "walls": walls,
                                                   "floors": [{"walls": ["south", "north"], "height": 1.2,
                                                               "load": 2000.0}]},
            "material": MATERIAL,
            "settlement": settlement or {"profile": "tunnel", "volume_loss": 2.0, "diameter": 3.0, "depth": 6.0,
                                         "axis_angle": 60.0, "center_x": 2.0, "center_y": 0.5}}


@pytest.fixture(scope="module")
def house():
    return mf.build(house_spec())


def box_bounds(model):
    owner = np.repeat(np.arange(model.sizes["block"]), model.block_node_count.values)
    points = np.c_[model.node_x.values, model.node_y.values, model.node_z.values]
    low = np.full((model.sizes["block"], 3), np.inf)
    high = np.full((model.sizes["block"], 3), -np.inf)
    np.minimum.at(low, owner, points)
    np.maximum.at(high, owner, points)
    return low, high


def test_the_house_is_laid_once_over_its_walls_less_its_openings(house):
    """Its masonry fills the walls' footprint (centre lines 2.4 x 1.8 m, 0.12 m thick: 2 t (a + b) in plan) times
    1.2 m, less the door and the window, exactly; no two blocks overlap (the walls run along x and y: boxes)."""
    masonry = mfp.masonry_blocks(house.block_role.values)
    t = 0.12
    expected = 2 * t * (2.4 + 1.8) * 1.2 - t * (0.48 * 0.72 + 0.48 * 0.36)
    assert house.block_volume.values[masonry].sum() == pytest.approx(expected, rel=1e-12)
    low, high = box_bounds(house)
    common = np.clip(np.minimum(high[:, None], high[None]) - np.maximum(low[:, None], low[None]), 0, None).prod(-1)
    np.fill_diagonal(common, 0.0)
    assert common.max() < 1e-12


def test_the_corners_are_toothed_course_by_course(house):
    """The block filling each corner's square alternates between the two walls from course to course."""
    low, high = box_bounds(house)
    masonry = mfp.masonry_blocks(house.block_role.values)
    centre = 0.5 * (low + high)
    for corner in ((2.4, 0.0), (2.4, 1.8), (0.0, 1.8), (0.0, 0.0)):
        owners = []
        for course in range(10):
            z = (course + 0.5) * 0.12
            inside = (masonry & (low[:, 0] <= corner[0] - 0.05) & (high[:, 0] >= corner[0] + 0.05)
                      & (low[:, 1] <= corner[1] - 0.05) & (high[:, 1] >= corner[1] + 0.05)
                      & (np.abs(centre[:, 2] - z) < 0.01))
            assert inside.sum() == 1, (corner, course)
            block = int(np.flatnonzero(inside)[0])
            owners.append("x" if high[block, 0] - low[block, 0] > high[block, 1] - low[block, 1] else "y")
        assert all(a != b for a, b in zip(owners[:-1], owners[1:])), (corner, owners)


def test_an_inner_wall_is_toothed_into_the_walls_it_abuts():
    """A cross wall from the south to the north wall (a T at each end): the masonry fills the walls' footprint
    in plan times their height (the cross wall between the others' inner faces), no two blocks overlap, and
    the block in each T's square is the through wall's in even courses and the cross wall's in odd ones."""
    spec = house_spec()
    spec["building"]["walls"].append(wall("cross", (1.2, 0.0), (1.2, 1.8)))
    spec["building"]["walls"][0]["openings"] = []
    spec["building"]["walls"][1]["openings"] = []
    model = mf.build(spec)
    masonry = mfp.masonry_blocks(model.block_role.values)
    t = 0.12
    expected = (2 * t * (2.4 + 1.8) + t * (1.8 - t)) * 1.2
    assert model.block_volume.values[masonry].sum() == pytest.approx(expected, rel=1e-12)
    low, high = box_bounds(model)
    common = np.clip(np.minimum(high[:, None], high[None]) - np.maximum(low[:, None], low[None]), 0, None).prod(-1)
    np.fill_diagonal(common, 0.0)
    assert common.max() < 1e-12
    for tee in ((1.2, 0.0), (1.2, 1.8)):
        for course in range(10):
            z = (course + 0.5) * 0.12
            inside = (masonry & (low[:, 0] <= tee[0] - 0.05) & (high[:, 0] >= tee[0] + 0.05)
                      & (low[:, 1] <= tee[1] - 0.05) & (high[:, 1] >= tee[1] + 0.05)
                      & (np.abs(0.5 * (low[:, 2] + high[:, 2]) - z) < 0.01))
            block = int(np.flatnonzero(inside)[0])
            along_y = high[block, 1] - low[block, 1] > high[block, 0] - low[block, 0]
            assert along_y == (course % 2 == 1), (tee, course)
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


def test_openings_have_lintels_and_floors_load_their_course(house):
    assert int((house.block_role.values == ROLE["lintel"]).sum()) == 2
    masonry = mfp.masonry_blocks(house.block_role.values)
    weight = 20000.0 * house.block_volume.values[masonry].sum()
    # the top course is odd: the later-listed wall of each corner runs through it; south stops short of both its
    # corners (2.4 - 0.12 m), north runs through its corner with east and stops short of west's (2.4 m)
    floors = 2000.0 * ((2.4 - 0.12) + 2.4)
    assert -house.dead_load.values[masonry, 2].sum() == pytest.approx(weight + floors, rel=1e-12)


DOOR = {"x": 0.96, "y": 0.0, "width": 0.48, "height": 0.72, "lintel_bearing": 0.12}


@pytest.mark.parametrize("openings", [[], [DOOR]], ids=["plain", "with a door"])
def test_a_straight_building_wall_is_the_planar_wall(openings):
    """The same wall over the same trough from a 2D spec (2D builder, 2D programme) and as a building of one wall
    (3D builder, 3D programme): the same support motions, alpha and settlement reaction. With a door on the
    ground the segments under it touch no masonry and carry nothing in both (3D support loads by contact area
    as 2D's by contact length; they went by the footprint)."""
    planar = mf.build({"title": "wall", "wall": {"width": 2.4, "height": 1.2, "thickness": 0.12}, "unit": UNIT,
                       "bond": {"pattern": "running", "first_course": "full"}, "material": MATERIAL,
                       "openings": openings,
                       "settlement": {"profile": "gaussian", "width": 0.8, "center": 1.9, "segment": 0.06},
                       "loading": {"type": "settlement"}})
    building = mf.build({"title": "wall", "building": {"unit": UNIT, "segment": 0.06,
                                                       "walls": [wall("w", (0, 0), (2.4, 0), openings)]},
                         "material": MATERIAL, "settlement": {"profile": "gaussian", "width": 0.8, "center_x": 1.9}})
    if not openings:  # the 2D wall lays no ground under a door, the building does (unloaded): the same blocks else
        assert building.sizes["block"] == planar.sizes["block"]
        moving = planar.block_role.values == ROLE["moving_support"]
        np.testing.assert_allclose(building.settlement_direction.values[moving][:, [0, 2, 4]],
                                   planar.settlement_direction.values[moving] * [1, 1, -1], atol=1e-12)
    a, b = mf.solve(planar, "la"), mf.solve(building, "la")
    assert float(b.collapse_multiplier) == pytest.approx(float(a.collapse_multiplier), rel=1e-7)
    assert float(b.moving_support_reaction) == pytest.approx(float(a.moving_support_reaction), rel=1e-7)


def test_a_door_on_the_ground_leaves_its_segments_unloaded_and_the_rest_share_the_weight_by_contact():
    """By hand: a wall 2.4 x 1.2 x 0.12 m of 20 kN/m3 with a door 0.48 x 0.72 m at x 0.96 (its lintel masonry too)
    weighs W = 20000 (2.4 x 1.2 - 0.48 x 0.72) 0.12 = 6082.56 N. On ten segments of 0.24 m, all settling under
    a trough over the wall, the two under the door touch no masonry: each of the other eight carries W / 8 up as
    dead load and down as live load, the two nothing."""
    model = mf.build({"title": "door", "building": {"unit": UNIT, "segment": 0.24,
                                                    "walls": [wall("w", (0, 0), (2.4, 0), [DOOR])]},
                      "material": MATERIAL, "settlement": {"profile": "gaussian", "width": 3.0, "center_x": 1.2}})
    ground = ~mfp.masonry_blocks(model.block_role.values)
    assert (model.block_role.values[ground] == ROLE["moving_support"]).all()
    low, high = box_bounds(model)
    middle = 0.5 * (low[ground, 0] + high[ground, 0])
    under_door = (middle > 0.96) & (middle < 1.44)
    weight = 20000.0 * (2.4 * 1.2 - 0.48 * 0.72) * 0.12
    assert -model.dead_load.values[~ground, 2].sum() == pytest.approx(weight, rel=1e-12)
    assert under_door.sum() == 2
    np.testing.assert_allclose(model.dead_load.values[ground, 2], np.where(under_door, 0.0, weight / 8), rtol=1e-12,
                               atol=1e-9)
    np.testing.assert_allclose(model.live_load.values[ground, 2], -model.dead_load.values[ground, 2], atol=1e-12)


def test_the_corner_buildings_ground_carries_the_weight_by_its_contact_with_the_masonry_in_plan():
    """An independent construction of the 3D rule on the corner building (two toothed walls, a door on the
    ground): each ground block's share is the area, by shapely in plan, of its top face under the first course's
    bottom faces, over that of all the ground; the builder's loads come from the contacts it finds in 3D."""
    import shapely

    from masonryfw.testing import corner_building

    model = corner_building()
    poly = mfp.polyhedra_of(model)
    index = poly.face_vertex_index()
    starts = np.r_[0, np.cumsum(poly.face_node_count)[:-1]]
    block = poly.face_block()
    normal, _, centre = mfp.face_normals_areas(poly)
    faces = [poly.vertices[index[a:a + n], :2] for a, n in zip(starts, poly.face_node_count)]
    ground = ~mfp.masonry_blocks(model.block_role.values)
    level = poly.vertices[:, 2][np.repeat(~ground, poly.block_node_count)].min()
    bottoms = [f for f, b, nz, c in zip(faces, block, normal[:, 2], centre) if not ground[b] and nz < -0.99
               and abs(c[2] - level) < 1e-9]
    under = shapely.union_all([shapely.Polygon(f) for f in bottoms])
    tops = {b: shapely.Polygon(f) for f, b, nz in zip(faces, block, normal[:, 2]) if ground[b] and nz > 0.99}
    area = np.array([tops[b].intersection(under).area if b in tops else 0.0 for b in range(block.max() + 1)])
    weight = -model.dead_load.values[~ground, 2].sum()
    moving = model.block_role.values == ROLE["moving_support"]
    assert (area[moving] == 0).any(), "the door's ground carries nothing"
    np.testing.assert_allclose(model.dead_load.values[moving, 2], weight * area[moving] / area.sum(), rtol=1e-9,
                               atol=1e-9 * weight)


def test_a_wall_along_y_is_the_wall_along_x_turned():
    """The same one-wall building along y with the trough's axis turned with it: the same alpha."""
    along_x = {"profile": "gaussian", "width": 0.8, "center_x": 1.9, "axis_angle": 90.0}
    along_y = {"profile": "gaussian", "width": 0.8, "center_y": 1.9, "axis_angle": 180.0}
    alphas = [float(mf.solve(mf.build({"title": "w", "building": {"unit": UNIT, "walls": [wall("w", (0, 0), end)]},
                                       "material": MATERIAL, "settlement": profile}), "la").collapse_multiplier)
              for end, profile in (((2.4, 0), along_x), ((0, 2.4), along_y))]
    assert alphas[1] == pytest.approx(alphas[0], rel=1e-7)


@pytest.mark.parametrize("change, message", [
    (lambda s: s["building"]["walls"][1].update(end=[5.6, 1.8]),
     "walls 'south' and 'east' meet at 29.36 degrees: walls are toothed at 30 degrees or more"),
    (lambda s: s["building"]["walls"][0].update(height=1.25), "not whole courses"),
    (lambda s: s["building"]["walls"][0]["openings"][0].update(x=2.2), "does not fit in the wall"),
    (lambda s: s["building"]["floors"][0].update(walls=["attic"]), "must list walls by name"),
    (lambda s: s["building"]["walls"][0]["openings"].append({"x": 1.2, "y": 0.72, "width": 0.48, "height": 0.24}),
     "wall 'south': its openings, lintels and the walls it meets overlap in course 6"),
    (lambda s: s.pop("settlement"), "spec table 'settlement' is missing"),
    (lambda s: s.update(space=2), "a \\[building\\] is 3D"),
    (lambda s: s["settlement"].update(center_x=400.0), "nothing settles under it"),
    (lambda s: s["building"]["walls"][0].update(colour="red"), "unknown spec key 'building.walls\\[0\\].colour'"),
])
def test_a_bad_building_spec_names_the_key_or_the_walls(change, message):
    spec = house_spec()
    change(spec)
    with pytest.raises(mf.SpecError, match=message):
        mf.build(spec)


def test_an_opening_off_the_bed_joints_is_moved_onto_them_and_said():
    spec = house_spec()
    spec["building"]["walls"][2]["openings"] = [{"x": 0.72, "y": 0.5, "width": 0.48, "height": 0.3}]
    notes = mf.build(spec).attrs["laying_notes"]
    assert "wall 'north' openings[0]: sill and head moved onto bed joints (y 0.48 m, height 0.36 m)" in notes


def test_the_engineers_stages_of_a_straight_building_wall_are_the_planar_walls():
    """A tunnel under a one-wall building and under the same wall from a 2D spec: the same greenfield slope and
    settlement (stage 1) and LTSM strain (stage 2) at S_max."""
    tunnel = {"profile": "tunnel", "volume_loss": 2.0, "diameter": 3.0, "depth": 6.0}
    planar = mf.build({"title": "wall", "wall": {"width": 2.4, "height": 1.2, "thickness": 0.12}, "unit": UNIT,
                       "bond": {"pattern": "running", "first_course": "full"}, "material": MATERIAL,
                       "settlement": {**tunnel, "center": 1.9}, "loading": {"type": "settlement"}})
    building = mf.build({"title": "wall", "building": {"unit": UNIT, "walls": [wall("w", (0, 0), (2.4, 0))]},
                         "material": MATERIAL, "settlement": {**tunnel, "center_x": 1.9}})
    a, b = mfp.assess(planar, 0.02), mfp.assess(building, 0.02)
    for name in ("slope", "greenfield_settlement", "strain"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-9), name
    assert {part.wall for part in b.parts} == {"w"}


@pytest.mark.parametrize("degrees", [0.0, 60.0, 30.0, 135.0, 180.0])
def test_a_walls_cut_of_the_greenfield_surface_is_the_surface_along_it(degrees):
    """The trough along a wall at an angle to the axis (``wall_profile``): its settlement and its horizontal
    movement along the wall are the plan profile's at the wall's points, projected."""
    from masonryfw.ground.assessment import wall_profile
    from masonryfw.ground.profiles import Profile

    profile = Profile("tunnel", 0.1, 0.01, center=0.3, width=3.0, depth=6.0)
    angle = np.radians(degrees)
    offset, cosine = -1.2, np.cos(angle)
    cut = wall_profile(profile, offset, cosine)
    s = np.linspace(-4.0, 9.0, 101)
    u = offset + cosine * s
    np.testing.assert_allclose(cut.rate(s), profile.rate(u), atol=1e-14)
    np.testing.assert_allclose(cut.horizontal(s), cosine * profile.horizontal(u), atol=1e-14)


def test_a_wall_along_the_trough_axis_settles_uniformly_and_is_not_strained():
    from masonryfw.ground.assessment import wall_profile
    from masonryfw.ground.profiles import Profile

    assert wall_profile(Profile("tunnel", 0.1, 0.01, center=0.3, width=3.0, depth=6.0), -1.2, 0.0) is None


def test_a_building_spec_is_read_validated_and_built_again(tmp_path):
    """``load_spec`` of a building (what a sweep or a script starts from), then ``build`` of what it returned."""
    path = tmp_path / "house.toml"
    path.write_text(mf.dump_toml(house_spec()))
    spec = mf.load_spec(path)
    assert mf.build(spec).sizes["block"] == mf.build(house_spec()).sizes["block"]
    broken = {**house_spec(), "building": {**house_spec()["building"], "floors": [{"walls": ["attic"], "height": 1.2,
                                                                                  "load": 1.0}]}}
    path.write_text(mf.dump_toml(broken))
    with pytest.raises(mf.SpecError, match="must list walls by name"):
        mf.load_spec(path)
    high = {**house_spec(), "building": {**house_spec()["building"], "floors": [{"walls": ["south"], "height": 60.0,
                                                                                "load": 1.0}]}}
    with pytest.raises(mf.SpecError, match="no course of the walls south ends there"):
        mf.load_spec(high)


def test_load_spec_reads_a_building_without_laying_it(monkeypatch):
    """Validating a building's spec reads and checks every key, but lays no block (it laid the whole building)."""
    import masonryfw.builders.building as building

    def refuse(*args, **kwargs):
        raise AssertionError("load_spec laid the building")

    monkeypatch.setattr(building, "lay_masonry", refuse)
    assert mf.load_spec(house_spec()) == house_spec()
    with pytest.raises(AssertionError, match="laid the building"):
        mf.build(house_spec())


def test_the_house_in_millimetres_is_the_house_in_metres():
    """Every length of the spec in mm with ``length_unit = "mm"`` (the floor loads stay N/m): the same blocks,
    alpha and settlement reaction (scaled inputs are non-dimensionalised inside)."""
    spec = house_spec()

    def mm(value):
        return [1000.0 * v for v in value] if isinstance(value, list) else 1000.0 * value

    walls = [{**w, **{k: mm(w[k]) for k in ("start", "end", "height", "thickness")},
              "openings": [{k: mm(v) for k, v in o.items()} for o in w["openings"]]} for w in spec["building"]["walls"]]
    in_mm = {**spec, "length_unit": "mm",
             "building": {**spec["building"], "unit": {k: mm(v) for k, v in UNIT.items()}, "walls": walls,
                          "floors": [{**f, "height": mm(f["height"])} for f in spec["building"]["floors"]]},
             "settlement": {k: mm(v) if k in ("diameter", "depth", "center_x", "center_y") else v
                            for k, v in spec["settlement"].items()}}
    a, b = mf.solve(mf.build(spec), "la"), mf.solve(mf.build(in_mm), "la")
    assert b.sizes["block"] == a.sizes["block"]
    assert float(b.collapse_multiplier) == pytest.approx(float(a.collapse_multiplier), rel=1e-9)
    assert float(b.moving_support_reaction) == pytest.approx(float(a.moving_support_reaction), rel=1e-9)


def test_crossing_walls_are_toothed_into_each_other():
    """Two inner walls crossing between their ends (an X): the masonry fills the walls' footprint in plan (the
    crossing square once) times their height, no two blocks (nor ground segments) overlap, and the block in
    the crossing's square is the first-listed wall's in even courses and the other's in odd ones."""
    spec = house_spec()
    spec["building"]["walls"] += [wall("a", (1.2, 0.6), (1.2, 1.5)), wall("b", (0.6, 1.0), (1.8, 1.0))]
    model = mf.build(spec)
    masonry = mfp.masonry_blocks(model.block_role.values)
    t = 0.12
    expected = (2 * t * (2.4 + 1.8) + t * (0.9 + 1.2 - t)) * 1.2 - t * (0.48 * 0.72 + 0.48 * 0.36)
    assert model.block_volume.values[masonry].sum() == pytest.approx(expected, rel=1e-12)
    low, high = box_bounds(model)
    common = np.clip(np.minimum(high[:, None], high[None]) - np.maximum(low[:, None], low[None]), 0, None).prod(-1)
    np.fill_diagonal(common, 0.0)
    assert common.max() < 1e-12
    eps = 1e-9
    in_a = (low[:, 0] >= 1.14 - eps) & (high[:, 0] <= 1.26 + eps)  # within wall a's strip (along y at x = 1.2)
    in_b = (low[:, 1] >= 0.94 - eps) & (high[:, 1] <= 1.06 + eps)  # within wall b's (along x at y = 1.0)
    for course in range(10):
        for point in ((1.17, 0.97), (1.23, 1.03)):
            covering = (masonry & (low[:, 0] < point[0]) & (high[:, 0] > point[0]) & (low[:, 1] < point[1])
                        & (high[:, 1] > point[1]) & (low[:, 2] < (course + 0.5) * 0.12) & (high[:, 2] > (course + 0.5) * 0.12))
            block = int(np.flatnonzero(covering)[0])
            assert covering.sum() == 1 and in_a[block] != in_b[block]
            assert in_a[block] == (course % 2 == 0), (course, point)
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


@pytest.mark.parametrize("extra, message", [
    (wall("twin", (0.0, 0.1), (2.4, 0.1)), "walls 'south' and 'twin' are laid into one another at"),
    (wall("short", (1.2, 1.77), (1.2, 0.9)), "walls 'north' and 'short' are laid into one another at"),
])
def test_walls_laid_into_one_another_are_refused_with_the_place(extra, message):
    """A wall 0.1 m beside another 0.12 m thick, a wall ending 0.03 m short of another's base line (inside it)."""
    spec = house_spec()
    spec["building"]["walls"].append(extra)
    with pytest.raises(mf.SpecError, match=message):
        mf.build(spec)


def plan_polygons(model):
    """Every block's plan (the convex hull of its vertices in x-y) and its bottom level."""
    import shapely

    owner = np.repeat(np.arange(model.sizes["block"]), model.block_node_count.values)
    xy = np.c_[model.node_x.values, model.node_y.values]
    hulls = [shapely.MultiPoint(xy[owner == b]).convex_hull for b in range(model.sizes["block"])]
    low, _ = box_bounds(model)
    return np.array(hulls, dtype=object), low[:, 2]


def assert_no_two_blocks_of_a_course_share_area(hulls, bottom) -> None:
    """Blocks of one course (one bottom level) whose plans overlap by any area."""
    import shapely

    for level in np.unique(np.round(bottom, 9)):
        course = np.flatnonzero(np.isclose(bottom, level))
        pairs = shapely.STRtree(hulls[course]).query(hulls[course], predicate="intersects")
        pairs = pairs[:, pairs[0] < pairs[1]]
        common = shapely.area(shapely.intersection(hulls[course][pairs[0]], hulls[course][pairs[1]]))
        assert common.max(initial=0.0) < 1e-12, level


@pytest.mark.parametrize("bond, thickness", [("running", 0.12), ("flemish", 0.24)])
def test_walls_meeting_at_other_angles_are_mitred_and_toothed(bond, thickness):
    """A house whose plan is a trapezoid (corners of 77, 103, 97 and 83 degrees), with a door: its masonry fills
    the walls' footprint, the ring between the centre-line plan offset by half the thickness out and in with
    mitred corners (shapely's buffer, an independent construction), times the height, less the door; no two
    blocks of a course share any area in plan; at each corner the block covering the mitre's outer point
    alternates between the two walls course by course; la finds a mechanism."""
    import shapely

    points = [(0, 0), (2.4, 0), (2.0, 1.8), (0.3, 1.8)]
    walls = [wall(name, points[i], points[(i + 1) % 4], thickness=thickness)
             for i, name in enumerate(["south", "east", "north", "west"])]
    walls[0]["openings"] = [{"x": 0.96, "y": 0.0, "width": 0.48, "height": 0.72}]
    spec = {"title": "trapezoid", "building": {"unit": {**UNIT, "depth": 0.12}, "walls": walls, "bond": bond},
            "material": MATERIAL, "settlement": {"profile": "gaussian", "width": 0.8, "axis_angle": 60.0,
                                                 "center_x": 2.0, "center_y": 0.5}}
    model = mf.build(spec)
    masonry = mfp.masonry_blocks(model.block_role.values)
    plan = shapely.Polygon(points)
    ring = plan.buffer(thickness / 2, join_style="mitre").difference(plan.buffer(-thickness / 2, join_style="mitre"))
    assert model.block_volume.values[masonry].sum() == pytest.approx(ring.area * 1.2 - thickness * 0.48 * 0.72,
                                                                     rel=1e-12)
    hulls, bottom = plan_polygons(model)
    assert_no_two_blocks_of_a_course_share_area(hulls, bottom)
    outer = np.asarray(plan.buffer(thickness / 2, join_style="mitre").exterior.coords)[:-1]
    centre = np.array(plan.centroid.coords[0])
    for corner in outer:
        probe = corner + 0.01 * (centre - corner) / np.linalg.norm(centre - corner)
        owners = []
        for course in range(10):
            inside = [b for b in np.flatnonzero(masonry & np.isclose(bottom, course * 0.12))
                      if hulls[b].contains(shapely.Point(probe))]
            assert len(inside) == 1, (corner, course)
            owners.append(walls_of(model, inside[0], points))
        assert all(a != b for a, b in zip(owners[:-1], owners[1:])), (corner, owners)
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


def walls_of(model, block, points):
    """The wall a block is laid in: the one whose centre line most of its plan's edges run parallel to (its two
    faces; a slanted end runs along the other wall, once)."""
    import shapely

    owner = np.repeat(np.arange(model.sizes["block"]), model.block_node_count.values)
    hull = shapely.MultiPoint(np.c_[model.node_x.values, model.node_y.values][owner == block]).convex_hull
    ring = np.asarray(hull.exterior.coords)
    edges = np.diff(ring, axis=0)
    edges /= np.linalg.norm(edges, axis=1)[:, None]
    lines = np.array([np.subtract(points[(i + 1) % 4], points[i]) for i in range(4)], dtype=float)
    lines /= np.linalg.norm(lines, axis=1)[:, None]
    parallel = np.abs(edges[:, None, 0] * lines[None, :, 1] - edges[:, None, 1] * lines[None, :, 0]) < 1e-9
    return int(np.argmax(parallel.sum(axis=0)))


@pytest.mark.parametrize("extra", [
    [wall("slant", (0.9, 0.0), (1.5, 1.8))],
    [wall("x1", (0.4, 0.4), (2.0, 1.4)), wall("x2", (0.6, 1.4), (1.8, 0.3))],
], ids=["T at 72 degrees", "crossing at 75 degrees"])
def test_a_slanted_inner_wall_is_toothed_into_the_walls_it_meets(extra):
    """An inner wall ending on two others at 72 degrees, and two inner walls crossing at 75 degrees: the masonry
    fills the union of the walls' strips in plan (each centre line widened by half the thickness both ways, flat
    at free ends, the outer ring mitred: shapely), times the height; no two blocks of a course share any area."""
    import shapely

    spec = house_spec()
    spec["building"]["walls"][0]["openings"] = []
    spec["building"]["walls"][1]["openings"] = []
    spec["building"]["walls"] += extra
    model = mf.build(spec)
    masonry = mfp.masonry_blocks(model.block_role.values)
    t = 0.12
    plan = shapely.Polygon([(0, 0), (2.4, 0), (2.4, 1.8), (0, 1.8)])
    ring = plan.buffer(t / 2, join_style="mitre").difference(plan.buffer(-t / 2, join_style="mitre"))
    strips = [shapely.LineString([w["start"], w["end"]]).buffer(t / 2, cap_style="flat") for w in extra]
    assert model.block_volume.values[masonry].sum() == pytest.approx(shapely.union_all([ring, *strips]).area * 1.2,
                                                                     rel=1e-12)
    hulls, bottom = plan_polygons(model)
    assert_no_two_blocks_of_a_course_share_area(hulls, bottom)
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


def test_walls_drawn_to_a_common_point_make_the_t_and_the_crossing_of_the_walls_drawn_through():
    """The south wall drawn as two walls meeting the cross wall's end at one point (three walls at a point, two in
    line) lays what the south wall drawn through and the cross wall abutting it lay (a T): the same volume, no
    overlap, the T's square the line's in even courses and the cross wall's in odd ones. Two inner walls drawn
    as four meeting at their crossing: the crossing of the two drawn through, the square alternating."""
    spec = house_spec()
    spec["building"]["walls"][0:1] = [wall("south a", (0, 0), (1.2, 0)), wall("south b", (1.2, 0), (2.4, 0))]
    spec["building"]["walls"][2]["openings"] = []
    spec["building"]["floors"] = []
    spec["building"]["walls"] += [wall("cross", (1.2, 0.0), (1.2, 1.8)),
                                  wall("x a", (0.3, 0.9), (0.6, 0.9)), wall("y a", (0.6, 0.4), (0.6, 0.9)),
                                  wall("x b", (0.6, 0.9), (1.0, 0.9)), wall("y b", (0.6, 0.9), (0.6, 1.4))]
    model = mf.build(spec)
    masonry = mfp.masonry_blocks(model.block_role.values)
    t = 0.12
    expected = (2 * t * (2.4 + 1.8) + t * (1.8 - t)) * 1.2 + t * (0.7 + 1.0 - t) * 1.2  # the crossing counted once
    assert model.block_volume.values[masonry].sum() == pytest.approx(expected, rel=1e-12)
    hulls, bottom = plan_polygons(model)
    import shapely

    assert_no_two_blocks_of_a_course_share_area(hulls, bottom)
    for point in ((1.21, 0.01), (0.61, 0.91), (0.63, 0.93)):
        for course in range(10):
            covering = [b for b in np.flatnonzero(masonry & np.isclose(bottom, course * 0.12))
                        if hulls[b].contains(shapely.Point(point))]
            assert len(covering) == 1
            x0, y0, x1, y1 = hulls[covering[0]].bounds
            along_x = x1 - x0 > y1 - y0 + 1e-9 or (y1 - y0 <= t + 1e-9 and x1 - x0 > t + 1e-9)
            assert along_x == (course % 2 == 0), (point, course, hulls[covering[0]].bounds)
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


@pytest.mark.parametrize("extra, message", [
    ([wall("south b", (2.4, 0), (3.6, 0)), wall("y", (2.4, 0), (3.0, -1.0))],
     "walls 'south', 'east', 'south b', 'y' meet at \\(2.4, 0\\)"),
    ([wall("y", (2.4, 0), (3.0, -1.0))], "walls 'south', 'east', 'y' meet at \\(2.4, 0\\)"),
])
def test_walls_at_a_point_that_make_no_corner_t_or_crossing_are_refused(extra, message):
    spec = house_spec()
    spec["building"]["walls"] += extra
    with pytest.raises(mf.SpecError, match=message):
        mf.build(spec)


def test_two_walls_in_line_are_one_wall():
    spec = {"title": "w", "building": {"unit": UNIT, "walls": [wall("a", (0, 0), (1.2, 0)), wall("b", (1.2, 0), (2.4, 0))]},
            "material": MATERIAL, "settlement": {"profile": "gaussian", "width": 0.8, "center_x": 1.9}}
    with pytest.raises(mf.SpecError, match="walls 'a', 'b' continue each other in a line at \\(1.2, 0\\): make them one"):
        mf.build(spec)


def test_a_slanted_flemish_house_over_a_tunnel_face_in_millimetres_is_the_house_in_metres():
    """Every new length at once in mm (walls at 77 to 103 degrees, two leaves in Flemish bond, a door, a tunnel
    with its face under the house): the same blocks and alpha as in metres (scaled inputs are
    non-dimensionalised inside)."""
    def spec(scale: float) -> dict:
        points = [(0, 0), (2.4, 0), (2.0, 1.8), (0.3, 1.8)]
        walls = [wall(name, [scale * c for c in points[i]], [scale * c for c in points[(i + 1) % 4]],
                      height=1.2 * scale, thickness=0.24 * scale) for i, name in enumerate("senw")]
        walls[0]["openings"] = [{"x": 0.96 * scale, "y": 0.0, "width": 0.48 * scale, "height": 0.72 * scale}]
        return {"title": "t", "length_unit": "mm" if scale == 1000 else "m",
                "building": {"unit": {"length": 0.24 * scale, "height": 0.12 * scale, "depth": 0.12 * scale},
                             "walls": walls, "bond": "flemish"},
                "material": MATERIAL, "settlement": {"profile": "tunnel", "volume_loss": 2.0, "diameter": 3.0 * scale,
                                                     "depth": 6.0 * scale, "axis_angle": 60.0, "center_x": 2.0 * scale,
                                                     "center_y": 0.5 * scale, "face": 1.0 * scale}}

    metres, millimetres = mf.build(spec(1.0)), mf.build(spec(1000.0))
    assert millimetres.sizes == metres.sizes
    np.testing.assert_allclose(millimetres.node_x.values, metres.node_x.values, rtol=1e-12, atol=1e-12)
    assert float(mf.solve(millimetres, "la").collapse_multiplier) == pytest.approx(
        float(mf.solve(metres, "la").collapse_multiplier), rel=1e-9)
