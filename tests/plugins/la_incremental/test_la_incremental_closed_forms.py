"""la-incremental against closed forms: toppling on a tilting support, a stack, a pier's capacity curve.

The references are rigid-body statics with finite rotations, independent of any programme: a block
riding a plank that turns about its end topples when its centroid passes over its downhill toe
(plank rotation atan(b/h)); two equal blocks stacked topple together at atan(b/2h); a b x h pier
rocking by phi about its toe stands under a horizontal multiplier tan(atan(b/h) - phi) and falls at
phi = atan(b/h), its centroid having moved by 2 R sin(phi/2), R half its diagonal.
"""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.testing as mt

B, H, PLANK = 0.4, 1.0, 2.0


def on_a_plank(rects, length_unit=1.0):
    """Units on a plank [0, 2] m that turns about its top-left corner: its centroid settles at rate 1,
    so the plank's rotation is t / (PLANK / 2)."""
    rects = [(0.0, -0.2, PLANK, 0.0), *rects]
    roles = ["moving_support"] + ["unit"] * (len(rects) - 1)
    return mt.rectangles_model(rects, roles, friction=0.8, motions={0: ("rotation", (0.0, 0.0))},
                               length_unit=length_unit)


ONE = [(0.6, 0.0, 0.6 + B, H)]
TWO = [(0.6, 0.0, 0.6 + B, H), (0.6, H, 0.6 + B, 2 * H)]


@pytest.mark.parametrize("rects, slenderness", [(ONE, B / H), (TWO, B / (2 * H))], ids=["block", "stack"])
@pytest.mark.parametrize("step, tolerance", [(0.02, 1e-3), pytest.param(0.005, 2e-4, marks=pytest.mark.slow)])
def test_la_incremental_topples_when_the_centroid_passes_the_toe(rects, slenderness, step, tolerance):
    result = mf.solve(on_a_plank(rects), "la-incremental", {"settlement": 1.0, "step": step})
    expected = 0.5 * PLANK * np.arctan(slenderness)
    assert float(result.settlement_capacity) == pytest.approx(expected, rel=tolerance)
    assert float(result.settlement_capacity) <= expected * (1 + 1e-9)  # the last configuration that stands


def test_la_incremental_the_same_in_millimetres():
    metres = mf.solve(on_a_plank(TWO), "la-incremental", {"settlement": 1.0})
    millimetres = mf.solve(on_a_plank(TWO, length_unit=1e3), "la-incremental", {"settlement": 1e3})
    assert float(millimetres.settlement_capacity) == pytest.approx(1e3 * float(metres.settlement_capacity), rel=1e-6)
    assert millimetres.sizes["step"] == metres.sizes["step"]


@pytest.mark.parametrize("b, h", [(0.4, 1.0), (0.3, 0.6)])
def test_la_incremental_pier_on_a_tilting_base_follows_its_capacity_curve(b, h):
    pier = mt.rectangles_model([(-1.0, -0.2, 2.0, 0.0), (0.0, 0.0, b, h)], ["fixed_support", "unit"],
                               friction=0.8, loading="tilt")
    result = mf.solve(pier, "la-incremental", {"settlement": 1.0})
    phi = -result.step_block_rotation.values[:, 1]
    assert phi.max() > 0.9 * np.arctan(b / h)
    np.testing.assert_allclose(result.step_load_factor.values, np.tan(np.arctan(b / h) - phi), atol=1e-7)
    radius = 0.5 * np.hypot(b, h)
    assert float(result.displacement_capacity) == pytest.approx(2 * radius * np.sin(np.arctan(b / h) / 2), rel=1e-4)


def test_a_bonded_pier_cracks_then_rocks_as_a_dry_one():
    """A pier whose base joint has tensile strength ft (and cohesion above mu ft) first stands under
    b/h + ft s b^2 / (W h) (la's closed form); once the joint has opened its bond is gone, and the pier
    follows the dry capacity curve tan(atan(b/h) - phi)."""
    b, h, ft, thickness = 0.4, 1.0, 2000.0, 0.1
    pier = mt.rectangles_model([(-1.0, -0.2, 2.0, 0.0), (0.0, 0.0, b, h)], ["fixed_support", "unit"], friction=0.8,
                               loading="tilt", tensile_strength=ft, cohesion=5000.0)
    weight = 12e3 * b * h * thickness
    result = mf.solve(pier, "la-incremental", {"settlement": 1.0})
    factor = result.step_load_factor.values
    assert factor[0] == pytest.approx(b / h + ft * thickness * b**2 / (weight * h), rel=1e-7)
    phi = -result.step_block_rotation.values[1:, 1]
    np.testing.assert_allclose(factor[1:], np.tan(np.arctan(b / h) - phi), atol=1e-7)
