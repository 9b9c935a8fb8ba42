"""3D models and results drawn in axonometry: what the model and mechanism kinds put on the figure."""
from __future__ import annotations

import numpy as np
import pytest
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt


@pytest.fixture(scope="module")
def corner():
    """The kit's corner building and its la result."""
    model = mt.corner_building()
    return model, mf.solve(model, "la")


def only_axes(figure):
    """The figure's one axes, a 3D one, after the figure is drawn (3D collections project on drawing)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(figure).draw()
    assert len(figure.axes) == 1 and figure.axes[0].name == "3d"
    return figure.axes[0]


def test_the_model_is_every_face_of_every_block(corner):
    model, _ = corner
    ax = only_axes(mf.render([model], "model"))
    drawn = [c for c in ax.collections if isinstance(c, Poly3DCollection)]
    assert len(drawn) == 1 and len(drawn[0].get_paths()) == int(model.block_face_count.values.sum())
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["unit", "lintel", "moving support"]
    assert "corner - model" in ax.get_title()


def test_the_mechanism_outlines_every_cracked_interface(corner):
    _, result = corner
    ax = only_axes(mf.render([result], "mechanism"))
    lines = [c for c in ax.collections if isinstance(c, Line3DCollection)]
    cracked = int(mf.cracked_joints(result).sum())
    assert cracked > 0 and len(lines) == 1 and len(lines[0].get_segments()) == cracked
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"cracked interfaces ({cracked}), seen through the masonry" in legend
    assert "alpha = " in ax.get_title()


def test_the_drawing_moves_blocks_relative_to_the_largest_macro_block(corner):
    """The drawn motion is relative to the largest macro-block's first block (which stands still); the relative
    motion between any two blocks is the mechanism's."""
    from masonryfw_compare.axonometric import moved_points, relative_to_largest
    from masonryfw_compare.block_plots import dominant_pieces

    _, result = corner
    geo = mfp.derive_geometry(result)
    pieces = dominant_pieces(result, geo)
    u = relative_to_largest(geo, mfp.block_motion(result), pieces)
    first = np.flatnonzero(pieces.number == 1)[0]
    vertex_block = np.repeat(np.arange(geo.sizes["block"]), geo.block_node_count.values)
    drawn = moved_points(geo, u, 1.0) - moved_points(geo, u, 0.0)
    assert np.abs(drawn[vertex_block == first]).max() < 1e-12
    whole = mfp.block_motion(result)
    actual = moved_points(geo, whole, 1.0) - moved_points(geo, whole, 0.0)
    points = np.c_[geo.node_x.values, geo.node_y.values, geo.node_z.values]
    centre = np.array([geo[f"block_centroid_{c}"].values[first] for c in "xyz"])
    rigid = whole[first, :3] + np.cross(whole[first, 3:], points - centre)  # the reference block's motion, everywhere
    np.testing.assert_allclose(actual - drawn, rigid, atol=1e-9 * np.abs(actual).max())


def test_the_cracks_of_a_3d_mechanism_are_its_cracked_joints_in_the_masonry_by_state(corner):
    """Limit analysis gives a shape, not a size: the cracks plot fills the joints cracked at the threshold (a joint
    with the ground is none), by state, and says there are no widths."""
    _, result = corner
    ax = only_axes(mf.render([result], "cracks"))
    derived = mf.at_threshold(result)
    masonry = mfp.masonry_blocks(result.block_role.values)[result.interface_blocks.values].all(axis=1)
    cracked = (derived.interface_state.values > 0) & masonry
    filled = [c for c in ax.collections if isinstance(c, Poly3DCollection)][1:]  # the blocks first
    assert sum(len(c.get_paths()) for c in filled) == int(cracked.sum()) > 0
    assert "no widths" in ax.get_legend().get_title().get_text()


@pytest.mark.parametrize("kind", ["forces"])
def test_the_kinds_that_draw_2d_only_say_so(corner, kind):
    with pytest.raises(mf.ModelError, match=f"the {kind} plot handles 2D models and results"):
        mf.render([corner[1]], kind)


def test_a_3d_result_exports_its_faces_and_interfaces_to_vtk(corner, tmp_path):
    """Every face a quad carrying its block; the vertices' displacement the blocks' rigid motion; every interface a
    polygon with its crack indicator and the forces at its vertices."""
    import meshio

    from masonryfw_compare.export import export_vtk

    model, result = corner
    written = export_vtk(result, tmp_path / "corner.vtu")
    assert [p.name for p in written] == ["corner.vtu", "corner_joints.vtu", "corner.vtm"]
    blocks, joints = meshio.read(written[0]), meshio.read(written[1])
    assert [(c.type, len(c.data)) for c in blocks.cells] == [("quad", int(model.block_face_count.values.sum()))]
    u = np.c_[result.block_displacement.values, result.block_rotation.values]
    owner = np.repeat(np.arange(model.sizes["block"]), model.block_node_count.values)
    centre = np.c_[result.block_centroid_x.values, result.block_centroid_y.values, result.block_centroid_z.values]
    expected = u[owner, :3] + np.cross(u[owner, 3:], blocks.points - centre[owner])
    np.testing.assert_allclose(blocks.point_data["displacement"], expected, atol=1e-12)
    assert len(joints.cells[0].data) == model.sizes["interface"]
    np.testing.assert_array_equal(joints.cell_data["crack_indicator"][0], result.crack_indicator.values)
    np.testing.assert_allclose(joints.point_data["interface_point_force"][:, 2], result.interface_point_force_z.values)


def test_the_3d_mechanism_cosine_is_the_l2_product_of_the_rigid_fields(corner):
    """Against Gauss quadrature over every box (2 x 2 x 2 points: exact for the quadratic integrand) of two
    random rigid-block fields."""
    from masonryfw_compare.comparison3d import inertia, rigid_field_cosine_3d

    model, _ = corner
    rng = np.random.default_rng(3)
    u_a, u_b = rng.normal(size=(2, model.sizes["block"], 6))
    points = np.c_[model.node_x.values, model.node_y.values, model.node_z.values].reshape(-1, 8, 3)
    low, high = points.min(axis=1), points.max(axis=1)  # the walls run along x and y: every block is a box
    gauss = 0.5 + np.array([-0.5, 0.5]) / np.sqrt(3.0)
    grid = np.stack(np.meshgrid(gauss, gauss, gauss, indexing="ij"), axis=-1).reshape(-1, 3)
    volume = np.prod(high - low, axis=1)
    sample = low[:, None] + grid[None] * (high - low)[:, None]  # (block, 8, 3)
    centre = np.c_[model.block_centroid_x.values, model.block_centroid_y.values, model.block_centroid_z.values]

    def field(u):
        return u[:, None, :3] + np.cross(u[:, None, 3:], sample - centre[:, None])

    def inner(p, q):
        return float(np.sum(volume[:, None] / 8.0 * np.einsum("bsi,bsi->bs", field(p), field(q))))

    expected = inner(u_a, u_b) / np.sqrt(inner(u_a, u_a) * inner(u_b, u_b))
    tensor = inertia(mfp.polyhedra_of(model))
    assert rigid_field_cosine_3d(u_a, u_b, model.block_volume.values, tensor) == pytest.approx(expected, rel=1e-12)


def test_the_3d_locus_distance_is_between_the_cracked_interfaces_centroids(corner):
    from masonryfw_compare.comparison3d import locus_scores_3d

    model, _ = corner
    count = model.interface_node_count.values
    points = np.c_[model.interface_node_x.values, model.interface_node_y.values, model.interface_node_z.values]
    centre = np.add.reduceat(points, np.r_[0, np.cumsum(count)[:-1]], axis=0) / count[:, None]
    a, b = np.zeros(model.sizes["interface"], dtype=bool), np.zeros(model.sizes["interface"], dtype=bool)
    a[3], b[[10, 40]] = True, True
    size = 7.0
    got = locus_scores_3d(model, a, b, size)
    to_b = min(np.linalg.norm(centre[3] - centre[10]), np.linalg.norm(centre[3] - centre[40])) / size
    area = model.interface_area.values[[10, 40]]
    to_a = np.average(np.linalg.norm(centre[[10, 40]] - centre[3], axis=1), weights=area) / size
    assert got["locus_distance_a_to_b"] == pytest.approx(to_b) and got["locus_distance_b_to_a"] == pytest.approx(to_a)


def test_a_3d_result_against_itself_scores_perfectly_and_against_another_model_is_refused(corner):
    model, result = corner
    same = mf.compare(result, result)
    assert float(same.crack_f1) == 1.0 and float(same.macro_block_ari) == 1.0
    assert float(same.mechanism_cosine) == pytest.approx(1.0) and float(same.locus_distance) == 0.0
    other = mf.solve(mf.checked_model(mfp.twin(mf.open_model("test-12c"))), "la")
    with pytest.raises(mf.ModelError, match="cannot compare results of different models"):
        mf.compare(result, other)


def test_the_compare_plot_of_two_3d_results_draws_each_mechanism_in_axonometry_with_its_scores(corner):
    """Two panels in axonometry, each the mechanism kind's drawing (its cracked interfaces outlined); the second
    titled with the crack comparator's scores against the first and each with its motion's amplification."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    model, cone = corner
    pyramid = mf.solve(model, "la", {"pyramid_sides": 8})
    figure = mf.render([cone, pyramid], "compare")
    FigureCanvasAgg(figure).draw()
    panels = [ax for ax in figure.axes if ax.name == "3d"]
    assert len(panels) == 2
    for panel, result in zip(panels, (cone, pyramid)):
        lines = [c for c in panel.collections if isinstance(c, Line3DCollection)]
        assert len(lines[0].get_segments()) == int(mf.cracked_joints(result).sum()) > 0
        assert panel.get_legend() is None and "motion relative to macro-block (1), x " in panel.get_title()
    scores = mf.compare(cone, pyramid, "crack")
    assert f"F1 {float(scores.crack_f1):.2f}, ARI {float(scores.macro_block_ari):.2f}" in panels[1].get_title()


def test_the_report_of_two_3d_results(corner, tmp_path):
    """The building in axonometry, its spec, the key numbers, each mechanism and cracked joints, and the
    agreement table of the cone
    against the 8-sided pyramid, labelled with the method each ran."""
    from masonryfw_compare.report import report_html

    model, cone = corner
    paths = [str(mf.save(cone, tmp_path / "cone.nc")),
             str(mf.save(mf.solve(model, "la", {"pyramid_sides": 8}), tmp_path / "pyramid.nc"))]
    text = report_html(paths, "masonryfw report cone.nc pyramid.nc")
    assert "<h2>The building</h2>" in text and text.count("<img ") == 6  # the building; each mechanism and cracks; both
    assert '<pre class="walls">' not in text  # a trough without a target settlement: no stages to assess
    assert "A: la (cone, ipm)" in text and "B: la (pyramid of 8 sides, ipm)" in text
    assert "<h2>Agreement</h2>" in text and 'id="agreement"' in text


def test_a_buildings_ltsm_plot_colours_each_wall_by_its_category_and_charts_the_worst():
    """The house over the tunnel with its face under it: the plan shows every wall as a line in the colour of its
    own LTSM category (each wall's largest part strain at the assessed settlement), the worst wall's name in the
    title, and one interaction chart per part of that wall; a drawn 3D result has no walls and is refused."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import to_hex

    from masonryfw_compare.block_plots import drawable_kinds
    from masonryfw_compare.figure_parts import DAMAGE_COLOURS

    spec = mf.load_spec(mf.bundled_spec_path("house-tunnel"))
    spec = {**spec, "settlement": {**spec["settlement"], "face": 2.0, "volume_loss": 4.5}}
    result = mf.solve(mf.build(spec), "la")
    assert "ltsm" in drawable_kinds(result)
    figure = mf.render([result], "ltsm")
    FigureCanvasAgg(figure).draw()
    settlement = float(result.settlement_target)
    stages = mfp.assess(result, settlement)
    walls = {w["name"] for w in __import__("json").loads(result.attrs["building_walls"])}
    strain = {name: max(settlement * p.strain for p in stages.parts if p.wall == name) for name in walls}
    plan = figure.axes[1]
    drawn = {tuple(np.round(line.get_xydata()[[0, -1]].ravel(), 6)): to_hex(line.get_color())
             for line in plan.get_lines() if line.get_linewidth() == 6}
    assert len(drawn) == len(walls)
    for wall in __import__("json").loads(result.attrs["building_walls"]):
        key = tuple(np.round(np.r_[wall["start"], wall["end"]], 6))
        assert drawn[key] == DAMAGE_COLOURS[int(mfp.ltsm_category(strain[wall["name"]]))]
    worst = max(strain, key=strain.get)
    assert f"worst wall: {worst!r}" in " ".join(figure.get_suptitle().split())  # the title over every panel
    charts = [ax for ax in figure.axes if ax.get_xlabel().startswith("horizontal strain")]
    assert len(charts) == sum(p.wall == worst for p in stages.parts)
    assert max(strain.values()) > 0.0005  # a category above 0 somewhere: the colours are not all one


def test_a_drawn_3d_result_has_no_walls_for_the_ltsm_plot(corner, tmp_path):
    from masonryfw.geometry import polyhedra
    from masonryfw_compare.block_plots import drawable_kinds
    from tests.core.test_core_drawing3d import write_obj

    model, _ = corner
    write_obj(tmp_path / "corner.obj", polyhedra.subset(mfp.polyhedra_of(model),
                                                        mfp.masonry_blocks(model.block_role.values)))
    drawn = mf.build({"title": "drawn", "geometry": {"mesh": str(tmp_path / "corner.obj")},
                      "material": {"unit_weight": 20000.0, "friction_angle": 30.0},
                      "settlement": {"profile": "tunnel", "volume_loss": 1.0, "diameter": 3.0, "depth": 6.0,
                                     "axis_angle": 30.0, "center_x": 1.4, "center_y": 0.2}})
    result = mf.solve(drawn, "la")
    assert "ltsm" not in drawable_kinds(result)
    with pytest.raises(mf.MasonryError, match="the ltsm plot needs walls to assess: a 3D drawing's blocks name none"):
        mf.render([result], "ltsm")
