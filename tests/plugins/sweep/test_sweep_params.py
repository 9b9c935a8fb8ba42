"""Sweep parameters: value syntax (hand-counted), key-path checks before any work, grid and zip points."""
from __future__ import annotations

import pytest

import masonryfw as mf
from masonryfw_sweep import parse_param, plan_sweep
from masonryfw_sweep.params import point_indices, with_values

SMALL_SPEC = """
title = "Small"
[wall]
width = 0.4
height = 0.1
thickness = 0.1
[unit]
length = 0.2
height = 0.05
[material]
unit_weight = 12000.0
friction_angle = 30.0
[supports.fixed]
kind = "fixed"
start = 0.0
end = 0.2
[supports.settling]
kind = "moving"
start = 0.2
end = 0.4
[loading]
type = "settlement"
"""


@pytest.mark.parametrize(
    "text, expected",
    [
        ("0.3:0.9:0.1", (0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)),  # stop included although 0.3 + 6 * 0.1 > 0.9
        ("0:1:0.25", (0.0, 0.25, 0.5, 0.75, 1.0)),
        ("0:1:0.3", (0.0, 0.3, 0.6, 0.9)),  # stop off the grid: not reached
        ("1:10:3", (1, 4, 7, 10)),
        ("0.9:0.3:-0.3", (0.9, 0.6, 0.3)),
    ],
)
def test_range_values_are_counted_by_hand(text, expected):
    param = parse_param(f"supports.settling.start={text}")
    assert param.values == expected
    assert all(type(v) is type(e) for v, e in zip(param.values, expected))


@pytest.mark.parametrize(
    "text, expected",
    [
        ("18,21.8,30", (18, 21.8, 30)),
        ("highs, clarabel", ("highs", "clarabel")),
        ("true,false", (True, False)),
        ("[[0.1, 0.0], [0.2, 0.0]]", ([0.1, 0.0], [0.2, 0.0])),
        ("0.5", (0.5,)),
    ],
)
def test_lists_read_each_item_as_a_toml_value(text, expected):
    assert parse_param(f"k={text}").values == expected


@pytest.mark.parametrize("text", ["k=1:0:0.1", "k=0:1:0", "k=0:1", "k=a:b:c", "k=", "k=1,,2", "=1", "k"])
def test_malformed_values_raise_quoting_the_parameter(text):
    with pytest.raises(mf.SpecError, match="--param"):
        parse_param(text)


def test_names_are_dimension_friendly():
    assert parse_param("supports.settling.start=0.5").name == "supports_settling_start"
    assert parse_param("option.solver=highs").option_name == "solver"


def test_with_values_edits_a_copy_and_indexes_arrays_of_tables():
    spec = {"a": {"b": 1}, "openings": [{"x": 0.1}, {"x": 0.5}]}
    edited = with_values(spec, [(("a", "b"), 2), (("openings", 1, "x"), 0.7), (("new", "key"), "v")])
    assert edited == {"a": {"b": 2}, "openings": [{"x": 0.1}, {"x": 0.7}], "new": {"key": "v"}}
    assert spec == {"a": {"b": 1}, "openings": [{"x": 0.1}, {"x": 0.5}]}
    with pytest.raises(mf.SpecError, match="'openings.2'"):
        with_values(spec, [(("openings", 2, "x"), 0.0)])


@pytest.mark.parametrize(
    "param, error, named",
    [
        ("material.frcition=0.4", mf.SpecError, "material.frcition"),  # unknown builder key
        ("material.friction=0.4,0.6", mf.SpecError, "material.friction"),  # clashes with friction_angle
        ("wall.width.x=1", mf.SpecError, "wall.width"),  # through a value
        ("option.nope=1", mf.PluginError, "nope"),
        ("option.solver=simplex", mf.PluginError, "solver"),
    ],
)
def test_unknown_keys_are_refused_before_any_work(tmp_path, param, error, named):
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL_SPEC)
    with pytest.raises(error, match=named.replace(".", r"\.")):
        plan_sweep(str(spec), "la", [param])


def test_a_builder_key_missing_from_the_spec_is_accepted(tmp_path):
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL_SPEC)
    plan = plan_sweep(str(spec), "la", ["material.cohesion=0,1000", "option.tolerance=1e-8"], {"solver": "osqp"})
    assert plan.shape == (2, 1)
    defaults = {o.name: o.default for o in mf.get_solver("la").options}
    assert plan.point_options((1, 0)) == {**defaults, "solver": "osqp", "tolerance": 1e-8}


def test_a_bad_value_of_a_known_key_is_left_to_its_point(tmp_path):
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL_SPEC)
    plan = plan_sweep(str(spec), "la", ["material.friction_angle=30,95"])  # 95 degrees fails at build
    assert plan.shape == (2,)


def test_grid_points_are_the_cartesian_product_in_c_order():
    params = [parse_param("a=1,2,3"), parse_param("b=x,y")]
    shape, points = point_indices(params, zipped=False)
    assert shape == (3, 2)
    assert points == [(0, 0), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1)]


def test_zip_pairs_values_and_needs_equal_lengths():
    shape, points = point_indices([parse_param("a=1,2"), parse_param("b=x,y")], zipped=True)
    assert shape == (2,) and points == [(0, 0), (1, 1)]
    with pytest.raises(mf.SpecError, match=r"a \(2\), b \(3\)"):
        point_indices([parse_param("a=1,2"), parse_param("b=x,y,z")], zipped=True)


def test_a_key_given_twice_is_refused():
    with pytest.raises(mf.SpecError, match="given twice"):
        plan_sweep("test-12c", "la", ["wall.thickness=0.1", "wall.thickness=0.2"])
