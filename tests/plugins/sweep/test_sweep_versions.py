"""A changed solver never gets an older result from the store: its recorded version carries a digest of its code.

A third-party solver is installed in a temporary site folder (module + dist-info, as
pip leaves it); the same sweep runs three times in fresh processes: solved, then
found in the store, then, after one line of the solver's code changed, solved again.
"""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import xarray as xr

SOLVER = '''
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp


def solve(model, options, progress):
    alpha = 0.5
    return xr.Dataset({"collapse_multiplier": ((), alpha, mfp.variable_attrs("collapse_multiplier"))})


@mfp.hookimpl
def masonryfw_solvers():
    return [mfp.Solver("half", "alpha = one half", solve, "1.0")]
'''


def install(site):
    (site / "half_mf.py").write_text(SOLVER)
    info = site / "half_mf-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: half_mf\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[masonryfw]\nhalf = half_mf\n")


def sweep(site, folder, name):
    done = subprocess.run(
        [sys.executable, "-m", "masonryfw", "sweep", "test-12c", "--plugin", "half", "--workers", "1",
         "--no-progress", "--param", "material.friction_angle=20,25", "-o", f"{name}.nc", "--store", "store"],
        cwd=folder, capture_output=True, text=True, timeout=300,
        env={**os.environ, "PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])})
    assert done.returncode == 0, done.stderr
    return xr.open_dataset(folder / f"{name}.nc")


def test_a_changed_solver_is_solved_again_and_an_unchanged_one_is_reused(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    install(site)
    first = sweep(site, tmp_path, "first")
    again = sweep(site, tmp_path, "again")
    assert first.from_store.values.tolist() == [0, 0]
    assert again.from_store.values.tolist() == [1, 1]
    version = first.attrs["solver_version"]
    assert version.startswith("1.0+") and again.attrs["solver_version"] == version

    (site / "half_mf.py").write_text(SOLVER.replace("alpha = 0.5", "alpha = 0.25"))  # a fix, version not bumped
    fixed = sweep(site, tmp_path, "fixed")
    assert fixed.from_store.values.tolist() == [0, 0]
    assert fixed.attrs["solver_version"] != version and fixed.attrs["solver_version"].startswith("1.0+")
    np.testing.assert_array_equal(fixed.alpha.values, [0.25, 0.25])
    assert (first.key.values != fixed.key.values).all()


def test_after_ctrl_c_no_logger_of_the_event_loop_or_dask_reports_a_failed_callback():
    """An interrupted sweep's message came with tornado's 'Exception in callback' traceback in CI: quieting the
    'tornado' logger left 'tornado.application', which distributed's configuration gives its own level (ERROR)
    and handler. Every logger under tornado, distributed and asyncio is quiet after quiet_shutdown."""
    import logging

    import distributed  # noqa: F401  (configures its loggers and tornado's, as a sweep's cluster does)

    from masonryfw_sweep.sweep import SHUTDOWN_LOGGERS, quiet_shutdown

    names = [n for n in logging.root.manager.loggerDict if n.split(".")[0] in SHUTDOWN_LOGGERS]
    assert "tornado.application" in names and logging.getLogger("tornado.application").isEnabledFor(logging.ERROR)
    saved = {name: logging.getLogger(name).level for name in names}
    try:
        quiet_shutdown()
        assert not any(logging.getLogger(name).isEnabledFor(logging.CRITICAL) for name in names)
    finally:
        for name, level in saved.items():
            logging.getLogger(name).setLevel(level)
