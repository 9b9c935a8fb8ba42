"""fdem as a plugin: result contents, equilibrium of the contact forces, interruption,
snapshots, and bad input naming what is wrong."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_fdem.scene import build_scene

ROLE = mfp.flags("block_role")
RESULT_VARIABLES = (
    "block_displacement", "interface_opening", "interface_slip", "interface_normal_force",
    "interface_shear_force", "interface_state", "crack_indicator", "macro_block", "step_settlement",
    "step_reaction", "step_kinetic_energy", "step_work_gravity", "step_work_support", "step_dissipated",
    "step_stored",
)


def test_fdem_is_registered_with_its_options():
    solver = mf.get_solver("fdem")
    names = {o.name for o in solver.options}
    assert {"mode", "settlement", "damping", "dt_safety", "loading_rate", "snapshots"} <= names


def test_gravity_state_contact_forces_carry_the_weight(small_wall):
    """At rest under gravity the support interfaces carry the whole weight (vertical equilibrium)."""
    result = mf.solve(small_wall, "fdem", {"settlement_ratio": 0.0})
    assert result.attrs["stop_reason"] == "at rest"
    weight = -small_wall.dead_load.values[small_wall.block_role.values < 2, 1].sum()
    sides = small_wall.interface_blocks.values
    on_support = (small_wall.block_role.values[sides] >= ROLE["fixed_support"]).any(axis=1)
    # the normal of a support interface points up or down; its normal force is vertical
    vertical = np.abs(small_wall.interface_normal_y.values[on_support])
    carried = (result.interface_normal_force.values[on_support].sum(axis=1) * vertical).sum()
    assert carried == pytest.approx(weight, rel=1e-3)
    assert np.all(result.interface_normal_force.values >= -1e-9 * weight)  # dry joints: no tension


def test_result_holds_format_variables_and_run_attributes(small_wall):
    result = mf.solve(small_wall, "fdem", {"snapshots": "0.001, 0.002"})
    for name in RESULT_VARIABLES:
        assert name in result, name
    assert result.attrs["solver"] == "fdem"
    assert result.attrs["fdem_dt_s"] < result.attrs["fdem_dt_critical_s"]
    assert result.attrs["fdem_steps"] > result.attrs["fdem_gravity_steps"] > 0
    assert result.attrs["interrupted"] == 0
    np.testing.assert_allclose(result.snapshot_settlement.values, [0.001, 0.002], atol=5e-5)
    moving = small_wall.block_role.values == ROLE["moving_support"]
    np.testing.assert_allclose(result.snapshot_block_displacement.values[:, moving, 1].ravel(),
                               -result.snapshot_settlement.values, rtol=1e-12)
    # the moving support went down by the last recorded settlement
    assert mfp.block_motion(result)[moving, 1] == pytest.approx(-result.step_settlement.values[-1])


def test_keyboard_interrupt_returns_the_state_reached(small_wall):
    calls = []

    def impatient(fraction, message):
        calls.append(fraction)
        if "settlement" in message and fraction > 0.3:
            raise KeyboardInterrupt

    result = mf.solve(small_wall, "fdem", {"plateau_tolerance": 0.0}, impatient)
    assert result.attrs["interrupted"] == 1
    assert result.attrs["stop_reason"] == "interrupted"
    settled = result.step_settlement.values[-1]
    assert 0 < settled < result.attrs["fdem_target_settlement"]
    moving = small_wall.block_role.values == ROLE["moving_support"]
    assert mfp.block_motion(result)[moving, 1] == pytest.approx(-settled)
    assert mf.check(result) == []


@pytest.mark.parametrize("options, named", [
    ({"damping": 1.5}, "damping"),
    ({"dt_safety": 0.0}, "dt_safety"),
    ({"mode": "elastic"}, "mode"),
    ({"snapshots": "1mm"}, "snapshots"),
])
def test_bad_options_name_the_option(small_wall, options, named):
    with pytest.raises(mf.PluginError, match=named):
        mf.solve(small_wall, "fdem", options)


def test_weightless_masonry_block_is_named(small_wall):
    weight = small_wall.block_unit_weight.values.copy()
    weight[3] = 0.0
    model = small_wall.assign(block_unit_weight=("block", weight, small_wall.block_unit_weight.attrs))
    with pytest.raises(mf.ModelError, match=r"block\(s\) 3:"):
        build_scene(model)


def test_sleeping_blocks_keep_the_crack_pattern(small_wall):
    """Sleeping (off by default) freezes the blocks at rest on the fixed side; the mechanism must not change."""
    awake = mf.solve(small_wall, "fdem", {})
    sleeping = mf.solve(small_wall, "fdem", {"sleep": 0.05})
    assert sleeping.attrs["fdem_asleep_blocks"] >= 1
    scores = mf.compare(awake, sleeping)
    assert scores.crack_f1.item() >= 0.9
    assert sleeping.step_reaction.values[-1] == pytest.approx(awake.step_reaction.values[-1], rel=0.1)


def test_a_block_sliding_down_an_incline_does_not_stand_and_says_so(walls):
    """A block on a 40 deg incline steeper than its 30 deg friction angle keeps sliding: no rest state. The
    gravity phase stops once it has slid a tenth of its height, and the result says it did not stand, which
    block and how far (its damage is no settlement's)."""
    model = walls.gravity_rotated(mf.build(walls.single_block_spec(0.4, 0.2, 30.0)), 40.0)
    result = mf.solve(model, "fdem", {})
    assert int(result.attrs["stood"]) == 0 and result.attrs["stop_reason"] == "did not stand under its own weight"
    assert int(result.attrs["gravity_motion_block"]) == 0 and float(result.attrs["gravity_motion"]) > 0.02


def test_the_threads_do_not_change_a_single_bit(small_wall):
    """The face pairs' forces are computed in parallel but summed in face order: one thread and two give
    the same trajectory, bit for bit (option threads)."""
    options = {"settlement": 0.002, "plateau_tolerance": 0.0}
    one = mf.solve(small_wall, "fdem", options | {"threads": 1})
    two = mf.solve(small_wall, "fdem", options | {"threads": 2})
    assert one.attrs["fdem_threads"] == 1
    assert np.array_equal(one.block_displacement.values, two.block_displacement.values)
    assert np.array_equal(one.step_reaction.values, two.step_reaction.values)


@pytest.mark.parametrize("name", ["test-12c", "panel-5", "facade-1-trough"])
def test_the_estimate_counts_the_gravity_phase(name):
    """A short target is mostly gravity phase (the wall coming to rest): the estimate's step count is within a
    factor 2 of the steps the run took (it assumed 5 % of the settlement's steps, 20 to 50 times too few)."""
    import re

    model = mf.open_model(name)
    options = {"settlement": 1e-4, "plateau_tolerance": 0.0}
    expected = mf.estimate(model, "fdem", options)
    estimated = int(re.search(r"about ([\d,]+) time steps", expected.basis).group(1).replace(",", ""))
    steps = int(mf.solve(model, "fdem", options).attrs["fdem_steps"])
    assert 0.5 * steps <= estimated <= 2.0 * steps
