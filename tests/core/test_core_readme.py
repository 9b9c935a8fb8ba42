"""The README's examples run as written (examples double as tests)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import xarray as xr

import masonryfw as mf

README = (Path(__file__).resolve().parents[2] / "README.md").read_text()


def _block(language: str, first_line: str) -> str:
    match = re.search(rf"```{language}\n{re.escape(first_line)}\n(.*?)```", README, re.S)
    assert match, f"README has no {language} block starting with {first_line!r}"
    return match.group(1)


def test_the_first_lines_give_the_run_and_test_commands():
    head = README.splitlines()[:12]
    assert any("pip install ." in line and "masonryfw solve" in line for line in head)
    assert any('pip install ".[test]"' in line and "pytest" in line for line in head)


def test_the_spec_of_the_tour_builds_a_valid_wall(tmp_path):
    spec = tmp_path / "my-wall.toml"
    spec.write_text(_block("toml", "# my-wall.toml"))
    model = mf.build(spec)
    assert mf.check(model) == []
    # 2 x 1 m of 0.2 x 0.05 units, a 0.4 x 0.4 window: masonry area by hand
    masonry = model.block_area.values[model.block_role.values <= mf.flags("block_role")["lintel"]].sum()
    assert abs(masonry - (2.0 * 1.0 - 0.4 * 0.4)) < 1e-12


def test_the_third_party_solver_of_the_tour_installs_and_solves(tmp_path):
    package = tmp_path / "my_solver"
    package.mkdir()
    (package / "__init__.py").write_text(_block("python", "# my_solver/__init__.py"))
    dist = tmp_path / "my_solver-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: my-solver\nVersion: 0.1\n")
    entry_point = _block("toml", "# pyproject.toml of your package").split("\n", 1)[1].replace('"', "")
    (dist / "entry_points.txt").write_text("[masonryfw]\n" + entry_point)
    out = tmp_path / "toy.nc"
    done = subprocess.run(
        [sys.executable, "-m", "masonryfw", "solve", "test-12c", "--plugin", "toy", "-o", str(out), "--no-progress"],
        env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 0, done.stderr
    result = xr.open_dataset(out)
    y = result.interface_y.values.mean(axis=1)
    np.testing.assert_allclose(result.crack_indicator.values, (y - y.min()) / (y.max() - y.min()))
    assert result.attrs["plugin_version"] == "0.1"
