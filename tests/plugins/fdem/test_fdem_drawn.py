"""fdem on drawn walls: non-convex blocks, an arch, and the load-factor search of a tilting table."""
from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.datasets.drawings import generate

LA_TESTS = Path(__file__).parents[1] / "la" / "test_la_drawn_walls.py"


def la_drawn_walls():
    """The la tests' stepped-wall builders (merged, rectangles, glued rectangles)."""
    spec = importlib.util.spec_from_file_location("la_drawn_walls", LA_TESTS)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def numbers(result) -> dict[str, float]:
    return {k.name: k.value for k in mf.key_numbers(result)}


def tilt_block(tmp_path, width: float, height: float, friction: float):
    """One ``width`` x ``height`` mm block on a base, weight sideways as the live load."""
    polygons = [[(0, 0), (width, 0), (width, height), (0, height)],
                [(-50, -50), (width + 50, -50), (width + 50, 0), (-50, 0)]]
    generate.write_dxf(tmp_path / "block.dxf", polygons, ["0", "0"])
    spec = {"title": "block", "geometry": {"dxf": str(tmp_path / "block.dxf")}, "wall": {"thickness": 0.1},
            "material": {"unit_weight": 20000.0, "friction": friction},
            "supports": {"base": {"kind": "fixed", "select": "lowest"}}, "loading": {"type": "tilt", "direction": 1}}
    return mf.build(spec)


@pytest.mark.parametrize("width, height, friction, expected", [
    (200, 100, math.tan(math.radians(30)), math.tan(math.radians(30))),  # slides: lambda = mu
    (100, 300, 0.9, 1 / 3),  # topples about its corner: lambda = b / h
])
def test_the_search_finds_a_block_s_sliding_or_toppling_multiplier(tmp_path, width, height, friction, expected):
    """The largest stable multiplier is within the search tolerance (1e-3) plus the contact's elastic give
    (the corner of a toppling block sinks into the base: 0.6 % measured) below the closed form."""
    result = mf.solve(tilt_block(tmp_path, width, height, friction), "fdem")
    alpha = float(result.collapse_multiplier)
    unstable = result.attrs["fdem_unstable_load_factor"]
    assert alpha < unstable <= alpha + 1e-3 + 1e-12
    assert alpha == pytest.approx(expected, rel=0.01)
    assert result.trial_stable.values[result.trial_load_factor.values <= alpha].all()
    assert result.attrs["stop_reason"] == "collapse bracketed"


def test_the_lact3_arch_tilts_within_a_percent_of_the_limit_analysis():
    """Measured: fdem 0.3047 (bracket to 0.3055) against la 0.3077, LACT3's tan(17.10 deg) = 0.3076; the arch
    fails by hinges, where the flow rule does not matter."""
    model = mf.open_model("lact3-arch")
    alpha = float(mf.solve(model, "fdem").collapse_multiplier)
    assert alpha == pytest.approx(float(mf.solve(model, "la").collapse_multiplier), rel=0.02)


def test_non_convex_blocks_settle_like_glued_rectangles_and_near_the_limit_analysis(tmp_path):
    """Stepped units (non-convex) against the same wall in rectangles with unbreakable joints: minimum
    reactions within 2 % (measured 0.8 %: the glued joints' springs give a little); and within 10 % of
    la's collapse reaction (measured 2.4 %)."""
    walls = la_drawn_walls()
    merged = numbers(mf.solve(walls._model(tmp_path, merged=True), "fdem"))
    glued = numbers(mf.solve(walls._model(tmp_path, merged=False, glue=True), "fdem"))
    la = numbers(mf.solve(walls._model(tmp_path, merged=True), "la"))
    assert merged["minimum_reaction"] == pytest.approx(glued["minimum_reaction"], rel=0.02)
    assert merged["minimum_reaction"] == pytest.approx(la["collapse_reaction"], rel=0.10)


def test_an_arch_on_a_settling_pier_sheds_what_the_limit_analysis_says():
    """The arch ring on piers (voussoirs drawn with arcs): fdem's minimum reaction within 10 % of la's
    collapse reaction (measured -1.6 %), its plateau within 2 % (measured +0.3 %)."""
    model = mf.open_model("arch-settlement")
    fdem, la = numbers(mf.solve(model, "fdem")), numbers(mf.solve(model, "la"))
    assert fdem["minimum_reaction"] == pytest.approx(la["collapse_reaction"], rel=0.10)
    assert fdem["plateau_reaction"] == pytest.approx(la["collapse_reaction"], rel=0.02)


def test_the_deformable_mode_triangulates_non_convex_blocks(tmp_path):
    """Stepped blocks are not fans from their centroid: triangulated, they settle within 3 % of the rigid
    mode's minimum reaction (measured 1.7 %, E = 1.14 GPa)."""
    spec = mf.load_spec(mf.bundled_spec_path("stepped-units"))
    spec["material"].update(young_modulus=1.14e9, poisson_ratio=0.2)
    model = mf.build(spec)
    deformable = numbers(mf.solve(model, "fdem", {"mode": "deformable"}))
    rigid = numbers(mf.solve(model, "fdem"))
    assert deformable["minimum_reaction"] == pytest.approx(rigid["minimum_reaction"], rel=0.03)


def test_an_interrupted_search_keeps_the_last_state_at_rest():
    """Ctrl-C in the fourth trial: the result is the state at rest under the largest stable multiplier so far."""
    model = mf.open_model("lact3-arch")
    seen = []

    def interrupt(fraction, message=""):
        seen.append(message)
        if sum("stable at load factor" in m for m in seen) == 3 and "stable at load factor" in message:
            raise KeyboardInterrupt  # once: Ctrl-C

    result = mf.solve(model, "fdem", progress=interrupt)
    assert int(result.attrs["interrupted"]) == 1
    stable = result.trial_load_factor.values[result.trial_stable.values == 1]
    assert float(result.collapse_multiplier) == stable.max()
    assert np.abs(mfp.block_motion(result)).max() < 0.05 * 0.0563  # at rest: no mechanism drawn
