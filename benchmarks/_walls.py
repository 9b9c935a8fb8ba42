"""The walls the benchmarks time: running bond of 200 x 50 mm units with the right 40 % of the base settling, in
the paper's material (12 kN/m3, 21.8 deg) or in brick (18 kN/m3, 30 deg, E 3 GPa: every solver runs it)."""
from __future__ import annotations

import math

PAPER = {"unit_weight": 12000.0, "friction_angle": 21.8, "cohesion": 0.0, "tensile_strength": 0.0}
BRICK = {"unit_weight": 18000.0, "friction_angle": 30.0, "cohesion": 0.0, "tensile_strength": 0.0,
         "young_modulus": 3e9, "poisson_ratio": 0.2}


def running_bond_spec(courses: int, per_course: int, material: dict = PAPER) -> dict:
    """``courses`` courses of ``per_course`` units, the right 40 % of the base settling by translation."""
    width = round(per_course * 0.2, 9)
    split = round(0.6 * width, 9)
    return {
        "title": f"running bond {courses} x {per_course}",
        "length_unit": "m",
        "wall": {"width": width, "height": round(courses * 0.05, 9), "thickness": 0.1},
        "unit": {"length": 0.2, "height": 0.05},
        "bond": {"pattern": "running", "first_course": "full"},
        "material": dict(material),
        "supports": {
            "fixed": {"kind": "fixed", "start": 0.0, "end": split},
            "settling": {"kind": "moving", "start": split, "end": width, "motion": "translation"},
        },
        "loading": {"type": "settlement"},
    }


def scale_spec(units: int) -> dict:
    """About ``units`` units in brick, 8:3 (the scale benchmark's walls)."""
    courses = round(math.sqrt(1.5 * units))
    return running_bond_spec(courses, round(units / courses), BRICK)
