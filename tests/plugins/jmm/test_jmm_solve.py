"""The jmm solver through masonryfw.solve on a small wall: result format, gravity, settlement, interruption."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_jmm.newton import NewtonSolver, State
from masonryfw_jmm.options import INCREMENTAL_OPTIONS
from masonryfw_jmm.problem import build_problem
from masonryfw_jmm.solver import History, _gravity_stage, elastic_unloading_settlement

FAST = {"mesh_size": 0.025, "max_steps": 6, "first_increment": 0.2}


@pytest.fixture(scope="module")
def model(small_wall):
    return small_wall


@pytest.fixture(scope="module")
def result(model):
    return mf.solve(model, "jmm", FAST)


def test_result_has_the_format_variables(result):
    for name in ["mesh_node_x", "mesh_node_y", "mesh_face_nodes", "mesh_node_ux", "mesh_node_uy",
                 "qp_x", "qp_y", "qp_failure", "step_settlement", "step_reaction", "step_newton_iterations",
                 "crack_indicator"]:
        assert name in result, name
    assert mf.check(result) == []
    assert set(np.unique(result.qp_failure.values)) <= {0, 1, 2, 3}
    assert ((result.crack_indicator.values >= 0) & (result.crack_indicator.values <= 1)).all()


def test_mesh_covers_the_wall_and_follows_the_courses(result):
    # 0.4 x 0.2 m in 25 mm cells: 16 x 8 cells, two triangles each; every course line is a mesh line
    assert result.sizes["mesh_face"] == 2 * 16 * 8
    y = np.unique(np.round(result.mesh_node_y.values, 9))
    assert set(np.round(np.arange(0, 0.2001, 0.05), 9)) <= set(y)


def test_gravity_reaction_splits_the_weight(result, model):
    weight = 12000.0 * 0.4 * 0.2 * 0.1
    first = float(result.step_reaction.values[0])
    # the moving support carries part of the weight; an elastic wall on a rigid base gives it about half
    assert 0.3 * weight < first < 0.7 * weight
    assert result.step_settlement.values[0] == 0.0


def test_settlement_unloads_the_moving_support(result):
    reaction = result.step_reaction.values
    settlement = result.step_settlement.values
    assert np.all(np.diff(settlement) > 0)
    assert reaction[-1] < reaction[0]
    assert np.all(np.diff(reaction) <= 1e-9 * reaction[0])
    assert (result.qp_failure.values > 0).any()


def test_interrupt_keeps_the_converged_steps(model):
    calls = []

    def progress(fraction, message):
        calls.append(message)
        if sum(m.startswith("step") for m in calls) == 2:  # reported: step 1, step 2; then the user presses ctrl-c
            raise KeyboardInterrupt

    result = mf.solve(model, "jmm", FAST, progress)
    assert result.attrs["interrupted"] == 1
    assert result.sizes["step"] == 3  # gravity + the two converged settlement steps
    assert "qp_failure" in result


def test_beta_from_the_unit_geometry(result):
    # beta = tan(phi) b / (2a) = 0.4 * 100 / (2 * 50) for 100 x 50 mm units
    assert result.attrs["jmm_beta"] == pytest.approx(0.4, rel=1e-3)


def test_bad_option_is_named(small_wall):
    with pytest.raises(mf.MasonryError, match="mesh_size"):
        mf.solve(small_wall, "jmm", {"mesh_size": -1.0})


FIXED = {**FAST, "max_steps": 4, "target_iterations": 30}  # steps grow by 1.5 whatever the Newton work: the same
# settlements in runs that are compared


def reactions_at(result, settlements):
    """The reaction history interpolated at ``settlements`` (step sizes adapt to the Newton work)."""
    return np.interp(settlements, result.step_settlement.values, result.step_reaction.values)


def test_tangent_regularisation_does_not_move_the_result(model):
    # kappa only changes the Newton direction; the converged reactions agree to the Newton tolerance
    reference = mf.solve(model, "jmm", FIXED)
    other = mf.solve(model, "jmm", {**FIXED, "vertex_stiffness": 3e-2, "settled_stiffness": 3e-2})
    common = reference.step_settlement.values[reference.step_settlement.values <= other.step_settlement.values[-1]]
    np.testing.assert_allclose(reactions_at(other, common), reactions_at(reference, common), rtol=2e-3)


def test_apex_regularisation_changes_the_reaction_by_less_than_its_size(model):
    # apexes moved by 1e-3 gamma H (default) against 1e-4: reactions (interpolated between steps) within 1 %
    reference = mf.solve(model, "jmm", FIXED)
    finer = mf.solve(model, "jmm", {**FIXED, "apex_shift": 1e-4})
    common = reference.step_settlement.values[reference.step_settlement.values <= finer.step_settlement.values[-1]]
    np.testing.assert_allclose(reactions_at(finer, common), reactions_at(reference, common), rtol=1e-2)


def test_cholesky_and_lu_take_the_same_newton_path(model, monkeypatch):
    # associated flow: CHOLMOD on the SPD tangent; the SuperLU fallback (no cvxopt) must give the same iterates
    cholesky = mf.solve(model, "jmm", FIXED)
    monkeypatch.setattr("masonryfw.runtime.linalg.has_cholmod", lambda: False)
    lu = mf.solve(model, "jmm", FIXED)
    np.testing.assert_array_equal(lu.step_newton_iterations.values, cholesky.step_newton_iterations.values)
    np.testing.assert_allclose(lu.step_reaction.values, cholesky.step_reaction.values, rtol=1e-9)


def test_newton_tolerance_does_not_move_the_reaction(model):
    # the residual is recomputed in full at every step, so a loose tolerance does not accumulate: the
    # default 1e-3 against 1e-5 (3x the iterations) on the same settlements (equal steps the tight
    # tolerance can take without cuts)
    even = {**FIXED, "first_increment": 0.1, "max_increment": 0.1, "max_iterations": 60}
    reference = mf.solve(model, "jmm", {**even, "tolerance": 1e-5})
    default = mf.solve(model, "jmm", even)
    common = default.step_settlement.values[default.step_settlement.values <= reference.step_settlement.values[-1]]
    np.testing.assert_allclose(reactions_at(reference, common), reactions_at(default, common), rtol=1e-5)
    assert reference.step_newton_iterations.values[1:].sum() > default.step_newton_iterations.values[1:].sum()


def test_elastic_unloading_settlement_is_one_linear_solve(model):
    # the reference solves K_ff du_f = -K_fm d_m with SciPy on the gravity state's tangent: the settlement
    # that would unload the support if the wall stayed on that tangent (it sizes the steps and the plateau)
    options = {**{o.name: o.default for o in INCREMENTAL_OPTIONS}, **FAST}
    problem = build_problem(mfp.derive_geometry(model), options)
    newton = NewtonSolver(problem, options["tolerance"], options["max_iterations"])
    state, _ = _gravity_stage(newton, State.initial(problem), History())
    K = problem.disc.stiffness(newton._regularised(state, False)).tocsc()
    free, moving = newton.free, problem.moving
    du = np.zeros(problem.disc.ndof)
    du[moving] = problem.moving_direction
    du[free] = spla.spsolve(K[free][:, free], -(K[free][:, moving] @ problem.moving_direction))
    slope = (K @ du)[moving[moving % 2 == 1]].sum()  # one support translating down: its vertical reaction
    settlement, measured_slope = elastic_unloading_settlement(newton, state)
    assert measured_slope == pytest.approx(slope, rel=1e-6)
    assert settlement == pytest.approx(newton.reaction(state) / -slope, rel=1e-6)


def test_the_gravity_stage_reports_every_newton_iteration():
    """On a big wall the gravity stage's iterations take seconds each (the gable house: minutes in all); each
    is reported with its residual, which falls to the tolerance."""
    messages: list[str] = []
    mf.solve(mf.open_model("test-12c"), "jmm", {"max_steps": 1},
             progress=lambda fraction, message="": messages.append(message))
    gravity = [m for m in messages if m.startswith("gravity 1: Newton iteration")]
    assert len(gravity) >= 2
    residuals = [float(m.split("residual ")[1].split(" ")[0]) for m in gravity]
    assert residuals[-1] <= 1e-3 < residuals[0]


def test_a_gravity_stage_cut_into_short_rounds_goes_on_from_where_it_got():
    """Panel 1's gravity stage (29 Newton iterations in one round) in rounds of twelve (max_iterations 3): each
    round goes on from the last one's iterate, the weight is never halved, and the state reached carries the
    weight as the long round's does (the moving support's reaction to the Newton tolerance). Restarting from the
    start threw a round's work away: on the drawn gable house a round of 120 iterations fell short at full
    weight, then at a half and a quarter."""
    options = {o.name: o.default for o in INCREMENTAL_OPTIONS}
    problem = build_problem(mfp.derive_geometry(mf.open_model("panel-1")), options)
    long_round = NewtonSolver(problem, options["tolerance"], options["max_iterations"])
    reference, _ = _gravity_stage(long_round, State.initial(problem), History())
    messages: list[str] = []
    short_rounds = NewtonSolver(problem, options["tolerance"], 3)
    state, failure = _gravity_stage(short_rounds, State.initial(problem), History(),
                                    lambda fraction, message="": messages.append(message))
    assert failure == ""
    assert all(m.startswith("gravity 1:") for m in messages)
    assert sum(m.startswith("gravity 1: Newton iteration 2,") for m in messages) == 3  # three rounds, none halved
    weight = float(np.linalg.norm(problem.gravity))
    assert short_rounds.reaction(state) == pytest.approx(long_round.reaction(reference),
                                                         abs=options["tolerance"] * weight)
