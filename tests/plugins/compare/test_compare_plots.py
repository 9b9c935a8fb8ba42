"""Every plot kind renders the results it supports and refuses the others with a clear message."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from PIL import Image

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_compare.block_plots import default_amplification, thrust_segments


def plot(result, kind, **options):
    """Draw through the core, as the CLI does; returns the figure and its first axes."""
    figure = mf.render([result] if isinstance(result, xr.Dataset) else result, kind, options)
    return figure, figure.axes[0]

def assert_no_empty_margin(grey: np.ndarray, largest: float = 0.06) -> None:
    """Something is drawn within ``largest`` of the image's size from each of its four edges."""
    inked_rows = np.flatnonzero((grey < 250).any(axis=1))
    inked_columns = np.flatnonzero((grey < 250).any(axis=0))
    height, width = grey.shape
    assert inked_rows[0] <= largest * height and inked_rows[-1] >= (1 - largest) * height - 1
    assert inked_columns[0] <= largest * width and inked_columns[-1] >= (1 - largest) * width - 1


SUPPORTED = {
    "mechanism": {"la", "fdem"},
    "cracks": {"la", "fdem"},
    "forces": {"la"},
    "plastic": {"jmm"},
    "history": {"fdem", "jmm"},
}
REFUSAL = {
    "mechanism": "result has no block_displacement: the mechanism plot needs block displacements",
    "cracks": "result has no interface_opening: the cracks plot needs the relative motion at the joints",
    "forces": "result has no interface_normal_force: the forces plot needs contact forces",
    "plastic": "result has no qp_failure: the plastic plot needs a continuum \\(jmm\\) result",
    "history": "the history plot needs an incremental \\(fdem or jmm\\) result",
}


@pytest.mark.parametrize("kind", sorted(SUPPORTED))
@pytest.mark.parametrize("result_kind", ["la", "fdem", "jmm"])
def test_each_kind_renders_what_it_supports_and_refuses_the_rest(results, tmp_path, kind, result_kind):
    if result_kind not in SUPPORTED[kind]:
        with pytest.raises(mf.MasonryError, match=REFUSAL[kind]):
            plot(results[result_kind], kind)
        return
    figure, ax = plot(results[result_kind], kind)
    figure.set_size_inches(5, 3)
    path = mf.save_figure(figure, tmp_path / f"{kind}-{result_kind}.png", dpi=100)
    with Image.open(path) as image:  # cropped to what is drawn (legends outside the axes included)
        grey = np.asarray(image.convert("L"))
    assert len(np.unique(grey)) > 2  # something was drawn
    assert_no_empty_margin(grey)
    assert ax.get_title().startswith("Grid wall - ")
    if kind != "history":
        assert ax.get_aspect() == 1.0 and ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


def test_compare_draws_side_by_side_panels_with_scores_in_the_titles(results, tmp_path):
    figure, _ = plot([results["la"], results["fdem"], results["jmm"]], "compare")
    titles = [ax.get_title() for ax in figure.axes if ax.get_visible() and ax.axison]
    assert titles == [
        "Grid wall\nla (highs), alpha = 0.3\nreference",
        "fdem\nF1 1.00, ARI 1.00, cos 1.00, d 0.00",
        "jmm\nF1 1.00, d 0.08",
    ]
    for suffix in (".svg", ".pdf"):
        assert mf.save_figure(figure, tmp_path / f"c{suffix}").stat().st_size > 1000
    with pytest.raises(mf.MasonryError, match="needs two or more results"):
        plot([results["la"]], "compare")


def test_compare_refuses_results_of_different_models(results, build):
    other = build.la_result(build.grid_model(cols=5, split=2))
    with pytest.raises(mf.ModelError, match="different models"):
        plot([results["la"], other], "compare")


def test_default_amplification_draws_the_largest_motion_as_a_tenth_of_the_wall(results):
    # LA mechanism: units translate by 1 (unit settlement); wall + supports: 1.2 m x 0.5 m, diagonal 1.3 m
    geo = mfp.derive_geometry(results["la"])
    assert default_amplification(geo, mfp.block_motion(results["la"])) == pytest.approx(0.13)
    # FEM/DEM: 5 mm -> 0.13 / 0.005
    assert default_amplification(geo, mfp.block_motion(results["fdem"])) == pytest.approx(26.0)


def test_thrust_passes_through_the_centre_of_pressure(results):
    """Interface 0: head joint x = 0.2, end 0 at y = 0.1, end 1 at y = 0; N = (10, 30) -> y = 0.1 - 0.75*0.1."""
    geo = mfp.derive_geometry(results["la"])
    normal = np.zeros((geo.sizes["interface"], 2))
    normal[0] = [10.0, 30.0]
    shear = np.zeros_like(normal)
    shear[0] = [1.0, 2.0]
    px, py, magnitude, segments = thrust_segments(geo, normal, shear, scale=1.0)
    assert (px.item(), py.item()) == pytest.approx((0.2, 0.025))
    assert magnitude.item() == pytest.approx(np.hypot(40.0, 3.0))
    # force on side 1: N n + V t with n = +x, t = (0, -1); the segment is centred on the point
    direction = segments[0, 1] - segments[0, 0]
    assert direction / np.linalg.norm(direction) == pytest.approx(np.array([40.0, -3.0]) / np.hypot(40.0, 3.0))
    assert segments[0].mean(axis=0) == pytest.approx([0.2, 0.025])


def test_plot_options_and_file_names_are_checked(results, tmp_path):
    with pytest.raises(mf.PluginError, match="unknown option 'colour'; valid options: amplification, threshold"):
        plot(results["la"], "mechanism", colour="red")
    with pytest.raises(mf.PluginError, match="option 'amplification' = 'big': not a float"):
        plot(results["la"], "mechanism", amplification="big")
    with pytest.raises(mf.PluginError, match="option 'amplification' = -1.0: must be > 0"):
        plot(results["la"], "mechanism", amplification=-1)
    figure, _ = plot(results["la"], "mechanism", amplification=50)
    with pytest.raises(mf.MasonryError, match="unknown file type '.jpg'"):
        mf.save_figure(figure, tmp_path / "m.jpg")


def test_the_core_renders_these_kinds_through_the_plugin_manager(results):
    figure = mf.render([results["jmm"]], "plastic", {"marker_size": "6"})
    # the title: the model, the solver, and the history's headline (the fixture's 100 N, 90 N at 5 mm)
    assert figure.axes[0].get_title() == "Grid wall - jmm\nR0 100 N, min 90 N at 5 mm, plateau 90 N"
