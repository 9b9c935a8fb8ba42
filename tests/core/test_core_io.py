"""netCDF I/O: atomic writes, refusal to overwrite inputs, history, hashes, read errors."""
from __future__ import annotations

import hashlib
import os
import re

import netCDF4
import numpy as np
import pytest
import xarray as xr

import masonryfw
import masonryfw.plugin_api
import masonryfw.testing
from masonryfw.format import io as mio
from masonryfw.runtime.errors import ModelError

HISTORY_LINE = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ masonryfw (\S+): (.*)")


def small_dataset(seed: int = 0) -> xr.Dataset:
    """Two square blocks with some float, int and flag data (save does not validate)."""
    rng = np.random.default_rng(seed)
    return xr.Dataset(
        {
            "node_x": ("node", [0.0, 1.0, 1.0, 0.0, 1.0, 2.0, 2.0, 1.0]),
            "node_y": ("node", [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0]),
            "block_node_count": ("block", np.array([4, 4])),
            "block_role": ("block", np.array([0, 3])),  # int64, as a careless writer leaves it
            "dead_load": (("block", "axis"), rng.normal(size=(2, 2))),
            "extra": ("node", rng.normal(size=8), {"units": "1", "long_name": "plugin data"}),
        },
        coords={"dof": ["ux", "uy", "rz"]},
        attrs={"title": "two blocks", "masonryfw_format": "model"},
    )


def open_fds_to(path) -> list[str]:
    """File descriptors of this process that point at ``path`` (Linux /proc)."""
    real = os.path.realpath(path)
    fd_dir = "/proc/self/fd"
    links = []
    for fd in os.listdir(fd_dir):
        try:
            links.append(os.readlink(os.path.join(fd_dir, fd)))
        except OSError:  # the fd of listdir itself is gone by now
            pass
    return [link for link in links if link == real]


# ------------------------------------------------------------------ hashes

def test_sha256_file_equals_hashlib_across_chunks(tmp_path):
    data = np.random.default_rng(1).bytes(3 * (1 << 20) + 17)  # crosses the 1 MiB chunks
    path = tmp_path / "blob.bin"
    path.write_bytes(data)
    assert mio.sha256_file(path) == hashlib.sha256(data).hexdigest()


def test_open_dataset_records_absolute_source_and_hash(tmp_path, monkeypatch):
    saved = mio.save(small_dataset(), tmp_path / "m.nc")
    monkeypatch.chdir(tmp_path)
    ds = mio.open_dataset("m.nc")
    assert ds.encoding["source"] == str(saved) and os.path.isabs(ds.encoding["source"])
    assert ds.encoding["sha256"] == hashlib.sha256(saved.read_bytes()).hexdigest()


def test_content_hash_ignores_file_details_and_order(tmp_path):
    ds = small_dataset()
    first = mio.open_dataset(mio.save(ds, tmp_path / "a.nc", command="one"))
    second = mio.open_dataset(mio.save(ds, tmp_path / "b.nc", command="two"))
    reference = mio.content_sha256(ds)
    assert mio.content_sha256(first) == reference  # written, read back, history differs
    assert mio.content_sha256(second) == reference
    permuted = xr.Dataset(
        {name: ds[name] for name in reversed(list(ds.data_vars))},
        coords=ds.coords,
        attrs=dict(reversed(list(ds.attrs.items()))),
    )
    assert list(permuted.data_vars) != list(ds.data_vars)
    assert mio.content_sha256(permuted) == reference
    with_geometry = masonryfw.plugin_api.derive_geometry(ds)  # derived values are not content
    assert mio.content_sha256(with_geometry) == reference


def test_content_hash_sees_one_ulp_and_structure(tmp_path):
    ds = small_dataset()
    reference = mio.content_sha256(ds)
    nudged = ds.copy(deep=True)
    nudged["dead_load"].values[1, 1] = np.nextafter(nudged["dead_load"].values[1, 1], np.inf)
    assert mio.content_sha256(nudged) != reference
    assert mio.content_sha256(ds.assign(extra=ds.extra.astype(np.float32))) != reference
    assert mio.content_sha256(ds.rename_vars(extra="extra2")) != reference
    assert mio.content_sha256(ds.assign_attrs(title="other")) != reference
    assert mio.content_sha256(ds.assign_attrs(history="anything")) == reference


def test_derived_variable_list_matches_derive_geometry():
    ds = small_dataset().assign(
        interface_blocks=(("interface", "side"), np.array([[0, 1]])),
        interface_x=(("interface", "end"), np.array([[1.0, 1.0]])),
        interface_y=(("interface", "end"), np.array([[0.0, 1.0]])),
    )
    mfp = masonryfw.plugin_api
    added = set(mfp.derive_geometry(ds).variables) - set(ds.variables)
    in_3d = mfp.twin(masonryfw.testing.small_settlement_wall())
    added_3d = set(mfp.derive_geometry(in_3d).variables) - set(in_3d.variables)
    assert added == set(mfp.DERIVED_GEOMETRY_VARIABLES)
    assert added | added_3d == set(mfp.DERIVED_VARIABLES)
    assert added_3d == {"block_volume", "block_centroid_x", "block_centroid_y", "block_centroid_z", "interface_area",
                        "interface_normal_x", "interface_normal_y", "interface_normal_z"}


# ------------------------------------------------------------------ reading errors

@pytest.mark.parametrize(
    "content, phrase",
    [
        (b"node_x = 0 1 2\n", "not a netCDF file"),
        (b"", "empty"),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(64), "not a netCDF file"),
    ],
    ids=["text", "empty", "png"],
)
def test_not_netcdf_files_are_named(tmp_path, content, phrase):
    path = tmp_path / "model.nc"
    path.write_bytes(content)
    with pytest.raises(ModelError, match=phrase) as caught:
        mio.open_dataset(path)
    assert str(path) in str(caught.value)


def test_truncated_netcdf_is_named(tmp_path):
    saved = mio.save(small_dataset(), tmp_path / "whole.nc")
    cut = tmp_path / "cut.nc"
    cut.write_bytes(saved.read_bytes()[:600])
    with pytest.raises(ModelError, match="cannot be read") as caught:
        mio.open_dataset(cut)
    assert str(cut) in str(caught.value)


def test_missing_file_and_directory_are_named(tmp_path):
    with pytest.raises(ModelError, match="no such file") as caught:
        mio.open_dataset(tmp_path / "absent.nc")
    assert str(tmp_path / "absent.nc") in str(caught.value)
    with pytest.raises(ModelError, match="is a directory") as caught:
        mio.open_dataset(tmp_path)
    assert str(tmp_path) in str(caught.value)


def test_reading_leaves_no_open_handle(tmp_path):
    path = tmp_path / "m.nc"
    small_dataset(seed=1).to_netcdf(path)
    before = mio.open_dataset(path)
    assert open_fds_to(path) == []
    # Overwrite in place (HDF5 refuses while a handle is open; a cached handle would
    # return stale data), then replace by rename: both readable anew.
    small_dataset(seed=2).to_netcdf(path, mode="w")
    after = mio.open_dataset(path)
    np.testing.assert_array_equal(after.extra.values, small_dataset(seed=2).extra.values)
    other = mio.save(small_dataset(seed=3), tmp_path / "other.nc")
    os.replace(other, path)
    np.testing.assert_array_equal(mio.open_dataset(path).extra.values, small_dataset(seed=3).extra.values)
    np.testing.assert_array_equal(before.extra.values, small_dataset(seed=1).extra.values)


# ------------------------------------------------------------------ atomic writes

def _failing_to_netcdf(self, path=None, *args, **kwargs):
    """Leave a partial file, as a write dying half-way would, then fail."""
    with open(path, "wb") as stream:
        stream.write(b"\x89HDF\r\n\x1a\n" + b"partial")
    raise OSError(28, "No space left on device")


def test_failed_write_leaves_target_and_no_temporary(tmp_path, monkeypatch):
    target = mio.save(small_dataset(seed=1), tmp_path / "m.nc")
    original = target.read_bytes()
    monkeypatch.setattr(xr.Dataset, "to_netcdf", _failing_to_netcdf)
    with pytest.raises(ModelError, match="No space left") as caught:
        mio.save(small_dataset(seed=2), target)
    assert str(target) in str(caught.value)
    assert target.read_bytes() == original
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.nc"]
    with pytest.raises(ModelError):
        mio.save(small_dataset(seed=2), tmp_path / "new.nc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.nc"]


def test_failed_rename_leaves_target_and_no_temporary(tmp_path, monkeypatch):
    target = mio.save(small_dataset(seed=1), tmp_path / "m.nc")
    original = target.read_bytes()

    def failing_replace(src, dst):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(mio.os, "replace", failing_replace)
    with pytest.raises(ModelError, match="Permission denied"):
        mio.save(small_dataset(seed=2), target)
    monkeypatch.undo()
    assert target.read_bytes() == original
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.nc"]


def test_save_keeps_permissions_of_replaced_file(tmp_path):
    target = mio.save(small_dataset(), tmp_path / "m.nc")
    target.chmod(0o640)
    mio.save(small_dataset(seed=5), target)
    assert target.stat().st_mode & 0o777 == 0o640


# ------------------------------------------------------------------ refusals

def test_save_refuses_to_overwrite_its_input(tmp_path, monkeypatch):
    source = mio.save(small_dataset(), tmp_path / "in.nc")
    original = source.read_bytes()
    ds = mio.open_dataset(source)
    (tmp_path / "link.nc").symlink_to(source)
    os.link(source, tmp_path / "hard.nc")
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path / "sub")
    for alias in (source, tmp_path / "link.nc", tmp_path / "hard.nc", "../in.nc", "./../sub/../in.nc"):
        with pytest.raises(ModelError, match="refusing to overwrite the file this dataset was read from"):
            mio.save(ds, alias)
    assert source.read_bytes() == original
    assert (tmp_path / "link.nc").is_symlink()
    mio.save(ds, "copy.nc")  # anywhere else is fine
    assert ds.encoding["source"] == str(source)  # saving does not change the dataset


def test_save_refuses_protected_and_result_model_file(tmp_path):
    model_file = mio.save(small_dataset(), tmp_path / "model.nc")
    fresh = small_dataset(seed=4)
    with pytest.raises(ModelError, match="protected"):
        mio.save(fresh, tmp_path / "model.nc", protect=[model_file])
    result = fresh.assign_attrs(source_file=str(model_file), masonryfw_format="result")
    with pytest.raises(ModelError, match="model file this result was computed from"):
        mio.save(result, model_file)
    mio.save(result, tmp_path / "result.nc")


def test_save_needs_an_existing_directory(tmp_path):
    with pytest.raises(ModelError, match="does not exist") as caught:
        mio.save(small_dataset(), tmp_path / "missing" / "m.nc")
    assert "missing" in str(caught.value)
    with pytest.raises(ModelError, match="is a directory"):
        mio.save(small_dataset(), tmp_path)


def test_save_returns_absolute_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    saved = mio.save(small_dataset(), "m.nc")
    assert saved.is_absolute() and saved == tmp_path.resolve() / "m.nc" and saved.is_file()


# ------------------------------------------------------------------ history and CF form

def test_history_grows_one_line_per_save(tmp_path):
    ds = small_dataset().assign_attrs(history="2020-01-01T00:00:00Z othertool 1.0: made it")
    first = mio.open_dataset(mio.save(ds, tmp_path / "a.nc"))
    second = mio.open_dataset(mio.save(first, tmp_path / "b.nc", command="masonryfw solve a.nc\n--plugin la"))
    lines = second.attrs["history"].split("\n")
    assert len(first.attrs["history"].split("\n")) == 2 and len(lines) == 3
    assert lines[0] == "2020-01-01T00:00:00Z othertool 1.0: made it"
    assert [HISTORY_LINE.fullmatch(line).groups() for line in lines[1:]] == [
        (masonryfw.__version__, "save"),
        (masonryfw.__version__, "masonryfw solve a.nc --plugin la"),
    ]
    assert ds.attrs["history"].count("\n") == 0  # the caller's dataset is untouched


def test_add_history_returns_new_dataset():
    ds = small_dataset()
    out = mio.add_history(ds, "step one")
    assert "history" not in ds.attrs
    assert HISTORY_LINE.fullmatch(out.attrs["history"]).group(2) == "step one"
    assert mio.add_history(out, "step two").attrs["history"].count("\n") == 1


def test_save_fills_cf_attributes_from_the_format(tmp_path):
    """Expected values are docs/format.md's tables, not the schema files."""
    ds = small_dataset()
    saved = mio.save(ds, tmp_path / "m.nc")
    with netCDF4.Dataset(saved) as nc:
        assert nc.getncattr("Conventions") == "CF-1.11"
        assert nc["node_x"].units == "m" and nc["dead_load"].units == "N"
        role = nc["block_role"]
        assert role.dtype == np.int8 and role.flag_values.dtype == np.int8
        assert list(role.flag_values) == [0, 1, 2, 3, 4]
        assert role.flag_meanings == "unit lintel fixed_support moving_support voussoir"
        assert nc["block_geometry"].geometry_type == "polygon"
        assert nc["extra"].long_name == "plugin data"  # a plugin's own attributes are kept
        for name in ("node_x", "block_role", "dead_load", "extra"):
            assert nc[name].filters()["zlib"] and nc[name].filters()["complevel"] == 4
        assert not nc["block_geometry"].filters()["zlib"]  # scalar: nothing to compress
        assert "_FillValue" not in nc["block_role"].ncattrs()
    assert ds.block_role.dtype == np.int64 and "units" not in ds.node_x.attrs
    assert "Conventions" not in ds.attrs and "block_geometry" not in ds.variables


def test_flag_values_outside_int8_are_rejected(tmp_path):
    ds = small_dataset().assign(block_role=("block", np.array([0, 300])))
    with pytest.raises(ModelError, match="'block_role'.*found 300 at flat index 1"):
        mio.save(ds, tmp_path / "m.nc")
    with pytest.raises(ModelError, match="'block_role'.*found 0.5"):
        mio.save(ds.assign(block_role=("block", [0.5, 3.0])), tmp_path / "m.nc")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ open_model

def test_open_model_of_a_missing_file_says_no_such_file(tmp_path):
    missing = tmp_path / "nowhere.nc"
    with pytest.raises(ModelError, match=f"{missing}: no such file$"):
        masonryfw.open_model(missing)


def test_open_model_unknown_name_says_both():
    with pytest.raises(ModelError) as caught:
        masonryfw.open_model("test-13c")
    message = str(caught.value)
    assert "test-13c: no such file, and not a bundled case" in message
    assert "test-12c" in message  # the bundled cases are listed


def test_open_model_bundled_name_and_its_file_agree(tmp_path):
    by_name = masonryfw.open_model("test-12c")
    saved = mio.save(by_name, tmp_path / "test-12c.nc")
    by_file = masonryfw.open_model(saved)
    assert mio.content_sha256(by_file) == mio.content_sha256(by_name)
    np.testing.assert_array_equal(by_file.block_centroid_x.values, by_name.block_centroid_x.values)


def test_open_model_of_a_result_file_is_its_model(tmp_path):
    model = masonryfw.open_model("test-12c")
    result = masonryfw.solve(model, "statics")
    loaded = masonryfw.open_model(mio.save(result, tmp_path / "result.nc"))
    assert loaded.attrs["masonryfw_format"] == "model" and "masonry_weight" not in loaded
    assert mio.content_sha256(loaded) == mio.content_sha256(model)
    np.testing.assert_array_equal(loaded.block_area.values, model.block_area.values)
