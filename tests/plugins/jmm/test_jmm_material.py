"""The JMM return mapping at one point against closed forms, a generic QP projection and finite differences."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from masonryfw_jmm.material import FAILURE, JointStrength, ReturnMap, elastic_matrix

MU = 0.4  # tan(21.8 deg), the paper's friction


def yield_values(rmap, stress):
    """``A s - b`` of every face (<= 0 inside the strength domain)."""
    return np.asarray(stress) @ rmap.A.T - rmap.b


def single_face_projection(trial, D, normal, limit):
    """Closest point on one plane n.s = limit in the energy norm: s = trial - (n.trial - limit) D n / (n.D n)."""
    normal = np.asarray(normal, float)
    return trial - (normal @ trial - limit) / (normal @ D @ normal) * (D @ normal)


def energy_projection(trial, D, A, b):
    """Reference: minimise (s - trial)^T D^-1 (s - trial) subject to A s <= b with SLSQP."""
    Dinv = np.linalg.inv(D)
    result = minimize(
        lambda s: (s - trial) @ Dinv @ (s - trial), np.zeros(3), jac=lambda s: 2 * Dinv @ (s - trial),
        constraints=[{"type": "ineq", "fun": lambda s: b - A @ s, "jac": lambda s: -A}],
        method="SLSQP", options={"ftol": 1e-15, "maxiter": 1000},
    )
    return result.x


def test_tension_normal_to_bed_plane_returns_to_the_cut_off():
    # cut-off below the Coulomb apex (sigma_t = 0.5 < c / tan(phi) = 2.5): it binds
    D = elastic_matrix(2.4, 0.2)
    strength = JointStrength(MU, MU, cohesion_bed=1.0, cohesion_head=100.0, tensile_bed=0.5, tensile_head=100.0)
    rmap = ReturnMap(strength, D)
    s = 2.0
    stress, _, active, _ = rmap(np.array([[0.0, s, 0.0]]))
    # along D e_y from (0, s, 0) to syy = sigma_t: sxx picks up -nu (s - sigma_t) (plane stress)
    np.testing.assert_allclose(stress[0], [-0.2 * (s - 0.5), 0.5, 0.0], atol=1e-12)
    assert rmap.failure_mode(active)[0] == FAILURE["tensile"]


def test_tension_at_the_paper_values_goes_to_the_apex_stress_free_joint():
    # c = sigma_t = 0: the cut-off coincides with the apex and is dropped; the bed joint opens
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, beta=0.8), D)
    assert rmap.names == ("bed+", "bed-", "head+", "head-")
    stress, _, active, _ = rmap(np.array([[-5.0, 1.0, 0.0]]))
    np.testing.assert_allclose(stress[0], [-5.0 - 0.2 * 1.0, 0.0, 0.0], atol=1e-12)
    assert rmap.failure_mode(active)[0] == FAILURE["tensile"]


def test_shear_on_bed_plane_under_compression_reaches_coulomb():
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, beta=0.5), D)
    trial = np.array([-10.0, -1.0, 1.0])  # head plane strongly confined, bed plane over-stressed
    stress, _, active, _ = rmap(trial[None])
    expected = single_face_projection(trial, D, [0.0, MU, 1.0], 0.0)
    np.testing.assert_allclose(stress[0], expected, atol=1e-12)
    assert stress[0, 2] == pytest.approx(-stress[0, 1] * MU, abs=1e-12)  # |tau| = sigma_n tan(phi)
    assert rmap.failure_mode(active)[0] == FAILURE["shear"]


def test_shear_on_bed_plane_without_dilatancy_keeps_the_normal_stress():
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, beta=0.5, dilatancy_bed=0.0, dilatancy_head=0.0), D)
    stress, _, _, _ = rmap(np.array([[-10.0, -1.0, 1.0]]))
    np.testing.assert_allclose(stress[0], [-10.0, -1.0, MU * 1.0], atol=1e-12)  # flow is pure slip


def test_head_plane_strength_is_raised_by_interlocking():
    D = elastic_matrix(2.4, 0.2)
    beta = 0.8
    rmap = ReturnMap(JointStrength(MU, MU, beta=beta), D)
    trial = np.array([-1.0, -10.0, 3.8])  # head: (1 + 8) 0.4 = 3.6 < 3.8; bed: 4.0
    stress, _, active, _ = rmap(trial[None])
    expected = single_face_projection(trial, D, [MU, beta * MU, 1.0], 0.0)
    np.testing.assert_allclose(stress[0], expected, atol=1e-12)
    assert stress[0, 2] == pytest.approx(-(stress[0, 0] + beta * stress[0, 1]) * MU, abs=1e-12)
    assert active[0].tolist() == [False, False, True, False]
    # without interlocking the same state would be far beyond the head strength 0.4
    assert JointStrength(MU, MU).faces()[0][2] @ trial > 3.0


def test_eq14_cohesion_and_tensile_strength_of_the_head_plane():
    # sigma_t1 = sigma_t0,1 - beta sigma_n2 + c0,2 beta / tan(phi_2); c_1 = c0,1 - (beta sigma_n2 - c0,2 beta/tan(phi_2)) tan(phi_1)
    s = JointStrength(0.5, 0.6, cohesion_bed=0.2, cohesion_head=0.1, tensile_bed=0.0, tensile_head=0.05, beta=0.7)
    A, b, _, names = s.faces()
    syy = -3.0
    head_plus, head_cut = names.index("head+"), names.index("head_cutoff")
    # on the head plane with sigma_n2 = syy: cut-off at sxx = sigma_t1, Coulomb at |tau| = c_1 - sxx tan(phi_1)
    sigma_t1 = 0.05 - 0.7 * syy + 0.2 * 0.7 / 0.5
    c_1 = 0.1 - (0.7 * syy - 0.2 * 0.7 / 0.5) * 0.6
    assert A[head_cut] @ [sigma_t1, syy, 0.0] == pytest.approx(b[head_cut])
    assert A[head_plus] @ [0.0, syy, c_1] == pytest.approx(b[head_plus])


def test_corner_of_two_surfaces_matches_the_energy_projection():
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, beta=1.0), D)
    # from the corner (sxx, syy, tau) = (0, -2, 0.8) (with beta = 1, bed+ and head+ both at yield)
    # along D (n_bed + n_head / 2): the return must come back to the corner
    corner = np.array([0.0, -2.0, 0.8])
    trial = corner + D @ (rmap.A[0] + 0.5 * rmap.A[2])
    stress, _, active, _ = rmap(trial[None])
    assert active[0].tolist() == [True, False, True, False]
    np.testing.assert_allclose(stress[0], corner, atol=1e-12)
    np.testing.assert_allclose(stress[0], energy_projection(trial, D, rmap.A, rmap.b), atol=2e-6)
    assert yield_values(rmap, stress)[0, [0, 2]] == pytest.approx([0.0, 0.0], abs=1e-12)


@pytest.mark.parametrize("hypothesis", ["plane_stress", "plane_strain"])
def test_random_trials_match_the_energy_projection(hypothesis):
    D = elastic_matrix(2.4, 0.2, hypothesis)
    strength = JointStrength(MU, 0.5, cohesion_bed=0.3, cohesion_head=0.1, tensile_bed=0.2, beta=0.6)
    rmap = ReturnMap(strength, D)
    assert "bed_cutoff" in rmap.names and "head_cutoff" in rmap.names
    trials = np.random.default_rng(1).normal(size=(60, 3)) * 3
    stress, _, _, _ = rmap(trials)
    reference = np.array([energy_projection(t, D, rmap.A, rmap.b) for t in trials])
    np.testing.assert_allclose(stress, reference, atol=2e-6)


def test_consistent_tangent_matches_finite_differences():
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, cohesion_bed=0.2, cohesion_head=0.2, tensile_bed=0.1, beta=0.8), D,
                     vertex_stiffness=0.0)
    strains = np.random.default_rng(2).normal(size=(200, 3))
    _, tangent, active, _ = rmap(strains @ D.T)
    h = 1e-6
    fd = np.stack([
        (rmap((strains + h * e) @ D.T)[0] - rmap((strains - h * e) @ D.T)[0]) / (2 * h) for e in np.eye(3)
    ], axis=2)
    # points exactly on a switch between active sets have no derivative; random trials hit none
    np.testing.assert_allclose(tangent, fd, atol=1e-6)
    assert (active.sum(axis=1) == 3).any() and (active.sum(axis=1) == 2).any() and (active.sum(axis=1) == 1).any()


def test_vertex_tangent_is_the_stated_fraction_of_elasticity():
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, beta=0.8), D, vertex_stiffness=1e-3)
    normals = rmap.A[[0, 1, 2]]  # bed+, bed-, head+
    trial = D @ normals.T @ np.array([1.0, 2.0, 0.5])  # in the cone of D n at the apex: returns to 0
    stress, tangent, active, _ = rmap(trial[None])
    np.testing.assert_allclose(stress[0], 0.0, atol=1e-12)
    assert active[0].sum() == 3
    np.testing.assert_allclose(tangent[0], 1e-3 * D, atol=1e-14)


def test_vectorised_return_puts_many_points_on_or_inside_the_yield_surface():
    D = elastic_matrix(2.4, 0.2)
    rmap = ReturnMap(JointStrength(MU, MU, beta=0.8), D)
    trials = np.random.default_rng(3).normal(size=(100_000, 3))
    stress, _, _, _ = rmap(trials)
    assert (yield_values(rmap, stress) <= 1e-9 * (1 + np.abs(trials).max(axis=1, keepdims=True))).all()
