"""What a user reads must be right: implausible inputs named, supports described as they move, labelled
records, plugins that say what they need, a progress line that keeps its numbers, figures told apart."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.cli import cli
from masonryfw.runtime.progress import StderrBar

WALL = """title = "plausibility"
{unit_line}
[wall]
width = {width}
height = 1.0
thickness = 0.1
[unit]
length = {unit}
height = 0.1
[material]
unit_weight = {weight}
{friction}
{young}
[supports.fixed]
kind = "fixed"
start = 0.0
end = {half}
[supports.settling]
kind = "moving"
start = {half}
end = {width}
[loading]
type = "settlement"
"""


def spec_text(width=2.0, unit=0.2, weight=18000.0, friction="friction_angle = 30.0", young="", unit_line="") -> str:
    return WALL.format(width=width, unit=unit, weight=weight, friction=friction, young=young, unit_line=unit_line,
                       half=width / 2)


@pytest.mark.parametrize(("change", "named", "meant"), [
    ({"weight": 18.0}, "material.unit_weight (block_unit_weight) = 18 N/m3", "probably kN/m3 were meant, in N/m3: 18000"),
    ({"weight": 1800.0}, "material.unit_weight (block_unit_weight) = 1800 N/m3",
     "a density in kg/m3 was given; its weight in N/m3 is: 17658"),
    ({"unit_line": 'length_unit = "mm"'}, "unit.length = 0.0002 m", 'probably metres were meant: remove length_unit = "mm"'),
    ({"friction": "friction_angle = 0.6"}, "material.friction_angle (or friction) = 0.6 deg",
     "the coefficient mu = 0.6 (31 deg) given as friction_angle"),
    ({"friction": "friction = 30.0"}, "= 88.1 deg (interface_friction mu = 30)",
     "degrees given as the coefficient: write friction_angle = 30"),
    ({"young": "young_modulus = 1144.8"}, "material.young_modulus (block_young_modulus) = 1144.8 Pa",
     "probably MPa were meant, in Pa: 1.1448e+09"),
    ({"unit": 3.0, "width": 6.0}, "unit.length = 3 m: masonry units are 10 mm to 2 m", ""),
])
def test_implausible_values_are_warned_with_the_key_and_what_was_meant(tmp_path, change, named, meant):
    """build warns (exit 0, the model written), check lists them (exit 0), check --strict refuses (exit 1)."""
    (tmp_path / "w.toml").write_text(spec_text(**change))
    runner = CliRunner()
    built = runner.invoke(cli, ["build", str(tmp_path / "w.toml"), "-o", str(tmp_path / "w.nc")])
    assert built.exit_code == 0, built.output
    assert named in built.output and meant in built.output
    assert "warning: " in built.output
    checked = runner.invoke(cli, ["check", str(tmp_path / "w.nc")])
    assert checked.exit_code == 0 and named in checked.output and "--strict makes them errors" in checked.output
    strict = runner.invoke(cli, ["check", "--strict", str(tmp_path / "w.nc")])
    assert strict.exit_code == 1 and named in strict.output and "Traceback" not in strict.output


def test_the_metre_wall_under_millimetres_is_named_whole():
    """The report's case: metre values under length_unit = "mm" build a wall 2 mm wide: the unit sizes and
    the wall's width and height each get their warning, all pointing at length_unit."""
    with pytest.warns(mf.PlausibilityWarning) as caught:
        mf.build(spec_text(unit_line='length_unit = "mm"'))
    messages = [str(w.message) for w in caught]
    assert any(m.startswith("wall.width: the masonry is 0.002 m wide") for m in messages)
    assert any(m.startswith("wall.height: the masonry is 0.001 m high") for m in messages)
    assert sum('remove length_unit = "mm"' in m for m in messages) == 4


@pytest.mark.parametrize("name", mf.BUNDLED_NAMES)
def test_bundled_walls_are_plausible(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error", mf.PlausibilityWarning)
        model = mf.open_model(name)
    assert mf.plausibility(model) == []


def test_info_says_how_a_trough_segment_moves():
    """A segment of the continuous ground translates and turns; info says so with the settlement of its two
    ends, which are the profile's there (no 'rotation about a pivot')."""
    run = CliRunner().invoke(cli, ["info", "facade-1-trough"])
    assert run.exit_code == 0
    assert "pivot" not in run.output
    model = mf.open_model("facade-1-trough")
    line = [line for line in run.output.splitlines() if "translates and turns" in line][3]
    x0, x1, left, right = map(float, re.search(r"x ([\d.]+)\.\.([\d.]+) m, moving: translates and turns: settles "
                                                r"([\d.]+) at its left end and ([\d.]+) at its right", line).groups())
    rate = np.exp(-0.5 * ((np.array([x0, x1]) - 0.75) / 0.25) ** 2)
    np.testing.assert_allclose([left, right], np.maximum(rate - 0.05, 0.0) / 0.95, atol=1e-4)  # cutoff 0.05
    assert model.sizes["block"] > 0


def test_records_are_labelled_in_plain_xarray(tmp_path):
    """An incremental result's history has a step coordinate: select a record by its number."""
    result = mf.solve(mf.open_model("test-12c"), "fdem", {"settlement": 0.001})
    mf.save(result, tmp_path / "r.nc")
    ds = xr.open_dataset(tmp_path / "r.nc")
    np.testing.assert_array_equal(ds.step.values, np.arange(ds.sizes["step"]))
    assert float(ds.step_reaction.sel(step=3)) == float(ds.step_reaction.values[3])
    ds.close()


def test_plugins_say_that_sweep_needs_dask(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "distributed" else real(name, *a))
    from masonryfw_sweep.commands import available_commands, sweep_command

    before = sweep_command.short_help
    try:
        commands = {c.name: c for c in available_commands()}
        assert "pip install 'masonryfw[sweep]'" in commands["sweep"].get_short_help_str(limit=200)
    finally:
        sweep_command.short_help = before


def test_the_progress_line_keeps_the_numbers_at_its_end():
    """An 80-column terminal: a long message loses words from its middle, never the reaction at its end."""
    class Stream:
        text = ""

        def write(self, part):
            self.text += part

        def flush(self):
            pass

    stream = Stream()
    bar = StderrBar(stream, columns=80)
    bar(0.4, "fdem: settlement 40% of target after 123,456 of 987,654 steps, reaction 0.723 R0")
    line = stream.text.split("\r")[-1]
    assert len(line) <= 80
    assert line.rstrip().endswith("reaction 0.723 R0") and "..." in line


@pytest.mark.parametrize("solver", ["fdem", "jmm"])
def test_an_interrupted_solve_does_not_report_completion(solver):
    """Ctrl-C in the middle: the bar stays where the run stopped, no progress of 1.0 is reported."""
    calls = []

    def progress(fraction, message=""):
        calls.append(fraction)
        if sum(f > 0 for f in calls) == 3:  # in the settlement: jmm's gravity stage reports 0 at every iteration
            raise KeyboardInterrupt

    options = {"settlement": 0.002} if solver == "fdem" else {"mesh_size": 0.1}
    result = mf.solve(mf.open_model("test-12c"), solver, options, progress=progress)
    assert int(result.attrs["interrupted"]) == 1
    assert max(calls) < 1.0


def test_report_of_a_trough_result_reads_right(tmp_path):
    """fdem over a trough: the forces are at the last record, not "at collapse"; the widest crack over the
    run with its joint and settlement, the largest category, the base gap, the deflection ratio and the
    angular distortion of the imposed ground are in the key numbers' table, each equal to the file's."""
    model = mf.open_model("facade-1-trough")
    result = mf.solve(model, "fdem", {"settlement": 0.002, "plateau_tolerance": 0.0})
    mf.save(result, tmp_path / "r.nc")
    run = CliRunner().invoke(cli, ["report", str(tmp_path / "r.nc"), "-o", str(tmp_path / "r.html"), "--no-progress"])
    assert run.exit_code == 0, run.output
    page = (tmp_path / "r.html").read_text()
    assert "joint resultants at the last record (settlement 2 mm)" in page and "at collapse" not in page
    numbers = {k.name: k.value for k in mf.key_numbers(result)}
    for label in ("widest crack", "damage category", "base gap", "deflection ratio", "angular distortion"):
        assert f">{label}<" in page
    assert f"joint {int(numbers['crack_interface'])} at x" in page
    ratio = float(result.step_deflection_ratio.values[-1])
    assert numbers["deflection_ratio"] == ratio and ratio > 0  # the axis under the middle pier: sagging
    assert numbers["crack_width"] == float(result.step_crack_width_max.values.max())
    assert numbers["damage_category"] == float(result.step_damage_category.values.max())


def test_three_results_of_one_solver_get_three_legend_entries(tmp_path):
    """Three fdem runs that differ only in their model (the segment length) are told apart by their files."""
    from masonryfw_compare.history_plot import distinct_labels

    results = []
    for k, segment in enumerate((0.05, 0.025, 0.0125)):
        spec = mf.load_spec(mf.bundled_spec_path("facade-1-trough"))
        spec["settlement"]["segment"] = segment
        mf.save(mf.solve(mf.build(spec), "fdem", {"settlement": 0.0005}), tmp_path / f"s{k}.nc")
        results.append(mf.open_dataset(tmp_path / f"s{k}.nc"))
    labels = distinct_labels(results)
    assert len(set(labels)) == 3
    assert labels == [f"fdem (s{k}.nc)" for k in range(3)]


SMALL_TUNNEL = {"title": "small", "length_unit": "m", "wall": {"width": 4.0, "height": 1.2, "thickness": 0.1},
                "unit": {"length": 0.4, "height": 0.1}, "material": {"unit_weight": 12000.0, "friction_angle": 30.0},
                "settlement": {"profile": "tunnel", "volume_loss": 1.5, "diameter": 6.0, "depth": 10.0, "center": 6.0},
                "loading": {"type": "settlement"}}


@pytest.mark.parametrize(("source", "within"), [("facade-1-trough", 0.06), (SMALL_TUNNEL, 1e-4)])
def test_one_dead_reaction_for_la_and_fdem(source, within):
    """R0 is the settlement reaction in both: la's of the paper's uniform dead loads, fdem's of its contact
    forces at rest. They differ only by where the weight really rests (5.0 % under Facade 1's piers over a
    narrow trough, 5e-6 under a plain wall over a tunnel); summed plainly against weighted, one report read
    1.26e5 and 1.70e5 N (35 %) for one model."""
    model = mf.open_model(source) if isinstance(source, str) else mf.build(source)
    la = {k.name: k.value for k in mf.key_numbers(mf.solve(model, "la"))}
    fdem = {k.name: k.value for k in mf.key_numbers(mf.solve(model, "fdem", {"settlement": 1e-5}))}
    assert la["dead_reaction"] == pytest.approx(mf.dead_reaction(model), rel=1e-12)
    assert fdem["dead_reaction"] == pytest.approx(la["dead_reaction"], rel=within)


def test_jmm_takes_plateau_slope_zero():
    """docs/settlements.md's advice for running jmm to a settlement is accepted: no plateau stop."""
    options = mfp.resolve_options("jmm", mf.get_solver("jmm").options, {"plateau_slope": "0"})
    assert options["plateau_slope"] == 0.0


def test_the_damage_history_is_one_axis_of_crack_width_with_category_bands():
    """No second axis beside the category labels to misread: one crack-width axis [mm], the category limits
    its ticks (0.1, 1, 5, 15, 25 mm)."""
    result = mf.solve(mf.open_model("facade-1-trough"), "fdem", {"settlement": 0.001})
    figure = mf.render([result], "history", {"quantity": "damage"})
    assert len(figure.axes) == 1
    ax = figure.axes[0]
    assert ax.get_ylabel() == "widest crack in the masonry [mm]"
    np.testing.assert_allclose(ax.get_yticks(), [0.0, 0.1, 1.0, 5.0, 15.0, 25.0])
