"""The interior point on second-order cones (la in 3D's Coulomb cone): Nesterov-Todd scaling from its definition,
the step to the cones' boundary, the normal matrix against its dense product, and the multiplier against
Clarabel's (an independent conic interior point on the KKT system) on every 3D model the tests build."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt
from masonryfw_la import backends, cones, ipm, limit3d, lorentz_kernels

from .test_la_limit3d import WALLS, single_box


def points_inside(rng, count: int, size: int = 3, margin=None) -> np.ndarray:
    """Stacked points inside ``count`` second-order cones, ``v0 - |v1|`` equal to ``margin`` (random when None)."""
    v = rng.normal(size=(count, size))
    gap = rng.uniform(0.01, 1.0, count) if margin is None else np.full(count, margin)
    v[:, 0] = np.linalg.norm(v[:, 1:], axis=1) + gap
    return v.ravel()


def dense_w(scaling: cones.LorentzScaling, power: int) -> np.ndarray:
    """``W^-power`` of each cone as dense matrices, column by column from the scaling's products."""
    count = scaling.sigma.shape[0]
    columns = [scaling.times(power, np.tile(unit, count)).reshape(-1, 3) for unit in np.eye(3)]
    return np.stack(columns, axis=2)


def dense_from_definition(s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``W = eta (2 v v^T - J)`` written out from Vandenberghe's formulas (the cones' docstring), per cone."""
    j = np.diag([1.0, -1.0, -1.0])
    s, y = s.reshape(-1, 3), y.reshape(-1, 3)
    ns, ny = (np.sqrt(np.einsum("ci,ij,cj->c", v, j, v)) for v in (s, y))
    sbar, ybar = s / ns[:, None], y / ny[:, None]
    gamma = np.sqrt((1.0 + np.einsum("ci,ci->c", sbar, ybar)) / 2.0)
    wbar = (sbar + ybar @ j) / (2.0 * gamma[:, None])
    v = (wbar + np.eye(3)[0]) / np.sqrt(2.0 * (wbar[:, :1] + 1.0))
    return np.sqrt(ns / ny)[:, None, None] * (2.0 * v[:, :, None] * v[:, None, :] - j)


@pytest.mark.parametrize("margin", [None, 1e-6, 1e-12])
def test_the_nesterov_todd_scaling_maps_s_and_y_to_one_point(margin):
    """``W^-1 s = W y = lambda`` (the definition of the scaling), ``W`` equal to its formula written out, symmetric
    with ``W J W = eta^2 J`` (a scaling of the cone onto itself); near the boundary too (the iterates at the end
    of a solve)."""
    rng = np.random.default_rng(5)
    soc = cones.SecondOrderCones(200)
    s, y = points_inside(rng, 200, margin=margin), points_inside(rng, 200, margin=margin)
    scaling = soc.scaling(s, y)
    lam = scaling.lam.ravel()
    assert np.allclose(scaling.times(1, s), lam, rtol=1e-9, atol=1e-12 * np.abs(lam).max())
    assert np.allclose(scaling.times(-1, y), lam, rtol=1e-9, atol=1e-12 * np.abs(lam).max())
    w = dense_w(scaling, -1)
    if margin is None:  # the formula loses digits near the boundary; the products hold there (above)
        assert np.allclose(w, dense_from_definition(s, y), rtol=1e-9, atol=1e-12 * np.abs(w).max())
    assert np.allclose(w, w.transpose(0, 2, 1), rtol=1e-12, atol=1e-14 * np.abs(w).max())
    j = np.diag([1.0, -1.0, -1.0])
    eta2 = np.sqrt(cones.lorentz_norm2(s.reshape(-1, 3)) / cones.lorentz_norm2(y.reshape(-1, 3)))
    assert np.allclose(np.einsum("cab,bd,cde->cae", w, j, w), eta2[:, None, None] * j, rtol=1e-8,
                       atol=1e-10 * eta2.max())
    assert soc.smallest_eigenvalue(lam) > 0.0
    assert np.allclose(scaling.lam_squared(), scaling.scaled_product(s, y))  # lambda o lambda = (W^-1 s) o (W y)


def test_the_arrow_solve_inverts_the_jordan_product():
    rng = np.random.default_rng(7)
    lam = points_inside(rng, 50)
    x = rng.normal(size=150)
    product = lorentz_kernels.jordan(lam, x)
    c = lam.reshape(-1, 3)  # u o v = (u . v, u0 v1 + v0 u1), written out
    assert np.allclose(product.reshape(-1, 3), np.c_[np.einsum("ij,ij->i", c, x.reshape(-1, 3)),
                                                     c[:, :1] * x.reshape(-1, 3)[:, 1:] + x.reshape(-1, 3)[:, :1]
                                                     * c[:, 1:]], rtol=1e-14)
    assert np.allclose(lorentz_kernels.arrow_solve(lam, product), x, rtol=1e-10, atol=1e-12)


def test_the_longest_step_ends_on_a_cones_boundary():
    """Along a random direction the step stops where the first cone's smallest eigenvalue ``v0 - |v1|`` reaches
    zero; a direction into every cone allows the whole step."""
    rng = np.random.default_rng(11)
    soc = cones.SecondOrderCones(100)
    for _ in range(20):
        v, d = points_inside(rng, 100), rng.normal(size=300) * 5.0
        step = soc.max_step(v, d)
        assert 0.0 < step < 1.0
        edge = v + step * d
        assert abs(soc.smallest_eigenvalue(edge)) < 1e-12 * np.abs(edge).max()
        assert soc.smallest_eigenvalue(v + 0.999 * step * d) > 0.0
    inward = points_inside(rng, 100)
    assert soc.max_step(points_inside(rng, 100), inward) == 1.0


def test_the_normal_matrix_of_cones_is_g_transpose_w_minus_two_g():
    """The normal matrix formed from each cone's scaled rows (grouped by interface) against the dense
    ``G^T W^-2 G`` on the corner building's programme."""
    blocks = limit3d.blocks_of(mt.corner_building())
    scales = limit3d.scales_of(blocks)
    cmap, _ = limit3d.column_map(blocks, scales)
    rows, _ = limit3d.cone_rows(blocks, scales)
    constraints = (rows @ cmap).tocsr()
    rng = np.random.default_rng(3)
    count = constraints.shape[0] // 3
    scaling = cones.SecondOrderCones(count).scaling(points_inside(rng, count), points_inside(rng, count))
    normal = ipm.NormalMatrix(constraints, cone_size=3)
    values = normal.cones.normal_values(scaling.normal_rows, normal.pattern.nnz)
    formed = sp.csc_matrix((values, normal.pattern.indices, normal.pattern.indptr), shape=normal.pattern.shape)
    blocks_w2 = sp.block_diag(list(dense_w(scaling, 2)), format="csr")
    dense = (constraints.T @ blocks_w2 @ constraints).toarray()
    assert np.allclose(formed.toarray(), np.tril(dense), rtol=1e-12, atol=1e-12 * np.abs(dense).max())


@pytest.mark.parametrize("margin", [None, 1e-8])
def test_a_regularised_programmes_normal_weights_are_the_inverse_of_w_squared_plus_the_weight(margin):
    """With a weight ``w`` on each cone's first component: the normal weights against the dense inverse of
    ``W^2 + w e0 e0^T``, their inverse against that matrix, the normal rows' ``R^T R`` against the same inverse, and
    ``w = 0`` giving back ``W^-2``."""
    rng = np.random.default_rng(13)
    count = 100
    soc = cones.SecondOrderCones(count)
    s, y = points_inside(rng, count, margin=margin), points_inside(rng, count, margin=margin)
    w = rng.uniform(0.0, 10.0, count)
    weight = np.zeros((count, 3))
    weight[:, 0] = w
    scaling = soc.scaling(s, y, weight.ravel())
    plain = soc.scaling(s, y)
    w2 = dense_w(plain, -2)  # W^2
    regularised = w2 + w[:, None, None] * np.eye(3)[0][:, None] * np.eye(3)[0][None, :]
    inverse = np.linalg.inv(regularised)
    v = rng.normal(size=3 * count)
    scale = np.abs(inverse).max(axis=(1, 2))[:, None]
    assert np.allclose(scaling.times_normal_weights(v).reshape(-1, 3), np.einsum("cij,cj->ci", inverse, v.reshape(-1, 3)),
                       rtol=1e-8, atol=1e-10 * scale * np.abs(v).max())
    assert np.allclose(scaling.times_normal_weights_inverse(v).reshape(-1, 3),
                       np.einsum("cij,cj->ci", regularised, v.reshape(-1, 3)), rtol=1e-9,
                       atol=1e-12 * np.abs(regularised).max())
    rows = scaling.normal_rows
    assert np.allclose(np.einsum("cki,ckj->cij", rows, rows), inverse, rtol=1e-8, atol=1e-10 * scale[:, :, None])
    assert np.allclose(scaling.primal_shift(v).reshape(-1, 3), weight * v.reshape(-1, 3))
    assert np.array_equal(soc.scaling(s, y, np.zeros(3 * count)).normal_rows, plain.normal_rows)


def clarabel_regularised(cost, constraints, live, weight):
    """``max lam - sum(w y^2) / 2`` over ``G^T y + lam a = c``, ``y`` in the cones, as Clarabel's QP in ``(y, lam)``:
    a second formulation of the regularised programme the interior point solves from the kinematic side."""
    import clarabel

    n_row, n_col = constraints.shape
    matrix = sp.vstack([sp.hstack([constraints.T, sp.csr_matrix(np.asarray(live)[:, None])]),
                        sp.hstack([-sp.identity(n_row), sp.csr_matrix((n_row, 1))])], format="csc")
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-10
    solution = clarabel.DefaultSolver(sp.diags(np.append(weight, 0.0), format="csc"), np.append(np.zeros(n_row), -1.0),
                                      matrix, np.concatenate([cost, np.zeros(n_row)]),
                                      [clarabel.ZeroConeT(n_col)] + [clarabel.SecondOrderConeT(3)] * (n_row // 3),
                                      settings).solve()
    return np.asarray(solution.x)[:n_row], np.asarray(solution.x)[-1]


@pytest.mark.parametrize("name", ["test-12c", "panel-1"])
def test_the_regularised_cone_programme_against_clarabels_qp(name):
    """The non-associative programme of a twin at its associative normal forces, regularised by ``w N^2 / 2``:
    our interior point's static multiplier and normal forces against Clarabel's QP of the same problem (measured:
    alpha to 2e-11, the forces to 1.6e-6 of the dead load), and the multiplier equal to the unregularised
    programme's alpha (the regularisation is exact: measured 5e-10 apart)."""
    from masonryfw_la import nonassociative3d

    blocks = limit3d.blocks_of(mf.checked_model(mfp.twin(mf.open_model(name))))
    programme, _ = nonassociative3d.flow_programme(blocks, limit3d.scales_of(blocks))
    normal, _ = nonassociative3d.associative_start(blocks, programme, "ipm", 1e-9)
    cost, weight = programme.cost(normal), 1e-2 * programme.squared_rows()
    ours = ipm.solve(cost, programme.constraints, programme.live, 1e-10, weight=weight, cone_size=3, acceptable=1e-8)
    y, lam = clarabel_regularised(cost, programme.constraints, programme.live, weight)
    plain = backends.solve_clarabel(cost, programme.constraints, programme.live, 1e-10, 3)
    assert ours.lam == pytest.approx(lam, abs=1e-9)
    assert ours.lam == pytest.approx(plain.alpha_primal, abs=5e-9)
    assert np.abs(programme.normal_forces(ours.y) - programme.normal_forces(y)).max() < 1e-5
    with pytest.raises(ValueError, match="first row only"):
        ipm.solve(cost, programme.constraints, programme.live, 1e-10, weight=np.roll(weight, 1), cone_size=3)


def clarabel_alpha(blocks: limit3d.Blocks3D) -> float:
    return limit3d.limit_state_3d(blocks, sides=0, solver="clarabel", tolerance=1e-10).alpha


def solved(blocks: limit3d.Blocks3D) -> limit3d.LimitState3D:
    state = limit3d.limit_state_3d(blocks, sides=0, solver="ipm")
    assert state.solution.status == "optimal"  # our interior point, not Clarabel's fallback
    return state


@pytest.mark.parametrize("name", WALLS)
def test_the_cone_on_every_bundled_walls_twin_against_clarabel(name):
    blocks = limit3d.blocks_of(mf.checked_model(mfp.twin(mf.open_model(name))))
    assert solved(blocks).alpha == pytest.approx(clarabel_alpha(blocks), rel=1e-7)


@pytest.mark.parametrize("building", ["corner", "house-tunnel"])
def test_the_cone_on_buildings_against_clarabel(building):
    """The kit's corner building (a door, toothed corners, a trough at 30 degrees) and the bundled house (1,126
    blocks, a tunnel's trough): alpha to 1e-7 of Clarabel's (the static check of its forces, block by block, is
    test_la_limit3d.py's, run on the default backend)."""
    model = mt.corner_building() if building == "corner" else mf.open_model(building)
    blocks = limit3d.blocks_of(model)
    assert solved(blocks).alpha == pytest.approx(clarabel_alpha(blocks), rel=1e-7)


def test_a_programme_without_an_optimum_gets_the_certificates_messages():
    """A box whose live load pushes it into its base (no mechanism lets it work) and a box overhanging its base
    (its weight alone overturns it): the interior point diverges and hands them to Clarabel, whose certificates
    give the messages, as for an LP."""
    with pytest.raises(backends.LiveLoadUnbounded, match="any multiple of the live load"):
        limit3d.limit_state_3d(single_box(1.0, 1.0, 0.5, 0.5, live_force=(0.0, 0.0, -1.0)))
    overhanging = single_box(1.0, 1.0, 0.5, 0.5, live_force=(1.0, 0.0, 0.0))
    shifted = overhanging._replace(centroid=overhanging.centroid + np.array([[0.0, 0.0, 0.0], [1.2, 0.0, 0.0]]))
    with pytest.raises(backends.DeadLoadNotCarried, match="dead load alone cannot be carried"):
        limit3d.limit_state_3d(shifted)
