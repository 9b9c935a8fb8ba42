"""Tunnels and the engineers' stages 1 and 2: the trough from the tunnel's parameters (closed forms), the
LTSM strains against a Timoshenko deep beam solved numerically, and the assessment every result carries."""
from __future__ import annotations

import math

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.ground.assessment import E_OVER_G, deep_beam_strains, ltsm_category, ltsm_parts
from masonryfw.ground.profiles import Profile


def timoshenko_midspan_deflection(load: float, length: float, bending_stiffness: float, shear_stiffness: float,
                                  elements: int = 8) -> float:
    """Midspan deflection of a simply supported Timoshenko beam under a central point load, from a finite-
    element model of two-node elements with the exact (interdependent interpolation) stiffness: a second
    formulation of the beam, solved numerically."""
    h = length / elements
    phi = 12.0 * bending_stiffness / (shear_stiffness * h**2)
    k = bending_stiffness / (h**3 * (1.0 + phi)) * np.array([
        [12.0, 6.0 * h, -12.0, 6.0 * h],
        [6.0 * h, (4.0 + phi) * h**2, -6.0 * h, (2.0 - phi) * h**2],
        [-12.0, -6.0 * h, 12.0, -6.0 * h],
        [6.0 * h, (2.0 - phi) * h**2, -6.0 * h, (4.0 + phi) * h**2]])
    n = 2 * (elements + 1)
    stiffness = np.zeros((n, n))
    for e in range(elements):
        dofs = slice(2 * e, 2 * e + 4)
        stiffness[dofs, dofs] += k
    force = np.zeros(n)
    force[2 * (elements // 2)] = load
    free = np.setdiff1d(np.arange(n), [0, n - 2])  # the ends held vertically, free to turn
    w = np.zeros(n)
    w[free] = np.linalg.solve(stiffness[np.ix_(free, free)], force[free])
    return float(w[2 * (elements // 2)])


@pytest.mark.parametrize("sagging", [True, False])
@pytest.mark.parametrize(("length", "height"), [(10.0, 6.0), (4.0, 8.0), (25.0, 3.0)])
def test_ltsm_strains_are_those_of_the_timoshenko_deep_beam(sagging, length, height):
    """The beam of Burland & Wroth: neutral axis at mid-height (sagging) or at the bottom (hogging), E/G = 2.6,
    shear area 2/3 H (the 1.5 peak of the parabolic shear stress), bent by a central load to a deflection
    ratio: its extreme fibre bending strain M t / (E I) and its diagonal strain at the supports (half the
    peak shear strain) equal the LTSM's closed forms to 1e-9."""
    young = 1.0e9
    shear = young / E_OVER_G
    t, inertia = (height / 2, height**3 / 12) if sagging else (height, height**3 / 3)
    ratio = 1.0e-3
    unit = timoshenko_midspan_deflection(1.0, length, young * inertia, shear * 2.0 / 3.0 * height)
    load = ratio * length / unit
    bending = load * length / 4.0 * t / (young * inertia)
    diagonal = 0.5 * 1.5 * (load / 2.0) / height / shear
    eps_b, eps_d = deep_beam_strains(ratio, length, height, sagging)
    assert eps_b == pytest.approx(bending, rel=1e-9)
    assert eps_d == pytest.approx(diagonal, rel=1e-9)


def gaussian(center: float, width: float, depth: float | None = None) -> Profile:
    return Profile("gaussian", 0.25, 0.0, center=center, width=width, depth=depth)


def test_ltsm_parts_split_at_the_inflection_points_and_read_the_trough():
    """A wall from x = 0 to 20 m under a trough centred at 12 m with i = 5 m: parts [0, 7] hogging, [7, 17]
    sagging, [17, 20] hogging. Each part's deflection ratio is the largest gap between the Gaussian and its
    chord (found here by a second route, a dense evaluation); its horizontal strain the O'Reilly & New
    motion's difference over its length."""
    profile = gaussian(12.0, 5.0, depth=10.0)
    parts = ltsm_parts(profile, 0.0, 20.0, 6.0)
    assert [(p.start, p.end, p.sagging) for p in parts] == [(0.0, 7.0, False), (7.0, 17.0, True), (17.0, 20.0, False)]
    for part in parts:
        x = np.linspace(part.start, part.end, 1_000_001)
        s = np.exp(-0.5 * ((x - 12.0) / 5.0) ** 2)
        chord = s[0] + (s[-1] - s[0]) * (x - x[0]) / (x[-1] - x[0])
        assert part.deflection_ratio == pytest.approx(np.abs(s - chord).max() / (part.end - part.start), rel=1e-9)
        h = -(np.array([part.start, part.end]) - 12.0) / 10.0 * np.exp(-0.5 * ((np.array([part.start, part.end]) - 12.0) / 5.0) ** 2)
        assert part.horizontal_strain == pytest.approx((h[1] - h[0]) / (part.end - part.start), rel=1e-12)
    assert parts[1].horizontal_strain < 0 < parts[0].horizontal_strain  # compression in sagging, tension beyond


def test_ltsm_category_counts_the_limits_reached():
    np.testing.assert_array_equal(ltsm_category([0.0, 4.99e-4, 5e-4, 7.5e-4, 1.49e-3, 1.5e-3, 3e-3, 0.1]),
                                  [0, 0, 1, 2, 2, 3, 4, 4])


TUNNEL = {"profile": "tunnel", "volume_loss": 1.0, "diameter": 6.0, "depth": 15.0, "trough_width_factor": 0.5,
          "center": 10.0}
FACADE = {"title": "facade", "length_unit": "m", "wall": {"width": 8.0, "height": 3.0, "thickness": 0.25},
          "unit": {"length": 0.25, "height": 0.125}, "material": {"unit_weight": 18000.0, "friction_angle": 30.0},
          "loading": {"type": "settlement"}}


def test_tunnel_trough_is_the_closed_form():
    """i = K z0, S_max = V_L pi D^2 / 4 / (sqrt(2 pi) i), S_v and S_h: the model records S_max as its
    settlement_target and the greenfield profile it was built over; the ground follows S_v / S_max per unit t."""
    model = mf.build({**FACADE, "settlement": TUNNEL})
    i = 0.5 * 15.0
    s_max = 0.01 * math.pi * 6.0**2 / 4.0 / (math.sqrt(2.0 * math.pi) * i)
    assert float(model.settlement_target) == pytest.approx(s_max, rel=1e-12)
    profile = mf.model_profile(model)
    assert (profile.kind, profile.center, profile.width, profile.depth) == ("tunnel", 10.0, i, 15.0)
    x = np.linspace(-5.0, 25.0, 31)
    np.testing.assert_allclose(profile.rate(x), np.exp(-(x - 10.0) ** 2 / (2 * i**2)), rtol=1e-12)
    np.testing.assert_allclose(profile.horizontal(x), -(x - 10.0) / 15.0 * np.exp(-(x - 10.0) ** 2 / (2 * i**2)),
                               rtol=1e-12, atol=1e-15)
    no_sideways = mf.model_profile(mf.build({**FACADE, "settlement": {**TUNNEL, "horizontal": False}}))
    np.testing.assert_array_equal(no_sideways.horizontal(x), 0.0)


@pytest.mark.parametrize(("change", "message"), [
    ({"volume_loss": -0.5}, "'settlement.volume_loss' = -0.5: must be positive"),
    ({"diameter": 0.0}, "'settlement.diameter' = 0.0: must be positive"),
    ({"depth": 2.0}, "'settlement.depth' = 2.0: the tunnel's crown would be above the ground"),
    ({"trough_width_factor": 0.0}, "'settlement.trough_width_factor' = 0.0: must be positive"),
    ({"center": 200.0}, "nothing settles under the wall"),
    ({"width": 5.0}, "'settlement.width' only applies to profile = 'gaussian'"),
    ({"horizontal": "yes"}, "'settlement.horizontal' = 'yes': must be true or false"),
])
def test_bad_tunnels_are_named(change, message):
    with pytest.raises(mf.SpecError, match=message.replace("(", r"\(").replace(")", r"\)")):
        mf.build({**FACADE, "settlement": {**TUNNEL, **change}})


def drawn_copy(model, path) -> dict:
    """The masonry of a built model written as a GeoJSON drawing (in metres), and a spec for it."""
    import json

    role = model.block_role.values
    starts = np.r_[0, np.cumsum(model.block_node_count.values)]
    features = []
    for b in np.flatnonzero(mfp.masonry_blocks(role)):
        ring = np.c_[model.node_x.values[starts[b]:starts[b + 1]], model.node_y.values[starts[b]:starts[b + 1]]]
        features.append({"type": "Feature", "properties": {"layer": "0"},
                         "geometry": {"type": "Polygon", "coordinates": [ring.tolist() + [ring[0].tolist()]]}})
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return {"title": "drawn", "geometry": {"polygons": str(path), "drawing_unit": "m"}, "wall": {"thickness": 0.25},
            "material": FACADE["material"], "loading": {"type": "settlement"}}


def test_a_drawn_facade_goes_over_a_tunnel_like_a_parametric_one(tmp_path):
    """The facade's blocks drawn as polygons and given the same [settlement]: the ground is made under the
    lowest masonry and cut into the same segments, so the model is the same (blocks, interfaces, supports'
    motions, S_max) and la's alpha and R0 agree to 1e-12."""
    parametric = mf.build({**FACADE, "settlement": TUNNEL})
    drawn = mf.build({**drawn_copy(parametric, tmp_path / "f.geojson"), "settlement": TUNNEL})
    assert drawn.sizes == parametric.sizes
    np.testing.assert_allclose(drawn.settlement_direction.values, parametric.settlement_direction.values, atol=1e-12)
    assert float(drawn.settlement_target) == float(parametric.settlement_target)
    a, b = (mf.solve(m, "la") for m in (parametric, drawn))
    assert float(b.collapse_multiplier) == pytest.approx(float(a.collapse_multiplier), abs=1e-12)
    assert mf.dead_reaction(drawn) == pytest.approx(mf.dead_reaction(parametric), rel=1e-12)


def test_a_drawn_ground_block_is_cut_into_the_continuous_ground():
    """LACT3's wall over a trough, its drawn base block chosen as the ground: the base is cut into segments
    whose tops follow the ground (neighbours meet), every piece carries masonry, and la solves it."""
    spec = mf.load_spec(mf.bundled_spec_path("lact3-wall"))
    del spec["supports"]
    spec["loading"] = {"type": "settlement"}
    spec["settlement"] = {"profile": "gaussian", "center": 1.0, "width": 0.5, "ground_select": "lowest"}
    model = mf.build(spec)
    moving = np.flatnonzero(model.block_role.values == mfp.flags("block_role")["moving_support"])
    assert moving.size > 20
    x0 = model.node_x.values[np.r_[0, np.cumsum(model.block_node_count.values)][moving]]
    order = moving[np.argsort(x0)]
    d = model.settlement_direction.values[order]
    cx = model.block_centroid_x.values[order]
    xmin, xmax, _, _ = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    left = d[:, 1] + d[:, 2] * (xmin[order] - cx)
    right = d[:, 1] + d[:, 2] * (xmax[order] - cx)
    np.testing.assert_allclose(left[1:], right[:-1], atol=1e-12)  # the ground has no steps
    assert 0 < float(mf.solve(model, "la").collapse_multiplier) < 1


@pytest.mark.parametrize(("change", "message"), [
    ({"supports": {"base": {"kind": "fixed", "select": "lowest"}}}, "spec tables 'settlement' and 'supports': give one"),
    ({"settlement": {**TUNNEL, "ground_layer": "NOPE"}}, "'settlement.ground_layer' = 'NOPE': no block of the drawing"),
    ({"settlement": {**TUNNEL, "ground_select": "highest"}}, "'settlement.ground_select' = 'highest': must be one of"),
])
def test_bad_drawn_grounds_are_named(tmp_path, change, message):
    spec = {**drawn_copy(mf.build({**FACADE, "settlement": TUNNEL}), tmp_path / "f.geojson"), "settlement": TUNNEL}
    with pytest.raises(mf.SpecError, match=message.replace("(", r"\(").replace(")", r"\)")):
        mf.build({**spec, **change})


@pytest.fixture(scope="module")
def small_tunnel():
    """A 4 m x 1.2 m wall of 0.4 m units over a tunnel trough (i = 5 m, axis 6 m: the wall sags and hogs)."""
    spec = {"title": "small", "length_unit": "m", "wall": {"width": 4.0, "height": 1.2, "thickness": 0.1},
            "unit": {"length": 0.4, "height": 0.1}, "material": {"unit_weight": 12000.0, "friction_angle": 30.0},
            "settlement": {"profile": "tunnel", "volume_loss": 1.5, "diameter": 6.0, "depth": 10.0, "center": 6.0},
            "loading": {"type": "settlement"}}
    return mf.build(spec)


def test_every_result_over_a_tunnel_carries_stages_1_and_2(small_tunnel):
    """fdem runs to S_max by default and derives step_ltsm_* at every record, linear in the settlement; la's key
    numbers assess at S_max; both equal masonryfw.ground.assessment at that settlement (one definition)."""
    from masonryfw.ground.assessment import assess

    s_max = float(small_tunnel.settlement_target)
    fdem = mf.solve(small_tunnel, "fdem")
    assert fdem.step_settlement.values[-1] == pytest.approx(s_max, rel=1e-3)
    assert fdem.attrs["stop_reason"] == "target settlement"
    unit = assess(small_tunnel, 1.0)
    np.testing.assert_allclose(fdem.step_ltsm_strain.values, np.abs(fdem.step_settlement.values) * unit.strain,
                               rtol=1e-12)
    np.testing.assert_array_equal(fdem.step_ltsm_category.values, ltsm_category(fdem.step_ltsm_strain.values))
    la = mf.solve(small_tunnel, "la")
    numbers = {k.name: k.value for k in mf.key_numbers(la)}
    stages = assess(small_tunnel, s_max)
    assert numbers["assessed_settlement"] == s_max
    assert numbers["ltsm_strain"] == pytest.approx(stages.strain, rel=1e-12)
    assert numbers["greenfield_settlement"] == pytest.approx(s_max * np.exp(-0.5 * ((4.0 - 6.0) / 5.0) ** 2), rel=1e-6)
    assert numbers["screened_out"] == 0.0  # 34 mm of settlement


def test_jmm_runs_to_the_models_target_too(small_tunnel):
    """At 0.3 % volume loss (S_max 6.8 mm): no plateau stop, the last step at S_max."""
    spec = mf.load_spec(small_tunnel.attrs["source_spec"])
    spec["settlement"]["volume_loss"] = 0.3
    model = mf.build(spec)
    result = mf.solve(model, "jmm", {"mesh_size": 0.1})
    assert result.attrs["stop_reason"] == "target settlement reached"
    assert float(result.step_settlement.values[-1]) == pytest.approx(float(model.settlement_target), rel=1e-9)
    assert "step_ltsm_category" in result


def test_the_ltsm_chart_is_drawn_and_refused_without_a_profile(small_tunnel, tmp_path):
    result = mf.solve(small_tunnel, "la")
    figure = mf.render([result], "ltsm")
    parts = mfp.assess(result, float(result.settlement_target)).parts
    assert len(figure.axes) == 2 + len(parts)  # the frame, the trough and a chart per part
    with pytest.raises(mf.MasonryError, match="the ltsm plot needs a"):
        mf.render([mf.solve(mf.open_model("test-12c"), "la")], "ltsm")


def test_info_shows_the_tunnel_and_its_trough():
    from click.testing import CliRunner

    from masonryfw.cli import cli

    run = CliRunner().invoke(cli, ["info", "tunnel-facade"])
    assert run.exit_code == 0
    s_max = 0.01 * math.pi * 36.0 / 4.0 / (math.sqrt(2.0 * math.pi) * 7.5)
    assert (f"settlement profile: tunnel, V_L 1 %, D 6 m, axis 15 m deep at x 10 m, K 0.5: i 7.5 m, "
            f"S_max {1e3 * s_max:.4g} mm (settlement_target)") in run.output
