"""Small walls for the fdem tests, built through the public API."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf


def single_block_spec(width: float, height: float, friction_angle: float) -> dict:
    """One unit on a fixed support of the same width, live load = its weight horizontally (+x)."""
    return {
        "title": "single block",
        "wall": {"width": width, "height": height, "thickness": 0.1},
        "unit": {"length": width, "height": height},
        "bond": {"pattern": "running", "first_course": "full"},
        "material": {"unit_weight": 20000.0, "friction_angle": friction_angle, "cohesion": 0.0,
                     "tensile_strength": 0.0},
        "supports": {"ground": {"kind": "fixed", "start": 0.0, "end": width}},
        "loading": {"type": "tilt", "direction": 1},
    }


def small_wall_spec(length_unit: str = "m") -> dict:
    """A 0.6 x 0.3 m dry wall (6 courses of 0.2 x 0.05 m units), the right 0.3 m settling."""
    scale = 1000.0 if length_unit == "mm" else 1.0
    return {
        "title": "small wall",
        "length_unit": length_unit,
        "wall": {"width": 0.6 * scale, "height": 0.3 * scale, "thickness": 0.1 * scale},
        "unit": {"length": 0.2 * scale, "height": 0.05 * scale},
        "bond": {"pattern": "running", "first_course": "full"},
        "material": {"unit_weight": 12000.0, "friction_angle": 21.8, "cohesion": 0.0, "tensile_strength": 0.0},
        "supports": {
            "fixed": {"kind": "fixed", "start": 0.0, "end": 0.3 * scale},
            "settling": {"kind": "moving", "start": 0.3 * scale, "end": 0.6 * scale, "motion": "translation"},
        },
        "loading": {"type": "settlement"},
    }


def gravity_rotated(model, angle_deg: float):
    """The same model with every masonry block's weight tilted by ``angle_deg`` (a plane inclined by it)."""
    theta = np.radians(angle_deg)
    dead = model.dead_load.values.copy()
    weight = -dead[:, 1]
    masonry = model.block_role.values < 2
    dead[masonry, 0] = weight[masonry] * np.sin(theta)
    dead[masonry, 1] = -weight[masonry] * np.cos(theta)
    return model.assign(dead_load=(("block", "axis"), dead, model.dead_load.attrs))


@pytest.fixture(scope="session")
def small_wall():
    return mf.build(small_wall_spec())


class Walls:
    """The helpers above, for test modules (which cannot import conftest under importlib mode)."""

    single_block_spec = staticmethod(single_block_spec)
    small_wall_spec = staticmethod(small_wall_spec)
    gravity_rotated = staticmethod(gravity_rotated)


@pytest.fixture(scope="session")
def walls():
    return Walls
