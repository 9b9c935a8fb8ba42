"""The ``ipm`` backend: closed forms, HiGHS's exact vertex, its SciPy fallback, its Clarabel fallback, symmetry."""
from __future__ import annotations

import sys

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_la import backends, cones, ipm

ROLE = mfp.flags("block_role")


def single_unit(walls, b, h, mu):
    """A b x h unit on a wide fixed base, pushed sideways by its weight: alpha = min(b/h, mu)."""
    return walls.rect_model([(-1.0, -0.2, 2.0, 0.0), (0.0, 0.0, b, h)], [ROLE["fixed_support"], ROLE["unit"]], friction=mu)


def unit_over_settling_support(walls, a, b=1.0, h=0.5):
    """A unit of width b over a fixed support [0, a] and a settling one [a, b]."""
    return walls.rect_model(
        [(0.0, -0.2, a, 0.0), (a, -0.2, b, 0.0), (0.0, 0.0, b, h)],
        [ROLE["fixed_support"], ROLE["moving_support"], ROLE["unit"]],
        loading="settlement",
    )


def centrally_settling_wall(walls):
    """Symmetric wall over a centred settling support: its optimum is a tie of mirror-image mechanisms."""
    units = walls.running_bond(6, 1.8, 0.3, 0.1)
    rects = np.vstack([(0.0, -0.1, 0.27, 0.0), (0.27, -0.1, 1.53, 0.0), (1.53, -0.1, 1.8, 0.0), units])
    roles = [ROLE["fixed_support"], ROLE["moving_support"], ROLE["fixed_support"]] + [ROLE["unit"]] * len(units)
    return walls.rect_model(rects, roles, loading="settlement")


def alpha(result) -> float:
    return float(result.collapse_multiplier)


@pytest.mark.parametrize("b, h, mu", [(0.4, 1.0, 0.65), (1.0, 0.5, 0.4)])
def test_la_ipm_single_unit_closed_form(walls, b, h, mu):
    result = walls.solve(single_unit(walls, b, h, mu), solver="ipm")
    assert alpha(result) == pytest.approx(min(b / h, mu), rel=1e-8)
    assert result.attrs["la_alpha_dual"] == pytest.approx(min(b / h, mu), rel=1e-8)
    assert str(result.lp_status.values) == "optimal"


@pytest.mark.parametrize("a", [0.2, 0.45, 0.7])
def test_la_ipm_unit_over_a_settling_support_closed_form(walls, a):
    """alpha = 1 - b(b/2 - a)/(b - a)^2 with the centroid over the settling part, else 1."""
    expected = 1.0 if a >= 0.5 else 1.0 - (0.5 - a) / (1.0 - a) ** 2
    assert alpha(walls.solve(unit_over_settling_support(walls, a), solver="ipm")) == pytest.approx(expected, abs=1e-8)


def test_la_ipm_ferris_tin_loi_against_the_highs_vertex(walls):
    model = walls.ferris_tin_loi_wall()
    result = walls.solve(model, solver="ipm")
    vertex = alpha(walls.solve(model, solver="highs", tolerance=1e-10))
    assert alpha(result) == pytest.approx(0.643, abs=1e-3)  # published
    assert alpha(result) == pytest.approx(vertex, rel=1e-8)
    assert result.attrs["la_alpha_dual"] == pytest.approx(vertex, rel=1e-8)


def test_la_ipm_without_cvxopt_uses_superlu_and_gives_the_same_alpha(walls, monkeypatch):
    model = walls.ferris_tin_loi_wall()
    with_cholmod = walls.solve(model, solver="ipm")
    monkeypatch.setitem(sys.modules, "cvxopt", None)  # `import cvxopt` now raises ImportError
    monkeypatch.setitem(sys.modules, "cvxopt.cholmod", None)
    assert mfp.cholesky_factor(ipm.lower_pattern(ipm.sp.identity(3, format="csr"))[0]).name == "superlu"
    without = walls.solve(model, solver="ipm")
    vertex = alpha(walls.solve(model, solver="highs", tolerance=1e-10))
    assert alpha(without) == pytest.approx(vertex, rel=1e-8)
    assert alpha(without) == pytest.approx(alpha(with_cholmod), rel=1e-9)
    assert str(without.lp_status.values) == "optimal"


def test_la_ipm_unbounded_problem_falls_back_to_clarabels_message(walls):
    """A live load pressing the unit onto its base: the iterates diverge, Clarabel certifies infeasibility."""
    model = walls.rect_model([(-0.5, -0.2, 1.5, 0.0), (0.0, 0.0, 0.4, 0.8)], [ROLE["fixed_support"], ROLE["unit"]])
    live = np.zeros_like(model.live_load.values)
    live[1, 1] = -500.0
    model = model.assign(live_load=model.live_load.copy(data=live))
    messages = []
    for backend in ("ipm", "clarabel"):
        with pytest.raises(mf.SolveError) as error:
            walls.solve(model, solver=backend)
        messages.append(str(error.value))
    assert messages[0] == messages[1] == backends.UNBOUNDED_MESSAGE


def test_la_ipm_failure_to_converge_falls_back_to_clarabel(walls, monkeypatch):
    monkeypatch.setattr(ipm, "MAX_ITERATIONS", 2)
    model = walls.ferris_tin_loi_wall()
    result = walls.solve(model, solver="ipm")
    status = str(result.lp_status.values)
    assert status.startswith("optimal (ipm fell back to clarabel: not converged in 2 iterations")
    assert alpha(result) == pytest.approx(alpha(walls.solve(model, solver="highs")), rel=1e-7)


def test_la_ipm_tied_mechanisms_come_out_symmetric(walls):
    """HiGHS returns one vertex of the tie; the interior point their mirror-symmetric mean."""
    model = centrally_settling_wall(walls)
    result = walls.solve(model, solver="ipm")
    assert alpha(result) == pytest.approx(alpha(walls.solve(model, solver="highs")), abs=1e-8)
    centroid = np.c_[model.block_centroid_x.values, model.block_centroid_y.values]
    mirrored = np.c_[1.8 - centroid[:, 0], centroid[:, 1]]
    image = np.argmin(np.abs(mirrored[:, None, :] - centroid[None, :, :]).sum(axis=2), axis=1)
    assert np.abs(centroid[image] - mirrored).max() < 1e-9  # every block has its mirror image
    u = mfp.block_motion(result)
    np.testing.assert_allclose(u[image] * [-1, 1, -1], u, atol=1e-6 * np.abs(u).max())


def test_la_ipm_returns_a_stalled_iterate_only_at_the_acceptable_tolerance():
    """Asked for more than double precision gives, the interior point stalls: an error, or, with an
    acceptable tolerance, the stalled iterate, whose alpha is HiGHS's exact vertex's to that tolerance."""
    from masonryfw_la import assembly

    model = mf.open_model("test-12c")
    wall = assembly.Wall.from_model(model)
    scales = assembly.model_scales(model, wall)
    lp = assembly.assemble(wall, scales, assembly.interface_kinematics(wall, scales))
    exact = backends.solve_lp("highs", lp.cost, lp.constraints, lp.live, 1e-10).alpha_primal
    with pytest.raises(ipm.IPMFailure, match="not converged"):
        ipm.solve(lp.cost, lp.constraints, lp.live, 1e-20)
    stalled = ipm.solve(lp.cost, lp.constraints, lp.live, 1e-20, acceptable=1e-9)
    assert stalled.iterations < ipm.MAX_ITERATIONS
    assert float(lp.cost @ stalled.x) == pytest.approx(exact, rel=1e-9)


def test_la_ipm_eliminated_slip_columns_solve_the_whole_normal_matrix(nonassociative_lp):
    """The slip bounds of a non-associative programme, eliminated from the normal matrix, against a direct sparse
    solve of the whole of it; with weights spanning twenty orders of magnitude, as near an optimum, backward stable
    (a residual at rounding level of ``|M| |x|``)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    lp = nonassociative_lp("test-12c")
    normal = ipm.NormalMatrix(lp.constraints)
    assert normal.elimination is not None and normal.elimination.columns.size == lp.cohesive_ends.size
    rng = np.random.default_rng(3)
    rhs = rng.standard_normal(lp.constraints.shape[1])
    for span, within in ((3, 1e-8), (10, None)):
        d = 10.0 ** rng.uniform(-span, span, lp.constraints.shape[0])
        normal.factorise(cones.OrthantScaling(np.ones_like(d), d, np.zeros_like(d)))  # D = y / s = d
        whole = (lp.constraints.T @ sp.diags(d) @ lp.constraints).tocsc()
        solved = normal.solve(rhs)
        if within is not None:
            reference = spla.spsolve(whole, rhs)
            np.testing.assert_allclose(solved, reference, rtol=within, atol=within * np.abs(reference).max())
        backward = np.abs(whole @ solved - rhs).max() / (abs(whole).max() * np.abs(solved).max())
        assert backward < 1e-15


@pytest.mark.parametrize("name", ["test-12c", "panel-3", "facade-1"])
def test_la_ipm_nonassociative_programme_against_the_highs_vertex(name, nonassociative_lp):
    """The programme whose slip columns the interior point eliminates: the same alpha as HiGHS's simplex."""
    lp = nonassociative_lp(name)
    exact = backends.solve_lp("highs", lp.cost, lp.constraints, lp.live, 1e-10).alpha_primal
    ours = backends.solve_lp("ipm", lp.cost, lp.constraints, lp.live, 1e-9)
    assert "clarabel" not in ours.status
    assert ours.alpha_primal == pytest.approx(exact, rel=1e-7, abs=1e-9)
