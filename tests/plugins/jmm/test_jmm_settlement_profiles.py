"""jmm under settlement profiles: per-support reactions, the settlement reaction, the crack band estimate."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

ROLE = mfp.flags("block_role")
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
    Newton tolerance), and masonry blocks carry nothing."""
    model, result = trough
    per_support = result.step_support_reaction.values
    weight = -mfp.block_loads(model, "dead")[mfp.masonry_blocks(model.block_role.values), 1].sum()
    np.testing.assert_allclose(per_support.sum(axis=1), weight, rtol=2e-3)
    assert np.all(per_support[:, mfp.masonry_blocks(model.block_role.values)] == 0)


@pytest.mark.parametrize("solver", ["jmm", "fdem"])
def test_settlement_reaction_of_supports_at_two_rates_weights_each_by_its_rate(solver):
    """Two supports translating down at rates 0.5 and 1: the settlement reaction is their vertical reactions
    weighted by rate over the fastest, 0.5 R_a + R_b (the work on the one settlement parameter), at every
    record, from the per-support reactions the solver reports beside it."""
    model = mf.build({**WALL, "supports": {"a": {"kind": "moving", "start": 0.0, "end": 0.8, "rate": 0.5},
                                           "fixed": {"kind": "fixed", "start": 0.8, "end": 1.6},
                                           "b": {"kind": "moving", "start": 1.6, "end": 2.4}}})
    options = {"mesh_size": 0.05, "max_steps": 8} if solver == "jmm" else {"settlement": 0.001}
    result = mf.solve(model, solver, options)
    a, b = (np.flatnonzero(model.block_role.values == ROLE["moving_support"]))
    per_support = result.step_support_reaction.values
    np.testing.assert_allclose(result.step_reaction.values, 0.5 * per_support[:, a] + per_support[:, b], rtol=1e-9)
    assert mf.dead_reaction(model) == pytest.approx(0.5 * float(model.dead_load.values[a, 1])
                                                    + float(model.dead_load.values[b, 1]), rel=1e-12)


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
    options = mfp.resolve_options("jmm", mf.get_solver("jmm").options, {"mesh_size": 0.05})
    problem = build_problem(mfp.derive_geometry(model), options)
    state = State.initial(problem)
    state.strain[:, 1] = 2e-3  # opening across the (horizontal) beds
    state.strain[:, 0] = 1e-3
    width, point = crack_band_width(problem, state)
    assert width == pytest.approx(2e-3 * problem.mesh_size / problem.length)
    assert problem.masonry_points[point]


def test_a_trough_under_the_whole_wall_runs_and_sheds_its_settlement_reaction():
    """The common case: every segment of the base settles (cutoff 0), at its own rate. The settlement reaction
    (the reactions' work on the one settlement parameter) drops as the wall bridges the trough, so jmm runs
    and stops on its plateau like any other settlement."""
    model = mf.build({**WALL, "settlement": {**TROUGH, "cutoff": 0.0}})
    assert not (model.block_role.values == ROLE["fixed_support"]).any()
    result = mf.solve(model, "jmm", {"mesh_size": 0.05})
    reaction = result.step_reaction.values
    assert reaction[-1] < 0.9 * reaction[0]
    assert reaction[0] == pytest.approx(mf.dead_reaction(model), rel=0.05)  # R0: elastic against uniform shares


@pytest.mark.parametrize("solver", ["jmm", "fdem"])
def test_a_base_that_settles_as_one_rigid_body_is_refused(solver):
    """Every support at one rate: the wall follows the ground rigidly, nothing deforms; a clear refusal."""
    model = mf.build({**WALL, "supports": {"a": {"kind": "moving", "start": 0.0, "end": 1.2},
                                           "b": {"kind": "moving", "start": 1.2, "end": 2.4}}})
    with pytest.raises(mf.ModelError, match=f"{solver}: every support moves by the same translation 0 -1 0 .*"
                                            "one rigid body"):
        mf.solve(model, solver)
