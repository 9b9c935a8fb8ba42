"""la on drawn walls: LACT3's published tilt angles, non-convex blocks against a second formulation."""
from __future__ import annotations

import math

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.datasets.drawings import generate

#: LACT3's solver test (LACT3_SolverTest.m): collapse angle of the tilting table [deg], c = 0.
PUBLISHED_TILT = {"lact3-wall": 16.73, "lact3-portal": 27.30, "lact3-arch": 17.10}


@pytest.mark.parametrize("name", sorted(PUBLISHED_TILT))
def test_lact3_samples_tilt_at_the_published_angle(walls, name):
    """alpha = tan(theta) to 1e-3 (the angles are published to 0.01 deg: 1.9e-4 in tan), and equal to an
    independent static LP of the same polygons to 1e-7."""
    model = mf.open_model(name)
    alpha = float(walls.solve(model).collapse_multiplier)
    assert alpha == pytest.approx(math.tan(math.radians(PUBLISHED_TILT[name])), abs=1e-3)
    assert alpha == pytest.approx(walls.static_alpha(model), abs=1e-7)


def _model(tmp_path, merged: bool, glue: bool = False):
    polygons, layers = generate.stepped_wall(merged)
    generate.write_geojson(tmp_path / "w.geojson", polygons, layers)
    spec = mf.load_spec(mf.bundled_spec_path("stepped-units"))
    spec["geometry"] = {**spec["geometry"], "polygons": str(tmp_path / "w.geojson")}
    model = mf.build(spec)
    if glue:  # the interfaces inside every stepped block of the merged drawing: never failing
        inside = _inner_joints(model, generate.stepped_wall(True)[0])
        for name in ("interface_cohesion", "interface_tensile_strength"):
            model[name].values[inside] = 1e7  # Pa: 5e4 N on a 0.005 m2 half joint, 60 times the wall weight
        model = mf.checked_model(model.drop_vars(mfp.DERIVED_GEOMETRY_VARIABLES))
    return model


def _inner_joints(model, merged_polygons) -> np.ndarray:
    """Interfaces whose midpoint lies inside one of the stepped (non-rectangular) blocks, 1e-9 m from its edges
    (mm to m by 0.001 and by / 1000 differ in the last bit)."""
    import shapely

    stepped = [shapely.Polygon(np.array(p) / 1000).buffer(-1e-9) for p in merged_polygons if len(p) > 4]
    mid = shapely.points(model.interface_x.values.mean(axis=1), model.interface_y.values.mean(axis=1))
    return np.flatnonzero(np.any([shapely.contains_properly(s, mid) for s in stepped], axis=0))


def test_merged_units_equal_glued_rectangles(walls, tmp_path):
    """Merging two units into one stepped block is the same as gluing their joint: the same alpha to 1e-9,
    from two formulations (non-convex polygons; rectangles with unbreakable joints); both equal the
    independent static LP, and merging changes alpha exactly by what gluing changes it."""
    rectangles = _model(tmp_path, merged=False)
    glued = _model(tmp_path, merged=False, glue=True)
    merged = _model(tmp_path, merged=True)
    assert merged.sizes["block"] == rectangles.sizes["block"] - 6
    assert _inner_joints(rectangles, generate.stepped_wall(True)[0]).size == 6
    alpha = {name: float(walls.solve(m, solver="highs").collapse_multiplier)  # the exact vertex of each LP
             for name, m in (("rectangles", rectangles), ("glued", glued), ("merged", merged))}
    assert alpha["merged"] == pytest.approx(alpha["glued"], abs=1e-9)
    assert alpha["merged"] == pytest.approx(walls.static_alpha(merged), abs=1e-7)
    assert alpha["rectangles"] == pytest.approx(walls.static_alpha(rectangles), abs=1e-7)
    assert alpha["merged"] > alpha["rectangles"] + 1e-3  # gluing joints that fail in the rectangles' mechanism


def test_an_arch_on_a_settling_pier_has_a_mechanism_through_its_voussoirs(walls):
    """The ring's voussoirs and the piers move; the fixed pier's base does not: la finds a mechanism with
    at least four macro-blocks (the three-hinge arch and its pier) and alpha equal to the static LP."""
    model = mf.open_model("arch-settlement")
    result = walls.solve(model)
    assert float(result.collapse_multiplier) == pytest.approx(walls.static_alpha(model), abs=1e-7)
    masonry = mfp.masonry_blocks(model.block_role.values)
    assert np.unique(result.macro_block.values[masonry]).size >= 3
