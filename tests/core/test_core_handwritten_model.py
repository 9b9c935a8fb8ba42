"""A model written by hand from docs/format.md alone, with plain xarray, loads and round-trips.

The file is built without any masonryfw writer: if it loads, a third-party tool
following docs/format.md can produce models; the same wall written in format
version 1 reads as the same model. Expected areas, centroids, lengths and
normals are hand values (rectangle and trapezoid formulas).

    y
    1.0        ____C____          C: trapezoid, bottom 0.5..1.5 at y=0.5, top 0.75..1.25 at y=1
    0.5  |____A____|____B____|    A: 0..1 x 0..0.5,  B: 1..2 x 0..0.5 (units)
    0.0  |__S______|  |______M|   S: fixed support 0..0.95, M: moving support 1.05..2
   -0.5
"""
from __future__ import annotations

import re

import netCDF4
import numpy as np
import pytest
import xarray as xr

import masonryfw
from masonryfw.runtime.errors import ModelError

UNIT_WEIGHT = 20_000.0  # N m-3
THICKNESS = 0.3  # m

# Vertices, counter-clockwise, block after block: A, B, C, S (fixed), M (moving).
POLYGONS = [
    [(0.0, 0.0), (1.0, 0.0), (1.0, 0.5), (0.0, 0.5)],
    [(1.0, 0.0), (2.0, 0.0), (2.0, 0.5), (1.0, 0.5)],
    [(0.5, 0.5), (1.5, 0.5), (1.25, 1.0), (0.75, 1.0)],
    [(0.0, -0.5), (0.95, -0.5), (0.95, 0.0), (0.0, 0.0)],
    [(1.05, -0.5), (2.0, -0.5), (2.0, 0.0), (1.05, 0.0)],
]
ROLE = [0, 0, 0, 2, 3]  # unit unit unit fixed_support moving_support

# Hand values. Trapezoid C: area = (1 + 0.5) / 2 * 0.5; centroid height above its base
# h (b + 2a) / (3 (a + b)) with b = 1 (bottom), a = 0.5 (top), h = 0.5.
AREA = [0.5, 0.5, 0.375, 0.475, 0.475]
CENTROID_X = [0.5, 1.5, 1.0, 0.475, 1.525]
CENTROID_Y = [0.25, 0.25, 0.5 + 0.5 * 2.0 / 4.5, -0.25, -0.25]

# Interfaces: (side 0, side 1), end points, kind (0 bed, 1 head, 2 support).
INTERFACES = [
    ((0, 1), ((1.0, 0.0), (1.0, 0.5)), 1),  # A|B head joint, normal +x
    ((0, 2), ((0.5, 0.5), (1.0, 0.5)), 0),  # A/C bed joint, normal +y
    ((1, 2), ((1.0, 0.5), (1.5, 0.5)), 0),  # B/C bed joint
    ((3, 0), ((0.0, 0.0), (0.95, 0.0)), 2),  # S/A support joint
    ((4, 1), ((1.05, 0.0), (2.0, 0.0)), 2),  # M/B support joint
]
LENGTH = [0.5, 0.5, 0.5, 0.95, 0.95]
NORMAL = [(1.0, 0.0), (0.0, 1.0), (0.0, 1.0), (0.0, 1.0), (0.0, 1.0)]


def _weights() -> np.ndarray:
    return np.array(AREA) * THICKNESS * np.array([UNIT_WEIGHT] * 3 + [0.0, 0.0])


def loads(dead, live) -> dict:
    """Version 2: forces over ``axis`` [N], moments apart [N m]."""
    return {"dead_load": (("block", "axis"), dead[:, :2], {"units": "N", "long_name": "dead load"}),
            "dead_moment": ("block", dead[:, 2], {"units": "N m", "long_name": "dead moment"}),
            "live_load": (("block", "axis"), live[:, :2], {"units": "N", "long_name": "live load"}),
            "live_moment": ("block", live[:, 2], {"units": "N m", "long_name": "live moment"})}


def loads_version_1(dead, live) -> dict:
    """Version 1: one variable over ``dof`` with per-component units (not CF)."""
    return {"dead_load": (("block", "dof"), dead, {"units": "N, N, N m", "long_name": "dead load"}),
            "live_load": (("block", "dof"), live, {"units": "N, N, N m", "long_name": "live load"})}


def hand_model(version: int = 2) -> xr.Dataset:
    """The wall above as docs/format.md describes a model, in plain xarray (``version`` 1: the old load layout)."""
    x = np.array([p[0] for poly in POLYGONS for p in poly])
    y = np.array([p[1] for poly in POLYGONS for p in poly])
    weight = _weights()
    # Settlement loading: masonry weight spread over the supported length 0.95 + 0.95;
    # the moving support carries its share upward (dead) and downward (live).
    share = weight.sum() * 0.95 / 1.9
    dead = np.zeros((5, 3))
    dead[:, 1] = -weight
    dead[4, 1] = share
    live = np.zeros((5, 3))
    live[4, 1] = -share
    fixed = np.zeros((5, 3), dtype=np.int8)
    fixed[3] = (1, 1, 1)
    fixed[4] = (1, 0, 1)
    settlement = np.zeros((5, 3))
    settlement[4] = (0.0, -1.0, 0.0)
    ends = np.array([e for _, e, _ in INTERFACES])  # (interface, end, xy)
    nint = len(INTERFACES)

    def var(dims, values, units, long_name, **extra):
        return (dims, values, {"units": units, "long_name": long_name, **extra})

    flags4 = np.array([0, 1, 2, 3], dtype=np.int8)
    return xr.Dataset(
        {
            "node_x": var("node", x, "m", "vertex x"),
            "node_y": var("node", y, "m", "vertex y"),
            "block_node_count": var("block", np.array([len(p) for p in POLYGONS], dtype=np.int32), "1", "vertices per block"),
            "block_geometry": ((), np.int32(0), {
                "geometry_type": "polygon", "node_count": "block_node_count",
                "node_coordinates": "node_x node_y", "units": "1", "long_name": "geometry container"}),
            "block_role": var("block", np.array(ROLE, dtype=np.int8), "1", "role", flag_values=flags4,
                              flag_meanings="unit lintel fixed_support moving_support"),
            "block_thickness": var("block", np.full(5, THICKNESS), "m", "thickness"),
            "block_unit_weight": var("block", np.array([UNIT_WEIGHT] * 3 + [0.0, 0.0]), "N m-3", "unit weight"),
            "interface_blocks": var(("interface", "side"), np.array([b for b, _, _ in INTERFACES], dtype=np.int32), "1", "blocks"),
            "interface_x": var(("interface", "end"), ends[:, :, 0], "m", "end x"),
            "interface_y": var(("interface", "end"), ends[:, :, 1], "m", "end y"),
            "interface_kind": var("interface", np.array([k for _, _, k in INTERFACES], dtype=np.int8), "1", "kind",
                                  flag_values=flags4, flag_meanings="bed head support other"),
            "interface_friction": var("interface", np.full(nint, 0.6), "1", "friction coefficient"),
            "interface_cohesion": var("interface", np.zeros(nint), "Pa", "cohesion"),
            "interface_tensile_strength": var("interface", np.zeros(nint), "Pa", "tensile strength"),
            **(loads_version_1(dead, live) if version == 1 else loads(dead, live)),
            "block_fixed": var(("block", "dof"), fixed, "1", "held components",
                               flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="free held"),
            "settlement_direction": var(("block", "dof"), settlement, "1", "settlement direction"),
        },
        coords={"dof": ("dof", ["ux", "uy", "rz"], {"units": "1", "long_name": "degree of freedom"})},
        attrs={
            "Conventions": "CF-1.11",
            "masonryfw_format": "model",
            "masonryfw_format_version": version,
            "title": "hand-written three-unit wall",
        },
    )


@pytest.fixture
def hand_file(tmp_path):
    path = tmp_path / "hand.nc"
    hand_model().to_netcdf(path)
    return path


def test_hand_model_loads_with_hand_areas_and_centroids(hand_file):
    model = masonryfw.open_model(hand_file)
    np.testing.assert_allclose(model.block_area.values, AREA, rtol=1e-12)
    np.testing.assert_allclose(model.block_centroid_x.values, CENTROID_X, rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.block_centroid_y.values, CENTROID_Y, rtol=0, atol=1e-12)


def test_hand_model_interface_lengths_normals_tangents(hand_file):
    model = masonryfw.open_model(hand_file)
    normal = np.array(NORMAL)
    np.testing.assert_allclose(model.interface_length.values, LENGTH, rtol=1e-12)
    np.testing.assert_allclose(model.interface_normal_x.values, normal[:, 0], atol=1e-12)
    np.testing.assert_allclose(model.interface_normal_y.values, normal[:, 1], atol=1e-12)
    # docs/architecture.md: t = (n_y, -n_x), so a bed joint (n = +y) has t = +x.
    np.testing.assert_allclose(model.interface_tangent_x.values, normal[:, 1], atol=1e-12)
    np.testing.assert_allclose(model.interface_tangent_y.values, -normal[:, 0], atol=1e-12)


def test_stored_derived_geometry_is_not_trusted(tmp_path):
    tampered = hand_model().assign(
        block_area=("block", np.full(5, 99.0)),
        block_centroid_x=("block", np.full(5, -7.0)),
        block_centroid_y=("block", np.full(5, 42.0)),
        interface_normal_x=("interface", np.full(5, 0.6)),
    )
    path = tmp_path / "tampered.nc"
    tampered.to_netcdf(path)
    model = masonryfw.open_model(path)
    np.testing.assert_allclose(model.block_area.values, AREA, rtol=1e-12)
    np.testing.assert_allclose(model.block_centroid_x.values, CENTROID_X, atol=1e-12)
    np.testing.assert_allclose(model.block_centroid_y.values, CENTROID_Y, atol=1e-12)
    np.testing.assert_allclose(model.interface_normal_x.values, np.array(NORMAL)[:, 0], atol=1e-12)


def test_save_round_trips_through_plain_xarray(hand_file, tmp_path):
    model = masonryfw.open_model(hand_file)
    saved = masonryfw.save(model, tmp_path / "saved.nc", command="test round trip")
    hand = hand_model()
    with xr.open_dataset(saved) as plain:
        for name, variable in hand.variables.items():
            np.testing.assert_array_equal(plain[name].values, variable.values, err_msg=name)
            assert plain[name].dims == variable.dims, name
        # Derived geometry is written for plain readers: the hand values again.
        np.testing.assert_allclose(plain.block_area.values, AREA, rtol=1e-12)
        np.testing.assert_allclose(plain.block_centroid_y.values, CENTROID_Y, atol=1e-12)
        assert plain.block_role.dtype == np.int8
        assert plain.title == hand.title
    again = masonryfw.open_model(saved)
    for name in model.variables:
        np.testing.assert_array_equal(again[name].values, model[name].values, err_msg=name)
    assert masonryfw.format.io.content_sha256(again) == masonryfw.format.io.content_sha256(model)


def test_saved_file_is_compressed_cf(hand_file, tmp_path):
    saved = masonryfw.save(masonryfw.open_model(hand_file), tmp_path / "saved.nc")
    with netCDF4.Dataset(saved) as nc:
        assert nc.getncattr("Conventions") == "CF-1.11"
        assert nc.data_model == "NETCDF4"
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ masonryfw \S+: save", nc.getncattr("history"))
        for name, variable in nc.variables.items():
            attrs = variable.ncattrs()
            assert "units" in attrs and "long_name" in attrs, name
            numeric = variable.dtype is not str and np.dtype(variable.dtype).kind in "biuf"
            if numeric and variable.ndim > 0:
                filters = variable.filters()
                assert filters["zlib"] and filters["shuffle"] and filters["complevel"] == 4, name
        for name in ("block_role", "interface_kind", "block_fixed"):
            assert nc[name].dtype == np.int8
            assert nc[name].getncattr("flag_values").dtype == np.int8
        geometry = nc["block_geometry"]
        assert geometry.geometry_type == "polygon"
        assert geometry.node_count == "block_node_count"
        assert geometry.node_coordinates == "node_x node_y"
        assert (nc["node_x"].axis, nc["node_y"].axis) == ("X", "Y")


def test_open_model_reports_every_problem(tmp_path):
    broken = hand_model()
    broken["block_thickness"].values[1] = -0.3
    broken["interface_friction"].values[2] = -0.6
    path = tmp_path / "broken.nc"
    broken.to_netcdf(path)
    with pytest.raises(ModelError) as caught:
        masonryfw.open_model(path)
    message = str(caught.value)
    assert str(path) in message and "problem(s)" in message
    assert len(caught.value.problems) >= 2
    assert "block_thickness" in message and "interface_friction" in message
    masonryfw.open_model(path, validate=False)  # the geometry is still sound


def test_a_version_1_file_reads_as_the_same_model(tmp_path):
    """Format version 1 (loads over ``dof``) is upgraded on reading: the same content as the version-2 file."""
    old, new = tmp_path / "v1.nc", tmp_path / "v2.nc"
    hand_model(version=1).to_netcdf(old)
    hand_model(version=2).to_netcdf(new)
    from_old, from_new = masonryfw.open_model(old), masonryfw.open_model(new)
    assert from_old.attrs["masonryfw_format_version"] == 2
    for name in ("dead_load", "dead_moment", "live_load", "live_moment"):
        np.testing.assert_array_equal(from_old[name].values, from_new[name].values, err_msg=name)
        assert from_old[name].dims == from_new[name].dims
    assert masonryfw.check(xr.open_dataset(old)) == []  # a plain reader's dataset checks as it reads
    result = masonryfw.solve(from_old, "statics")
    assert float(result.masonry_weight) == pytest.approx(_weights().sum())
