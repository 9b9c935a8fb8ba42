"""What the core does once, and when it must do it again: a model checked once is checked again when
its contents change (even in place); a solve makes the solver's estimate once; a comparison checks
each input once."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw import api


@pytest.fixture
def counting_solver(registered):
    """A solver that stays still, and counts the calls of its estimate."""
    calls = []

    def still(model, options, progress):
        return xr.Dataset(mfp.motion_variables(np.zeros((model.sizes["block"], 3))),
                          attrs={"rotations": "small", "flow_rule": "associative"})

    def estimate(model, options):
        calls.append(options["scale"])
        return mfp.Estimate(seconds=0.1, memory=1e6, basis="counted")

    registered(still, "still", estimate=estimate, options=(mfp.Option("scale", float, 1.0, "unused", above=0.0),))
    return calls


def test_an_array_edited_in_place_is_checked_again():
    model = mf.open_model("test-12c")
    assert mf.checked_model(model) is not None
    model.block_unit_weight.values[3] = -1.0  # in place: the same array object
    with pytest.raises(mf.ModelError, match="block_unit_weight"):
        mf.checked_model(model)


def test_a_solve_makes_the_estimate_once_per_model_and_options(counting_solver):
    model = mf.checked_model(mf.open_model("test-12c"))
    assert mf.estimate(model, "still").basis == "counted"
    mf.solve(model, "still")
    assert counting_solver == [1.0]
    mf.solve(model, "still", {"scale": 2.0})  # other options: a new estimate
    assert counting_solver == [1.0, 2.0]
    edited = model.copy(deep=True)
    edited.block_unit_weight.values[3] *= 1.5  # other contents: a new estimate
    mf.solve(edited, "still")
    assert counting_solver == [1.0, 2.0, 1.0]


def test_a_comparison_of_n_results_checks_each_once(monkeypatch):
    model = mf.open_model("test-12c")
    results = [mf.solve(model, "la", {"solver": backend}) for backend in ("ipm", "clarabel", "highs")]
    checked = []
    real = api.check
    monkeypatch.setattr(api, "check", lambda ds, **kw: checked.append(kw.get("kind")) or real(ds, **kw))
    for other in results[1:]:
        mf.compare(results[0], other)
    assert checked.count("result") == 3  # the first result once, not once per comparison
    results[0].block_unit_weight.values[3] = -1.0  # edited in place: checked again, and refused
    with pytest.raises(mf.ModelError, match="block_unit_weight"):
        mf.compare(results[0], results[1])


def test_a_solve_from_the_command_line_checks_looks_up_resolves_and_builds_once(monkeypatch, tmp_path):
    """The CLI checked a model twice (``open_model``, then ``checked_model``), looked the solver up and resolved its
    options twice (for the estimate, then the solve), and fdem built its scene twice: once each now."""
    from masonryfw import cli
    from masonryfw.format import model
    from masonryfw_fdem import scene3d

    calls: dict[str, int] = {}

    def counted(module, name):
        real = getattr(module, name)

        def call(*args, **kwargs):
            calls[name] = calls.get(name, 0) + 1
            return real(*args, **kwargs)
        monkeypatch.setattr(module, name, call)

    counted(model, "check")
    counted(api, "lookup")
    counted(api, "resolve_options")
    counted(scene3d, "build_scene")  # the estimate and the solve both take their scene from scene3d.scene_of
    with pytest.raises(SystemExit) as end:
        cli.main(["solve", "test-12c", "--plugin", "fdem", "--option", "settlement=0.0002", "--no-progress",
                  "-o", str(tmp_path / "r.nc")])
    assert end.value.code == 0
    assert calls == {"check": 1, "lookup": 1, "resolve_options": 1, "build_scene": 1}
