"""The wall builder against hand counts and closed forms."""
from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import tomllib

import masonryfw
import masonryfw.plugin_api
from masonryfw import SpecError, build, load_spec
from masonryfw.plugin_api import flags
from masonryfw.readers.spec import dump_toml

GAMMA = 12000.0
THICKNESS = 0.1
ROLE = flags("block_role")
KIND = flags("interface_kind")


def wall_spec(width=0.4, height=0.1, unit_length=0.2, unit_height=0.05, **sections) -> dict:
    """A valid spec: a wall on one fixed support, settlement of nothing unless supports are given."""
    spec = {
        "title": "tiny",
        "wall": {"width": width, "height": height, "thickness": THICKNESS},
        "unit": {"length": unit_length, "height": unit_height},
        "material": {"unit_weight": GAMMA, "friction_angle": 30.0},
        "supports": {"base": {"kind": "fixed", "start": 0.0, "end": width}},
        "loading": {"type": "tilt", "direction": 1},
    }
    spec.update(sections)
    return spec


def rectangles(ds, role=None) -> set[tuple[float, ...]]:
    """``{(x0, x1, y0, y1)}`` of the blocks (rounded to 1e-9 m), optionally of one role."""
    x = ds.node_x.values.reshape(-1, 4)
    y = ds.node_y.values.reshape(-1, 4)
    keep = np.ones(x.shape[0], dtype=bool) if role is None else ds.block_role.values == ROLE[role]
    boxes = np.stack((x.min(1), x.max(1), y.min(1), y.max(1)), axis=1)[keep]
    return {tuple(np.round(b, 9)) for b in boxes}


def kind_counts(ds) -> dict[str, int]:
    counts = np.bincount(ds.interface_kind.values, minlength=4)
    return {name: int(counts[value]) for name, value in KIND.items()}


# --------------------------------------------------------------------------- hand-counted walls


def test_two_by_two_running_bond_blocks_and_interfaces_by_hand():
    ds = build(wall_spec())
    assert rectangles(ds, "unit") == {
        (0.0, 0.2, 0.0, 0.05), (0.2, 0.4, 0.0, 0.05),
        (0.0, 0.1, 0.05, 0.1), (0.1, 0.3, 0.05, 0.1), (0.3, 0.4, 0.05, 0.1),
    }
    assert rectangles(ds, "fixed_support") == {(0.0, 0.4, -0.05, 0.0)}
    # heads: 1 + 2; beds: breakpoints 0, .1, .2, .3, .4 -> 4; support: under the 2 bottom units.
    assert kind_counts(ds) == {"bed": 4, "head": 3, "support": 2, "other": 0}


def test_first_course_half_starts_the_bottom_course_with_a_half_unit():
    ds = build(wall_spec(bond={"pattern": "running", "first_course": "half"}))
    assert rectangles(ds, "unit") == {
        (0.0, 0.1, 0.0, 0.05), (0.1, 0.3, 0.0, 0.05), (0.3, 0.4, 0.0, 0.05),
        (0.0, 0.2, 0.05, 0.1), (0.2, 0.4, 0.05, 0.1),
    }


def test_stack_bond_three_by_two_by_hand():
    ds = build(wall_spec(width=0.6, bond={"pattern": "stack"}))
    assert rectangles(ds, "unit") == {
        (x0, x1, y0, y1) for x0, x1 in ((0.0, 0.2), (0.2, 0.4), (0.4, 0.6)) for y0, y1 in ((0.0, 0.05), (0.05, 0.1))
    }
    assert kind_counts(ds) == {"bed": 3, "head": 4, "support": 3, "other": 0}


def opening_wall() -> dict:
    """5 units of 0.1 x 0.05 wide, 4 courses; a 0.1 x 0.05 opening in course 1 with a 0.1 bearing lintel."""
    return wall_spec(width=0.5, height=0.2, unit_length=0.1,
                     openings=[{"x": 0.2, "y": 0.05, "width": 0.1, "height": 0.05, "lintel_bearing": 0.1}])


def test_opening_with_lintel_by_hand():
    ds = build(opening_wall())
    units = rectangles(ds, "unit")
    course1 = {(0.0, 0.05), (0.05, 0.15), (0.15, 0.2), (0.3, 0.35), (0.35, 0.45), (0.45, 0.5)}
    assert {(b[0], b[1]) for b in units if b[2] == 0.05} == course1  # halves at the jambs, kept
    assert {(b[0], b[1]) for b in units if b[2] == 0.1} == {(0.0, 0.1), (0.4, 0.5)}
    assert rectangles(ds, "lintel") == {(0.1, 0.4, 0.1, 0.15)}
    assert len(units) == 5 + 6 + 2 + 6
    # heads 4 + 4 + 2 + 5; beds 8 + 8 + 8 (none across the opening); support under 5 units.
    assert kind_counts(ds) == {"bed": 24, "head": 15, "support": 5, "other": 0}


def test_cut_remnants_shorter_than_half_a_unit_join_their_neighbour():
    spec = wall_spec(width=0.5, height=0.1, unit_length=0.1,
                     openings=[{"x": 0.12, "y": 0.0, "width": 0.26, "height": 0.05, "lintel_bearing": 0.0}])
    bottom = {(b[0], b[1]) for b in rectangles(build(spec), "unit") if b[2] == 0.0}
    # full course 0 | .1 | .2 | .3 | .4 | .5 cut at .12 and .38: the .02 remnants join the outer units.
    assert bottom == {(0.0, 0.12), (0.38, 0.5)}


def test_width_not_a_whole_number_of_units_ends_with_a_cut_unit():
    ds = build(wall_spec(width=0.53, height=0.1, unit_length=0.1))
    units = rectangles(ds, "unit")
    full = sorted((b[0], b[1]) for b in units if b[2] == 0.0)
    half = sorted((b[0], b[1]) for b in units if b[2] == 0.05)
    assert full == [(0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.53)]  # .03 sliver merged
    assert half == [(0.0, 0.05), (0.05, 0.15), (0.15, 0.25), (0.25, 0.35), (0.35, 0.45), (0.45, 0.53)]


# --------------------------------------------------------------------------- closed forms


def test_areas_and_dead_load_match_the_wall_minus_openings():
    ds = build(opening_wall())
    masonry = ds.block_role.values <= ROLE["lintel"]
    area = 0.5 * 0.2 - 0.1 * 0.05
    assert ds.block_area.values[masonry].sum() == pytest.approx(area, rel=1e-12)
    assert -ds.dead_load.values[masonry, 1].sum() == pytest.approx(GAMMA * THICKNESS * area, rel=1e-12)
    assert np.all(ds.dead_load.values[~masonry] == 0.0)
    assert np.all(ds.dead_load.values[:, 0] == 0.0) and np.all(ds.dead_moment.values == 0.0)


def test_bundled_facade_area_is_the_closed_form():
    ds = build(masonryfw.bundled_spec_path("facade-3"))
    masonry = ds.block_role.values <= ROLE["lintel"]
    assert ds.block_area.values[masonry].sum() == pytest.approx(1.5 * 1.8 - 6 * 0.2 * 0.35, rel=1e-12)


@pytest.mark.parametrize(
    "supports, openings, moving_share",
    [
        # contact 0.3 of 0.4 on the moving support
        ({"f": (0.0, 0.1), "m": (0.1, 0.4)}, [], 0.3 / 0.4),
        # a gap 0.1..0.2 under the wall: contact 0.1 + 0.2
        ({"f": (0.0, 0.1), "m": (0.2, 0.4)}, [], 0.2 / 0.3),
        # a door 0.15..0.25 over both supports: contacts 0.15 and 0.15
        ({"f": (0.0, 0.2), "m": (0.2, 0.4)},
         [{"x": 0.15, "y": 0.0, "width": 0.1, "height": 0.05, "lintel_bearing": 0.05}], 0.5),
    ],
)
def test_settlement_reaction_is_the_weight_share_of_the_moving_contact(supports, openings, moving_share):
    spec = wall_spec(height=0.15, openings=openings, loading={"type": "settlement"},
                     supports={name: {"kind": "moving" if name == "m" else "fixed", "start": a, "end": b}
                               for name, (a, b) in supports.items()})
    ds = build(spec)
    weight = GAMMA * THICKNESS * (0.4 * 0.15 - sum(o["width"] * o["height"] for o in openings))
    moving = np.flatnonzero(ds.block_role.values == ROLE["moving_support"])
    assert moving.size == 1
    reaction = weight * moving_share
    assert masonryfw.plugin_api.block_loads(ds, "dead")[moving[0]] == pytest.approx([0.0, reaction, 0.0], rel=1e-12, abs=1e-12)
    assert masonryfw.plugin_api.block_loads(ds, "live")[moving[0]] == pytest.approx([0.0, -reaction, 0.0], rel=1e-12, abs=1e-12)
    assert np.all(ds.live_load.values[ds.block_role.values != ROLE["moving_support"]] == 0.0)
    assert ds.block_fixed.values[moving[0]].tolist() == [1, 0, 1]
    assert ds.settlement_direction.values[moving[0]].tolist() == [0.0, -1.0, 0.0]


def test_rotating_support_direction_is_the_rigid_rotation_about_the_pivot():
    spec = wall_spec(loading={"type": "settlement"}, supports={
        "f": {"kind": "fixed", "start": 0.0, "end": 0.2},
        "m": {"kind": "moving", "start": 0.2, "end": 0.4, "motion": "rotation", "pivot": [0.2, 0.0]},
    })
    ds = build(spec)
    moving = np.flatnonzero(ds.block_role.values == ROLE["moving_support"])[0]
    # centre (0.3, -0.025); clockwise rotation rz about (0.2, 0): v = rz (-r_y, r_x) = rz (0.025, 0.1); the
    # settlement parameter is the centroid's settlement, v_y = -1: rz = -10, v = (-0.25, -1)
    expected = np.array([-0.25, -1.0, -10.0])
    assert ds.settlement_direction.values[moving] == pytest.approx(expected, rel=1e-12)
    assert ds.block_fixed.values[moving].tolist() == [0, 0, 0]


@pytest.mark.parametrize("direction", [1, -1])
def test_tilt_live_loads_are_the_weights_and_every_support_is_held(direction):
    spec = opening_wall()
    spec["loading"] = {"type": "tilt", "direction": direction}
    spec["supports"] = {"f": {"kind": "fixed", "start": 0.0, "end": 0.2},
                        "m": {"kind": "moving", "start": 0.2, "end": 0.5}}
    ds = build(spec)
    masonry = ds.block_role.values <= ROLE["lintel"]
    weight = GAMMA * THICKNESS * ds.block_area.values[masonry]
    assert ds.live_load.values[masonry, 0] == pytest.approx(direction * weight, rel=1e-12)
    assert np.all(ds.live_load.values[masonry, 1:] == 0.0)
    assert np.all(ds.live_load.values[~masonry] == 0.0)
    assert np.all(ds.block_fixed.values[~masonry] == 1)
    assert np.all(ds.settlement_direction.values == 0.0)
    assert np.all(ds.block_role.values[~masonry] == ROLE["fixed_support"])


def test_millimetres_give_the_same_model_as_metres():
    metres = opening_wall()
    metres["loading"] = {"type": "settlement"}
    metres["supports"] = {"f": {"kind": "fixed", "start": 0.0, "end": 0.25},
                          "m": {"kind": "moving", "start": 0.25, "end": 0.5}}
    millimetres = copy.deepcopy(metres)
    millimetres["length_unit"] = "mm"
    for table in ("wall", "unit"):
        millimetres[table] = {k: v * 1000 for k, v in metres[table].items()}
    millimetres["openings"] = [{k: v * 1000 for k, v in o.items()} for o in metres["openings"]]
    for support in millimetres["supports"].values():
        support["start"] *= 1000
        support["end"] *= 1000
    a, b = build(metres), build(millimetres)
    assert set(a.data_vars) == set(b.data_vars)
    assert a.sizes == b.sizes
    for name in a.data_vars:
        np.testing.assert_allclose(b[name].values, a[name].values, rtol=1e-12, atol=1e-15, err_msg=name)


# --------------------------------------------------------------------------- the dataset contract


def test_model_has_every_required_variable_and_attribute_of_the_schema():
    ds = build(opening_wall())
    schema = masonryfw.plugin_api.load_schema("model")
    for name, var in schema["variables"].items():
        if var["required"] or name in ("block_geometry", "dof"):
            assert name in ds.variables, name
            assert list(ds[name].dims) == var["dims"], name
            assert ds[name].attrs["units"] == var["units"], name
            assert ds[name].attrs["long_name"] == var["long_name"], name
    assert ds.block_geometry.attrs["geometry_type"] == "polygon"
    assert ds.block_geometry.attrs["node_coordinates"] == "node_x node_y"
    assert ds.dof.values.tolist() == ["ux", "uy", "rz"]
    assert ds.attrs["Conventions"] == "CF-1.11"
    assert ds.attrs["masonryfw_format"] == "model"
    assert ds.attrs["masonryfw_format_version"] == 2
    assert ds.attrs["title"] == "tiny"
    assert np.all(ds.block_area.values > 0)  # counter-clockwise vertices
    assert np.all(ds.interface_friction.values == pytest.approx(math.tan(math.radians(30.0))))


def test_source_spec_of_a_dict_is_toml_that_reads_back_to_the_dict():
    spec = opening_wall()
    spec["description"] = 'quotes " and\nnew lines'
    ds = build(spec)
    assert tomllib.loads(ds.attrs["source_spec"]) == spec
    assert tomllib.loads(dump_toml(spec)) == spec


def test_source_spec_of_text_is_the_text_itself(tmp_path):
    text = dump_toml(opening_wall()) + "# a comment the user wrote\n"
    path = tmp_path / "wall.toml"
    path.write_text(text)
    for source in (text, path, str(path)):
        assert build(source).attrs["source_spec"] == text
    assert load_spec(path) == opening_wall()


@pytest.mark.parametrize("loading", [{"type": "settlement"}, {"type": "tilt", "direction": -1}])
@pytest.mark.parametrize("motion", [{"motion": "translation"}, {"motion": "rotation", "pivot": [0.5, 0.0]}])
def test_built_models_pass_the_checks(loading, motion):
    spec = opening_wall()
    spec["loading"] = loading
    spec["supports"] = {"f": {"kind": "fixed", "start": 0.0, "end": 0.25},
                        "m": {"kind": "moving", "start": 0.25, "end": 0.5, **motion}}
    assert masonryfw.check(build(spec)) == []


def test_a_missing_spec_file_is_a_spec_error(tmp_path):
    with pytest.raises(SpecError, match="not found"):
        load_spec(str(tmp_path / "nothing.toml"))


def test_a_hundred_by_hundred_wall_has_its_units_counted_by_hand():
    """Its build time is a benchmark (benchmarks/bench_interfaces.py), not a timed test."""
    spec = wall_spec(width=100 * 0.2, height=100 * 0.05, loading={"type": "settlement"},
                     supports={"f": {"kind": "fixed", "start": 0.0, "end": 10.0},
                               "m": {"kind": "moving", "start": 10.0, "end": 20.0}})
    ds = build(spec)
    assert int(np.sum(ds.block_role.values == ROLE["unit"])) == 50 * 100 + 50 * 101


# --------------------------------------------------------------------------- spec errors


def settlement_spec() -> dict:
    return wall_spec(width=0.6, height=0.3, loading={"type": "settlement"},
                     openings=[{"x": 0.2, "y": 0.05, "width": 0.2, "height": 0.1, "lintel_bearing": 0.1}],
                     supports={"fixed": {"kind": "fixed", "start": 0.0, "end": 0.3},
                               "moving": {"kind": "moving", "start": 0.3, "end": 0.6}})


def _set(path: str, value):
    def edit(spec):
        *parents, last = path.split(".")
        table = spec
        for key in parents:
            table = table[int(key)] if key.isdigit() else table[key]
        if value is DELETE:
            del table[last]
        else:
            table[last] = value
    return edit


DELETE = object()
SECOND_OPENING = {"x": 0.3, "y": 0.1, "width": 0.1, "height": 0.05, "lintel_bearing": 0.0}


@pytest.mark.parametrize(
    "edit, key",
    [
        (_set("titel", "x"), "titel"),
        (_set("wall.widht", 0.6), "wall.widht"),
        (_set("wall.thickness", DELETE), "wall.thickness"),
        (_set("title", DELETE), "title"),
        (_set("wall.width", "0.6"), "wall.width"),
        (_set("unit.length", -0.2), "unit.length"),
        (_set("wall.thickness", 0.0), "wall.thickness"),
        (_set("wall.height", -0.3), "wall.height"),  # 0.23 (not whole courses) is laid, a cut course on top
        (_set("length_unit", "km"), "length_unit"),
        (_set("bond", {"pattern": "herringbone"}), "bond.pattern"),  # flemish is laid (masonryfw.builders.bond)
        (_set("material.friction", 0.4), "material.friction"),
        (_set("material.friction_angle", DELETE), "material.friction_angle"),
        (_set("material.poisson_ratio", 0.5), "material.poisson_ratio"),
        (_set("material.unit_weight", float("nan")), "material.unit_weight"),
        (_set("openings.0.width", 0.5), "openings[0].width"),
        (_set("openings.0.y", 0.07), "openings[0].y"),
        (_set("openings.0.height", 0.25), "openings[0].height"),
        (_set("openings.0.lintel_bearing", 0.3), "openings[0].lintel_bearing"),
        (_set("openings.0.sill", 0.3), "openings[0].sill"),
        (lambda s: s["openings"].append(dict(SECOND_OPENING)), "openings[1]"),
        (_set("openings", {"x": 0.1}), "openings"),
        (_set("supports.moving.end", 0.7), "supports.moving.end"),
        (_set("supports.moving.start", 0.25), "supports.moving"),
        (_set("supports.moving.end", 0.3), "supports.moving.end"),
        (_set("supports.moving.motion", "rotation"), "supports.moving.pivot"),
        (_set("supports.moving.pivot", [0.3, 0.0]), "supports.moving.pivot"),
        (_set("supports.fixed.motion", "translation"), "supports.fixed.motion"),
        (_set("supports.moving.kind", "sinking"), "supports.moving.kind"),
        (_set("supports", {}), "supports"),
        (_set("supports.moving.kind", "fixed"), "loading.type"),
        (_set("loading.type", "tilt"), "loading.direction"),
        (_set("loading.direction", 1), "loading.direction"),
        (_set("loading.typ", "tilt"), "loading.typ"),
    ],
)
def test_every_spec_error_names_its_key(edit, key):
    spec = settlement_spec()
    build(copy.deepcopy(spec))  # the unedited spec is valid
    edit(spec)
    with pytest.raises(SpecError) as info:
        build(spec)
    assert f"'{key}" in str(info.value)


def test_a_moving_support_with_no_masonry_on_it_is_an_error():
    spec = wall_spec(width=0.6, height=0.2, unit_length=0.1, loading={"type": "settlement"},
                     openings=[{"x": 0.4, "y": 0.0, "width": 0.1, "height": 0.05, "lintel_bearing": 0.05}],
                     supports={"fixed": {"kind": "fixed", "start": 0.0, "end": 0.4},
                               "under_door": {"kind": "moving", "start": 0.4, "end": 0.5}})
    with pytest.raises(SpecError, match="'supports.under_door'"):
        build(spec)


def test_invalid_toml_text_is_a_spec_error():
    with pytest.raises(SpecError, match="not valid TOML"):
        load_spec('title = "x"\n[wall\nwidth = 1')


def test_typos_get_a_suggestion():
    spec = settlement_spec()
    spec["wall"]["widht"] = spec["wall"].pop("width")
    with pytest.raises(SpecError, match="did you mean 'wall.width'"):
        build(spec)
