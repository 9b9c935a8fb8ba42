"""Vectorised polygon geometry against closed forms."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp


def _ragged(polygons):
    x = np.concatenate([np.asarray(p, float)[:, 0] for p in polygons])
    y = np.concatenate([np.asarray(p, float)[:, 1] for p in polygons])
    return x, y, np.array([len(p) for p in polygons])


def test_area_and_centroid_of_rectangle_triangle_and_hexagon():
    rect = [(1, 2), (4, 2), (4, 3), (1, 3)]
    tri = [(0, 0), (3, 0), (0, 6)]
    hexagon = [(np.cos(a), np.sin(a)) for a in np.linspace(0, 2 * np.pi, 7)[:-1]]
    area, cx, cy = mfp.polygon_area_centroid(*_ragged([rect, tri, hexagon]))
    np.testing.assert_allclose(area, [3.0, 9.0, 1.5 * np.sqrt(3)], rtol=1e-14)
    np.testing.assert_allclose(cx, [2.5, 1.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(cy, [2.5, 2.0, 0.0], atol=1e-14)


def test_clockwise_polygon_has_negative_area():
    area, _, _ = mfp.polygon_area_centroid(*_ragged([[(0, 0), (0, 1), (1, 1), (1, 0)]]))
    assert area[0] == pytest.approx(-1.0)


def test_far_from_origin_keeps_precision():
    """A 1 mm brick 1,000 km from the origin: shifting by the first vertex keeps full precision."""
    x0 = 1e6
    brick = [(x0, x0), (x0 + 1e-3, x0), (x0 + 1e-3, x0 + 5e-4), (x0, x0 + 5e-4)]
    area, cx, cy = mfp.polygon_area_centroid(*_ragged([brick]))
    assert area[0] == pytest.approx(5e-7, rel=1e-6)
    assert cx[0] - x0 == pytest.approx(5e-4, rel=1e-6)
    assert cy[0] - x0 == pytest.approx(2.5e-4, rel=1e-6)


def test_offsets_bounds_and_scale():
    x, y, n = _ragged([[(0, 0), (2, 0), (2, 1), (0, 1)], [(2, 0), (3, 0), (2.5, 4)]])
    np.testing.assert_array_equal(mfp.block_offsets(n), [0, 4, 7])
    np.testing.assert_array_equal(mfp.node_block(n), [0, 0, 0, 0, 1, 1, 1])
    xmin, xmax, ymin, ymax = mfp.block_bounds(x, y, n)
    np.testing.assert_array_equal(xmin, [0, 2])
    np.testing.assert_array_equal(ymax, [1, 4])
    assert mfp.model_scale(x, y) == pytest.approx(5.0)


def test_interface_normal_points_out_of_side0_and_tangent_is_n_rotated_minus_90():
    # a bed joint y = 1 on a 2 x 1 block, and an inclined joint of a triangle stored in the "wrong" end order
    x, y, n = _ragged([[(0, 0), (2, 0), (2, 1), (0, 1)], [(0, 0), (1, 0), (0, 1)]])
    ix = np.array([[0.0, 2.0], [1.0, 0.0]])
    iy = np.array([[1.0, 1.0], [0.0, 1.0]])
    length, nx, ny, tx, ty = mfp.interface_frame(ix, iy, np.array([0, 1]), x, y, n)
    np.testing.assert_allclose(length, [2.0, np.sqrt(2)])
    np.testing.assert_allclose([nx[0], ny[0], tx[0], ty[0]], [0, 1, 1, 0], atol=1e-15)
    np.testing.assert_allclose([nx[1], ny[1]], [np.sqrt(0.5), np.sqrt(0.5)])
    np.testing.assert_allclose([tx[1], ty[1]], [np.sqrt(0.5), -np.sqrt(0.5)])


def test_the_normal_of_a_non_convex_block_follows_its_edge_not_its_centroid():
    """An L (centroid (1.1, 1.1)) with a block in its notch: the centroid lies beyond both joint lines."""
    ell = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]
    notch = [(1, 1), (3, 1), (3, 2), (1, 2)]
    x, y, n = _ragged([ell, notch])
    assert mfp.polygon_area_centroid(x, y, n)[1][0] == pytest.approx(1.1)
    found = mf.detect_interfaces(x, y, n)
    _, nx, ny, _, _ = mfp.interface_frame(found["x"], found["y"], found["blocks"][:, 0], x, y, n)
    assert found["blocks"].tolist() == [[0, 1], [0, 1]]
    normals = sorted(zip(np.round(nx, 12).tolist(), np.round(ny, 12).tolist()))
    assert normals == [(0.0, 1.0), (1.0, 0.0)]  # out of the L: up through its notch floor, right through its wall


def test_degenerate_blocks_get_the_vertex_mean_and_nan_bounds():
    """A collinear 'polygon' has zero area; its centroid falls back to the vertex mean so errors can point at it."""
    x = np.array([0.0, 1.0, 2.0, 5.0, 6.0, 6.0])
    y = np.array([0.0, 0.0, 0.0, 5.0, 5.0, 6.0])
    counts = np.array([3, 0, 3])
    area, cx, cy = mfp.polygon_area_centroid(x, y, counts)
    assert area[0] == 0.0 and cx[0] == 1.0 and cy[0] == 0.0
    assert area[2] == pytest.approx(0.5)
    xmin, xmax, _, _ = mfp.block_bounds(x, y, counts)
    assert np.isnan(xmin[1]) and xmax[2] == 6.0
