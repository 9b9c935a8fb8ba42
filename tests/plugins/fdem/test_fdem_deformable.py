"""fdem mode=deformable: the CST kernel against the linear B^T D B stiffness and plane-stress
uniaxial stress, a column's compression under its own weight against the closed form, the
limit E -> infinity against the rigid mode, and the energy balance."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_fdem.deformable import cst_element_forces, element_constants, fan_triangles, shape_gradients

ROLE = mfp.flags("block_role")


def plane_stress(young: float, nu: float) -> np.ndarray:
    return young / (1 - nu**2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])


def reference_stiffness(px: np.ndarray, py: np.ndarray, young: float, nu: float) -> np.ndarray:
    """Dense linear CST stiffness A B^T D B (textbook formula), dofs (u0, v0, u1, v1, u2, v2)."""
    area = 0.5 * np.linalg.det(np.array([[1, px[0], py[0]], [1, px[1], py[1]], [1, px[2], py[2]]]))
    b = np.array([py[1] - py[2], py[2] - py[0], py[0] - py[1]]) / (2 * area)
    c = np.array([px[2] - px[1], px[0] - px[2], px[1] - px[0]]) / (2 * area)
    strain = np.zeros((3, 6))
    strain[0, 0::2], strain[1, 1::2] = b, c
    strain[2, 0::2], strain[2, 1::2] = c, b
    return area * strain.T @ plane_stress(young, nu) @ strain


def internal_forces(x, y, x0, y0, triangles, young, nu):
    grad_x, grad_y, area = shape_gradients(x0, y0, triangles)
    n_tri = triangles.shape[0]
    force = np.zeros((x0.size, 2))
    packed, constants = element_constants(triangles, grad_x, grad_y, area, np.full(n_tri, young),
                                          np.full(n_tri, nu), np.ones(n_tri, dtype=np.bool_))
    energy = cst_element_forces(x, y, packed, constants, force)  # the time loop's kernel
    return force, energy


def test_cst_kernel_matches_dense_linear_stiffness_on_random_triangles():
    rng = np.random.default_rng(7)
    triangles = np.array([[0, 1, 2]])
    for _ in range(20):
        px, py = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
        if (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]) < 0:  # counter-clockwise
            px, py = px[::-1].copy(), py[::-1].copy()
        young, nu = rng.uniform(1, 10), rng.uniform(0, 0.45)
        u = rng.normal(size=6) * 1e-7
        force, energy = internal_forces(px + u[0::2], py + u[1::2], px, py, triangles, young, nu)
        stiffness = reference_stiffness(px, py, young, nu)
        expected = -stiffness @ u
        assert force.ravel() == pytest.approx(expected, rel=1e-5, abs=1e-6 * np.abs(expected).max())
        assert energy == pytest.approx(0.5 * u @ stiffness @ u, rel=1e-5)


def test_cst_rigid_rotation_carries_no_strain():
    """Green-Lagrange strain: a block rocking by 30 degrees stays unstressed (a linear CST would not)."""
    x0, y0 = np.array([0.0, 2.0, 2.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0, 1.0, 0.5])
    triangles = fan_triangles(np.array([0, 4]))
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    force, energy = internal_forces(3 + c * x0 - s * y0, -1 + s * x0 + c * y0, x0, y0, triangles, 5.0, 0.3)
    assert np.abs(force).max() < 1e-12
    assert abs(energy) < 1e-14


def test_fan_patch_under_uniaxial_stress_gives_e_eps_and_poisson_contraction():
    """A 2 x 1 rectangle meshed as a 4-triangle fan, stretched by eps along x and contracted by
    nu eps along y: the nodal forces are those of the traction sigma = E eps on the right and left
    edges (plane stress) and of no stress on the top and bottom edges."""
    young, nu, eps, width, height = 3.0, 0.25, 1e-7, 2.0, 1.0
    x0, y0 = np.array([0.0, width, width, 0.0, 1.0]), np.array([0.0, 0.0, height, height, 0.5])
    triangles = fan_triangles(np.array([0, 4]))
    force, _ = internal_forces(x0 * (1 + eps), y0 * (1 - nu * eps), x0, y0, triangles, young, nu)
    traction = young * eps * height
    assert force[[1, 2], 0].sum() == pytest.approx(-traction, rel=1e-6)  # internal force resists the stretch
    assert force[[0, 3], 0].sum() == pytest.approx(traction, rel=1e-6)
    assert np.abs(force[:, 1]).max() < 1e-6 * traction  # sigma_yy = 0: free lateral contraction
    assert np.abs(force[4]).max() < 1e-6 * traction  # uniform stress: the inner node is balanced


def column_spec(young: float) -> dict:
    return {
        "title": "column",
        "wall": {"width": 0.2, "height": 0.4, "thickness": 0.1},
        "unit": {"length": 0.2, "height": 0.05},
        "bond": {"pattern": "stack"},
        "material": {"unit_weight": 20000.0, "friction_angle": 30.0, "cohesion": 0.0, "tensile_strength": 0.0,
                     "young_modulus": young, "poisson_ratio": 0.0},
        "supports": {"ground": {"kind": "fixed", "start": 0.0, "end": 0.2}},
        "loading": {"type": "tilt", "direction": 1},
    }


def test_column_compresses_under_self_weight_by_the_closed_form():
    """8 stacked units on a fixed support: the deformable top unit sits lower than the rigid one by the
    compression of the column below its centroid, rho g (H y - y^2 / 2) / E at y = H - h / 2
    (the joints' penalty springs carry the same forces in both modes and cancel)."""
    young, unit_weight, wall_height, unit_height = 8e6, 20000.0, 0.4, 0.05
    model = mf.build(column_spec(young))
    gravity = {"rest_tolerance": 1e-7, "load_factor": 0.0}  # a tilt model, but gravity only
    deformable = mf.solve(model, "fdem", {"mode": "deformable", **gravity})
    rigid = mf.solve(model, "fdem", gravity)
    top = int(np.argmax(np.where(model.block_role.values < ROLE["fixed_support"], model.block_centroid_y.values, -1)))
    y = wall_height - unit_height / 2
    expected = unit_weight * (wall_height * y - y**2 / 2) / young
    shortening = mfp.block_motion(rigid)[top, 1] - mfp.block_motion(deformable)[top, 1]
    assert shortening == pytest.approx(expected, rel=0.01)  # measured 0.1 %
    assert np.abs(deformable.step_energy_error.values).max() < 0.01


SETTLEMENT_OPTIONS = {"settlement": 0.004, "plateau_tolerance": 0.0}


def elastic_small_wall(walls, young: float):
    spec = walls.small_wall_spec()
    spec["material"] |= {"young_modulus": young, "poisson_ratio": 0.2}
    return mf.build(spec)


def reaction_gap(result, reference, dead: float) -> float:
    """Largest reaction difference over 1-4 mm of settlement, over the dead reaction."""
    settlement = np.linspace(0.001, 0.004, 7)

    def reaction(r):
        phase = r.step_phase.values == 1
        return np.interp(settlement, r.step_settlement.values[phase], r.step_reaction.values[phase])

    return float(np.abs(reaction(result) - reaction(reference)).max() / dead)


@pytest.fixture(scope="module")
def stiff_small_wall(walls):
    model = elastic_small_wall(walls, 1e9)
    return (model, mf.solve(model, "fdem", SETTLEMENT_OPTIONS | {"mode": "deformable"}),
            mf.solve(model, "fdem", SETTLEMENT_OPTIONS))


def test_deformable_wall_approaches_the_rigid_mode_as_e_grows(walls, stiff_small_wall):
    """E = 1 GPa (units ~100x stiffer than the joints' penalty springs): the reaction history within
    0.5 % of the dead reaction of the rigid mode's, the same cracks and mechanism; E = 10 MPa is
    further from it (measured: 1.5 % against 0.2 %)."""
    model, stiff, rigid = stiff_small_wall
    dead = model.dead_load.values[model.block_role.values == ROLE["moving_support"], 1].sum()
    stiff_gap = reaction_gap(stiff, rigid, dead)
    assert stiff_gap < 0.005
    scores = mf.compare(rigid, stiff)
    assert scores.crack_f1.item() > 0.9
    assert scores.mechanism_cosine.item() > 0.99
    soft = mf.solve(elastic_small_wall(walls, 1e7), "fdem", SETTLEMENT_OPTIONS | {"mode": "deformable"})
    assert reaction_gap(soft, rigid, dead) > 2 * stiff_gap


def test_deformable_energy_balance_within_one_percent(stiff_small_wall):
    _, deformable, _ = stiff_small_wall
    assert np.abs(deformable.step_energy_error.values).max() < 0.01
    assert deformable.step_stored.values[-1] > 0


def test_deformable_mode_needs_elastic_constants(walls):
    model = mf.build(walls.small_wall_spec())
    with pytest.raises(mf.ModelError, match="block_young_modulus"):
        mf.solve(model, "fdem", {"mode": "deformable"})
