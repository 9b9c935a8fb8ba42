"""Units and symmetry: alpha does not depend on how the wall is written down."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw.plugin_api as mfp

ROLE = mfp.flags("block_role")


def settling_wall(walls, *, mirrored=False, length_unit=1.0):
    """5 courses x 4 units, the right 60 % of the base settling (the left 60 % if ``mirrored``)."""
    units = walls.running_bond(5, 1.2, 0.3, 0.1)
    width = 1.2
    supports = np.array([(0.0, -0.1, 0.48, 0.0), (0.48, -0.1, width, 0.0)])
    rects = np.vstack([supports, units])
    roles = [ROLE["fixed_support"], ROLE["moving_support"]] + [ROLE["unit"]] * len(units)
    if mirrored:
        rects = np.c_[width - rects[:, 2], rects[:, 1], width - rects[:, 0], rects[:, 3]]
    return walls.rect_model(rects, roles, loading="settlement", length_unit=length_unit)


@pytest.mark.parametrize("backend", ["highs", "clarabel", "osqp"])
def test_la_same_wall_in_mm_and_in_m(walls, backend):
    in_m = walls.solve(settling_wall(walls), solver=backend)
    in_mm = walls.solve(settling_wall(walls, length_unit=1000.0), solver=backend)
    assert float(in_mm.collapse_multiplier) == pytest.approx(float(in_m.collapse_multiplier), rel=1e-9)
    # the mechanism: the support moves by 1 model unit, so translations match and rotations scale by 1/1000
    np.testing.assert_allclose(
        mfp.block_motion(in_mm) * [1, 1, 1000], mfp.block_motion(in_m), atol=1e-6
    )


def test_la_ferris_wall_in_mm(walls):
    """A tilting case too (no moving support: the largest translation is normalised to 1)."""
    alphas = [
        float(walls.solve(walls.ferris_tin_loi_wall(length_unit=k), solver="highs").collapse_multiplier)
        for k in (1.0, 1000.0)
    ]
    assert alphas[1] == pytest.approx(alphas[0], rel=1e-9)


def mirror_map(model, mirrored) -> np.ndarray:
    """Index in ``mirrored`` of the mirror image (x -> width - x) of every block of ``model``."""
    width = model.node_x.values.max() + model.node_x.values.min()
    image = np.round(np.c_[width - model.block_centroid_x.values, model.block_centroid_y.values], 9)
    key = np.round(np.c_[mirrored.block_centroid_x.values, mirrored.block_centroid_y.values], 9)
    index = {tuple(k): i for i, k in enumerate(key)}
    return np.array([index[tuple(k)] for k in image])


def test_la_mirrored_wall_mirrored_mechanism(walls):
    """Mirroring x -> W - x: same alpha, mechanism (ux, uy, rz) -> (-ux, uy, -rz) of the mirror block.

    Clarabel converges to the centre of the optimal face, which mirroring maps onto itself.
    """
    right = settling_wall(walls)
    left = settling_wall(walls, mirrored=True)
    res_right = walls.solve(right, solver="clarabel")
    res_left = walls.solve(left, solver="clarabel")
    assert float(res_left.collapse_multiplier) == pytest.approx(float(res_right.collapse_multiplier), rel=1e-9)
    match = mirror_map(right, left)  # block i of `right` is block match[i] of `left`
    u_right = mfp.block_motion(res_right)
    u_left = mfp.block_motion(res_left)[match]
    np.testing.assert_allclose(u_left * [-1, 1, -1], u_right, atol=1e-6 * np.abs(u_right).max())
    np.testing.assert_array_equal(
        res_left.macro_block.values[match] == res_left.macro_block.values[match][0],
        res_right.macro_block.values == res_right.macro_block.values[0],
    )


@pytest.mark.parametrize("backend", ["clarabel", "osqp"])
def test_la_central_settlement_gives_a_symmetric_mechanism(walls, backend):
    """A symmetric wall over a centred settling support: the mechanism is its own mirror image.

    The optimum of this wall is a tie (HiGHS returns one vertex of the optimal
    face, not symmetric); the interior point converges to the face's centre and
    the proximal OSQP steps to the point nearest the origin, both symmetric.
    """
    units = walls.running_bond(6, 1.8, 0.3, 0.1)
    rects = np.vstack([(0.0, -0.1, 0.27, 0.0), (0.27, -0.1, 1.53, 0.0), (1.53, -0.1, 1.8, 0.0), units])
    roles = [ROLE["fixed_support"], ROLE["moving_support"], ROLE["fixed_support"]] + [ROLE["unit"]] * len(units)
    model = walls.rect_model(rects, roles, loading="settlement")
    result = walls.solve(model, solver=backend)
    reference = walls.solve(model, solver="highs")
    assert float(result.collapse_multiplier) == pytest.approx(float(reference.collapse_multiplier), abs=1e-7)
    u = mfp.block_motion(result)
    match = mirror_map(model, model)
    np.testing.assert_allclose(u[match] * [-1, 1, -1], u, atol=1e-5 * np.abs(u).max())
