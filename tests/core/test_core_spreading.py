"""A support that moves sideways (an arch's springing moving out): the spec's ``direction`` key."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf

SPEC = """
title = "spreading"
[wall]
width = 1.0
height = 0.4
thickness = 0.1
[unit]
length = 0.2
height = 0.1
[bond]
pattern = "running"
[material]
unit_weight = 18000.0
friction_angle = 35.0
[supports.left]
kind = "fixed"
start = 0.0
end = 0.5
[supports.right]
kind = "moving"
start = 0.5
end = 1.0
{extra}
[loading]
type = "settlement"
"""


def build(extra: str):
    return mf.build(SPEC.format(extra=extra))


def test_a_support_moving_sideways_holds_only_what_does_not_move():
    model = build('direction = [2.0, 0.0]\nrate = 0.5')
    moving = np.flatnonzero(model.block_role.values == 3)[0]
    assert model.block_fixed.values[moving].tolist() == [0, 1, 1]
    np.testing.assert_allclose(model.settlement_direction.values[moving], [0.5, 0.0, 0.0])  # unit vector x rate
    share = float(model.dead_load.values[moving, 1])
    np.testing.assert_allclose(model.live_load.values[moving], [share, 0.0])  # along the motion
    assert mf.dead_reaction(model) == 0.0  # the dead loads do no work along a sideways motion


def test_the_default_direction_is_down():
    assert build("").settlement_direction.values[-1].tolist() == build('direction = [0, -1]').settlement_direction.values[-1].tolist()


@pytest.mark.parametrize("extra, words", [
    ('direction = [0, 0]', "supports.right.direction"),
    ('direction = [1]', "must be a non-zero pair"),
    ('motion = "rotation"\npivot = [0.5, 0.0]\ndirection = [1, 0]', "only applies to motion = 'translation'"),
])
def test_a_bad_direction_is_named(extra, words):
    with pytest.raises(mf.SpecError, match=words.replace("[", r"\[").replace(".", r"\.")):
        build(extra)
