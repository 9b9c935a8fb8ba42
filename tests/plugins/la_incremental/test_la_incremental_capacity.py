"""Where each damage category is first reached, from one run, against separate runs to each settlement.

One run to a large settlement answers every smaller one: a run to settlement s reaches exactly the
categories the long run reached by s (to within the record spacing), the LTSM's categories at s are the
LTSM thresholds below s, and a tunnel's volume loss is its S_max scaled (the trough keeps its shape).
"""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.results.damage import first_exceeding
from tests.support import cli

TUNNEL_WALL = """
title = "tunnel wall"
[wall]
width = 4.0
height = 2.0
thickness = 0.2
[unit]
length = 0.4
height = 0.2
[bond]
pattern = "running"
[material]
unit_weight = 18000.0
friction_angle = 35.0
[settlement]
profile = "tunnel"
volume_loss = 1.0
diameter = 6.0
depth = 12.0
center = 5.0
[loading]
type = "settlement"
"""


def test_first_exceeding_is_linear_between_records_and_known_to_their_spacing():
    settlement = np.array([0.0, 1.0, 2.0, 3.5])
    width = np.array([0.0, 0.5, 1.5, 1.0])
    assert first_exceeding(settlement, width, 1.0) == pytest.approx((1.5, 1.0))
    assert first_exceeding(settlement, width, 0.2) == pytest.approx((0.4, 1.0))
    assert np.isnan(first_exceeding(settlement, width, 2.0)).all()
    assert first_exceeding(settlement, width + 3.0, 1.0) == (0.0, 0.0)  # over from the first record, exactly


#: A run to its target: fdem would stop at its reaction plateau (masonryfw capacity sets this too).
TO_THE_END = {"la-incremental": {}, "fdem": {"plateau_tolerance": 0.0}}


@pytest.fixture(scope="module", params=["la-incremental", pytest.param("fdem", marks=pytest.mark.slow)])
def long_run(request):
    return request.param, mf.solve(mf.open_model("test-8c"), request.param,
                                   {"settlement": 0.03, **TO_THE_END[request.param]})


@pytest.mark.parametrize("target", [0.0015, 0.004, 0.012, 0.025])
def test_one_run_gives_the_categories_of_separate_runs(long_run, target):
    solver, long_run = long_run
    short = mf.solve(mf.open_model("test-8c"), solver, {"settlement": target, **TO_THE_END[solver]})
    thresholds = long_run.category_settlement.values
    expected = int(np.sum(thresholds <= target))
    reached = int(short.step_damage_category.values.max())
    spacing = np.diff(long_run.step_settlement.values).max()
    near = np.abs(thresholds - target) <= spacing
    assert reached == expected or near.any(), (target, thresholds, reached)
    assert 1 <= expected <= 5  # the targets span the categories: the test compares something


def test_a_tunnel_wall_in_volume_loss(tmp_path):
    spec = tmp_path / "tunnel-wall.toml"
    spec.write_text(TUNNEL_WALL)
    model = mf.build(spec)
    long = mf.solve(model, "la-incremental", {"settlement": 0.02})
    per_metre = 1.0 / float(model.settlement_target)  # V_L [%] per metre of S_max at the spec's V_L = 1 %
    np.testing.assert_allclose(long.category_volume_loss.values, per_metre * long.category_settlement.values)
    np.testing.assert_allclose(long.category_ltsm_volume_loss.values[:4],
                               per_metre * long.category_ltsm_settlement.values[:4])
    # the LTSM: at its threshold the strain equals the limit (the strain is linear in the settlement)
    for limit, at in zip(mfp.LTSM_LIMITS, long.category_ltsm_settlement.values[:4]):
        assert mfp.assess(model, float(at)).strain == pytest.approx(limit, rel=1e-12)
    screen = mfp.assess(model, float(long.screen_settlement))
    assert max(screen.slope * 500.0, screen.greenfield_settlement / 0.010) == pytest.approx(1.0, rel=1e-12)
    first = float(long.category_volume_loss.values[0])
    assert np.isfinite(first)
    for loss, category in ((0.8 * first, 0), (1.25 * first, 1)):
        short = mf.solve(model, "la-incremental", {"settlement": loss / per_metre})
        assert int(short.step_damage_category.values.max()) == category


def test_capacity_command_prints_the_category_in_volume_loss(tmp_path):
    spec = tmp_path / "tunnel-wall.toml"
    spec.write_text(TUNNEL_WALL)
    done = cli(["capacity", str(spec), "--plugin", "la-incremental", "--volume-loss", "1.5", "--category", "1",
                "--no-progress", "-o", str(tmp_path / "out.nc")], tmp_path)
    assert done.returncode == 0, done.stderr
    first = done.stdout.splitlines()[2]
    assert first.startswith("category 1 (very slight): first reached at") and "V_L" in first
    assert "stage 2: LTSM" in done.stdout and "stage 1: the greenfield screen" in done.stdout
    result = mf.open_dataset(tmp_path / "out.nc")
    assert "category_volume_loss" in result and float(result.step_settlement.values[-1]) > 0
    refused = cli(["capacity", "test-8c", "--volume-loss", "2", "--no-progress"], tmp_path)
    assert refused.returncode == 1 and "not over a tunnel" in refused.stderr


def test_a_tunnel_history_has_a_volume_loss_axis(tmp_path):
    spec = tmp_path / "tunnel-wall.toml"
    spec.write_text(TUNNEL_WALL)
    model = mf.build(spec)
    result = mf.solve(model, "la-incremental", {"settlement": 0.01})
    figure = mf.render([result], "history")
    top = [child for child in figure.axes[0].child_axes if child.get_xlabel().startswith("tunnel volume loss")]
    assert len(top) == 1
    figure.canvas.draw()
    ticks = [t.get_text().replace("\u2212", "-") for t in top[0].get_xticklabels() if t.get_text()]
    assert ticks and all(0 <= float(t) <= 1.0 for t in ticks)  # V_L 1 % is S_max, the run went to 10 mm < S_max
    plain = mf.render([mf.solve(mf.open_model("test-8c"), "la-incremental", {"settlement": 0.002})], "history")
    assert not plain.axes[0].child_axes
