"""la with non-associative friction: joints that slide without opening.

References: closed forms (a unit between a base and a cap; rocking; a unit over a
settling support; cohesion), the associative alpha as an upper bound, the same
wall in another block order and in millimetres, and the other backends.
"""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

from .test_la_closed_forms import single_unit, unit_on_two_supports

NONASSOCIATIVE = {"flow": "nonassociative"}
STATE = mfp.flags("interface_state")


def capped_unit(walls, b=0.4, h=0.3, mu=0.5):
    """A b x h unit on a fixed base under a fixed cap that only touches it, pushed sideways by its weight."""
    role = walls.ROLE
    return walls.rect_model([(-1.0, -0.2, 2.0, 0.0), (0.0, 0.0, b, h), (-1.0, h, 2.0, h + 0.2)],
                            [role["fixed_support"], role["unit"], role["fixed_support"]], friction=mu)


@pytest.mark.parametrize("backend", ["highs", "ipm", "clarabel"])
@pytest.mark.parametrize("mu", [0.3, 0.5, 0.8])
def test_a_capped_unit_slides_at_mu_without_dilatancy(walls, backend, mu):
    """The cap carries nothing (zero initial contact force), so only the base resists: alpha = mu exactly.
    Associative joints would have to open as they slide, which the cap forbids: no mechanism at all."""
    model = capped_unit(walls, mu=mu)
    with pytest.raises(mf.SolveError, match="can carry any multiple"):
        walls.solve(model, solver=backend)
    result = walls.solve(model, solver=backend, **NONASSOCIATIVE)
    assert float(result.collapse_multiplier) == pytest.approx(mu, rel=1e-7)
    assert result.attrs["flow_rule"] == "nonassociative"
    assert np.isnan(result.attrs["la_alpha_associative"])
    u = mfp.block_motion(result)[1]
    assert u[1] == pytest.approx(0.0, abs=1e-7) and u[2] == pytest.approx(0.0, abs=1e-7)  # slides flat
    assert set(result.interface_state.values.tolist()) == {STATE["slide"]}  # slip without opening


@pytest.mark.parametrize("b, h, mu", [(0.4, 1.0, 0.65), (0.3, 0.6, 0.6), (1.0, 0.5, 0.4), (0.6, 0.8, 0.3)])
def test_a_free_unit_rocks_or_slides_as_in_the_associative_closed_form(walls, b, h, mu):
    """alpha = min(b/h, mu): rocking needs no slip; a free unit sliding on its base does no dilatancy work."""
    result = walls.solve(single_unit(walls, b, h, friction=mu), **NONASSOCIATIVE)
    assert float(result.collapse_multiplier) == pytest.approx(min(b / h, mu), rel=1e-6)


@pytest.mark.parametrize("a", [0.1, 0.35, 0.7])
def test_a_unit_over_a_settling_support_pivots_as_in_the_closed_form(walls, a):
    expected = 1.0 if a >= 0.5 else 1.0 - (0.5 - a) / (1.0 - a) ** 2
    result = walls.solve(unit_on_two_supports(walls, a), **NONASSOCIATIVE)
    assert float(result.collapse_multiplier) == pytest.approx(expected, abs=1e-6)


@pytest.mark.parametrize("mu, cohesion, tension", [(0.4, 200.0, 0.0), (0.8, 1000.0, 500.0)])
def test_cohesion_and_tension_as_in_the_associative_closed_form(walls, mu, cohesion, tension):
    """Sliding: alpha W = mu W + c b s (the capacity of the normal force W); rocking with the tension."""
    b, h, s, gamma = 0.5, 1.0, 0.1, 12e3
    weight = gamma * b * h * s
    model = single_unit(walls, b, h, friction=mu, cohesion=cohesion, tensile_strength=tension, thickness=s)
    ft = min(tension, cohesion / mu)
    expected = min(b / h + ft * s * b**2 / (weight * h), mu + cohesion * b * s / weight)
    assert float(walls.solve(model, **NONASSOCIATIVE).collapse_multiplier) == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("case", mf.CASE_NAMES)
def test_the_associative_alpha_bounds_the_nonassociative_one_on_every_bundled_wall(walls, case):
    model = mf.open_model(case)
    associative = walls.solve(model)
    result = walls.solve(model, **NONASSOCIATIVE)
    alpha, bound = float(result.collapse_multiplier), float(associative.collapse_multiplier)
    assert result.attrs["la_flow_converged"] == 1
    assert result.attrs["la_alpha_associative"] == pytest.approx(bound, abs=1e-9)
    assert alpha <= bound + 1e-6
    if not np.isin(associative.interface_state.values, [STATE["slide"], STATE["open_slide"]]).any():
        assert alpha == pytest.approx(bound, abs=1e-5)  # no slip in the associative mechanism: no difference


def test_the_chosen_solution_does_not_depend_on_block_order_or_units(walls):
    model = mf.open_model("test-12c")
    reference = float(walls.solve(model, **NONASSOCIATIVE).collapse_multiplier)
    rng = np.random.default_rng(3)
    shuffled = mt.permuted(model, rng.permutation(model.sizes["block"]), rng.permutation(model.sizes["interface"]))
    assert float(walls.solve(shuffled, **NONASSOCIATIVE).collapse_multiplier) == pytest.approx(reference, abs=1e-5)
    in_mm = mt.scaled(model, 1000.0)
    assert float(walls.solve(in_mm, **NONASSOCIATIVE).collapse_multiplier) == pytest.approx(reference, abs=1e-5)


def test_an_iteration_that_does_not_converge_says_so(walls, caplog):
    model = mf.open_model("test-12c")
    result = walls.solve(model, flow="nonassociative", flow_iterations=2)
    assert result.attrs["la_flow_converged"] == 0
    assert "did not converge" in result.attrs["stop_reason"]
    assert "did not converge" in caplog.text


@pytest.mark.parametrize("case", ["test-12c", "panel-1"])
def test_the_regularised_lp_selects_the_least_squared_normal_forces(case, monkeypatch, nonassociative_lp):
    """One regularised ipm solve gives the LP's alpha and the forces of the selection QP (a second
    formulation: HiGHS's LP, then Clarabel on the optimal face)."""
    from masonryfw_la import backends, ipm, nonassociative

    lp = nonassociative_lp(case)
    exact = backends.solve_lp("highs", lp.cost, lp.constraints, lp.live, 1e-10)
    monkeypatch.setattr(nonassociative, "SELECTION_TOLERANCE", 1e-10)
    rows = nonassociative.selection_rows(lp) > 0
    selected = nonassociative.least_squared_forces(lp.cost, lp.constraints, lp.live, rows * 1.0, exact.alpha_primal,
                                                   1e-10)
    regularised = ipm.solve(lp.cost, lp.constraints, lp.live, nonassociative.SELECTION_IPM_TOLERANCE,
                            weight=nonassociative.SELECTION_WEIGHT * rows)
    assert regularised.lam == pytest.approx(exact.alpha_primal, abs=1e-9)
    assert np.abs(regularised.y[rows] - selected[rows]).max() < 5e-5  # forces over the dead load
    equilibrium = lp.constraints.T @ regularised.y + regularised.lam * lp.live - lp.cost
    assert np.abs(equilibrium).max() < 1e-8


def test_an_inexact_regularisation_is_corrected_by_the_exact_finish(walls, monkeypatch):
    """With a weight far above the exactness threshold the regularised LPs select other forces; the finish with
    the exact selection (the QP) still ends where the sequence of LP + QP does from the start (highs), and where
    it does from the default weight, to the flow tolerance."""
    from masonryfw_la import nonassociative

    model = mf.open_model("panel-2")
    default = float(walls.solve(model, **NONASSOCIATIVE).collapse_multiplier)
    by_qp = float(walls.solve(model, solver="highs", **NONASSOCIATIVE).collapse_multiplier)
    monkeypatch.setattr(nonassociative, "SELECTION_WEIGHT", 10.0)
    result = walls.solve(model, **NONASSOCIATIVE)
    assert result.attrs["la_flow_converged"] == 1
    assert float(result.collapse_multiplier) == pytest.approx(by_qp, abs=1e-6)
    assert float(result.collapse_multiplier) == pytest.approx(default, abs=1e-6)


def test_an_lp_that_fails_mid_sequence_stops_it_with_the_last_iterate(walls, monkeypatch, caplog):
    """Minutes of work are not thrown away for one LP: the last iterate, flagged, with the reason."""
    from masonryfw_la import nonassociative

    solved = nonassociative.selected_solution
    calls = []

    def failing_third(selection, programme):
        calls.append(programme)
        if len(calls) == 3:
            raise mf.SolveError("la: the least-compression contact forces were not found (Clarabel: MaxIterations)")
        return solved(selection, programme)

    monkeypatch.setattr(nonassociative, "selected_solution", failing_third)
    result = walls.solve(mf.open_model("test-12c"), **NONASSOCIATIVE)
    assert result.attrs["la_flow_converged"] == 0
    assert result.attrs["la_flow_iterations"] == 2
    assert "LP 3 of the non-associative sequence failed" in result.attrs["stop_reason"]
    assert "MaxIterations" in caplog.text
    assert 0.7 < float(result.collapse_multiplier) < 0.76  # between the non-associative 0.7465 and the associative 0.7517


_ORDERS_SCRIPT = """
import json, numpy as np, masonryfw as mf
from masonryfw.testing import permuted, small_settlement_wall
model = small_settlement_wall()
alphas = []
for seed in range(4):
    rng = np.random.default_rng(seed)
    shuffled = permuted(model, rng.permutation(model.sizes["block"]), rng.permutation(model.sizes["interface"]))
    alphas.append(float(mf.solve(shuffled, "la", {"flow": "nonassociative"}).collapse_multiplier))
print(json.dumps(alphas))
"""


def test_the_nonassociative_answer_depends_on_neither_block_order_nor_thread_count():
    """The conformance kit's wall (a small wall whose regularised selection moved with the round-off: alpha
    spread 4.4e-6 over 12 block orders before the exact finish) in four block orders, with one and with two
    BLAS/OpenMP threads: one alpha to 1e-7 (measured spread 2e-8), the flow tolerance being 1e-6."""
    import json
    import os
    import subprocess
    import sys

    alphas = []
    for threads in ("1", "2"):
        env = {**os.environ, "OMP_NUM_THREADS": threads, "OPENBLAS_NUM_THREADS": threads, "NUMBA_NUM_THREADS": threads}
        done = subprocess.run([sys.executable, "-c", _ORDERS_SCRIPT], env=env, capture_output=True, text=True,
                              timeout=300)
        assert done.returncode == 0, done.stderr
        alphas += json.loads(done.stdout.strip().splitlines()[-1])
    assert max(alphas) / min(alphas) - 1 < 1e-7, alphas


def test_a_failed_exact_finish_reports_the_regularised_fixed_point_and_says_so(walls, monkeypatch):
    """The finish's QP can fail (Clarabel's iteration cap on the 1,000-unit wall): the sequence's regularised
    fixed point is then reported, converged, and the result says the finish failed; its alpha is the exact
    one's to the selections' spread (docs/la.md: up to 1.5e-5)."""
    from masonryfw_la import nonassociative

    model = mf.open_model("panel-2")
    exact = walls.solve(model, **NONASSOCIATIVE)

    def failing(*args):
        raise mf.SolveError("la: the least-compression contact forces were not found (Clarabel: MaxIterations)")

    monkeypatch.setattr(nonassociative, "least_squared_forces", failing)
    result = walls.solve(model, **NONASSOCIATIVE)
    assert result.attrs["la_flow_converged"] == 1 and "stop_reason" not in result.attrs
    assert "exact finish by LP + QP: failed at LP" in result.attrs["la_flow_selection"]
    assert "exact finish by LP + QP (docs/la.md)" in exact.attrs["la_flow_selection"]
    assert result.attrs["la_flow_iterations"] < exact.attrs["la_flow_iterations"]
    assert float(result.collapse_multiplier) == pytest.approx(float(exact.collapse_multiplier), abs=2e-5)


def test_a_second_start_from_zero_forces_says_whether_it_ends_at_the_same_alpha(walls, caplog):
    """Option flow_starts = 2: Test 12C's sequence from zero normal forces ends where the one from the associative
    forces does (measured 6.8e-10 apart); Panel 1's does not converge in 100 LPs from zero (it oscillates 7.4e-6 off
    the first start's alpha), and the result says the starts do not agree."""
    agreeing = walls.solve(mf.open_model("test-12c"), flow="nonassociative", flow_starts=2)
    assert agreeing.attrs["la_flow_starts_agree"] == 1
    assert agreeing.attrs["la_flow_alpha_from_zero"] == pytest.approx(float(agreeing.collapse_multiplier), abs=1e-6)
    assert "do not agree" not in caplog.text
    disagreeing = walls.solve(mf.open_model("panel-1"), flow="nonassociative", flow_starts=2)
    assert disagreeing.attrs["la_flow_starts_agree"] == 0
    assert "the two starts do not agree" in caplog.text and "(not converged)" in caplog.text
