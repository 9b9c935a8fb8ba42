"""The plugin manager: loading through entry points, lookup, solve/compare/render and their errors.

References: the hand-built model of ``conftest.py`` (weights and support loads
counted by hand), the distribution metadata written by the tests themselves,
and ``hashlib`` over the file bytes.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import subprocess
import sys
import textwrap
import warnings
from importlib.metadata import EntryPoint, entry_points
from importlib.metadata import version as dist_version

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.cli import cli, main
from masonryfw.contract import registry
from masonryfw.runtime.errors import ModelError, PluginError, SolveError

# ---------------------------------------------------------------- in-process plugins

class ToyPlugin:
    """A plugin object registered by hand: contributes the records it is given."""

    def __init__(self, solvers=(), comparators=(), plotters=()):
        self.solvers, self.comparators, self.plotters = list(solvers), list(comparators), list(plotters)

    @mfp.hookimpl
    def masonryfw_solvers(self):
        return self.solvers

    @mfp.hookimpl
    def masonryfw_comparators(self):
        return self.comparators

    @mfp.hookimpl
    def masonryfw_plotters(self):
        return self.plotters


def constant_alpha(model, options, progress):
    """A solver whose collapse multiplier is its option ``alpha``."""
    return xr.Dataset(
        {"collapse_multiplier": ((), float(options["alpha"]), mfp.variable_attrs("collapse_multiplier"))},
        attrs={"constant_backend": "none"},  # a plugin's own detail, kept in its result
    )


CONSTANT = mfp.Solver("constant", "alpha from an option", constant_alpha, "3.1", (mfp.Option("alpha", float, 0.5, "alpha"),))


def alpha_gap(a, b, options):
    return xr.Dataset({"alpha_gap": ((), abs(float(a.collapse_multiplier) - float(b.collapse_multiplier)), {"units": "1", "long_name": "|alpha_a - alpha_b|"})})


def failing_solver(exception):
    def solve(model, options, progress):
        raise exception

    return mfp.Solver("failing", "raises", solve, "0")


def returning_solver(produced):
    return mfp.Solver("returning", "returns a fixed dataset", lambda model, options, progress: produced(model), "0")


@pytest.fixture
def manager():
    """The real plugin manager (entry points loaded afresh), reset afterwards."""
    registry.reset()
    yield mfp.plugin_manager()
    registry.reset()


@pytest.fixture
def empty_manager(monkeypatch):
    """A plugin manager that sees no entry point at all."""
    monkeypatch.setattr(registry, "entry_points", lambda group: [])
    registry.reset()
    yield mfp.plugin_manager()
    registry.reset()


# ---------------------------------------------------------------- loading and lookup

def test_builtin_plugins_come_from_the_entry_point_group():
    """Exactly the entry points load (the ones that cannot are warnings); the example is one of them."""
    declared = {ep.name for ep in entry_points(group="masonryfw")}
    registry.reset()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            manager = mfp.plugin_manager()
        failed = {re.match(r"masonryfw plugin '([^']+)'", str(w.message)).group(1) for w in caught
                  if issubclass(w.category, registry.PluginLoadWarning)}
        info = {p.name: p for p in registry.installed_plugins()}
        assert set(info) == declared - failed and "example" not in failed
        assert info["example"].distribution == "masonryfw"
        assert info["example"].version == dist_version("masonryfw")
        assert [s.name for s in info["example"].solvers] == ["statics"]
        assert mf.get_solver("statics").solve is info["example"].solvers[0].solve
        assert mfp.plugin_manager() is manager  # cached
    finally:
        registry.reset()


def test_a_plugin_that_fails_to_import_is_a_warning_and_the_others_load(monkeypatch):
    example = next(ep for ep in entry_points(group="masonryfw") if ep.name == "example")
    ghost = EntryPoint("ghost", "no_such_module_for_masonryfw", "masonryfw")
    monkeypatch.setattr(registry, "entry_points", lambda group: [ghost, example])
    registry.reset()
    try:
        with pytest.warns(registry.PluginLoadWarning, match=r"'ghost'.*no_such_module_for_masonryfw.*ModuleNotFoundError"):
            mfp.plugin_manager()
        assert mf.get_solver("statics").name == "statics"
    finally:
        registry.reset()


def test_a_hook_that_raises_is_a_warning(empty_manager):
    class Raising:
        @mfp.hookimpl
        def masonryfw_solvers(self):
            raise RuntimeError("cannot list")

    empty_manager.register(Raising(), name="raising")
    empty_manager.register(ToyPlugin([CONSTANT]), name="toy")
    with pytest.warns(registry.PluginLoadWarning, match=r"'raising'.*RuntimeError: cannot list"):
        assert mf.get_solver("constant") is CONSTANT


def test_unknown_names_list_the_valid_ones(empty_manager):
    with pytest.raises(PluginError, match="no solver is installed"):
        mf.get_solver("statics")
    with pytest.raises(PluginError, match="no comparator is installed"):
        mf.get_comparator("x")
    with pytest.raises(PluginError, match="no plotter is installed"):
        mf.get_plotter("x")
    empty_manager.register(ToyPlugin([CONSTANT, failing_solver(ValueError())]), name="toy")
    with pytest.raises(PluginError, match=r"unknown solver 'nope'; valid solvers: constant, failing"):
        mf.get_solver("nope")
    with pytest.raises(PluginError, match=r"unknown solver 'constnat' \(did you mean 'constant'\?\)"):
        mf.get_solver("constnat")


def test_the_same_name_from_two_plugins_names_both(empty_manager):
    empty_manager.register(ToyPlugin([CONSTANT]), name="first")
    empty_manager.register(ToyPlugin([CONSTANT]), name="second")
    with pytest.raises(PluginError, match=r"solver 'constant' is provided twice: by plugin 'first' and by plugin 'second'"):
        mf.get_solver("constant")


# ---------------------------------------------------------------- solve

def test_statics_on_the_hand_model(manager, model):
    """Hand count (conftest): W = 96 + 144 + 120 = 360 N shared 0.4 : 0.6 by the supports."""
    result = mf.solve(model, "statics")
    assert result.attrs["masonryfw_format"] == "result"
    np.testing.assert_allclose(result.support_dead_reaction.values, [0, 0, 0, 144.0, 216.0])
    assert float(result.masonry_weight) == pytest.approx(360.0)
    # dead: Fy = -360 + 216; Mz = 0.2*-96 + 0.7*-144 + 0.5*-120 + 0.7*216 = -28.8
    np.testing.assert_allclose(result.total_dead_force.values, [0.0, -144.0], atol=1e-9)
    assert float(result.total_dead_moment) == pytest.approx(-28.8)
    np.testing.assert_allclose(result.total_live_force.values, [0.0, -216.0], atol=1e-9)
    assert float(result.total_live_moment) == pytest.approx(0.7 * -216.0)
    assert result.support_dead_reaction.attrs["units"] == "N"
    assert mf.check(result) == []


def test_result_carries_the_model_and_the_provenance(manager, model):
    result = mf.solve(model, "statics")
    for name in model.data_vars:
        np.testing.assert_array_equal(result[name].values, model[name].values)
    attrs = result.attrs
    assert (attrs["plugin"], attrs["solver"], attrs["title"]) == ("example", "statics", "Hand wall")
    assert attrs["plugin_version"] == dist_version("masonryfw")
    assert json.loads(attrs["solver_options"]) == {}
    assert 0 <= attrs["wall_time_s"] < 10
    assert attrs["model_sha256"] == mfp.content_sha256(model)
    assert "input_sha256" not in attrs and "source_file" not in attrs  # not read from a file
    assert "solve: solver statics (plugin example)" in attrs["history"]


def test_statics_refuses_a_wall_that_touches_no_support(model):
    from masonryfw_example.statics import solve_statics

    floating = mfp.derive_geometry(model.isel(interface=[0, 1, 2]))  # bed and head joints only
    with pytest.raises(SolveError, match="statics: no wall block rests on a support block"):
        solve_statics(floating, {}, mfp.no_progress)


def test_statics_on_the_bundled_test_12c(manager):
    """Closed form (datasets/README.md): W = 1.1 * 0.6 * 0.1 m3 * 12 kN/m3 = 792 N; supports 0.5 and 0.6 of 1.1 m.

    The plugin's share of the moving support equals the dead load the builder put on it.
    """
    model = mf.open_model("test-12c")
    result = mf.solve(model, "statics")
    assert float(result.masonry_weight) == pytest.approx(792.0)
    roles = mfp.flags("block_role")
    role = result.block_role.values
    assert result.support_dead_reaction.values[role == roles["fixed_support"]] == pytest.approx([792 * 0.5 / 1.1])
    moving = role == roles["moving_support"]
    assert result.support_dead_reaction.values[moving] == pytest.approx([792 * 0.6 / 1.1])
    assert result.support_dead_reaction.values[moving] == pytest.approx(model.dead_load.values[moving, 1])
    assert result.total_live_force.values[1] == pytest.approx(-792 * 0.6 / 1.1)


def test_solving_a_result_solves_its_model_only(manager, model):
    manager.register(ToyPlugin([CONSTANT]), name="toy")
    first = mf.solve(model, "constant", {"alpha": 0.5})
    assert first.attrs["constant_backend"] == "none"
    again = mf.solve(first, "statics")
    assert "collapse_multiplier" not in again and "constant_backend" not in again.attrs
    assert (again.attrs["solver"], again.attrs["solver_options"]) == ("statics", "{}")
    assert again.attrs["model_sha256"] == first.attrs["model_sha256"] == mfp.content_sha256(model)


def test_result_of_a_model_file_records_the_file_hash(manager, model_file):
    result = mf.solve(mf.open_model(model_file), "statics")
    assert result.attrs["input_sha256"] == hashlib.sha256(model_file.read_bytes()).hexdigest()
    assert result.attrs["source_file"] == str(model_file.resolve())


def test_options_are_resolved_and_recorded(empty_manager, model):
    empty_manager.register(ToyPlugin([CONSTANT]), name="toy")
    result = mf.solve(model, "constant", {"alpha": "0.25"})
    assert float(result.collapse_multiplier) == 0.25
    assert json.loads(result.attrs["solver_options"]) == {"alpha": 0.25}
    # registered by hand: no distribution, so masonryfw's version; the record's version plus its code's digest
    assert result.attrs["plugin_version"] == mf.__version__
    assert re.fullmatch(r"3\.1\+[0-9a-f]{12}", result.attrs["solver_version"])
    with pytest.raises(PluginError, match=r"solver 'constant': unknown option 'beta'; valid options: alpha"):
        mf.solve(model, "constant", {"beta": 1})
    with pytest.raises(PluginError, match=r"solver 'constant': option 'alpha' = 'high': not a float"):
        mf.solve(model, "constant", {"alpha": "high"})


def test_an_invalid_model_is_refused_before_the_solver_runs(empty_manager, model):
    calls = []
    empty_manager.register(ToyPlugin([mfp.Solver("spy", "", lambda m, o, p: calls.append(1), "0")]), name="toy")
    model["block_thickness"][1] = -0.1
    model["interface_friction"][2] = -1.0
    with pytest.raises(ModelError) as caught:
        mf.solve(model, "spy")
    assert len(caught.value.problems) >= 2
    assert "block_thickness" in str(caught.value) and "interface_friction" in str(caught.value)
    assert calls == []


def test_a_crashing_solver_becomes_a_solve_error_chained_to_the_cause(empty_manager, model):
    cause = ZeroDivisionError("division by zero")
    empty_manager.register(ToyPlugin([failing_solver(cause)]), name="toy")
    with pytest.raises(SolveError, match=r"^solver failing failed: ZeroDivisionError: division by zero$") as caught:
        mf.solve(model, "failing")
    assert caught.value.__cause__ is cause


def test_a_masonry_error_from_a_solver_propagates_unchanged(empty_manager, model):
    own = SolveError("infeasible: the wall cannot stand")
    empty_manager.register(ToyPlugin([failing_solver(own)]), name="toy")
    with pytest.raises(SolveError) as caught:
        mf.solve(model, "failing")
    assert caught.value is own


@pytest.mark.parametrize(
    "produced, message",
    [
        (lambda m: m[["dead_load"]] * 2, r"returned variable\(s\) dead_load that belong to its input"),
        (lambda m: xr.Dataset({"crack_indicator": ("interface", np.zeros(2))}), "do not fit its input"),
        (lambda m: {"collapse_multiplier": 1.0}, "returned dict, not an xarray.Dataset"),
        (lambda m: xr.Dataset({"crack_indicator": ("interface", np.full(m.sizes["interface"], 2.0))}),
         r"(?s)the result of solver returning is invalid.*interface 5: crack_indicator = 2 is above the maximum 1"),
    ],
    ids=["overwrites-model", "wrong-size", "not-a-dataset", "out-of-bounds"],
)
def test_a_solver_returning_a_bad_result_is_a_solve_error(empty_manager, model, produced, message):
    empty_manager.register(ToyPlugin([returning_solver(produced)]), name="toy")
    with pytest.raises(SolveError, match=message):
        mf.solve(model, "returning")


# ---------------------------------------------------------------- compare and render

def test_compare_builds_a_comparison_dataset_with_the_schema_attributes(empty_manager, model):
    empty_manager.register(ToyPlugin([CONSTANT], [mfp.Comparator("alpha-gap", "|alpha a - alpha b|", alpha_gap, "1.2")]), name="toy")
    a = mf.solve(model, "constant", {"alpha": 0.5})
    b = mf.solve(model, "constant", {"alpha": 0.125})
    comparison = mf.compare(a, b)  # the only comparator installed
    assert float(comparison.alpha_gap) == 0.375
    required = [k for k, v in mfp.load_schema("comparison")["global_attributes"].items() if v["required"]]
    assert set(required) <= set(comparison.attrs)
    assert comparison.attrs["masonryfw_format"] == "comparison"
    assert comparison.attrs["comparator"] == "alpha-gap"
    assert re.fullmatch(r"1\.2\+[0-9a-f]{12}", comparison.attrs["comparator_version"])
    assert comparison.attrs["input_a_sha256"] == mfp.content_sha256(a)
    assert comparison.attrs["input_a_sha256"] != comparison.attrs["input_b_sha256"]
    assert mf.check(comparison) == []


def test_compare_without_a_comparator_says_so(empty_manager, model):
    with pytest.raises(PluginError, match="no comparator is installed"):
        mf.compare(model, model)


def test_render_draws_with_the_plotter(empty_manager, model):
    def outline(datasets, ax, options):
        for ds in datasets:
            ax.plot(ds.node_x.values, ds.node_y.values, options["style"])

    empty_manager.register(ToyPlugin(plotters=[mfp.Plotter("nodes", "", outline, "1", (mfp.Option("style", str, "k."),))]), name="toy")
    figure = mf.render([model], None, {"style": "r+"})
    (line,) = figure.axes[0].lines
    np.testing.assert_array_equal(line.get_xdata(), model.node_x.values)
    assert line.get_marker() == "+"


# ---------------------------------------------------------------- a real third-party installation

THIRDPARTY = '''
"""A third-party plugin installed by dist-info only: a null solver."""
import numpy as np
import xarray as xr
from click.testing import CliRunner

import masonryfw as mf
import masonryfw.plugin_api as mfp


def solve_null(model, options, progress):
    """Zero motion (so no crack); alpha = scale * sum|live| / sum|dead|."""
    alpha = options["scale"] * np.abs(model.live_load.values).sum() / np.abs(model.dead_load.values).sum()
    return xr.Dataset({
        **mfp.motion_variables(np.zeros((model.sizes["block"], 3))),
        "collapse_multiplier": ((), alpha, mfp.variable_attrs("collapse_multiplier")),
    }, attrs={"rotations": "small", "flow_rule": "associative"})


@mfp.hookimpl
def masonryfw_solvers():
    return [mfp.Solver("tp-null", "null solver", solve_null, "2.5",
                      (mfp.Option("scale", float, 1.0, "multiplies alpha"),))]
'''


def _install(root, module: str, version: str, entry_name: str, source: str):
    """Install ``module`` into ``root`` the way pip would leave it: source + dist-info."""
    root.mkdir(parents=True, exist_ok=True)
    (root / f"{module}.py").write_text(textwrap.dedent(source))
    info = root / f"{module}-{version}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text(f"[masonryfw]\n{entry_name} = {module}\n")
    return root


@pytest.fixture(scope="module")
def site(tmp_path_factory, make_model):
    """Three site directories (good, broken, duplicate plugin) and a model file."""
    base = tmp_path_factory.mktemp("thirdparty")
    good = _install(base / "good", "thirdparty_mf", "0.1", "thirdparty", THIRDPARTY)
    broken = _install(base / "broken", "broken_mf", "0.3", "broken", "raise RuntimeError('deliberately broken')\n")
    duplicate = _install(base / "dup", "dup_mf", "0.2", "dup", THIRDPARTY.replace('"2.5"', '"9"'))
    model_path = base / "wall.nc"
    make_model().to_netcdf(model_path)
    return {"good": good, "broken": broken, "dup": duplicate, "model": model_path, "work": base}


def run_cli(args, *, sites=(), cwd=None):
    """``python -m masonryfw ARGS`` in a fresh process that finds plugins in ``sites``."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(map(str, sites)))
    return subprocess.run(
        [sys.executable, "-m", "masonryfw", *map(str, args)],
        capture_output=True, text=True, env=env, cwd=cwd, timeout=120,
    )


@pytest.fixture
def installed(site, monkeypatch):
    """``installed("good", "dup")``: those site directories on ``sys.path``, plugins reloaded.

    The in-process twin of ``PYTHONPATH=...``: entry points are found by the same
    ``importlib.metadata`` scan of ``sys.path``, without a new interpreter.
    """
    def install(*names):
        for name in names:
            monkeypatch.syspath_prepend(str(site[name]))
        registry.reset()

    yield install
    for module in ("thirdparty_mf", "dup_mf", "broken_mf"):
        sys.modules.pop(module, None)
    registry.reset()


def test_thirdparty_solver_runs_from_the_command_line(site, tmp_path):
    before = hashlib.sha256(site["model"].read_bytes()).hexdigest()
    run = run_cli(["solve", site["model"], "--plugin", "tp-null", "--option", "scale=2"], sites=[site["good"]], cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    out = tmp_path / "wall.tp-null.nc"
    assert f"result: {out.name}" in run.stdout
    with xr.open_dataset(out) as result:
        # hand count: sum|live| = 216, sum|dead| = 96 + 144 + 120 + 216 = 576; times scale 2
        assert float(result.collapse_multiplier) == pytest.approx(2 * 216 / 576)
        assert result.attrs["plugin"] == "thirdparty"
        assert result.attrs["plugin_version"] == "0.1"  # from the dist-info, not the record's 2.5
        assert result.attrs["solver"] == "tp-null"
        assert json.loads(result.attrs["solver_options"]) == {"scale": 2.0}
        assert result.attrs["input_sha256"] == before
        assert np.all(result.crack_indicator.values == 0)
    assert "alpha = 0.75" in run.stdout
    assert hashlib.sha256(site["model"].read_bytes()).hexdigest() == before


def test_a_broken_thirdparty_plugin_warns_and_the_rest_are_listed(installed, capsys):
    installed("good", "broken")
    with pytest.raises(SystemExit) as exited:
        main(["plugins"])
    assert exited.value.code == 0
    out, err = capsys.readouterr()
    assert "warning: masonryfw plugin 'broken'" in err
    assert "broken_mf 0.3" in err and "RuntimeError: deliberately broken" in err
    assert "Traceback" not in err
    assert "thirdparty (thirdparty_mf 0.1)" in out and "tp-null" in out
    assert "statics" in out
    assert "--option scale=<float> (default 1.0)  multiplies alpha" in out


def test_two_thirdparty_plugins_with_one_solver_name_are_named(installed, site, tmp_path, monkeypatch):
    installed("good", "dup")
    monkeypatch.chdir(tmp_path)
    run = CliRunner().invoke(cli, ["solve", str(site["model"]), "--plugin", "tp-null"])
    assert run.exit_code == 1
    assert "solver 'tp-null' is provided twice" in run.stderr
    assert "'thirdparty' (distribution thirdparty_mf 0.1)" in run.stderr and "'dup' (distribution dup_mf 0.2)" in run.stderr
    assert not list(tmp_path.glob("*.nc"))


@pytest.mark.parametrize(
    "extra, expected",
    [
        (["--plugin", "nope"], "error: unknown solver 'nope'; valid solvers: "),
        (["--plugin", "tp-null", "--option", "speed=3"], "solver 'tp-null': unknown option 'speed'; valid options: scale"),
        (["--plugin", "tp-null", "--option", "scale=big"], "solver 'tp-null': option 'scale' = 'big': not a float"),
    ],
    ids=["unknown-plugin", "unknown-option", "bad-option-type"],
)
def test_bad_plugin_choices_exit_1_with_a_message(installed, site, tmp_path, monkeypatch, extra, expected):
    installed("good")
    monkeypatch.chdir(tmp_path)
    before = hashlib.sha256(site["model"].read_bytes()).hexdigest()
    run = CliRunner().invoke(cli, ["solve", str(site["model"]), *extra])
    assert run.exit_code == 1
    assert expected in run.stderr
    if "nope" in extra:
        assert "statics" in run.stderr and "tp-null" in run.stderr
    assert hashlib.sha256(site["model"].read_bytes()).hexdigest() == before
    assert not list(tmp_path.glob("*.nc"))
