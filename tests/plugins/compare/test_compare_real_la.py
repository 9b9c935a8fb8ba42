"""The comparator, the plots and the export on real limit-analysis results of bundled walls."""
from __future__ import annotations

import meshio
import numpy as np
import pytest
import xarray as xr

import masonryfw as mf
from masonryfw_compare import export_vtk


def plot(result, kind, **options):
    """Draw through the core, as the CLI does; returns the figure and its first axes."""
    figure = mf.render([result] if isinstance(result, xr.Dataset) else result, kind, options)
    return figure, figure.axes[0]


def compare(a, b, options):
    return mf.compare(a, b, "crack", options)


@pytest.fixture(scope="module")
def la_12c():
    return mf.solve(mf.open_model("test-12c"), "la", {"solver": "highs"})


def test_a_real_result_against_itself_and_with_one_crack_healed(la_12c):
    same = compare(la_12c, la_12c, {})
    for name in ("crack_f1", "crack_jaccard", "crack_overlap", "crack_spearman", "macro_block_ari", "mechanism_cosine"):
        assert same[name].item() == pytest.approx(1.0), name
    indicator = la_12c.crack_indicator.values.copy()
    cracked = np.flatnonzero(indicator > 0.1)
    n = cracked.size
    assert n > 3
    indicator[cracked[0]] = 0.0
    healed = la_12c.assign(crack_indicator=la_12c.crack_indicator.copy(data=indicator))
    s = compare(la_12c, healed, {})
    # B = A minus one joint: precision 1, recall (n-1)/n, F1 2(n-1)/(2n-1), Jaccard (n-1)/n
    assert s.crack_precision.item() == 1.0
    assert s.crack_recall.item() == pytest.approx((n - 1) / n)
    assert s.crack_f1.item() == pytest.approx(2 * (n - 1) / (2 * n - 1))
    assert s.crack_jaccard.item() == pytest.approx((n - 1) / n)


def test_results_of_two_bundled_walls_are_refused(la_12c):
    la_8c = mf.solve(mf.open_model("test-8c"), "la")
    with pytest.raises(mf.ModelError, match="cannot compare results of different models: .* blocks"):
        mf.compare(la_12c, la_8c, "crack")


@pytest.mark.parametrize("kind", ["mechanism", "cracks", "forces"])
def test_the_discrete_plot_kinds_draw_a_real_result(la_12c, kind):
    figure, ax = plot(la_12c, kind)
    # R0 = 792 N * 0.6 / 1.1 = 432 N (datasets/README.md); the collapse reaction is (1 - alpha) R0
    alpha = float(la_12c.collapse_multiplier)
    assert ax.get_title().replace("\n", " ") == (f"Test 12C - la (highs) alpha = {alpha:.4f} (the share of R0 = 432 N "
                                                f"the settling ground sheds before collapse), collapse reaction "
                                                f"{(1 - alpha) * 432:.4g} N")
    assert len(ax.collections) >= 2


def test_the_export_of_a_real_result_has_one_cell_per_block_and_joint(la_12c, tmp_path):
    export_vtk(la_12c, tmp_path / "w.vtu")
    blocks = meshio.read(tmp_path / "w.vtu")
    joints = meshio.read(tmp_path / "w_joints.vtu")
    assert sum(len(c.data) for c in blocks.cells) == la_12c.sizes["block"]
    assert blocks.points.shape[0] == la_12c.sizes["node"]
    assert len(joints.cells[0].data) == la_12c.sizes["interface"]
    assert joints.point_data["interface_normal_force"].size == 2 * la_12c.sizes["interface"]
