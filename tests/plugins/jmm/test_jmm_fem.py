"""FE kernels and Newton on small problems: patch test, cantilever (beam theory), shear block limit (mu P)."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from skfem import MeshTri

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_jmm.fem import Discretisation
from masonryfw_jmm.material import JointStrength, ReturnMap, elastic_matrix
from masonryfw_jmm.newton import NewtonSolver, State
from masonryfw_jmm.problem import Problem

E, NU = 2.4, 0.2


def rectangle(width, height, nx, ny):
    return MeshTri.init_tensor(np.linspace(0, width, nx + 1), np.linspace(0, height, ny + 1))


def solve_elastic(disc, D, prescribed, values, force):
    K = disc.stiffness(np.broadcast_to(D, (disc.n_points, 3, 3)))
    free = np.setdiff1d(np.arange(disc.ndof), prescribed)
    u = np.zeros(disc.ndof)
    u[prescribed] = values
    rhs = force[free] - K[free][:, prescribed] @ values
    u[free] = spla.spsolve(K[free][:, free].tocsc(), rhs)
    return u


@pytest.mark.parametrize("element", ["p1", "p2"])
def test_patch_test_reproduces_a_linear_field(element):
    mesh = rectangle(1.0, 0.7, 5, 4)
    mesh = MeshTri(mesh.p + 0.03 * np.sin(7 * mesh.p[::-1]) * (mesh.p > 0) * (mesh.p < [[1.0], [0.7]]), mesh.t)
    disc = Discretisation(mesh, element, np.ones(mesh.t.shape[1]))
    D = elastic_matrix(E, NU)
    boundary = np.unique(disc.basis.get_dofs().all())
    x, y = disc.basis.doflocs
    exact = np.empty(disc.ndof)
    exact[0::2] = 1e-3 * (2 * x + 3 * y + 1)
    exact[1::2] = 1e-3 * (-x + 0.5 * y - 2)
    prescribed = np.concatenate([2 * boundary, 2 * boundary + 1])
    u = solve_elastic(disc, D, prescribed, exact[prescribed], np.zeros(disc.ndof))
    np.testing.assert_allclose(u, exact, atol=1e-14)
    np.testing.assert_allclose(disc.strain(u), np.tile([2e-3, 0.5e-3, 2e-3], (disc.n_points, 1)), atol=1e-13)


def test_cantilever_tip_deflection_matches_timoshenko_beam():
    L, h, t, P = 2.0, 0.2, 1.0, 1e-4
    mesh = rectangle(L, h, 40, 4)
    disc = Discretisation(mesh, "p2", np.full(mesh.t.shape[1], t))
    D = elastic_matrix(E, NU)
    x, y = disc.basis.doflocs
    clamped = np.nonzero(np.isclose(x, 0.0))[0]
    tip = np.nonzero(np.isclose(x, L))[0]
    force = np.zeros(disc.ndof)
    force[2 * tip + 1] = -P / tip.size  # resultant P; the shear-stress profile only matters near the tip
    prescribed = np.concatenate([2 * clamped, 2 * clamped + 1])
    u = solve_elastic(disc, D, prescribed, np.zeros(prescribed.size), force)
    G = E / (2 * (1 + NU))
    inertia, area = t * h**3 / 12, t * h
    beam = P * L**3 / (3 * E * inertia) + P * L / (5 / 6 * G * area)
    deflection = -u[2 * tip + 1].mean()
    assert deflection == pytest.approx(beam, rel=0.01)


def shear_block_problem(beta=1.5, pressure=1.0, width=1.0, height=0.5, n=(8, 4), vertex_stiffness=1e-2):
    """Simple shear of a JMM block: base fixed, ux = t y / h on the sides and the top (plate), top loaded by p."""
    mesh = rectangle(width, height, *n)
    disc = Discretisation(mesh, "p2", np.ones(mesh.t.shape[1]))
    D = elastic_matrix(E, NU)
    x, y = disc.basis.doflocs
    base = np.nonzero(np.isclose(y, 0.0))[0]
    driven = np.nonzero(~np.isclose(y, 0.0) & (np.isclose(x, 0) | np.isclose(x, width) | np.isclose(y, height)))[0]
    top = np.isclose(y[driven], height)
    facets = mesh.facets_satisfying(lambda p: np.isclose(p[1], height))
    top_nodes = disc.facet_dofs(facets)
    # consistent P2 load of a uniform pressure on the top edge: Simpson weights per edge (1/6, 4/6, 1/6)
    load = np.zeros(disc.ndof)
    edge = width / n[0]
    ends = np.isclose(x[top_nodes] % edge, 0.0) | np.isclose(x[top_nodes] % edge, edge)
    weights = np.where(ends, edge / 3, 2 * edge / 3)
    weights[np.isclose(x[top_nodes], 0) | np.isclose(x[top_nodes], width)] = edge / 6
    load[2 * top_nodes + 1] = -pressure * weights
    strength = JointStrength(0.4, 0.4, beta=beta)
    problem = Problem(
        mesh=None, disc=disc, return_map=ReturnMap(strength, D, vertex_stiffness),
        masonry_points=np.ones(disc.n_points, bool), D_points=np.broadcast_to(D, (disc.n_points, 3, 3)).copy(),
        gravity=load, fixed=np.concatenate([2 * base, 2 * base + 1]), moving=2 * driven,
        moving_direction=y[driven] / height, moving_weight=np.zeros(driven.size),
        support_uy=2 * base + 1, support_of=np.zeros(base.size, int), length=1.0, mesh_size=edge, stress=1.0, displacement=1.0, force=1.0, beta=beta, young=E, poisson=NU,
        strength=strength,
    )
    return problem, top


def load_to(newton, state, targets):
    """Converged states at the settlement ``targets`` (halving a failed increment); their reports."""
    reports, done = [], 0.0
    for target in targets:
        step = target - done
        while done < target - 1e-12:
            trial, report = newton.step(state, 1.0, min(done + step, target))
            if report.converged:
                state, done = trial, min(done + step, target)
                reports.append(report)
            else:
                step /= 2
                assert step > 1e-3, report.residuals
    return state, reports


def test_shear_block_reaches_mu_times_the_vertical_load():
    # the base shear (= the horizontal force on all driven nodes) at the limit is mu P exactly:
    # upper bound: the block slides on a bed plane (dilating against p); lower bound: tau <= mu |syy| on any section
    width, pressure = 1.0, 1.0
    problem, _ = shear_block_problem(width=width, pressure=pressure, n=(4, 2))
    newton = NewtonSolver(problem, tolerance=1e-5, max_iterations=40, regularisation=(1e-2, 1e-2))
    state, reports = load_to(newton, State.initial(problem), [0.0, 0.3, 6.0])
    shear = state.residual[problem.moving].sum()
    assert shear == pytest.approx(0.4 * pressure * width, rel=1e-4)


def test_newton_converges_quadratically_into_the_plastic_range():
    # one step from the loaded elastic block into shear yielding (single active faces): the exact
    # consistent tangent gives r_{k+1} <= C r_k^2 down to round-off
    problem, _ = shear_block_problem()
    newton = NewtonSolver(problem, tolerance=1e-13, max_iterations=20, regularisation=(1e-6, 1e-6))
    state, report = newton.step(State.initial(problem), 1.0, 0.0)
    state, report = newton.step(state, 1.0, 0.2)
    r = np.asarray(report.residuals)
    assert report.converged and r[-1] < 1e-13 and r[0] > 1e-2
    assert state.active.any(axis=1).sum() > 0  # plastic points exist
    assert all(b <= 10 * a**2 for a, b in zip(r[:-1], r[1:])), r


def test_a_guess_at_the_solution_replaces_the_predictor():
    # the extrapolated-increment predictor: an exact guess (the converged displacements of a tight
    # solve) is taken and the step needs no Newton correction; a poor guess is ignored
    problem, _ = shear_block_problem()
    newton = NewtonSolver(problem, tolerance=1e-10, max_iterations=40, regularisation=(1e-2, 1e-2))
    loaded, _ = newton.step(State.initial(problem), 1.0, 0.0)
    exact, report = newton.step(loaded, 1.0, 0.2)
    assert report.converged and report.iterations > 1
    guessed, guessed_report = newton.step(loaded, 1.0, 0.2, guess=exact.u)
    assert guessed_report.iterations == 1
    np.testing.assert_allclose(guessed.stress, exact.stress, atol=1e-9)
    noise = np.random.default_rng(0).normal(size=exact.u.size)
    poor, poor_report = newton.step(loaded, 1.0, 0.2, guess=exact.u + noise)
    assert poor_report.residuals[0] == report.residuals[0]  # the tangent predictor kept
    np.testing.assert_allclose(poor.stress, exact.stress, atol=1e-8)


@pytest.mark.parametrize("case, options", [("test-12c", {}), ("facade-3", {}), ("panel-2", {"mesh_size": 0.04}),
                                           ("test-12c", {"element": "p1"})])
def test_the_estimated_dofs_are_the_meshs_to_ten_percent(case, options):
    """The estimate counts DOFs from the masonry's area; the mesher counts them on the mesh it makes."""
    from masonryfw_jmm.estimate import mesh_dofs
    from masonryfw_jmm.problem import build_problem

    model = mf.checked_model(mf.open_model(case))
    resolved = mfp.resolve_options("jmm", mf.get_solver("jmm").options, options)
    estimated, _ = mesh_dofs(model, resolved, resolved["element"])
    actual = build_problem(model, resolved).disc.ndof
    assert abs(estimated / actual - 1) < 0.1, (estimated, actual)


@pytest.mark.parametrize("case", ["arch-settlement", "lact3-arch", "lact3-portal"])
def test_the_estimated_dofs_of_drawn_walls_are_the_meshs_to_a_quarter(case):
    """gmsh's unstructured cells are estimated from the masonry's area and perimeter."""
    from masonryfw_jmm.estimate import mesh_dofs
    from masonryfw_jmm.problem import build_problem

    model = mf.checked_model(mf.open_model(case))
    resolved = mfp.resolve_options("jmm", mf.get_solver("jmm").options, {})
    estimated, _ = mesh_dofs(model, resolved)
    actual = build_problem(model, resolved).disc.ndof
    assert abs(estimated / actual - 1) < 0.25, (estimated, actual)
