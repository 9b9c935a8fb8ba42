"""Results a person can read: the compare table, the history overlay and its CSV, the numbered mechanism.

On Test 12C solved by la, fdem and jmm. The references are independent of the drawing code: the
closed-form dead load R0 = 792 N x 0.6 / 1.1 = 432 N (datasets/README.md), the result files' own
variables, and the comparator's scores.
"""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.cli import cli
from masonryfw_compare.block_plots import DOMINANT_SHARE
from masonryfw_compare.history_plot import STRIP_SHARE, gravity_records

R0 = 792.0 * 0.6 / 1.1


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


@pytest.fixture(scope="module")
def opened(test_12c_files):
    return {solver: mf.open_dataset(path) for solver, path in test_12c_files.items()}


def test_compare_prints_both_headlines_and_each_score_with_what_it_measures(test_12c_files, opened):
    run = invoke("compare", test_12c_files["la"], test_12c_files["fdem"])
    assert run.exit_code == 0, run.output
    lines = run.stdout.splitlines()
    assert lines[0] == f"A: {test_12c_files['la']} (la (ipm))" and lines[1] == f"B: {test_12c_files['fdem']} (fdem)"
    alpha = float(opened["la"].collapse_multiplier)
    row = next(line for line in lines if line.startswith("alpha "))
    assert row.split()[1:3] == [f"{alpha:.4f}", "-"]
    row = next(line for line in lines if line.startswith("collapse reaction"))
    assert f"{(1 - alpha) * R0:.4g} N" in row
    fdem = opened["fdem"]
    settling = fdem.step_reaction.values[gravity_records(fdem.step_settlement.values) - 1:]
    row = next(line for line in lines if line.startswith("minimum reaction"))
    assert f"{settling.min():.4g} N at" in row
    scores = mf.compare(opened["la"], fdem, "crack")
    for name in ("crack_f1", "macro_block_ari", "mechanism_cosine", "locus_distance"):
        row = next(line for line in lines if line.startswith(name + " "))
        assert row.split()[1] == f"{float(scores[name]):.4g}"
        assert scores[name].attrs["comment"] in row  # what it measures and its range
    assert "1 = the same mechanism, 0 = unrelated, -1 = opposite" in run.stdout


def _not_json(name):
    raise AssertionError(f"{name} written as a JSON number")


def test_compare_of_three_results_scores_every_pair(test_12c_files, opened):
    paths = [test_12c_files[s] for s in ("la", "fdem", "jmm")]
    run = invoke("compare", *paths)
    assert run.exit_code == 0, run.output
    header = next(line for line in run.stdout.splitlines() if line.startswith("crack score"))
    assert header.split()[2:] == ["A-B", "A-C", "B-C"]
    scores = json.loads(invoke("compare", *paths, "--json").stdout, parse_constant=_not_json)  # NaN is not JSON
    assert [(p["a"], p["b"]) for p in scores["pairs"]] == [(str(paths[0]), str(paths[1])), (str(paths[0]), str(paths[2])),
                                                         (str(paths[1]), str(paths[2]))]
    expected = mf.compare(opened["fdem"], opened["jmm"], "crack")
    assert scores["pairs"][2]["scores"]["mechanism_cosine"] == float(expected.mechanism_cosine)
    refused = invoke("compare", *paths, "-o", "three.nc")
    assert refused.exit_code == 1 and "-o writes the comparison of two results, got 3" in refused.stderr
    assert invoke("compare", paths[0]).exit_code == 2


def test_a_continuum_result_is_scored_by_its_mechanism_too(opened):
    scores = mf.compare(opened["la"], opened["jmm"], "crack")
    assert {"mechanism_cosine", "macro_block_ari"} <= set(scores.data_vars)
    masonry = mfp.masonry_blocks(opened["jmm"].block_role.values)
    assert np.isfinite(mfp.block_motion(opened["jmm"])[masonry]).all()


def test_history_csv_holds_the_curves_numbers_and_la_s_collapse_reaction(test_12c_files, opened, tmp_path):
    out = tmp_path / "history.csv"
    run = invoke("plot", test_12c_files["fdem"], test_12c_files["jmm"], test_12c_files["la"], "--kind", "history",
                 "-o", out)
    assert run.exit_code == 0, run.output
    with out.open() as handle:
        rows = list(csv.DictReader(handle))
    for solver in ("fdem", "jmm"):
        mine = [r for r in rows if r["result"] == solver]
        ds = opened[solver]
        np.testing.assert_array_equal([float(r["settlement_m"]) for r in mine], ds.step_settlement.values)
        np.testing.assert_array_equal([float(r["reaction_N"]) for r in mine], ds.step_reaction.values)
        np.testing.assert_array_equal([int(r["damage_category"]) for r in mine], ds.step_damage_category.values)
        assert [r["stage"] for r in mine].count("gravity") == gravity_records(ds.step_settlement.values)
    (la_row,) = [r for r in rows if r["result"] == "la (ipm)"]
    assert float(la_row["reaction_N"]) == pytest.approx((1 - float(opened["la"].collapse_multiplier)) * R0, rel=1e-12)
    refused = invoke("plot", test_12c_files["la"], "--kind", "mechanism", "-o", tmp_path / "m.csv")
    assert refused.exit_code == 1 and "the mechanism plot draws no curves to write as CSV; kinds with curves: history" \
        in refused.stderr
    mismatch = invoke("plot", test_12c_files["fdem"], "--kind", "history", "--format", "svg", "-o", tmp_path / "h.png")
    assert mismatch.exit_code == 1 and "--format svg needs a file ending in .svg" in mismatch.stderr


def test_the_history_overlays_results_with_the_dead_load_and_la_s_collapse_reaction(opened, tmp_path):
    figure = mf.render([opened["fdem"], opened["jmm"], opened["la"]], "history", {"xscale": "log"})
    ax = figure.axes[0]
    assert ax.get_xscale() == "log"
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels[:2] == ["fdem", "jmm"]
    alpha = float(opened["la"].collapse_multiplier)
    levels = {round(float(line.get_ydata()[0]), 9) for line in ax.get_lines() if len(set(line.get_ydata())) == 1}
    assert round(R0, 9) in levels and round((1 - alpha) * R0, 9) in levels
    for suffix in (".png", ".svg", ".pdf"):
        assert mf.save_figure(figure, tmp_path / f"h{suffix}").stat().st_size > 1000
    zoomed = mf.render([opened["fdem"], opened["jmm"]], "history", {"settlement_max": 0.01}).axes[0]
    assert zoomed.get_xlim()[1] == 0.01
    # both results have damage categories: two strips along the top, above every curve
    low, high = zoomed.get_ylim()
    below_strips = low + (1 - 2 * STRIP_SHARE) * (high - low)
    for solver in ("fdem", "jmm"):
        ds = opened[solver]
        settling = ds.step_settlement.values > 0
        shown = settling & (1e3 * ds.step_settlement.values <= 0.01)
        assert ds.step_reaction.values[shown].max() < below_strips


@pytest.mark.parametrize("threshold", [0.01, 0.1])
def test_the_mechanism_numbers_the_pieces_holding_two_percent_of_the_masonry(opened, threshold):
    """At the core's threshold Test 12C's mechanism has only dominant pieces; at 1 % it has small ones too."""
    ds = opened["la"]
    masonry = mfp.masonry_blocks(ds.block_role.values)
    derived = mf.at_threshold(ds, threshold)
    labels, inverse = np.unique(derived.macro_block.values[masonry], return_inverse=True)
    area = np.bincount(inverse, weights=np.abs(ds.block_area.values[masonry]))
    dominant = int((area >= DOMINANT_SHARE * area.sum()).sum())
    ax = mf.render([ds], "mechanism", {"threshold": threshold}).axes[0]
    numbers = sorted(t.get_text() for t in ax.texts)
    assert numbers == sorted(f"({k})" for k in range(1, dominant + 1))
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    small = [text for text in legend if text.startswith("small pieces")]
    assert small == ([f"small pieces ({labels.size - dominant})"] if labels.size > dominant else [])
    assert (labels.size > dominant) == (threshold < 0.05)
    opening, slip = ds.interface_opening.values, ds.interface_slip.values
    motion = np.hypot(np.maximum(opening, 0.0), slip).max(axis=1)  # docs/format.md, by hand
    inner = ~mfp.support_blocks(ds.block_role.values)[ds.interface_blocks.values].all(axis=1)
    cracked = int((inner & (motion > threshold * motion[inner].max())).sum())
    assert f"cracked joints ({cracked})" in legend
    faces = [c for c in ax.collections if c.get_linewidths()[0] > 1.0]
    assert len(faces[0].get_segments()) == 2 * cracked  # each crack on both blocks' faces
    title = ax.get_title().replace("\n", " ")
    assert f"alpha = {float(ds.collapse_multiplier):.4f} (the share of R0 = {R0:.4g} N the settling ground sheds " \
        "before collapse)" in title
    assert title.endswith(f"collapse reaction {(1 - float(ds.collapse_multiplier)) * R0:.4g} N")


def test_a_sweep_s_points_go_on_the_history_at_their_settlements(opened):
    """A hand-made sweep of two friction angles (one point failed): its solved points' smallest
    reactions and plateaus, drawn and tabulated where the sweep's own numbers put them."""
    status = {"flag_values": np.array([0, 1], np.int8), "flag_meanings": "ok failed"}
    sweep = xr.Dataset(
        {"status": ("friction", np.array([0, 1, 0], np.int8), status),
         "minimum_reaction": ("friction", [100.0, np.nan, 90.0]),
         "minimum_reaction_settlement": ("friction", [0.001, np.nan, 0.002]),
         "plateau_reaction": ("friction", [110.0, np.nan, 95.0]),
         "plateau_settlement": ("friction", [0.008, np.nan, 0.009])},
        coords={"friction": ("friction", [20.0, 25.0, 30.0], {"sweep_key": "material.friction_angle"})},
        attrs={"masonryfw_format": "sweep", "title": "sweep of Test 12C", "solver": "fdem",
               "sweep_keys": "material.friction_angle"},
    )
    ax = mf.render([opened["fdem"], sweep], "history").axes[0]
    smallest, plateau = [c for c in ax.collections if c.get_label().startswith("sweep of")]
    np.testing.assert_allclose(smallest.get_offsets(), [[1.0, 100.0], [2.0, 90.0]])
    np.testing.assert_allclose(plateau.get_offsets(), [[8.0, 110.0], [9.0, 95.0]])
    assert smallest.get_label() == "sweep of material.friction_angle: smallest reaction (2 points)"
    header, rows = mf.plot_table([sweep], "history")
    assert [r[:5] for r in rows if r[0].startswith("sweep")] == [
        ["sweep material.friction_angle=20.0", 0, "smallest reaction", 0.001, 100.0],
        ["sweep material.friction_angle=20.0", 0, "plateau", 0.008, 110.0],
        ["sweep material.friction_angle=30.0", 1, "smallest reaction", 0.002, 90.0],
        ["sweep material.friction_angle=30.0", 1, "plateau", 0.009, 95.0],
    ]
    with pytest.raises(mf.MasonryError, match="its status variable has no 'ok' flag"):
        mf.render([sweep.drop_vars("status")], "history")
    la_sweep = sweep.drop_vars(["minimum_reaction", "minimum_reaction_settlement"]).assign_attrs(solver="la")
    with pytest.raises(mf.MasonryError, match="draws the points of sweeps of an incremental solver"):
        mf.render([la_sweep], "history")
