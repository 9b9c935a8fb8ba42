"""The command line: exit codes, messages, outputs, and inputs left untouched.

References: the hand-built model of ``conftest.py`` (counts and loads by hand)
and ``hashlib`` over the input files before and after every command.
"""
from __future__ import annotations

import hashlib
import io
import json
import subprocess
import sys

import click
import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.cli import cli
from masonryfw.contract import registry


class ToolsPlugin:
    """In-process plugin: a solver with a settable alpha, a comparator and a plotter."""

    @mfp.hookimpl
    def masonryfw_solvers(self):
        def constant(model, options, progress):
            return xr.Dataset({"collapse_multiplier": ((), options["alpha"], mfp.variable_attrs("collapse_multiplier"))})

        return [mfp.Solver("constant", "alpha from an option", constant, "1", (mfp.Option("alpha", float, 0.5),))]

    @mfp.hookimpl
    def masonryfw_comparators(self):
        def gap(a, b, options):
            value = abs(float(a.collapse_multiplier) - float(b.collapse_multiplier))
            return xr.Dataset({"alpha_gap": ((), value, {"units": "1", "long_name": "|alpha_a - alpha_b|"})})

        return [mfp.Comparator("alpha-gap", "difference of the multipliers", gap, "1")]

    @mfp.hookimpl
    def masonryfw_plotters(self):
        def nodes(datasets, ax, options):
            ax.plot(datasets[0].node_x.values, datasets[0].node_y.values, "k.")

        return [mfp.Plotter("nodes", "the polygon vertices", nodes, "1")]


@pytest.fixture
def tools():
    """The real plugins plus :class:`ToolsPlugin`."""
    registry.reset()
    mfp.plugin_manager().register(ToolsPlugin(), name="tools")
    yield
    registry.reset()


@pytest.fixture
def no_plugins(monkeypatch):
    monkeypatch.setattr(registry, "entry_points", lambda group: [])
    registry.reset()
    yield
    registry.reset()


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def sha256(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


# ---------------------------------------------------------------- exit 0

def test_check_ok_counts_blocks_and_interfaces(model_file):
    run = invoke("check", model_file)
    assert run.exit_code == 0, run.output
    assert run.stdout.strip() == "OK: 5 blocks, 6 interfaces"


def test_info_gives_the_hand_counts(model_file):
    run = invoke("info", model_file)
    assert run.exit_code == 0, run.output
    out = run.stdout
    assert "title: Hand wall" in out
    assert "blocks: 5 (unit 3, lintel 0, fixed support 1, moving support 1)" in out
    assert "interfaces: 6 (bed 2, head 1, support 3, other 0)" in out
    assert "wall: 1 m x 0.3 m" in out and "thickness: 0.1 m" in out
    assert "block 3: x 0..0.4 m, fixed (held 1 1 1)" in out
    assert "block 4: x 0.4..1 m, moving: translates: settles 1 per unit t; settlement direction (0, -1, 0)" in out
    assert "dead load on masonry: Fx = 0 N, Fy = -360 N" in out  # 96 + 144 + 120
    assert "dead load on supports: Fx = 0 N, Fy = 216 N" in out
    assert "live load on supports: Fx = 0 N, Fy = -216 N" in out


def test_solve_writes_the_default_output_and_a_summary(model_file, in_tmp):
    run = invoke("solve", model_file, "--plugin", "statics", "--no-progress")
    assert run.exit_code == 0, run.output
    out = in_tmp / "hand_wall.statics.nc"
    assert f"result: {out.name}" in run.stdout
    assert "masonry_weight = 360 N" in run.stdout
    assert run.stderr == ""  # no bar with --no-progress (and none off a terminal)
    with xr.open_dataset(out) as result:
        assert result.attrs["solver"] == "statics"
        assert f"masonryfw solve {model_file} --plugin statics --no-progress" in result.attrs["history"]
        np.testing.assert_allclose(result.support_dead_reaction.values, [0, 0, 0, 144, 216])


def test_plugins_lists_the_builtin_solver(tools):
    run = invoke("plugins")
    assert run.exit_code == 0, run.output
    assert f"example (masonryfw {mf.__version__})" in run.stdout
    assert "  solver statics: load resultants" in run.stdout
    assert "tools (registered in-process)" in run.stdout
    assert "--option alpha=<float> (default 0.5)" in run.stdout


def test_compare_and_plot_through_the_command_line(tools, model_file, in_tmp):
    for alpha, name in ((0.5, "a.nc"), (0.125, "b.nc")):
        assert invoke("solve", model_file, "--plugin", "constant", "--option", f"alpha={alpha}", "-o", name).exit_code == 0
    run = invoke("compare", "a.nc", "b.nc", "--comparator", "alpha-gap", "--json", "-o", "c.nc")
    assert run.exit_code == 0, run.output
    assert json.loads(run.stdout) == {"comparator": "alpha-gap", "scores": {"alpha_gap": 0.375}}
    with xr.open_dataset(in_tmp / "c.nc") as comparison:
        assert comparison.attrs["masonryfw_format"] == "comparison"
        assert comparison.attrs["input_a_sha256"] == sha256(in_tmp / "a.nc")
    run = invoke("plot", "a.nc", "--kind", "nodes", "-o", "a.png")
    assert run.exit_code == 0, run.output
    assert (in_tmp / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- exit 1 and 2

def test_check_prints_every_problem(make_model, tmp_path):
    bad = make_model()
    bad["block_thickness"][1] = -0.1
    bad["interface_friction"][2] = -1.0
    path = tmp_path / "bad.nc"
    bad.to_netcdf(path)
    run = invoke("check", path)
    assert run.exit_code == 1
    assert "block_thickness" in run.stdout and "interface_friction" in run.stdout
    assert "problem(s)" in run.stderr


@pytest.mark.parametrize(
    "args",
    [["no-such-command"], ["solve"], ["solve", "x.nc"], ["solve", "x.nc", "--plugin", "statics", "--option", "novalue"]],
    ids=["unknown-command", "missing-model", "missing-plugin", "option-without-equals"],
)
def test_usage_errors_exit_2(args):
    assert invoke(*args).exit_code == 2


def test_no_plotter_installed_is_a_clear_error(no_plugins, model_file, in_tmp):
    run = invoke("plot", model_file, "-o", "x.png")
    assert run.exit_code == 1
    assert run.stderr.strip() == "error: no plotter is installed"
    assert not (in_tmp / "x.png").exists()


def test_failing_commands_leave_the_input_unchanged(tools, model_file, in_tmp):
    before = sha256(model_file)
    failing = [
        (["solve", model_file, "--plugin", "statics", "-o", model_file], "refusing to overwrite"),
        (["solve", model_file, "--plugin", "statics", "-o", in_tmp / ".." / in_tmp.name / model_file.name], "refusing"),
        (["solve", model_file, "--plugin", "nope"], "unknown solver 'nope'"),
        (["solve", model_file, "--plugin", "constant", "--option", "alpha=x"], "option 'alpha' = 'x': not a float"),
        (["compare", model_file, model_file, "--comparator", "alpha-gap", "-o", model_file], "refusing to overwrite"),
        (["compare", model_file, model_file, "--comparator", "alpha-gap"], "result A"),
        (["plot", model_file, "--kind", "nodes", "-o", model_file], "unknown file type '.nc'"),
        (["info", in_tmp / "missing.nc"], "missing.nc"),
    ]
    for args, message in failing:
        run = invoke(*args)
        assert run.exit_code == 1, (args, run.output)
        assert run.stderr.startswith("error: ") and message in run.stderr, (args, run.stderr)
        assert "Traceback" not in run.output
        assert sha256(model_file) == before, args
    assert sha256(model_file) == before


def test_solve_refuses_an_output_onto_its_input_before_solving(no_plugins, model_file):
    calls = []

    class Spy:
        @mfp.hookimpl
        def masonryfw_solvers(self):
            return [mfp.Solver("spy", "records its calls", lambda m, o, p: calls.append(1), "0")]

    mfp.plugin_manager().register(Spy(), name="spy")
    run = invoke("solve", model_file, "--plugin", "spy", "-o", model_file)
    assert run.exit_code == 1 and "refusing to overwrite the input" in run.stderr
    assert calls == []


def test_plot_refuses_to_overwrite_its_input(tools, model_file, in_tmp):
    alias = in_tmp / "alias.png"
    alias.symlink_to(model_file)
    run = invoke("plot", model_file, "--kind", "nodes", "-o", alias)
    assert run.exit_code == 1 and "refusing to overwrite the input" in run.stderr
    assert model_file.read_bytes()[:4] != b"\x89PNG"


# ---------------------------------------------------------------- as a real process

def test_debug_shows_the_traceback_and_plain_mode_does_not(tmp_path):
    missing = tmp_path / "missing.nc"
    plain = invoke("check", missing)
    assert plain.exit_code == 1
    assert plain.stderr == f"error: {missing}: no such file\n"
    debug = subprocess.run([sys.executable, "-m", "masonryfw", "--debug", "check", str(missing)],
                           capture_output=True, text=True, timeout=120)
    assert debug.returncode == 1
    assert "Traceback (most recent call last)" in debug.stderr
    assert f"masonryfw.runtime.errors.ModelError: {missing}: no such file" in debug.stderr


class FakeTerminal(io.StringIO):
    """A text stream that says it is a terminal."""

    def isatty(self):
        return True


@pytest.mark.parametrize("no_progress, drawn", [([], True), (["--no-progress"], False)], ids=["bar", "no-progress"])
def test_progress_bar_on_a_terminal_unless_no_progress(model_file, in_tmp, monkeypatch, no_progress, drawn):
    terminal = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    cli.main(["solve", str(model_file), "--plugin", "statics", *no_progress], prog_name="masonryfw", standalone_mode=False)
    assert (("[" + "#" * 20 + "] 100% done") in terminal.getvalue()) is drawn
    assert ("%" in terminal.getvalue()) is drawn


# ---------------------------------------------------------------- bundled cases and plugin commands

def test_build_check_info_and_datasets_on_a_bundled_case(in_tmp):
    """Test 12C (datasets/README.md): 1.1 x 0.6 x 0.1 m at 12 kN/m3, 6 x 12 = 72 units + 2 supports.

    Closed form: W = 1.1 * 0.6 * 0.1 * 12000 = 792 N; the moving support (0.6 of 1.1 m)
    carries 792 * 0.6 / 1.1 = 432 N.
    """
    run = invoke("build", "test-12c", "-o", "t12.nc")
    assert run.exit_code == 0, run.output
    spec = in_tmp / "wall.toml"
    spec.write_bytes(mf.bundled_spec_path("test-12c").read_bytes())
    refused = invoke("build", spec, "-o", spec)
    assert refused.exit_code == 1 and "refusing to overwrite" in refused.stderr
    assert spec.read_bytes() == mf.bundled_spec_path("test-12c").read_bytes()
    assert invoke("check", "t12.nc").stdout.startswith("OK: 74 blocks, ")
    listing = invoke("datasets").stdout.splitlines()
    assert len(listing) == len(mf.BUNDLED_NAMES) == 22
    assert any(line.split()[:3] == ["test-12c", "Test", "12C"] and line.endswith(" 74 blocks") for line in listing)
    out = invoke("info", "t12.nc").stdout
    assert "blocks: 74 (unit 72, lintel 0, fixed support 1, moving support 1)" in out
    assert "wall: 1.1 m x 0.6 m" in out and "thickness: 0.1 m" in out
    assert "dead load on masonry: Fx = 0 N, Fy = -792 N" in out
    assert "dead load on supports: Fx = 0 N, Fy = 432 N" in out
    assert "x 0.5..1.1 m, moving: translates: settles 1 per unit t" in out


class CommandsPlugin:
    """Contributes CLI commands with the names it is given."""

    def __init__(self, *names):
        self.names = names

    @mfp.hookimpl
    def masonryfw_commands(self):
        def make(name):
            @click.command(name)
            @click.argument("who")
            def hello(who):
                """Greet WHO."""
                click.echo(f"hello {who} from {name}")

            return hello

        return [make(name) for name in self.names]


def test_plugin_commands_join_the_cli(no_plugins):
    mfp.plugin_manager().register(CommandsPlugin("hello"), name="greeter")
    run = invoke("hello", "world")
    assert (run.exit_code, run.stdout) == (0, "hello world from hello\n")
    assert "hello" in invoke("--help").stdout
    assert "  command hello: Greet WHO." in invoke("plugins").stdout


def test_plugin_commands_that_clash_are_errors_naming_the_plugins(no_plugins):
    mfp.plugin_manager().register(CommandsPlugin("hello", "solve"), name="greeter")
    run = invoke("hello", "world")
    assert run.exit_code == 1
    assert run.stderr == "error: command 'solve' of plugin 'greeter' clashes with the built-in command\n"
    mfp.plugin_manager().unregister(name="greeter")
    mfp.plugin_manager().register(CommandsPlugin("hello"), name="first")
    mfp.plugin_manager().register(CommandsPlugin("hello"), name="second")
    run = invoke("hello", "world")
    assert run.exit_code == 1
    assert "command 'hello' is provided twice: by plugin 'first' and by plugin 'second'" in run.stderr
    assert invoke("--help").exit_code == 0  # help still lists the built-in commands
