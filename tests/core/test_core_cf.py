"""Every kind of file the project writes passes the IOOS compliance checker's CF-1.11 suite with no error.

The checker is an independent implementation of the CF rules (UDUNITS units,
coordinate variables without fill values, geometry containers, flags). It is a
test dependency (``pip install ".[test]"``); without it the test is skipped.
"""
from __future__ import annotations

import json

import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

runner = pytest.importorskip("compliance_checker.runner")


def cf_errors(path, tmp_path) -> list[tuple[str, list[str]]]:
    """The high-priority (error) checks the file fails, with their messages."""
    runner.CheckSuite().load_all_available_checkers()
    report = tmp_path / f"{path.stem}.json"
    runner.ComplianceChecker.run_checker(str(path), ["cf:1.11"], 0, "normal", output_filename=str(report),
                                         output_format="json")
    results = json.loads(report.read_text())["cf:1.11"]
    return [(r["name"], r["msgs"]) for r in results["high_priorities"] if r["value"][0] < r["value"][1]]


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """One file of every kind: a model, each solver's result, a comparison, a sweep."""
    folder = tmp_path_factory.mktemp("cf")
    model = mt.small_settlement_wall()
    files = {"model": mf.save(model, folder / "model.nc")}
    options = {"fdem": {"snapshots": "0.001"}, "jmm": {"max_steps": 4}}
    results = {}
    for solver in ("la", "fdem", "jmm", "jmm-limit", "statics"):
        results[solver] = mf.solve(model, solver, options.get(solver, {}))
        files[solver] = mf.save(results[solver], folder / f"{solver}.nc")
    files["comparison"] = mf.save(mf.compare(results["la"], results["fdem"], "crack"), folder / "comparison.nc")
    drawn = mf.open_model("lact3-arch")  # a model of a drawing, and the tilt results (load factors, trials)
    files["drawn model"] = mf.save(drawn, folder / "drawn.nc")
    for solver in ("fdem", "jmm", "jmm-limit"):
        files[f"{solver} tilt"] = mf.save(mf.solve(drawn, solver), folder / f"{solver}-tilt.nc")
    from masonryfw_sweep import combine, plan_sweep
    from masonryfw_sweep.tasks import run_point

    plan = plan_sweep(mf.dump_toml(dict(mf.load_spec(mf.bundled_spec_path("test-12c")))), "la",
                      ["material.friction_angle=20,25"])
    records = [run_point(plan.spec, [(("material", "friction_angle"), value)], "la", plan.options,
                         str(folder / "store"), {}) for value in (20, 25)]
    files["sweep"] = mf.save(combine(plan, records, folder, str(folder / "store")), folder / "sweep.nc")
    in_3d = mf.checked_model(mfp.twin(model))
    files["3D model"] = mf.save(in_3d, folder / "model3d.nc")
    files["3D la"] = mf.save(mf.solve(in_3d, "la"), folder / "la3d.nc")
    return files


@pytest.mark.parametrize("kind", ["model", "la", "fdem", "jmm", "jmm-limit", "statics", "comparison", "sweep",
                                  "drawn model", pytest.param("fdem tilt", marks=pytest.mark.slow),
                                  pytest.param("jmm tilt", marks=pytest.mark.slow),
                                  pytest.param("jmm-limit tilt", marks=pytest.mark.slow), "3D model", "3D la"])
def test_cf_checker_finds_no_error(written, tmp_path, kind):
    assert cf_errors(written[kind], tmp_path) == []
