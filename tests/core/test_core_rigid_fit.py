"""``masonryfw.rigid_fit``: the L2 projection of a sampled field onto each block's rigid motions."""
from __future__ import annotations

import numpy as np

import masonryfw.plugin_api as mfp


def test_a_rigid_field_is_recovered_exactly_whatever_the_points_and_weights():
    rng = np.random.default_rng(7)
    block = rng.integers(0, 4, 400)
    x, y = rng.random(400) + 3 * block, rng.random(400)
    cx, cy = np.array([0.4, 3.6, 6.5, 9.5]), np.array([0.5, 0.4, 0.6, 0.5])
    motion = rng.normal(size=(4, 3))
    ux, uy = mfp.point_motion(motion, cx, cy, x, y, block)
    fitted = mfp.rigid_fit(block, x, y, ux, uy, rng.random(400) + 0.1, cx, cy)
    np.testing.assert_allclose(fitted, motion, atol=1e-12)


def test_a_pure_shear_projects_onto_its_rotation_and_the_mean_translation():
    """u = (g y, 0) on the unit square (uniform weights): the closest rigid motion is the rotation
    rz = -g/2 (the skew part of grad u) and the centroid's own motion (g/2, 0), in closed form."""
    n = 201
    gx, gy = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
    x, y = gx.ravel(), gy.ravel()
    g = 0.3
    fitted = mfp.rigid_fit(np.zeros(x.size, int), x, y, g * y, 0 * y, np.ones(x.size), [0.5], [0.5])
    np.testing.assert_allclose(fitted[0], [g / 2, 0.0, -g / 2], atol=1e-12)


def test_mm_and_m_give_the_same_motion_scaled():
    rng = np.random.default_rng(3)
    block = np.repeat([0, 1], 30)
    x, y = rng.random(60) + block, rng.random(60)
    ux, uy = rng.normal(size=60), rng.normal(size=60)
    cx, cy = [0.5, 1.5], [0.5, 0.5]
    metres = mfp.rigid_fit(block, x, y, ux, uy, np.ones(60), cx, cy)
    millimetres = mfp.rigid_fit(block, 1e3 * x, 1e3 * y, 1e3 * ux, 1e3 * uy, np.ones(60), np.multiply(cx, 1e3),
                               np.multiply(cy, 1e3))
    np.testing.assert_allclose(millimetres[:, :2], 1e3 * metres[:, :2], rtol=1e-10)
    np.testing.assert_allclose(millimetres[:, 2], metres[:, 2], rtol=1e-10)


def test_blocks_without_points_or_with_one_point_are_undetermined():
    fitted = mfp.rigid_fit([1, 1], [0.2, 0.2], [0.1, 0.1], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0], [0.0, 0.0, 0.0],
                          [0.0, 0.0, 0.0])
    assert np.isnan(fitted[[0, 2]]).all()  # no point
    assert np.isnan(fitted[1]).all()  # one place: no rotation can be told
