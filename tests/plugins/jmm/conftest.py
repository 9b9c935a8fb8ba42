"""The small wall shared by the jmm tests: 0.4 x 0.2 m, 100 x 50 mm units, half of the base settling."""
import pytest

import masonryfw as mf

SMALL_WALL = {
    "title": "jmm small wall",
    "length_unit": "m",
    "wall": {"width": 0.4, "height": 0.2, "thickness": 0.1},
    "unit": {"length": 0.1, "height": 0.05},
    "bond": {"pattern": "running", "first_course": "full"},
    "material": {"unit_weight": 12000.0, "friction_angle": 21.8, "cohesion": 0.0, "tensile_strength": 0.0,
                 "young_modulus": 1.2264e9, "poisson_ratio": 0.2},
    "supports": {
        "fixed": {"kind": "fixed", "start": 0.0, "end": 0.2},
        "settling": {"kind": "moving", "start": 0.2, "end": 0.4, "motion": "translation"},
    },
    "loading": {"type": "settlement"},
}


@pytest.fixture(scope="module")
def small_wall():
    return mf.build(SMALL_WALL)
