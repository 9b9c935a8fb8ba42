"""The README's examples run as written (examples double as tests)."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

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
    masonry = model.block_area.values[model.block_role.values <= mfp.flags("block_role")["lintel"]].sum()
    assert abs(masonry - (2.0 * 1.0 - 0.4 * 0.4)) < 1e-12


def install_the_tour_plugin(site: Path) -> dict:
    """The README's package written into ``site`` as pip would install it (its module and a dist-info with the
    entry points of the README's pyproject.toml); returns that pyproject."""
    package = site / "my_solver"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text(_block("python", "# my_solver/__init__.py"))
    pyproject = tomllib.loads(_block("toml", "# pyproject.toml of your package"))
    project = pyproject["project"]
    dist = site / f"my_solver-{project['version']}.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {project['name']}\nVersion: {project['version']}\n")
    entry_points = "".join(f"{k} = {v}\n" for k, v in project["entry-points"]["masonryfw"].items())
    (dist / "entry_points.txt").write_text("[masonryfw]\n" + entry_points)
    return pyproject


def test_the_third_party_solver_of_the_tour_installs_and_solves(tmp_path):
    pyproject = install_the_tour_plugin(tmp_path)
    assert pyproject["build-system"]["build-backend"] == "setuptools.build_meta"
    out = tmp_path / "toy.nc"
    done = subprocess.run(
        [sys.executable, "-m", "masonryfw", "solve", "test-12c", "--plugin", "toy", "-o", str(out), "--no-progress"],
        env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 0, done.stderr
    result = mf.open_dataset(out)
    assert result.attrs["plugin_version"] == "0.1" and result.attrs["solver_version"].startswith("0.1+")
    # the core derived the cracks: the head joints along the settling support's edge (x = 0.5 m) and the
    # base joints over it; the units standing over the settling support are one macro-block
    cracked = result.crack_indicator.values > 0
    head = result.interface_kind.values == mfp.flags("interface_kind")["head"]
    assert np.all(np.isclose(result.interface_x.values[cracked & head], 0.5, atol=0.1))
    assert np.unique(result.macro_block.values[mfp.block_motion(result)[:, 1] < 0]).size == 1


def test_the_conformance_kit_of_the_tour_passes_for_the_tour_plugin(tmp_path):
    install_the_tour_plugin(tmp_path / "site")
    tests = tmp_path / "tests"
    tests.mkdir()
    (tests / "test_toy.py").write_text(_block("python", "# tests/test_toy.py"))
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tests)],
                          env={**os.environ, "PYTHONPATH": str(tmp_path / "site")}, capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"\b11 passed", done.stdout), done.stdout


def test_the_trough_of_the_tour_builds_under_the_tour_wall(tmp_path):
    spec = tomllib.loads(_block("toml", "# my-wall.toml"))
    del spec["supports"]
    spec.update(tomllib.loads(_block("toml", "# over-a-trough.toml: my-wall.toml with [settlement] in place of "
                                             "its [supports.*] tables")))
    model = mf.build(spec)
    assert mf.check(model) == []
    assert (model.block_role.values == mfp.flags("block_role")["moving_support"]).sum() >= 5


def test_the_buildings_step_of_the_tour_runs_as_written(tmp_path):
    step = README[README.index("**6. Buildings in 3D.**"):README.index("**7. Damage in buildings.**")]
    commands = [part.split() for line in step.splitlines() if line.startswith("    masonryfw ")
                for part in line.strip().split("#")[0].split(" && ")]
    assert [c[1] for c in commands] == ["build", "check", "info", "solve", "plot", "plot", "export", "report"]
    for words in commands:
        done = subprocess.run([sys.executable, "-m", "masonryfw", *words[1:]], cwd=tmp_path, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, (words, done.stderr)
    assert (tmp_path / "house.png").stat().st_size > 10_000 and (tmp_path / "stages.png").stat().st_size > 10_000
    assert (tmp_path / "house.vtm").exists() and (tmp_path / "house_joints.vtu").exists()
    text = (tmp_path / "house.html").read_text()
    assert text.count("<img ") == 4  # the model, the mechanism, the cracks, the stages
    assert text.count('<pre class="walls">') == 1  # the house's stages wall by wall at its S_max


def test_the_hand_over_step_ends_with_a_report_and_runs_as_written(tmp_path):
    step = README[README.index("**5. Hand it over.**"):README.index("**6. Buildings in 3D.**")]
    commands = [line.strip() for line in step.splitlines() if line.startswith("    masonryfw ")]
    assert commands[-1].startswith("masonryfw report ")
    for command in commands:
        for part in command.split("#")[0].split(" && "):
            words = part.split()
            assert words[0] == "masonryfw"
            done = subprocess.run([sys.executable, "-m", "masonryfw", *words[1:]], cwd=tmp_path, capture_output=True,
                                  text=True, timeout=300)
            assert done.returncode == 0, (part, done.stderr)
    text = (tmp_path / "test-12c.html").read_text()
    assert text.count("<img ") >= 10 and (tmp_path / "history.pdf").stat().st_size > 1000
    assert (tmp_path / "history.csv").read_text().startswith("result,record,stage,settlement_m,reaction_N")


@pytest.mark.slow  # 17 s; the tunnel keys and stages are tested by default in test_core_tunnels.py
def test_the_tunnel_step_of_the_tour_runs_as_written(tmp_path):
    """Step 1d: fdem runs the bundled facade to its trough's S_max (15 mm: V_L 1 %, D 6 m, z0 15 m, K 0.5) and
    prints the three stages; the ltsm chart is drawn; la assesses stages 1 and 2 at S_max."""
    step = README[README.index("**1d. Or ask what a planned tunnel does to it.**"):README.index("**1e. Or ask the reverse")]
    commands = [line.strip().split("#")[0].split() for line in step.splitlines() if line.startswith("    masonryfw ")]
    assert len(commands) == 3
    outputs = []
    for words in commands:
        done = subprocess.run([sys.executable, "-m", "masonryfw", *words[1:], "--no-progress"]
                              if words[1] == "solve" else [sys.executable, "-m", "masonryfw", *words[1:]],
                              cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, (words, done.stderr)
        outputs.append(done.stdout)
    assert "stages at S = 15 mm: stage 1" in outputs[0] and "stage 2 (LTSM)" in outputs[0] and "stage 3 (fdem)" in outputs[0]
    assert "stage 3 (la" in outputs[2]
    fdem = mf.open_dataset(tmp_path / "tunnel-facade.fdem.nc")
    assert float(fdem.step_settlement.values[-1]) >= 0.999 * float(fdem.settlement_target.values)
    assert (tmp_path / "ltsm.png").stat().st_size > 20_000


@pytest.mark.slow  # 45 s; the diagnose command is tested by default in tests/plugins/diagnose
def test_the_diagnosis_step_of_the_tour_runs_as_written(tmp_path):
    """Step 1e: the bundled survey (drawn from fdem's run of facade-1 settling under x = 1.2 .. 1.5 m, stopped at
    6.65 mm: datasets/surveys/README.md) points back to that step, and its levelling to that settlement: the
    side, the edge, hogging and the family determined, the settlement's interval holding 6.65 mm."""
    step = README[README.index("**1e. Or ask the reverse"):README.index("**2. Solve, look")]
    commands = [line.strip().split() for line in step.splitlines() if line.startswith("    masonryfw ")]
    assert len(commands) == 3
    root = Path(__file__).resolve().parents[2]
    outputs = []
    for words in commands:
        words = [str(root / w) if w.startswith("datasets/") else w for w in words]
        extra = ["--no-progress", "--json"] if words[1] == "diagnose" else []
        done = subprocess.run([sys.executable, "-m", "masonryfw", *words[1:], *extra], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, (words, done.stderr)
        outputs.append(done.stdout)
    data = json.loads(outputs[0])
    best = data["candidates"][0]
    assert best["settlement"] == {"profile": "step", "start": 1.2, "end": 1.5, "segment": 0.1}
    assert best["magnitude"] == pytest.approx(6.65e-3, rel=0.15)
    determined = data["determined"]
    assert (determined["side"], determined["edge"], determined["mode"], determined["family"]) == (
        "right", 1.2, "hogging", "step")
    low, high = determined["magnitude_interval"]
    assert low < 6.65e-3 < high and data["ranked_by"] == "fdem"
    assert "the right part settled relative to the rest, the ground breaking at 1.20 m" in data["verdict"]
    assert (tmp_path / "diagnosis.png").stat().st_size > 20_000
    assert "Diagnosis" in (tmp_path / "diagnosis.html").read_text()


@pytest.mark.slow  # 40 s: fdem to 60 mm, la-incremental on the tunnel facade
def test_the_how_far_step_of_the_tour_runs_as_written(tmp_path):
    """Step 1f: la-incremental follows Test 12C to 60 mm, fdem beside it, one history figure; capacity says where
    the tunnel facade first reaches category 1, in volume loss."""
    step = README[README.index("**1f. Or ask how far it can go.**"):README.index("**1e. Or ask the reverse")]
    commands = [line.strip().split("#")[0].split() for line in step.splitlines() if line.startswith("    masonryfw ")]
    assert len(commands) == 4
    outputs = []
    for words in commands:
        extra = ["--no-progress"] if words[1] in ("solve", "capacity") else []
        done = subprocess.run([sys.executable, "-m", "masonryfw", *words[1:], *extra], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, (words, done.stderr)
        outputs.append(done.stdout)
    assert "reached the target 0.06 m before collapse" in outputs[0]
    assert (tmp_path / "how-far.png").stat().st_size > 20_000
    assert outputs[3].splitlines()[2].startswith("category 1 (very slight): first reached at")


@pytest.mark.slow  # 3 minutes: fdem settles the 1,126-block house to its S_max
def test_the_damage_in_buildings_step_of_the_tour_runs_as_written(tmp_path):
    step = README[README.index("**7. Damage in buildings.**"):README.index("## Where to read more")]
    commands = [line.strip().split("#")[0].split() for line in step.splitlines() if line.startswith("    masonryfw ")]
    assert [c[1] for c in commands] == ["solve", "capacity", "plot", "plot", "export", "plot"]
    outputs = []
    la = subprocess.run([sys.executable, "-m", "masonryfw", "solve", "house-tunnel", "--plugin", "la"], cwd=tmp_path,
                        capture_output=True, text=True, timeout=300)  # step 6's, which the last plot compares with
    assert la.returncode == 0, la.stderr
    for words in commands:
        done = subprocess.run([sys.executable, "-m", "masonryfw", *words[1:], *(["--no-progress"] if words[1] == "solve"
                                                                              else [])],
                              cwd=tmp_path, capture_output=True, text=True, timeout=1200)
        assert done.returncode == 0, (words, done.stderr)
        outputs.append(done.stdout)
    walls = [w["name"] for w in json.loads(mf.open_model("house-tunnel").attrs["building_walls"])]
    assert "wall by wall at S = " in outputs[0] and all(f"\n{name} " in outputs[0] for name in walls)
    assert "wall by wall, the volume loss V_L at which each category is first reached" in outputs[1]
    assert (tmp_path / "cracks.png").stat().st_size > 10_000 and (tmp_path / "damage.png").stat().st_size > 10_000
    assert (tmp_path / "settling_series.pvd").read_text().count("<DataSet ") == 20
    assert (tmp_path / "both.png").stat().st_size > 20_000
