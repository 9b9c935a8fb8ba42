"""jmm under settlement profiles (issue 14): per-support reactions, the crack band estimate, rates."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf

ROLE = mf.flags("block_role")
WALL = {"title": "trough wall", "length_unit": "m", "wall": {"width": 2.4, "height": 0.4, "thickness": 0.1},
        "unit": {"length": 0.2, "height": 0.1},
        "material": {"unit_weight": 12000.0, "friction_angle": 30.0, "young_modulus": 1.2e9, "poisson_ratio": 0.2},
        "loading": {"type": "settlement"}}
TROUGH = {"profile": "gaussian", "center": 1.2, "width": 0.3, "segment": 0.2, "cutoff": 0.05, "depth": 5.0}


@pytest.fixture(scope="module")
def trough():
    model = mf.build({**WALL, "settlement": TROUGH})
    return model, mf.solve(model, "jmm", {"mesh_size": 0.05})


def test_jmm_support_reactions_carry_the_weight_at_every_step(trough):
    """Static equilibrium: at every converged step the supports together carry the wall's weight (to the
    Newton tolerance), the moving ones sum to step_reaction, and masonry blocks carry nothing."""
    model, result = trough
    per_support = result.step_support_reaction.values
    weight = -mf.block_loads(model, "dead")[mf.masonry_blocks(model.block_role.values), 1].sum()
    np.testing.assert_allclose(per_support.sum(axis=1), weight, rtol=2e-3)
    moving = model.block_role.values == ROLE["moving_support"]
    np.testing.assert_allclose(per_support[:, moving].sum(axis=1), result.step_reaction.values, rtol=1e-12)
    assert np.all(per_support[:, mf.masonry_blocks(model.block_role.values)] == 0)


def test_jmm_trough_sheds_load_from_the_settling_segments(trough):
    model, result = trough
    moving = model.block_role.values == ROLE["moving_support"]
    first, last = result.step_support_reaction.values[[0, -1]]
    assert last[moving].sum() < first[moving].sum()  # the settling ground carries less ...
    assert last[~moving].sum() > first[~moving].sum()  # ... and the fixed ground more


def test_jmm_crack_width_estimate_and_its_category(trough):
    _, result = trough
    width = result.step_crack_width_max.values
    assert width[0] < width[-1]
    assert np.all(width >= 0)
    np.testing.assert_array_equal(result.step_damage_category.values, mf.damage_category(width))
    assert "crack band" in result.step_crack_width_max.attrs["long_name"]


def test_crack_band_width_is_the_plastic_opening_strain_times_the_mesh_size():
    """A uniform plastic strain (stress zero) across the beds: the width is that strain times the mesh size
    (the definition of the estimate), in the problem's units."""
    from masonryfw_jmm.newton import State
    from masonryfw_jmm.problem import build_problem
    from masonryfw_jmm.solver import crack_band_width

    model = mf.build({**WALL, "settlement": TROUGH})
    options = mf.resolve_options("jmm", mf.get_solver("jmm").options, {"mesh_size": 0.05})
    problem = build_problem(mf.derive_geometry(model), options)
    state = State.initial(problem)
    state.strain[:, 1] = 2e-3  # opening across the (horizontal) beds
    state.strain[:, 0] = 1e-3
    assert crack_band_width(problem, state) == pytest.approx(2e-3 * problem.mesh_size / problem.length)


def test_jmm_and_fdem_refuse_a_wall_whose_every_support_settles():
    """Then the moving supports carry the whole weight whatever the settlement: no reaction drop to follow."""
    model = mf.build({**WALL, "settlement": {**TROUGH, "cutoff": 0.0}})
    assert not (model.block_role.values == ROLE["fixed_support"]).any()
    with pytest.raises(mf.ModelError, match="every support of the wall settles"):
        mf.solve(model, "jmm")
    with pytest.raises(mf.ModelError, match="plateau_tolerance=0"):
        mf.solve(model, "fdem")
