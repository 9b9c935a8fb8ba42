"""Sweeps on a two-process dask cluster: the combined dataset, values against in-process solves,
failures recorded with their messages, and resumes that solve nothing twice.

Reference: one ``mf.solve`` per point in this process, on the bundled spec edited
by hand (``reference_solve`` in conftest.py); the store's files (inode and
modification time) count what was solved.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_sweep import failed_points, plan_sweep, run_sweep

STARTS = (0.5, 0.8, 1.2)  # 1.2 lies beyond the settling support's end (1.1): a SpecError at build
SOLVERS = ("highs", "clarabel")
GRID = [f"supports.settling.start={','.join(map(str, STARTS))}", f"option.solver={','.join(SOLVERS)}"]
ZIP = ["supports.fixed.end=0.5,0.1", "supports.settling.start=0.5,1.0"]  # point 1: base mostly unsupported


def _results(store) -> dict[str, tuple[int, int]]:
    """``{result file: (inode, mtime_ns)}`` of a store: changes whenever a point is solved again."""
    folder = store / "results"
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in sorted(folder.glob("*.nc"))}


@pytest.fixture(scope="module")
def grid_run(client, tmp_path_factory):
    folder = tmp_path_factory.mktemp("grid")
    plan = plan_sweep("test-12c", "la", GRID)
    sweep = run_sweep(plan, client, folder / "store", folder)
    return plan, sweep, folder


def test_the_grid_has_the_swept_keys_as_dimensions(grid_run):
    _, sweep, _ = grid_run
    assert sweep.status.dims == ("supports_settling_start", "option_solver")
    np.testing.assert_array_equal(sweep.supports_settling_start.values, STARTS)
    assert sweep.option_solver.values.tolist() == list(SOLVERS)
    assert sweep.supports_settling_start.attrs["sweep_key"] == "supports.settling.start"
    for name in ("alpha", "collapse_reaction", "macro_blocks", "wall_time_s",
                 "message", "result_path", "key", "from_store"):
        assert sweep[name].dims == sweep.status.dims, name


def test_values_equal_single_solves_in_process(grid_run, reference_solve):
    _, sweep, folder = grid_run
    for start in STARTS[:2]:
        for solver in SOLVERS:
            point = sweep.sel(supports_settling_start=start, option_solver=solver)
            reference = reference_solve(start, solver=solver)
            assert int(point.status) == 0
            for name, variable in (("alpha", "collapse_multiplier"), ("collapse_reaction", "moving_support_reaction")):
                assert float(point[name]) == pytest.approx(float(reference[variable]), rel=1e-12, abs=1e-12), name
            masonry = mfp.masonry_blocks(reference.block_role.values)
            assert float(point.macro_blocks) == np.unique(reference.macro_block.values[masonry]).size
            stored = mf.open_dataset(folder / str(point.result_path.values))
            assert float(stored.collapse_multiplier) == float(point.alpha)
            assert stored.attrs["solver_options"] == reference.attrs["solver_options"]


def test_a_bad_spec_value_is_recorded_and_the_others_run(grid_run):
    _, sweep, _ = grid_run
    bad = sweep.sel(supports_settling_start=1.2)
    assert (bad.status.values == 1).all()  # spec_error
    assert all("'supports.settling.end'" in str(m) and "must exceed start" in str(m) for m in bad.message.values)
    assert np.isnan(bad.alpha.values).all()
    assert (bad.result_path.values == "").all()
    assert (sweep.sel(supports_settling_start=[0.5, 0.8]).status.values == 0).all()
    listed = failed_points(sweep)
    assert [where for where, _ in listed] == [
        "supports.settling.start=1.2, option.solver='highs'", "supports.settling.start=1.2, option.solver='clarabel'"]


def test_a_solver_failure_is_recorded_and_keys_are_shared_across_sweeps(grid_run, client):
    plan, grid, folder = grid_run
    zipped = run_sweep(plan_sweep("test-12c", "la", ZIP, {"solver": "highs"}, zipped=True), client,
                       folder / "store", folder)
    assert zipped.status.dims == ("point",)
    assert zipped.supports_fixed_end.values.tolist() == [0.5, 0.1]
    assert zipped.status.values.tolist() == [0, 3]  # ok, solve_error
    assert "dead load alone cannot be carried" in str(zipped.message.values[1])
    # Point 0 is the grid's (0.5, highs) point: same model and options -> same key, found in the store.
    same = grid.sel(supports_settling_start=0.5, option_solver="highs")
    assert str(zipped.key.values[0]) == str(same.key.values)
    assert int(zipped.from_store.values[0]) == 1
    assert float(zipped.alpha.values[0]) == float(same.alpha)


def test_a_rerun_solves_nothing_and_an_interrupted_point_is_solved_again(grid_run, client):
    plan, first, folder = grid_run
    store = folder / "store"
    before = _results(store)
    again = run_sweep(plan, client, store, folder)
    assert _results(store) == before  # nothing rewritten
    assert again.from_store.sel(supports_settling_start=[0.5, 0.8]).values.all()
    np.testing.assert_array_equal(again.alpha.values, first.alpha.values)

    # A kill between the result file and its record; a truncated result; a temporary file left behind.
    keys = first.key.sel(supports_settling_start=0.5).values.tolist()
    (store / "results" / f"{keys[0]}.json").unlink()
    truncated = store / "results" / f"{keys[1]}.nc"
    truncated.write_bytes(truncated.read_bytes()[:1000])
    (store / "results" / f".{keys[1]}.nc.0123456789ab.tmp").write_bytes(b"\x89HDF partial")
    resumed = run_sweep(plan, client, store, folder)
    assert resumed.from_store.sel(supports_settling_start=0.5).values.tolist() == [0, 0]
    assert resumed.from_store.sel(supports_settling_start=0.8).values.tolist() == [1, 1]
    after = _results(store)
    assert {name for name in after if after[name] != before[name]} == {f"{k}.nc" for k in keys}
    np.testing.assert_array_equal(resumed.alpha.values, first.alpha.values)
    assert os.path.getsize(truncated) > 1000
