"""A support that moves sideways (an arch's springing moving out): the spec's ``direction`` key."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

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


@pytest.mark.parametrize("kind", ["geojson", "csv", "dxf"])
def test_a_spreading_support_means_the_same_in_a_drawn_spec(tmp_path, kind):
    """An arch whose right springing moves out, given as blocks (mf.testing.arch_model, a parametric model) and
    drawn block by block (GeoJSON, CSV, DXF) with ``direction = [1, 0]`` on its springing's layer: the same support
    motion and the same alpha (the drawn specs refused the key)."""
    import json

    import ezdxf

    from masonryfw.testing import arch_model

    arch = arch_model(0.15, voussoirs=16)
    counts = arch.block_node_count.values
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    rings = [np.c_[arch.node_x.values[a:a + n], arch.node_y.values[a:a + n]].tolist() for a, n in zip(starts, counts)]
    role = arch.block_role.values
    layers = ["LEFT" if r == mfp.ROLE["fixed_support"] else "RIGHT" if r == mfp.ROLE["moving_support"] else "ARCH"
              for r in role]
    if kind == "geojson":
        features = [{"type": "Feature", "properties": {"layer": layer},
                     "geometry": {"type": "Polygon", "coordinates": [ring + ring[:1]]}}
                    for ring, layer in zip(rings, layers)]
        (tmp_path / "arch.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": features}))
        geometry = 'polygons = "arch.geojson"\ndrawing_unit = "m"'
    elif kind == "csv":
        rows = ["block,x,y,layer"] + [f"{k},{x!r},{y!r},{layer}" for k, (ring, layer) in enumerate(zip(rings, layers))
                                      for x, y in ring]
        (tmp_path / "arch.csv").write_text("\n".join(rows) + "\n")
        geometry = 'polygons = "arch.csv"\ndrawing_unit = "m"'
    else:
        doc = ezdxf.new()
        for ring, layer in zip(rings, layers):
            doc.modelspace().add_lwpolyline(ring, close=True, dxfattribs={"layer": layer})
        doc.saveas(tmp_path / "arch.dxf")
        geometry = 'dxf = "arch.dxf"\ndrawing_unit = "m"'
    (tmp_path / "arch.toml").write_text(
        f'title = "drawn arch"\n[geometry]\n{geometry}\n[wall]\nthickness = 0.1\n[material]\nunit_weight = 20000.0\n'
        'friction = 0.8\n[supports.left]\nkind = "fixed"\nlayer = "LEFT"\n[supports.right]\nkind = "moving"\n'
        'layer = "RIGHT"\ndirection = [1, 0]\n[loading]\ntype = "settlement"\n')
    drawn = mf.build(tmp_path / "arch.toml")
    moving = drawn.block_role.values == mfp.ROLE["moving_support"]
    np.testing.assert_allclose(drawn.settlement_direction.values[moving], [[1.0, 0.0, 0.0]])
    assert drawn.block_fixed.values[moving].tolist() == arch.block_fixed.values[role == mfp.ROLE["moving_support"]].tolist()
    a, b = mf.solve(arch, "la"), mf.solve(drawn, "la")
    assert float(b.collapse_multiplier) == pytest.approx(float(a.collapse_multiplier), rel=1e-7)
