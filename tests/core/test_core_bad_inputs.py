"""A corpus of bad inputs: each gives exit code 1 from the CLI, a message naming the problem,
no traceback, and the input file unchanged.

The model cases break the hand-built five-block model of ``conftest.py`` (plain xarray,
docs/format.md) in one way each; the others are files that are not models at all, bad
specs, and bad solver requests.
"""
from __future__ import annotations

import hashlib

import numpy as np
import pytest
from click.testing import CliRunner

from masonryfw.cli import cli


def _set(name, index, value):
    def breaker(ds):
        values = ds[name].values.copy()
        values[index] = value
        ds[name] = (ds[name].dims, values, ds[name].attrs)
        return ds
    return breaker


def _attr(name, value):
    def breaker(ds):
        if value is None:
            del ds.attrs[name]
        else:
            ds.attrs[name] = value
        return ds
    return breaker


def _block0_vertices(xy):
    """Replace block 0's four vertices (nodes 0..3)."""
    def breaker(ds):
        x, y = ds.node_x.values.copy(), ds.node_y.values.copy()
        x[:4], y[:4] = np.array(xy, float).T
        ds["node_x"] = ("node", x, ds.node_x.attrs)
        ds["node_y"] = ("node", y, ds.node_y.attrs)
        return ds
    return breaker


def _shift_block2_down(ds):
    y = ds.node_y.values.copy()
    y[8:12] -= 0.05
    ds["node_y"] = ("node", y, ds.node_y.attrs)
    return ds


def _drop_interfaces_of_block2(ds):
    keep = ~(ds.interface_blocks.values == 2).any(axis=1)
    return ds.isel(interface=np.flatnonzero(keep))


def _transpose_dead_load(ds):
    ds["dead_load"] = (("axis", "block"), ds.dead_load.values.T, ds.dead_load.attrs)
    return ds


def _no_live_load(ds):
    ds["live_load"] = (ds.live_load.dims, np.zeros_like(ds.live_load.values), ds.live_load.attrs)
    return ds


def _bad_node_count(ds):
    ds["block_node_count"] = ("block", np.array([4, 4, 4, 4, 5], np.int32), ds.block_node_count.attrs)
    return ds


def _poisson(ds):
    ds["block_poisson_ratio"] = ("block", np.full(ds.sizes["block"], 0.7), {"units": "1", "long_name": "nu"})
    return ds


MODEL_CASES = {  # name: (breaker, what the message must say)
    "repeated vertex": (_block0_vertices([(0, 0), (0, 0), (0.4, 0.2), (0, 0.2)]), r"block 0: .*repeated"),
    "clockwise": (_block0_vertices([(0, 0), (0, 0.2), (0.4, 0.2), (0.4, 0)]), r"block 0: .*clockwise"),
    "self-intersection": (_block0_vertices([(0, 0), (0.4, 0.2), (0.4, 0), (0, 0.2)]), r"block 0: .*intersects itself"),
    "zero area": (_block0_vertices([(0, 0), (0.2, 0), (0.4, 0), (0.3, 0)]), r"block 0: "),
    "collinear vertices": (_block0_vertices([(0, 0), (0.2, 0), (0.4, 0), (0, 0.2)]), r"block 0: .*straight line"),
    "overlap": (_shift_block2_down, r"block \d: .*overlap"),
    "NaN vertex": (_set("node_x", 5, np.nan), r"node_x.*(NaN|not finite)"),
    "inf load": (_set("dead_load", (1, 1), np.inf), r"dead_load.*(inf|not finite)"),
    "negative friction": (_set("interface_friction", 2, -0.4), r"interface 2: .*interface_friction"),
    "negative thickness": (_set("block_thickness", 1, -0.1), r"block 1: .*block_thickness"),
    "negative unit weight": (_set("block_unit_weight", 0, -1.0), r"block 0: .*block_unit_weight"),
    "moving support without direction": (_set("settlement_direction", (4, 1), 0.0), r"block 4: .*settlement"),
    "direction on a unit": (_set("settlement_direction", (0, 1), -1.0), r"block 0: .*settlement"),
    "missing block": (_set("interface_blocks", (2, 1), 9), r"interface 2: .*block 9"),
    "same block both sides": (_set("interface_blocks", (1, 1), 0), r"interface 1: "),
    "segment off its blocks": (_set("interface_y", (1, 0), 0.25), r"interface 1: .*does not lie on an edge"),
    "zero-length interface": (_set("interface_x", (1, 1), 0.0), r"interface 1: .*(zero|length)"),
    "connected to nothing": (_drop_interfaces_of_block2, r"block 2: .*(connected|interface)"),
    "role out of range": (_set("block_role", 1, 7), r"block 1: .*block_role"),
    "kind out of range": (_set("interface_kind", 0, 9), r"interface 0: .*interface_kind"),
    "wrong dims": (_transpose_dead_load, r"dead_load.*dims"),
    "no live load": (_no_live_load, r"no live load"),
    "node count mismatch": (_bad_node_count, r"block_node_count"),
    "poisson out of bounds": (_poisson, r"block_poisson_ratio"),
    "missing variable": (lambda ds: ds.drop_vars("interface_friction"), r"interface_friction.*missing|missing.*interface_friction"),
    "unknown format version": (_attr("masonryfw_format_version", 7), r"format version"),
    "unknown kind": (_attr("masonryfw_format", "mesh"), r"masonryfw_format"),
    "no Conventions": (_attr("Conventions", None), r"Conventions"),
    "no title": (_attr("title", None), r"title"),
}

NOT_A_MODEL = {  # file name: (bytes, message)
    "notes.nc": (b"these are my notes, not a model\n", r"not a netCDF file"),
    "empty.nc": (b"", r"empty"),
    "picture.nc": (b"\x89PNG\r\n\x1a\n" + bytes(64), r"not a netCDF file"),
}

BAD_SPECS = {  # name: (TOML text, message naming the key)
    "typo": ('title = "w"\n[wall]\nwdith = 1.0\n', r"wdith"),
    "negative width": (
        'title = "w"\n[wall]\nwidth = -1.0\nheight = 0.1\nthickness = 0.1\n[unit]\nlength = 0.2\nheight = 0.05\n'
        '[material]\nunit_weight = 12000.0\nfriction = 0.4\n'
        '[supports.base]\nkind = "fixed"\nstart = 0.0\nend = 1.0\n[loading]\ntype = "tilt"\n',
        r"wall.width",
    ),
    "not TOML": ("title = \n[[[", r"TOML"),
}


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _assert_clean_failure(result, message, path=None, digest=None):
    assert result.exit_code == 1, result.output
    assert isinstance(result.exception, SystemExit), "an unhandled exception escaped the CLI"
    assert "Traceback" not in result.output
    assert __import__("re").search(message, result.output), result.output
    if path is not None:
        assert _sha(path) == digest, "the input file was changed"


@pytest.mark.parametrize("case", sorted(MODEL_CASES))
def test_a_broken_model_fails_check_with_a_message_naming_the_problem(case, make_model, tmp_path):
    breaker, message = MODEL_CASES[case]
    path = tmp_path / "broken.nc"
    breaker(make_model()).to_netcdf(path)
    digest = _sha(path)
    _assert_clean_failure(CliRunner().invoke(cli, ["check", str(path)]), message, path, digest)
    # solving it fails the same way, before any solver runs, and writes nothing
    result = CliRunner().invoke(cli, ["solve", str(path), "--plugin", "statics", "-o", str(tmp_path / "r.nc")])
    _assert_clean_failure(result, message, path, digest)
    assert not (tmp_path / "r.nc").exists()


@pytest.mark.parametrize("name", sorted(NOT_A_MODEL))
def test_a_file_that_is_not_a_model_fails_with_its_path(name, tmp_path):
    content, message = NOT_A_MODEL[name]
    path = tmp_path / name
    path.write_bytes(content)
    for command in (["check", str(path)], ["info", str(path)]):
        _assert_clean_failure(CliRunner().invoke(cli, command), message, path, _sha(path))


def test_a_missing_file_and_a_directory_fail_clearly(tmp_path):
    _assert_clean_failure(CliRunner().invoke(cli, ["check", str(tmp_path / "nope.nc")]), r"nope.nc")
    _assert_clean_failure(CliRunner().invoke(cli, ["check", str(tmp_path)]), r"directory")


@pytest.mark.parametrize("name", sorted(BAD_SPECS))
def test_a_bad_spec_fails_build_naming_the_key(name, tmp_path):
    text, message = BAD_SPECS[name]
    spec = tmp_path / "wall.toml"
    spec.write_text(text)
    digest = _sha(spec)
    result = CliRunner().invoke(cli, ["build", str(spec), "-o", str(tmp_path / "wall.nc")])
    _assert_clean_failure(result, message, spec, digest)
    assert not (tmp_path / "wall.nc").exists()


def test_bad_solver_requests_list_the_valid_choices(model_file, tmp_path):
    digest = _sha(model_file)
    out = str(tmp_path / "r.nc")
    unknown_plugin = CliRunner().invoke(cli, ["solve", str(model_file), "--plugin", "nosuch", "-o", out])
    _assert_clean_failure(unknown_plugin, r"nosuch.*statics|statics.*nosuch", model_file, digest)
    unknown_option = CliRunner().invoke(
        cli, ["solve", str(model_file), "--plugin", "statics", "--option", "speed=11", "-o", out]
    )
    _assert_clean_failure(unknown_option, r"speed", model_file, digest)
    onto_input = CliRunner().invoke(cli, ["solve", str(model_file), "--plugin", "statics", "-o", str(model_file)])
    _assert_clean_failure(onto_input, r"refusing to overwrite", model_file, digest)


def test_each_broken_model_differs_from_a_valid_one_by_its_break_alone(make_model):
    """The unbroken model has no problem, so every problem the corpus reports comes from its own break."""
    import masonryfw as mf

    assert mf.check(make_model()) == []
    for case, (breaker, message) in MODEL_CASES.items():
        problems = mf.check(breaker(make_model()))
        assert problems, case
        assert any(__import__("re").search(message, str(p)) for p in problems), (case, [str(p) for p in problems])


def test_an_open_mesh_fails_build_naming_its_block_and_line_and_the_mesh_is_unchanged(tmp_path):
    mesh = tmp_path / "box.obj"
    mesh.write_text("o box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n")
    spec = tmp_path / "box.toml"
    spec.write_text('title = "box"\n[geometry]\nmesh = "box.obj"\n[material]\nunit_weight = 20000.0\n'
                    'friction_angle = 30.0\n[settlement]\nprofile = "gaussian"\nwidth = 1.0\n')
    digests = _sha(spec), _sha(mesh)
    result = CliRunner().invoke(cli, ["build", str(spec), "-o", str(tmp_path / "box.nc")])
    _assert_clean_failure(result, r"block 'box' \(line 10\): not a closed solid: the edge from \(0, 0, 0\) to "
                                  r"\(0, 1, 0\)", spec, digests[0])
    assert _sha(mesh) == digests[1] and not (tmp_path / "box.nc").exists()
