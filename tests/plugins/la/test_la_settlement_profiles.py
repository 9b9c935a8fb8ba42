"""la under settlement profiles: supports at their own rates, troughs, tilts.

References: the single-support model (a profile at rate 1 everywhere must be the
same problem), the mirror image of a symmetric problem, and the static LP of the
tests' conftest, in which the moving supports are coupled by one settlement parameter.
"""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf

WALL = {
    "title": "long wall", "length_unit": "m",
    "wall": {"width": 4.0, "height": 1.2, "thickness": 0.1},
    "unit": {"length": 0.4, "height": 0.1},
    "material": {"unit_weight": 12000.0, "friction_angle": 30.0},
    "loading": {"type": "settlement"},
}


def wall(**tables) -> dict:
    return {**WALL, **tables}


def trough(center: float, width: float = 0.6, segment: float = 0.2, **more) -> dict:
    return wall(settlement={"profile": "gaussian", "center": center, "width": width, "segment": segment,
                            "cutoff": 0.05, **more})


def test_la_tilt_of_the_ground_is_the_single_support_rotating_about_the_pivot(walls):
    """The continuous ground of a tilt starting at x = 2 m, cut into ten 0.2 m segments, is one rigid rotation
    of the base about (2, 0): the same problem as a single support from 2 m to 4 m rotating about that pivot
    (the paper's loads do the same work per unit rotation: W L_s / L on each segment, linear rates), so the
    same alpha to 1e-9, and in both the settlement reaction at collapse is (1 - alpha) R0."""
    single = mf.build(wall(supports={"fixed": {"kind": "fixed", "start": 0.0, "end": 2.0},
                                     "settling": {"kind": "moving", "start": 2.0, "end": 4.0,
                                                  "motion": "rotation", "pivot": [2.0, 0.0]}}))
    profiled = mf.build(wall(settlement={"profile": "linear", "start": 2.0, "segment": 0.2, "cutoff": 0.0}))
    moving = profiled.block_role.values == walls.ROLE["moving_support"]
    assert moving.sum() == 10
    np.testing.assert_allclose(profiled.settlement_direction.values[moving, 2], -0.5)  # one angle per unit t
    results = [walls.solve(m, solver="highs") for m in (single, profiled)]
    a, b = (float(r.collapse_multiplier) for r in results)
    assert 0 < a < 1
    assert b == pytest.approx(a, abs=1e-9)
    for model, result, alpha in zip((single, profiled), results, (a, b)):
        assert float(result.moving_support_reaction) == pytest.approx((1 - alpha) * mf.dead_reaction(model), rel=1e-6)


def mirrored_blocks(model) -> np.ndarray:
    """Index of every block's mirror image about the wall's vertical axis."""
    cx, cy = model.block_centroid_x.values, model.block_centroid_y.values
    axis = 0.5 * (model.node_x.values.min() + model.node_x.values.max())
    key = np.round(np.c_[cx, cy] * 1e6).astype(np.int64)
    lookup = {tuple(k): i for i, k in enumerate(key)}
    mirror = np.round(np.c_[2 * axis - cx, cy] * 1e6).astype(np.int64)
    return np.array([lookup[tuple(k)] for k in mirror])


def test_la_symmetric_trough_gives_a_mirror_symmetric_mechanism(walls):
    """Stack bond (a mirror-symmetric wall) over a trough centred under it: the mechanism is its own
    mirror image (ux and rz change sign, uy stays), and so is the crack pattern."""
    spec = trough(2.0, depth=8.0)
    spec["bond"] = {"pattern": "stack"}
    model = mf.build(spec)
    mirror = mirrored_blocks(model)
    result = walls.solve(model, solver="highs")
    u, rz = result.block_displacement.values, result.block_rotation.values
    scale = np.abs(u).max()
    np.testing.assert_allclose(u[mirror, 0], -u[:, 0], atol=1e-6 * scale)
    np.testing.assert_allclose(u[mirror, 1], u[:, 1], atol=1e-6 * scale)
    np.testing.assert_allclose(rz[mirror], -rz, atol=1e-6 * scale)
    moving = np.flatnonzero(model.block_role.values == walls.ROLE["moving_support"])
    np.testing.assert_allclose(model.settlement_direction.values[mirror[moving], 0],
                               -model.settlement_direction.values[moving, 0], atol=1e-12)


@pytest.mark.parametrize("spec", [
    pytest.param(wall(supports={"left": {"kind": "moving", "start": 0.0, "end": 1.0, "rate": 0.5},
                                "middle": {"kind": "fixed", "start": 1.0, "end": 3.0},
                                "right": {"kind": "moving", "start": 3.0, "end": 4.0, "rate": 2.0}}),
                 id="two-moving-supports-at-rates-0.5-and-2"),
    pytest.param(trough(2.0), id="sagging-trough-16-segments"),
    pytest.param(trough(4.0, depth=5.0), id="hogging-trough-with-horizontal-motion"),
    pytest.param(wall(settlement={"profile": "linear", "start": 1.0, "segment": 0.5}), id="tilt"),
])
def test_la_matches_the_static_lp_with_coupled_supports(walls, spec):
    model = mf.build(spec)
    assert (model.block_role.values == walls.ROLE["moving_support"]).sum() >= 2
    reference = walls.static_alpha(model)
    for backend in ("highs", "ipm"):
        assert float(walls.solve(model, solver=backend).collapse_multiplier) == pytest.approx(reference, abs=1e-7)


def test_la_rates_scale_the_mechanism_not_alpha(walls):
    """Every moving support at rate 2 instead of 1: the same programme with t halved, so the same alpha
    and a mechanism twice as large per unit t."""
    def model(rate):
        return mf.build(wall(supports={"fixed": {"kind": "fixed", "start": 0.0, "end": 2.5},
                                       "settling": {"kind": "moving", "start": 2.5, "end": 4.0, "rate": rate}}))
    one, two = walls.solve(model(1.0), solver="highs"), walls.solve(model(2.0), solver="highs")
    assert float(two.collapse_multiplier) == pytest.approx(float(one.collapse_multiplier), abs=1e-9)
    np.testing.assert_allclose(two.block_displacement.values, 2 * one.block_displacement.values, atol=1e-7)


def test_la_trough_under_a_bundled_facade():
    """A trough under Facade 1 (the study of docs/settlements.md) solves and sheds part of the reactions."""
    spec = mf.load_spec(mf.bundled_spec_path("facade-1"))
    del spec["supports"]
    spec["settlement"] = {"profile": "gaussian", "center": 1.2, "width": 0.25, "segment": 0.1, "cutoff": 0.05}
    result = mf.solve(mf.build(spec), "la")
    assert 0 < float(result.collapse_multiplier) < 1


@pytest.mark.parametrize("spec", [pytest.param(trough(2.0), id="sagging"),
                                  pytest.param(trough(4.0, depth=5.0), id="hogging-with-horizontal-motion")])
def test_la_collapse_reaction_of_a_trough_is_one_minus_alpha_of_the_dead_reactions(walls, spec):
    """The settlement reaction of the dual contact forces on the settling segments (their forces and moments
    on the segments, each weighted by its motion: the work on the one settlement parameter, which the LP
    fixes, horizontal ground motion and rotations included) is (1 - alpha) R0, R0 the dead loads' alike."""
    model = mf.build(spec)
    result = walls.solve(model, solver="highs")
    alpha = float(result.collapse_multiplier)
    assert 0 < alpha < 1
    assert float(result.moving_support_reaction) == pytest.approx((1 - alpha) * mf.dead_reaction(model), rel=1e-6)


def test_jmm_limit_refuses_supports_at_different_rates():
    """Its LP minimises one vertical reaction: a profile (segments that turn and settle at their own rates) needs
    the incremental jmm (a clear refusal)."""
    model = mf.build(trough(2.0))
    with pytest.raises(mf.ModelError, match="needs a downward vertical translation.*use the solver jmm"):
        mf.solve(model, "jmm-limit")
