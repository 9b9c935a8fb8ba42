"""jmm-limit: the static (lower-bound) LP of the JMM continuum against closed forms and the incremental plateau.

References, all independent of the LP:
- shear block: the base shear can never exceed mu p L (Coulomb on the bed plane of any horizontal
  section), and the incremental test (test_jmm_fem.py) reaches it;
- settlement: the rigid wedge over the moving support bounded by the line from the support edge
  inclined at phi to the vertical. Its velocity jump (0, -1) makes the angle phi with that line,
  so the strain rate is (0, sin phi, -cos phi), the flow direction of the bed- face, and with
  c = 0 it dissipates nothing: every admissible stress field has R >= W_wedge (virtual work), i.e.
  alpha <= gamma t h^2 tan(phi) / 2 / R_0. The static LP gives alpha <= the exact value <= this bound;
- the rigid unit of the LA closed form (tests/plugins/la/test_la_closed_forms.py), which the
  continuum (joints everywhere) can only undercut.
"""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshTri

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_jmm.limit import StaticField, settlement_lp, solve_lp
from masonryfw_jmm.material import JointStrength

MU = 0.4
STRENGTH = JointStrength(MU, MU, beta=0.8)
ROLE = mfp.flags("block_role")
FLAG = mfp.flags("qp_failure")


def rectangle_field(width, height, nx, ny):
    mesh = MeshTri.init_tensor(np.linspace(0, width, nx + 1), np.linspace(0, height, ny + 1))
    return StaticField(mesh.p, mesh.t, np.ones(mesh.t.shape[1]))


def boundary_where(field, test):
    """Boundary edge occurrences whose midpoint passes ``test(x, y)``."""
    E = field.edges
    ends = field.triangles[E.local[E.boundary], E.element[E.boundary][:, None]]
    x, y = field.points[0, ends].mean(axis=1), field.points[1, ends].mean(axis=1)
    return E.boundary[test(x, y)]


def shear_block_limit(n, width=1.0, height=0.5, pressure=1.0):
    """Largest base shear of a weightless JMM block: base held, top plate (ty = -p, tx free), sides ty = 0, tx free."""
    field = rectangle_field(width, height, *n)
    base = boundary_where(field, lambda x, y: np.isclose(y, 0.0))
    top = boundary_where(field, lambda x, y: np.isclose(y, height))
    sides = boundary_where(field, lambda x, y: np.isclose(x, 0.0) | np.isclose(x, width))
    equilibrium, load = field.equilibrium(np.zeros((field.n_el, 2)))
    continuity = field.continuity()
    top_y = field.boundary_traction(top)[1::2]
    side_y = field.boundary_traction(sides)[1::2]
    equalities = sp.vstack([equilibrium, continuity, top_y, side_y], format="csr")
    rhs = np.concatenate([load, np.zeros(continuity.shape[0]), -pressure * np.ones(top_y.shape[0]),
                          np.zeros(side_y.shape[0])])
    A, b, _, _ = JointStrength(MU, MU, beta=1.5).faces()
    corner = np.repeat(np.arange(3 * field.n_el), A.shape[0])
    face = np.tile(np.arange(A.shape[0]), 3 * field.n_el)
    inequalities, bounds = field.strength(A, b, corner, face)
    base_force_x = field.boundary_resultant(base).toarray()[0]  # force of the base on the block
    return -solve_lp(base_force_x, equalities, rhs, inequalities, bounds).objective


def test_shear_block_limit_approaches_mu_p_from_below():
    shears = [shear_block_limit(n) for n in [(4, 2), (8, 4), (16, 8)]]
    # lower bounds: never above mu p L, rising with the mesh (measured 0.3750, 0.3961, 0.3997)
    assert all(s <= MU * (1 + 1e-7) for s in shears), shears
    assert shears[0] < shears[1] < shears[2]
    assert shears[2] == pytest.approx(MU, rel=2e-3)


def unit_alpha(a, n, b=1.0, h=0.5):
    """alpha of a b x h JMM body (unit weight 1, c = 0) on fixed [0, a] and moving [a, b]."""
    field = rectangle_field(b, h, *n)
    fixed = boundary_where(field, lambda x, y: np.isclose(y, 0.0) & (x < a))
    moving = boundary_where(field, lambda x, y: np.isclose(y, 0.0) & (x > a))
    A, bounds, _, _ = STRENGTH.faces()
    lp = settlement_lp(field, np.ones(field.n_el), np.arange(field.n_el), A, bounds, fixed, moving)
    assert lp.dead_reaction == pytest.approx(h * b * (b - a) / b)  # W L_moving / L_contact
    sol = solve_lp(lp.cost, lp.equalities, lp.rhs, lp.inequalities, lp.bounds)
    return 1.0 - sol.objective / lp.dead_reaction


def wedge_alpha(a, b=1.0, h=0.5):
    """The phi-wedge mechanism: alpha = (h^2 tan(phi) / 2) / (h (b - a)), valid while h tan(phi) <= b - a."""
    assert h * MU <= b - a
    return h * MU / (2 * (b - a))


def rigid_unit_alpha(a, b=1.0):
    """LA closed form for a rigid unit: 1 if the centroid is over the fixed part, else 1 - b(b/2 - a)/(b - a)^2."""
    return 1.0 if a >= b / 2 else 1.0 - b * (b / 2 - a) / (b - a) ** 2


@pytest.mark.parametrize("a", [0.1, 0.3, 0.45, 0.5])
def test_unit_over_a_settling_support_meets_the_wedge_mechanism(a):
    alpha = unit_alpha(a, (20, 10))
    # static LP <= exact <= wedge bound; here they meet (to the LP tolerance) on a 20 x 10 mesh already
    assert alpha == pytest.approx(wedge_alpha(a), abs=1e-6)
    # the continuum is far weaker than the rigid unit (0.11 against 0.51 at a = 0.1)
    assert alpha < rigid_unit_alpha(a)


def test_unit_with_the_wedge_near_the_free_side_converges_from_below():
    coarse, fine = unit_alpha(0.7, (20, 10)), unit_alpha(0.7, (40, 20))
    exact = wedge_alpha(0.7)  # 1/3; the rigid unit stands (alpha 1)
    assert coarse < fine <= exact + 1e-7  # measured 0.3269, 0.33333
    assert fine == pytest.approx(exact, abs=1e-5)


def limit(model, **given):
    return mf.solve(model, "jmm-limit", given)


def wedge_reaction(model, height, fixed_end, wall_end):
    """R of the phi-wedge mechanism: weight over the moving support less the wedge gamma t h^2 tan(phi) / 2."""
    gamma, t = 12000.0, float(model.block_thickness.values[0])
    tan_phi = np.tan(np.radians(21.8))
    return gamma * t * height * (wall_end - fixed_end) - gamma * t * height**2 * tan_phi / 2


def test_limit_result_format_and_dead_reaction(small_wall):
    result = limit(small_wall, mesh_size=0.025)
    assert mf.check(result) == []
    for name in ["mesh_node_x", "mesh_node_y", "mesh_face_nodes", "qp_x", "qp_y", "qp_failure",
                 "collapse_multiplier", "moving_support_reaction", "crack_indicator"]:
        assert name in result, name
    assert result.attrs["solver"] == "jmm-limit"
    assert result.sizes["qp"] == 3 * result.sizes["mesh_face"]
    # R_0: the paper's settlement dead load, as the builder puts it on the moving support block
    moving = int(np.nonzero(small_wall.block_role.values == ROLE["moving_support"])[0][0])
    assert result.attrs["jmm_dead_reaction_n"] == pytest.approx(float(small_wall.dead_load.values[moving, 1]))
    alpha = 1.0 - float(result.moving_support_reaction) / result.attrs["jmm_dead_reaction_n"]
    assert float(result.collapse_multiplier) == pytest.approx(alpha)
    assert (result.qp_failure.values == FLAG["shear"]).any()
    assert ((result.crack_indicator.values >= 0) & (result.crack_indicator.values <= 1)).all()


def test_small_wall_limit_reaction_falls_towards_the_wedge_bound(small_wall):
    exact_bound = wedge_reaction(small_wall, 0.2, 0.2, 0.4)  # 38.4 N
    coarse = float(limit(small_wall, mesh_size=0.05, apex_shift=0.0).moving_support_reaction)
    fine = float(limit(small_wall, mesh_size=0.025, apex_shift=0.0).moving_support_reaction)
    # statically admissible fields: R >= the mechanism's R (virtual work); the bound drops as the mesh is refined
    assert exact_bound <= fine < coarse  # measured 38.40 <= 39.81 < 40.98
    assert fine == pytest.approx(exact_bound, rel=0.05)


def test_small_wall_incremental_plateau_is_below_the_static_bound(small_wall):
    # the incremental run (displacement FE: too strong, so its reaction too low) against the static LP
    # (too weak: reaction too high) on the same 25 mm mesh; measured 36.28 N < 38.40 N (wedge) < 39.78 N
    static = float(limit(small_wall, mesh_size=0.025).moving_support_reaction)
    plateau = float(mf.solve(small_wall, "jmm", {"mesh_size": 0.025}).step_reaction.values[-1])
    assert plateau < wedge_reaction(small_wall, 0.2, 0.2, 0.4) < static
    assert plateau == pytest.approx(static, rel=0.1)


@pytest.fixture(scope="module")
def test_12c():
    return mf.open_model("test-12c")


def test_12c_limit_is_the_wedge_mechanism(test_12c):
    # 1100 x 600 mm wall, fixed [0, 0.5], moving [0.5, 1.1] m: the phi-wedge gives R = 345.61 N, alpha 0.2000
    bound = wedge_reaction(test_12c, 0.6, 0.5, 1.1)
    coarse = limit(test_12c, mesh_size=0.1, apex_shift=0.0)
    fine = limit(test_12c, mesh_size=0.05, apex_shift=0.0)
    r_coarse, r_fine = float(coarse.moving_support_reaction), float(fine.moving_support_reaction)
    assert bound * (1 - 1e-9) <= r_fine <= r_coarse  # measured 345.606, 345.673
    assert r_fine == pytest.approx(bound, rel=1e-6)
    assert float(fine.collapse_multiplier) == pytest.approx(0.6 * np.tan(np.radians(21.8)) / 2 / 0.6, rel=1e-4)
    # the plastic points draw the wedge's edge: x = 0.5 + y tan(phi), within one cell
    shear = fine.qp_failure.values == FLAG["shear"]
    x, y = fine.qp_x.values[shear], fine.qp_y.values[shear]
    assert shear.sum() > 50
    assert np.median(np.abs(x - (0.5 + y * np.tan(np.radians(21.8))))) < 0.05


def test_rotating_support_is_refused(small_wall):
    moving = int(np.nonzero(small_wall.block_role.values == ROLE["moving_support"])[0][0])
    direction, held = small_wall.settlement_direction.values.copy(), small_wall.block_fixed.values.copy()
    direction[moving], held[moving] = [0.0, -0.8, 0.6], 0
    model = small_wall.assign(settlement_direction=small_wall.settlement_direction.copy(data=direction),
                              block_fixed=small_wall.block_fixed.copy(data=held))
    with pytest.raises(mf.ModelError, match=f"jmm-limit: moving support block {moving}"):
        limit(model)


def test_12c_incremental_plateau_against_the_limit_reaction(test_12c):
    # same meshes, default options (apex_shift 1e-3 in both). The incremental plateau (displacement FE: too
    # strong) rises with the mesh towards the exact wedge value 345.6 N from below; the static LP (too weak)
    # sits on it from above. Measured: plateau 306.9 N (100 mm), 311.2 N (50 mm); static LP 345.4 N.
    static = float(limit(test_12c, mesh_size=0.05).moving_support_reaction)
    plateaus = [float(mf.solve(test_12c, "jmm", {"mesh_size": size}).step_reaction.values[-1]) for size in (0.1, 0.05)]
    assert plateaus[0] < plateaus[1] < wedge_reaction(test_12c, 0.6, 0.5, 1.1) < static * (1 + 1e-3)
    assert plateaus[1] == pytest.approx(static, rel=0.15)
