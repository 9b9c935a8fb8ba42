"""Validation: a hand-written valid model gives no problem; each way of breaking it gives its problem.

The model is written here with plain xarray from docs/format.md (no masonryfw writer)::

    y 0.5 +---------+---------+
          | unit 0  | unit 1  |
    y 0   +-------+-+-+-------+
          | fixed 2 | | moving 3|    supports [0, 0.9] and [1.1, 2] x [-0.5, 0]
    y-0.5 +-------+   +-------+
          x 0    0.9  1.1     2
"""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from masonryfw.format.checks import Problem, check
from masonryfw.geometry.interfaces import detect_interfaces

BOXES = [(0.0, 1.0, 0.0, 0.5), (1.0, 2.0, 0.0, 0.5), (0.0, 0.9, -0.5, 0.0), (1.1, 2.0, -0.5, 0.0)]
ROLES = [0, 0, 2, 3]  # unit unit fixed_support moving_support
INTERFACES = [  # side 0, side 1, (x0, x1), (y0, y1), kind
    (0, 1, (1.0, 1.0), (0.5, 0.0), 1),
    (2, 0, (0.0, 0.9), (0.0, 0.0), 2),
    (3, 1, (1.1, 2.0), (0.0, 0.0), 2),
]


def polygon_nodes(polygons):
    x = [p[0] for poly in polygons for p in poly]
    y = [p[1] for poly in polygons for p in poly]
    return np.array(x, float), np.array(y, float), np.array([len(p) for p in polygons], dtype=np.int32)


def rectangle(x0, x1, y0, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def model_dataset(polygons=None, roles=None, interfaces=None, live_value=-1000.0):
    """A docs/format.md model with plain xarray: blocks, interfaces, loads and supports as given."""
    polygons = polygons or [rectangle(*b) for b in BOXES]
    roles = np.array(roles or ROLES, dtype=np.int8)
    interfaces = interfaces or INTERFACES
    x, y, counts = polygon_nodes(polygons)
    nb, ni = counts.size, len(interfaces)
    fixed = np.zeros((nb, 3), np.int8)
    fixed[roles == 2] = (1, 1, 1)
    fixed[roles == 3] = (1, 0, 1)
    direction = np.zeros((nb, 3))
    direction[roles == 3] = (0.0, -1.0, 0.0)
    dead = np.zeros((nb, 3))
    dead[roles <= 1, 1] = -1000.0
    live = np.zeros((nb, 3))
    live[roles == 3, 1] = live_value

    def var(dims, values, units, long_name, **extra):
        return (dims, values, {"units": units, "long_name": long_name, **extra})

    flags_role = {"flag_values": np.array([0, 1, 2, 3], np.int8),
                  "flag_meanings": "unit lintel fixed_support moving_support"}
    flags_kind = {"flag_values": np.array([0, 1, 2, 3], np.int8), "flag_meanings": "bed head support other"}
    return xr.Dataset(
        {
            "node_x": var("node", x, "m", "vertex x"),
            "node_y": var("node", y, "m", "vertex y"),
            "block_node_count": var("block", counts, "1", "vertices per block"),
            "block_geometry": ((), np.int32(0), {"geometry_type": "polygon", "node_count": "block_node_count",
                                                "node_coordinates": "node_x node_y"}),
            "block_role": var("block", roles, "1", "role", **flags_role),
            "block_thickness": var("block", np.full(nb, 0.3), "m", "thickness"),
            "block_unit_weight": var("block", np.where(roles <= 1, 20e3, 0.0), "N m-3", "unit weight"),
            "interface_blocks": var(("interface", "side"), np.array([i[:2] for i in interfaces], np.int32).reshape(ni, 2), "1", "blocks"),
            "interface_x": var(("interface", "end"), np.array([i[2] for i in interfaces], float).reshape(ni, 2), "m", "x"),
            "interface_y": var(("interface", "end"), np.array([i[3] for i in interfaces], float).reshape(ni, 2), "m", "y"),
            "interface_kind": var("interface", np.array([i[4] for i in interfaces], np.int8), "1", "kind", **flags_kind),
            "interface_friction": var("interface", np.full(ni, 0.6), "1", "mu"),
            "interface_cohesion": var("interface", np.zeros(ni), "Pa", "cohesion"),
            "interface_tensile_strength": var("interface", np.zeros(ni), "Pa", "tensile strength"),
            "dead_load": var(("block", "axis"), dead[:, :2], "N", "dead load"),
            "dead_moment": var("block", dead[:, 2], "N m", "dead moment"),
            "live_load": var(("block", "axis"), live[:, :2], "N", "live load"),
            "live_moment": var("block", live[:, 2], "N m", "live moment"),
            "block_fixed": var(("block", "dof"), fixed, "1", "held"),
            "settlement_direction": var(("block", "dof"), direction, "1", "settlement"),
        },
        coords={"dof": ("dof", ["ux", "uy", "rz"], {"units": "1", "long_name": "dof"})},
        attrs={"Conventions": "CF-1.11", "masonryfw_format": "model", "masonryfw_format_version": 2,
               "title": "two units on two supports"},
    )


def result_dataset(**changes):
    ds = model_dataset()
    ds.attrs.update(masonryfw_format="result", plugin="la", plugin_version="0.1", solver="clarabel",
                    solver_version="0.1+0123456789ab", core_version="0.1+0123456789ab",
                    solver_options='{"tolerance": 1e-9}', wall_time_s=0.01)
    ds["collapse_multiplier"] = ((), 0.42, {"units": "1", "long_name": "alpha"})
    ds["crack_indicator"] = ("interface", np.array([1.0, 0.0, 0.5]), {"units": "1", "long_name": "crack"})
    ds["interface_state"] = ("interface", np.array([1, 0, 0], np.int8), {"units": "1", "long_name": "state"})
    ds.attrs.update(changes)
    return ds


def the_only(problems, where):
    """The one problem reported at ``where`` (the test fails listing all problems otherwise)."""
    found = [p for p in problems if p.where == where]
    assert len(found) == 1, [str(p) for p in problems]
    return found[0]


def with_nodes(ds, polygons):
    """``ds`` with new polygons (same blocks), keeping everything else."""
    x, y, counts = polygon_nodes(polygons)
    ds = ds.drop_dims("node").assign(
        node_x=("node", x, {"units": "m", "long_name": "x"}),
        node_y=("node", y, {"units": "m", "long_name": "y"}),
    )
    ds["block_node_count"].values[:] = counts
    return ds


# ---------------------------------------------------------------- valid datasets

def test_valid_model_has_no_problem():
    assert check(model_dataset()) == []


def test_valid_model_after_a_netcdf_round_trip(tmp_path):
    path = tmp_path / "model.nc"
    model_dataset().to_netcdf(path)
    with xr.open_dataset(path) as ds:
        assert check(ds) == []


def test_problem_string_names_where_what_and_the_point():
    assert str(Problem("block 12", "clockwise vertex order", 0.1, 0.35)) == "block 12: clockwise vertex order at (0.1, 0.35)"
    assert str(Problem("attribute title", "missing")) == "attribute title: missing"


# ---------------------------------------------------------------- format layer

def test_missing_required_attribute():
    ds = model_dataset()
    del ds.attrs["title"]
    assert "missing" in the_only(check(ds), "attribute title").message


def test_wrong_conventions():
    ds = model_dataset()
    ds.attrs["Conventions"] = "CF-1.6"
    assert "'CF-1.11'" in the_only(check(ds), "attribute Conventions").message


@pytest.mark.parametrize("version", [3, np.int32(3), "3"])
def test_unknown_format_version_is_one_clear_problem(version):
    ds = model_dataset()
    ds.attrs["masonryfw_format_version"] = version
    problems = check(ds)
    assert len(problems) == 1
    assert problems[0].where == "attribute masonryfw_format_version"
    assert "unknown format version 3" in problems[0].message or "unknown format version '3'" in problems[0].message


def test_unknown_dataset_kind():
    ds = model_dataset()
    ds.attrs["masonryfw_format"] = "drawing"
    assert "unknown dataset kind 'drawing'" in the_only(check(ds), "attribute masonryfw_format").message


def test_missing_variable():
    ds = model_dataset().drop_vars("block_thickness")
    assert "missing" in the_only(check(ds), "variable block_thickness").message


def test_wrong_dims():
    ds = model_dataset()
    ds["interface_x"] = ds["interface_x"].transpose()
    assert "dims" in the_only(check(ds), "variable interface_x").message


def test_wrong_fixed_dimension_size():
    ds = model_dataset().isel(dof=[0, 1])
    assert "must be 3" in the_only(check(ds), "dimension dof").message


def test_float_flags_are_a_dtype_problem():
    ds = model_dataset()
    ds["block_role"] = ds["block_role"].astype(float)
    assert "int" in the_only(check(ds), "variable block_role").message


def test_wrong_units():
    ds = model_dataset()
    ds["node_x"].attrs["units"] = "mm"
    assert "'mm'" in the_only(check(ds), "variable node_x").message


def test_non_finite_vertex_names_its_block_and_point():
    ds = model_dataset()
    ds["node_x"].values[5] = np.nan  # second vertex of block 1
    problem = the_only(check(ds), "block 1")
    assert "node_x of vertex 5 = nan is not finite" in problem.message


def test_negative_friction():
    ds = model_dataset()
    ds["interface_friction"].values[2] = -0.2
    problem = the_only(check(ds), "interface 2")
    assert "interface_friction = -0.2 is below the minimum 0" in problem.message
    assert (problem.x, problem.y) == (1.55, 0.0)  # interface midpoint


def test_zero_thickness_and_negative_unit_weight():
    ds = model_dataset()
    ds["block_thickness"].values[0] = 0.0
    ds["block_unit_weight"].values[1] = -5.0
    problems = check(ds)
    assert "must be greater than 0" in the_only(problems, "block 0").message
    problem = the_only(problems, "block 1")
    assert "block_unit_weight = -5" in problem.message
    assert (problem.x, problem.y) == (1.5, 0.25)  # block centroid


def test_infinite_load_names_the_component():
    ds = model_dataset()
    ds["dead_load"].values[0, 1] = np.inf
    ds["dead_moment"].values[1] = -np.inf
    assert "dead_load[y] = inf is not finite" in the_only(check(ds), "block 0").message
    assert "dead_moment = -inf is not finite" in the_only(check(ds), "block 1").message


def test_invalid_flag():
    ds = model_dataset()
    ds["block_role"].values[1] = 7
    problems = check(ds)
    assert "block_role = 7 is not a valid flag" in the_only(problems, "block 1").message


def test_node_count_that_does_not_match_the_vertices():
    ds = model_dataset()
    ds["block_node_count"].values[0] = 5
    assert "sums to 17" in the_only(check(ds), "variable block_node_count").message


def test_too_few_vertices():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[3] = [(1.1, -0.5), (2.0, -0.5)]
    problems = check(with_nodes(model_dataset(), polygons))
    assert any(p.where == "block 3" and "block_node_count = 2 is below the minimum 3" in p.message for p in problems)


# ---------------------------------------------------------------- polygons

def test_repeated_vertex():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[0] = polygons[0] + [polygons[0][0]]  # first vertex repeated at the end
    problem = the_only(check(with_nodes(model_dataset(), polygons)), "block 0")
    assert "coincide (repeated vertex)" in problem.message
    assert (problem.x, problem.y) == (0.0, 0.0)


def test_collinear_vertex():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[1] = [(1.0, 0.0), (1.5, 0.0), (2.0, 0.0), (2.0, 0.5), (1.0, 0.5)]
    problem = the_only(check(with_nodes(model_dataset(), polygons)), "block 1")
    assert "zero turn" in problem.message
    assert (problem.x, problem.y) == (1.5, 0.0)


def test_clockwise_block():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[0] = polygons[0][::-1]
    problem = the_only(check(with_nodes(model_dataset(), polygons)), "block 0")
    assert "clockwise vertex order (negative area -0.5 m2)" in problem.message
    assert (problem.x, problem.y) == (0.5, 0.25)


def test_self_intersecting_block():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[1] = [(1.0, 0.0), (2.0, 0.0), (1.0, 0.5), (2.0, 0.5)]  # bow tie: edges cross at (1.5, 0.25)
    problems = check(with_nodes(model_dataset(), polygons))
    problem = next(p for p in problems if p.where == "block 1" and "intersects itself" in p.message)
    assert (problem.x, problem.y) == pytest.approx((1.5, 0.25))


def test_zero_area_block():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[1] = [(1.0, 0.0), (1.5, 0.0), (2.0, 0.0)]
    problems = check(with_nodes(model_dataset(), polygons))
    assert any(p.where == "block 1" and "zero area" in p.message for p in problems)


NOTCHED = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.5), (0.5, 0.3), (0.0, 0.5)]  # unit 0 with a notch in its top


def test_a_non_convex_block_is_a_block():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[0] = NOTCHED
    assert [p for p in check(with_nodes(model_dataset(), polygons)) if p.where == "block 0"] == []


@pytest.mark.parametrize("drop, overlaps", [(0.0, False), (0.05, True)])
def test_a_block_in_a_notch_touches_it_and_one_pushed_in_overlaps(drop, overlaps):
    """The wedge filling the notch exactly touches it; pushed down by 0.05 m it overlaps by 0.05 cos(angle of the notch's side)."""
    wedge = [(0.5, 0.3 - drop), (1.0, 0.5 - drop), (0.0, 0.5 - drop)]
    polygons = [rectangle(*b) for b in BOXES] + [wedge]
    polygons[0] = NOTCHED
    found = [p for p in check(model_dataset(polygons=polygons, roles=ROLES + [0])) if "overlaps" in p.message]
    assert bool(found) == overlaps
    if overlaps:
        assert found[0].where == "block 0" and "overlaps block 4" in found[0].message
        depth = float(found[0].message.split("interpenetration ")[1].split(" ")[0])
        assert depth == pytest.approx(drop * 0.5 / np.hypot(0.5, 0.2))


def test_overlapping_blocks_report_the_penetration_depth():
    # Unit 1 pushed 0.2 m into unit 0: the separating-axis depth is min(0.2 in x, 0.5 in y) = 0.2.
    polygons = [rectangle(*b) for b in BOXES]
    polygons[1] = rectangle(0.8, 1.8, 0.0, 0.5)
    problems = check(with_nodes(model_dataset(), polygons))
    problem = next(p for p in problems if p.where == "block 0" and "overlaps" in p.message)
    assert "overlaps block 1 (interpenetration 0.2 m)" in problem.message
    assert (problem.x, problem.y) == pytest.approx((0.9, 0.25))


def test_rotated_overlap_found_and_touching_blocks_are_not_overlaps():
    # A diamond whose lower corner dips 0.1 m into unit 0: SAT depth along y is 0.1.
    diamond = [(0.5, 0.4), (0.8, 0.7), (0.5, 1.0), (0.2, 0.7)]
    polygons = [rectangle(*b) for b in BOXES] + [diamond]
    problems = check(model_dataset(polygons=polygons, roles=ROLES + [0]))
    overlaps = [p for p in problems if "overlaps" in p.message]
    assert len(overlaps) == 1 and overlaps[0].where == "block 0"
    depth = float(overlaps[0].message.split("interpenetration ")[1].split(" ")[0])
    # Separating axes: the unit's top normal gives 0.5 - 0.4 = 0.1; the diamond's lower
    # edge normals (+-1, -1)/sqrt(2) give (1.5 - 0.9)/sqrt(2) = 0.42; the others more.
    assert depth == pytest.approx(0.1)


# ---------------------------------------------------------------- interfaces

def test_interface_referring_to_a_missing_block():
    interfaces = list(INTERFACES)
    interfaces[0] = (0, 9, (1.0, 1.0), (0.5, 0.0), 1)
    problems = check(model_dataset(interfaces=interfaces))
    assert "side 1 refers to block 9, but the blocks are numbered 0..3" in the_only(problems, "interface 0").message


def test_interface_with_the_same_block_on_both_sides():
    interfaces = list(INTERFACES)
    interfaces[0] = (1, 1, (1.0, 1.0), (0.5, 0.0), 1)
    problems = check(model_dataset(interfaces=interfaces))
    assert "both sides are block 1" in the_only(problems, "interface 0").message


def test_interface_not_on_an_edge_of_its_blocks():
    interfaces = list(INTERFACES)
    interfaces[0] = (0, 1, (1.2, 1.2), (0.5, 0.0), 1)  # 0.2 m right of the common edge
    problems = [p for p in check(model_dataset(interfaces=interfaces)) if p.where == "interface 0"]
    assert len(problems) == 2
    assert "does not lie on an edge of block 0 (side 0)" in problems[0].message
    assert "does not lie on an edge of block 1 (side 1)" in problems[1].message
    assert (problems[0].x, problems[0].y) == (1.2, 0.25)


def test_zero_length_interface():
    interfaces = list(INTERFACES)
    interfaces[0] = (0, 1, (1.0, 1.0), (0.25, 0.25), 1)
    assert "zero length" in the_only(check(model_dataset(interfaces=interfaces)), "interface 0").message


# ---------------------------------------------------------------- mechanics

def test_block_connected_to_nothing():
    polygons = [rectangle(*b) for b in BOXES] + [rectangle(5.0, 6.0, 0.0, 0.5)]
    problem = the_only(check(model_dataset(polygons=polygons, roles=ROLES + [0])), "block 4")
    assert "connected to nothing" in problem.message
    assert (problem.x, problem.y) == (5.5, 0.25)


def test_support_carrying_nothing():
    problems = check(model_dataset(interfaces=[INTERFACES[0], INTERFACES[2]]))
    assert "fixed support carries nothing" in the_only(problems, "block 2").message


def test_moving_support_with_zero_settlement_direction():
    ds = model_dataset()
    ds["settlement_direction"].values[3] = 0.0
    assert "cannot settle" in the_only(check(ds), "block 3").message


def test_settlement_direction_length_is_the_rate():
    """A moving support's direction need not be a unit vector (its length is its rate)."""
    ds = model_dataset()
    ds["settlement_direction"].values[3] = (0.0, -0.5, 0.0)
    assert [p for p in check(ds) if p.where == "block 3"] == []


def test_settlement_along_a_held_component():
    ds = model_dataset()
    ds["block_fixed"].values[3] = (1, 1, 1)
    assert "block_fixed holds uy" in the_only(check(ds), "block 3").message


def test_non_moving_block_with_a_settlement_direction():
    ds = model_dataset()
    ds["settlement_direction"].values[0] = (0.0, -1.0, 0.0)
    assert "only moving supports settle" in the_only(check(ds), "block 0").message


def test_no_live_load():
    problems = check(model_dataset(live_value=0.0))
    assert "no live load: the collapse multiplier is undefined" in the_only(problems, "variable live_load").message


def test_no_support_at_all():
    ds = model_dataset()
    ds["block_role"].values[:] = 0
    ds["settlement_direction"].values[:] = 0.0
    assert "no support block" in the_only(check(ds), "variable block_role").message


def test_every_problem_is_reported_at_once():
    polygons = [rectangle(*b) for b in BOXES]
    polygons[0] = polygons[0][::-1]
    ds = with_nodes(model_dataset(live_value=0.0), polygons)
    del ds.attrs["title"]
    ds["interface_friction"].values[1] = -1.0
    ds["block_thickness"].values[3] = np.nan
    found = {(p.where, key) for p in check(ds) for key in ("missing", "clockwise", "friction", "not finite", "no live load") if key in p.message}
    assert found == {
        ("attribute title", "missing"),
        ("block 0", "clockwise"),
        ("interface 1", "friction"),
        ("block 3", "not finite"),
        ("variable live_load", "no live load"),
    }


# ---------------------------------------------------------------- results and comparisons

def test_valid_result_and_result_checked_as_model():
    assert check(result_dataset()) == []
    assert check(result_dataset(), kind="model") == []


def test_model_is_not_a_result():
    problems = check(model_dataset(), kind="result")
    assert "is 'model' but a result dataset was expected" in the_only(problems, "attribute masonryfw_format").message
    assert {"attribute plugin", "attribute solver", "attribute solver_options"} <= {p.where for p in problems}


def test_result_attributes_and_variables():
    ds = result_dataset(solver_options="{tolerance: 1e-9")
    del ds.attrs["plugin"]
    ds["crack_indicator"].values[1] = 1.5
    ds["interface_state"].values[2] = 9
    ds["block_displacement"] = (("block", "axis"), np.full((4, 2), np.nan), {"units": "m", "long_name": "u"})
    problems = check(ds)
    assert "missing" in the_only(problems, "attribute plugin").message
    assert "not valid JSON" in the_only(problems, "attribute solver_options").message
    assert "crack_indicator = 1.5 is above the maximum 1" in the_only(problems, "interface 1").message
    assert "interface_state = 9 is not a valid flag" in the_only(problems, "interface 2").message
    assert sum("block_displacement" in p.message for p in problems) == 8


def test_result_variable_with_wrong_dims():
    ds = result_dataset()
    ds["crack_indicator"] = ("step", np.zeros(3), {"units": "1"})
    assert "dims" in the_only(check(ds), "variable crack_indicator").message


def test_comparison_attributes():
    attrs = {"Conventions": "CF-1.11", "masonryfw_format": "comparison", "masonryfw_format_version": 1,
             "title": "la vs fdem", "comparator": "crack", "comparator_version": "0.1",
             "comparator_options": "{}", "input_a_sha256": "ab", "input_b_sha256": "cd"}
    assert check(xr.Dataset(attrs=attrs)) == []
    del attrs["input_b_sha256"]
    assert "missing" in the_only(check(xr.Dataset(attrs=attrs)), "attribute input_b_sha256").message


# ---------------------------------------------------------------- scale

def running_bond_model(courses, units):
    """A running-bond wall on one moving support, interfaces from detect_interfaces (only input here)."""
    polygons = []
    for r in range(courses):
        joints = np.arange(units + 1) * 2.0 if r % 2 == 0 else np.concatenate(([0.0], np.arange(units) * 2.0 + 1.0, [2.0 * units]))
        polygons += [rectangle(a, b, r * 1.0, r + 1.0) for a, b in zip(joints[:-1], joints[1:])]
    polygons.append(rectangle(0.0, 2.0 * units, -1.0, 0.0))
    roles = [0] * (len(polygons) - 1) + [3]
    found = detect_interfaces(*polygon_nodes(polygons))
    interfaces = [(int(b[0]), int(b[1]), tuple(x), tuple(y), 0) for b, x, y in zip(found["blocks"], found["x"], found["y"])]
    return model_dataset(polygons=polygons, roles=roles, interfaces=interfaces)


def test_large_valid_wall_has_no_problem_and_a_shifted_unit_is_found():
    ds = running_bond_model(12, 10)
    assert check(ds) == []
    ds["node_x"].values[4 * 25: 4 * 26] += 0.3  # unit 25 (third course) pushed into its right neighbour
    problems = check(ds)
    assert any(p.where == "block 25" and "overlaps block 26 (interpenetration 0.3 m)" in p.message for p in problems)
