"""Settlement profiles and damage: the spec keys, the supports they make, the damage scale."""
from __future__ import annotations

import math

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

ROLE = mfp.flags("block_role")
BASE = {
    "title": "long wall", "length_unit": "m",
    "wall": {"width": 4.0, "height": 1.2, "thickness": 0.1},
    "unit": {"length": 0.4, "height": 0.1},
    "material": {"unit_weight": 12000.0, "friction_angle": 30.0},
    "loading": {"type": "settlement"},
}
TROUGH = {"profile": "gaussian", "center": 1.0, "width": 0.3, "segment": 0.1, "cutoff": 0.05, "depth": 10.0}


def moving_supports(model):
    moving = np.flatnonzero(model.block_role.values == ROLE["moving_support"])
    x0 = np.array([model.node_x.values[4 * b] for b in moving])
    return moving, x0


def top_corners(model, blocks):
    """Per support block: the x of its top corners (left, right) and their motion (ux, uy) per unit t, from
    ``settlement_direction`` as a small rigid motion about the centroid."""
    nodes = np.c_[model.node_x.values, model.node_y.values].reshape(-1, 4, 2)[blocks]  # rectangles
    x = np.c_[nodes[:, :, 0].min(axis=1), nodes[:, :, 0].max(axis=1)]
    top = nodes[:, :, 1].max(axis=1)
    d = model.settlement_direction.values[blocks]
    cx, cy = model.block_centroid_x.values[blocks], model.block_centroid_y.values[blocks]
    ux = d[:, 0, None] - d[:, 2, None] * (top - cy)[:, None]
    uy = d[:, 1, None] + d[:, 2, None] * (x - cx[:, None])
    return x, ux * np.ones_like(x), uy


def test_gaussian_trough_segments_follow_peck_and_oreilly_new():
    """The ground is continuous: the top corners of every segment move down by (S - c) / (1 - c) at the
    segment ends, S(x) = exp(-(x - x0)^2 / (2 i^2)) less the cutoff c (0 where S <= c), so neighbouring
    segments meet; their top edge moves sideways by the mean of h = -(x - x0) / z0 times that at its ends;
    segments whose ends both stay still are fixed and merge into one block on each side."""
    model = mf.build({**BASE, "settlement": TROUGH})
    role = model.block_role.values
    supports = np.flatnonzero(np.isin(role, [ROLE["fixed_support"], ROLE["moving_support"]]))
    supports = supports[np.argsort(model.block_centroid_x.values[supports])]
    x, ux, uy = top_corners(model, supports)
    rate = np.maximum(np.exp(-0.5 * ((x - 1.0) / 0.3) ** 2) - 0.05, 0.0) / 0.95
    np.testing.assert_allclose(uy, -rate, atol=1e-12)
    np.testing.assert_allclose(uy[1:, 0], uy[:-1, 1], atol=1e-12)  # continuous at every common end
    h = -(x - 1.0) / 10.0 * rate
    np.testing.assert_allclose(ux, h.mean(axis=1, keepdims=True) * np.ones_like(h), atol=1e-12)
    moving = role[supports] == ROLE["moving_support"]
    assert moving.sum() == 16  # ends 0.3 .. 1.7: S > 0.05 for |x - 1| < 0.3 sqrt(2 ln 20) = 0.735
    assert (~moving).sum() == 2  # [0, 0.2] and [1.8, 4] each merged
    np.testing.assert_array_equal(model.block_fixed.values[supports[moving]], [[0, 0, 0]] * 16)
    # the paper's loading per support: the uniform share of the weight, up (dead) and down (live)
    weight = -mfp.block_loads(model, "dead")[mfp.masonry_blocks(role), 1].sum()
    np.testing.assert_allclose(mfp.block_loads(model, "dead")[supports[moving], 1], weight * 0.1 / 4.0)
    np.testing.assert_allclose(mfp.block_loads(model, "live")[supports[moving], 1], -weight * 0.1 / 4.0)


def test_profile_lengths_in_millimetres_give_the_metre_model():
    in_mm = {**BASE, "length_unit": "mm", "wall": {"width": 4000.0, "height": 1200.0, "thickness": 100.0},
             "unit": {"length": 400.0, "height": 100.0},
             "settlement": {**TROUGH, "center": 1000.0, "width": 300.0, "segment": 100.0, "depth": 10000.0}}
    a, b = mf.build({**BASE, "settlement": TROUGH}), mf.build(in_mm)
    np.testing.assert_allclose(b.settlement_direction.values, a.settlement_direction.values, atol=1e-12)
    np.testing.assert_allclose(b.node_x.values, a.node_x.values, atol=1e-12)


def test_linear_and_table_profiles():
    """A tilt's segments all turn by the same angle and meet: together one rigid rotation of the base about
    the profile's start; a table is interpolated at the segment ends."""
    tilt = mf.build({**BASE, "settlement": {"profile": "linear", "segment": 1.0, "cutoff": 0.0}})
    moving = np.flatnonzero(tilt.block_role.values == ROLE["moving_support"])
    np.testing.assert_allclose(tilt.settlement_direction.values[moving, 2], -0.25)
    _, _, uy = top_corners(tilt, moving)
    np.testing.assert_allclose(-uy, [[0.0, 0.25], [0.25, 0.5], [0.5, 0.75], [0.75, 1.0]], atol=1e-12)
    table = mf.build({**BASE, "settlement": {"profile": "table", "segment": 1.0, "points": [[1.0, 0.0], [3.0, 1.0]]}})
    moving = np.flatnonzero(table.block_role.values == ROLE["moving_support"])
    _, _, uy = top_corners(table, moving)
    half = (0.5 - 0.01) / 0.99  # the default cutoff 0.01 taken off, a rate of 1 kept
    np.testing.assert_allclose(-uy, [[0.0, half], [half, 1.0], [1.0, 1.0]], atol=1e-12)


def test_rate_of_a_support_range_scales_its_direction():
    spec = {**BASE, "supports": {"fixed": {"kind": "fixed", "start": 0.0, "end": 2.0},
                                 "slow": {"kind": "moving", "start": 2.0, "end": 4.0, "rate": 0.5}}}
    model = mf.build(spec)
    moving = model.block_role.values == ROLE["moving_support"]
    np.testing.assert_array_equal(model.settlement_direction.values[moving], [[0.0, -0.5, 0.0]])


def test_a_door_at_the_base_leaves_no_support_segment_under_it():
    spec = {**BASE, "openings": [{"x": 1.6, "y": 0.0, "width": 0.8, "height": 0.6, "lintel_bearing": 0.4}],
            "settlement": {**TROUGH, "center": 2.0, "width": 1.0, "segment": 0.4}}
    model = mf.build(spec)
    supports = np.isin(model.block_role.values, [ROLE["fixed_support"], ROLE["moving_support"]])
    x0 = model.node_x.values.reshape(-1, 4)[supports, 0]  # rectangles: 4 nodes each
    assert not np.any((x0 >= 1.6 - 1e-9) & (x0 < 2.4 - 1e-9))


@pytest.mark.parametrize(("change", "message"), [
    ({"settlement": TROUGH, "supports": {"a": {"kind": "fixed", "start": 0.0, "end": 4.0}}}, "give one of them"),
    ({"settlement": {**TROUGH, "profile": "cosine"}}, "'settlement.profile' = 'cosine': must be one of"),
    ({"settlement": {**TROUGH, "width": 0.0}}, "'settlement.width' = 0.0: must be positive"),
    ({"settlement": {**TROUGH, "points": [[0, 1], [1, 1]]}}, "'settlement.points' only applies to profile = 'table'"),
    ({"settlement": {"profile": "table", "segment": 0.5, "points": [[1.0, 0.1], [0.5, 0.2]]}},
     "point 1 ([0.5, 0.2]) must lie right of the one before"),
    ({"settlement": {"profile": "table", "segment": 0.5, "points": [[1.0, -0.1], [2.0, 0.2]]}}, "negative rate"),
    ({"settlement": {**TROUGH, "center": 40.0}}, "nothing settles under the wall"),
    ({"settlement": {**TROUGH, "segmnt": 0.1}}, "did you mean 'settlement.segment'"),
])
def test_bad_profiles_are_named(change, message):
    with pytest.raises(mf.SpecError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")
                       .replace("]", r"\]")):
        mf.build({**BASE, **change})


def test_rate_keys_are_checked():
    spec = {**BASE, "supports": {"fixed": {"kind": "fixed", "start": 0.0, "end": 2.0, "rate": 2.0},
                                 "m": {"kind": "moving", "start": 2.0, "end": 4.0}}}
    with pytest.raises(mf.SpecError, match="'supports.fixed.rate' only applies to kind = 'moving'"):
        mf.build(spec)
    spec["supports"] = {"m": {"kind": "moving", "start": 0.0, "end": 4.0, "rate": -1.0}}
    with pytest.raises(mf.SpecError, match="'supports.m.rate' = -1.0: must be positive"):
        mf.build(spec)


@pytest.mark.parametrize(("width_mm", "category"), [
    (0.0, 0), (0.05, 0), (0.1, 0), (0.11, 1), (1.0, 1), (1.2, 2), (5.0, 2), (7.0, 3), (15.0, 3), (20.0, 4),
    (25.0, 4), (30.0, 5),
])
def test_damage_categories_follow_burlands_table(width_mm, category):
    assert int(mf.damage_category(width_mm * 1e-3)) == category


def test_profile_distortion_closed_forms():
    """Three points: the middle one 1 below the chord of the ends 2 apart: deflection ratio 1/2 (sagging,
    positive), angular distortion 1; raised instead: -1/2. A tilt (a straight profile) distorts nothing."""
    x = np.array([0.0, 1.0, 2.0])
    assert mfp.distortion(x, np.array([0.0, -1.0, 0.0])) == pytest.approx((0.5, 1.0))
    assert mfp.distortion(x, np.array([-1.0, 0.0, -1.0])) == pytest.approx((-0.5, 1.0))
    assert mfp.distortion(x, np.array([0.0, -0.5, -1.0])) == pytest.approx((0.0, 0.0))
    # a trough: Peck's profile sampled finely, its steepest slope at the inflection point (x0 +- i)
    i = 0.3
    xs = np.linspace(-2, 2, 4001)
    ratio, beta = mfp.distortion(xs, -np.exp(-0.5 * (xs / i) ** 2))
    assert ratio == pytest.approx(1.0 / 4.0, rel=1e-3)  # the axis 1 below the chord, over the 4 m span
    assert beta == pytest.approx(math.exp(-0.5) / i, rel=1e-4)


def test_support_profile_of_a_trough_model():
    model = mf.build({**BASE, "settlement": TROUGH})
    x, v = mfp.support_profile(model)
    assert np.all(np.diff(x) > 0)
    moving = v < 0  # 0.1 m segments: the ground at a midpoint is the mean of its ends' (less the cutoff)
    ends = np.exp(-0.5 * ((x[moving, None] + [-0.05, 0.05] - 1.0) / 0.3) ** 2)
    np.testing.assert_allclose(v[moving], -(np.maximum(ends - 0.05, 0.0) / 0.95).mean(axis=1), rtol=1e-12)


def test_cli_builds_solves_and_draws_a_trough_wall(tmp_path):
    """The bundled trough wall through the CLI: build, la, the damage history of a small fdem run;
    a bad profile exits 1 naming the key, with no traceback."""
    from click.testing import CliRunner

    from masonryfw.cli import cli

    def invoke(*args):
        return CliRunner().invoke(cli, [str(a) for a in args])

    model = tmp_path / "trough.nc"
    built = invoke("build", "facade-1-trough", "-o", model)
    assert built.exit_code == 0, built.output
    solved = invoke("solve", model, "--plugin", "la", "-o", tmp_path / "la.nc")
    assert solved.exit_code == 0, solved.output
    assert "alpha" in solved.output
    block = tmp_path / "block.toml"
    block.write_text(mf.dump_toml({**BASE, "wall": {"width": 1.2, "height": 0.2, "thickness": 0.1},
                                   "settlement": {**TROUGH, "center": 0.6, "width": 0.2, "segment": 0.2}}))
    invoke("build", block, "-o", tmp_path / "block.nc")
    run = invoke("solve", tmp_path / "block.nc", "--plugin", "fdem", "--option", "settlement=0.002",
                 "-o", tmp_path / "fdem.nc")
    assert run.exit_code == 0, run.output
    assert "damage_category" in run.output and "crack_width" in run.output
    drawn = invoke("plot", tmp_path / "fdem.nc", "--kind", "history", "--option", "quantity=damage",
                   "-o", tmp_path / "damage.png")
    assert drawn.exit_code == 0, drawn.output
    assert (tmp_path / "damage.png").stat().st_size > 10_000
    bad = tmp_path / "bad.toml"
    bad.write_text(mf.dump_toml({**BASE, "settlement": {**TROUGH, "segment": -0.1}}))
    failed = invoke("build", bad, "-o", tmp_path / "bad.nc")
    assert failed.exit_code == 1
    assert "'settlement.segment' = -0.1: must be positive" in failed.output
    assert "Traceback" not in failed.output


def test_a_step_profile_is_the_papers_settling_support():
    """``profile = "step"`` over [1.6, 4.0] m is the same loading as a moving support range there: the segments
    under it translate down at rate 1, the rest hold, and la's alpha and collapse reaction agree with the
    support-range wall's to the solver's tolerance."""
    step = mf.build({**BASE, "settlement": {"profile": "step", "start": 1.6, "end": 4.0, "segment": 0.4}})
    ranges = mf.build({**BASE, "supports": {"left": {"kind": "fixed", "start": 0.0, "end": 1.6},
                                            "right": {"kind": "moving", "start": 1.6, "end": 4.0}}})
    moving, x0 = moving_supports(step)
    assert np.allclose(np.sort(x0), np.arange(1.6, 4.0 - 1e-9, 0.4))
    assert np.allclose(step.settlement_direction.values[moving], [0.0, -1.0, 0.0])
    a, b = mf.solve(step, "la", {}), mf.solve(ranges, "la", {})
    assert float(a.collapse_multiplier) == pytest.approx(float(b.collapse_multiplier), abs=1e-6)
    numbers = [{n.name: n.value for n in mf.key_numbers(r)} for r in (a, b)]
    assert numbers[0]["collapse_reaction"] == pytest.approx(numbers[1]["collapse_reaction"], rel=1e-5)


def test_a_step_must_end_after_it_starts():
    with pytest.raises(mf.SpecError, match="'settlement.end' = 1.0: must exceed 'settlement.start' = 2.0"):
        mf.build({**BASE, "settlement": {"profile": "step", "start": 2.0, "end": 1.0}})
