"""la in 3D with non-associative friction (joints that slide without opening), against closed forms, the planar
non-associative sequence on the 3D twins of walls, and a static check written from the definitions."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt
from masonryfw_la import limit3d, nonassociative3d

from .test_la_limit3d import boxes_on_a_base, single_box, static_residuals
from .test_la_nonassociative import capped_unit

NONASSOCIATIVE = {"solver": None, "tolerance": 1e-9, "flow_tolerance": 1e-6, "flow_relaxation": 1.0,
                  "flow_iterations": 100}


def flow(blocks: limit3d.Blocks3D) -> nonassociative3d.Flow3D:
    return nonassociative3d.solve(blocks, NONASSOCIATIVE, mfp.no_progress)


@pytest.mark.parametrize("degrees", [0.0, 30.0, 45.0, 101.0])
def test_a_block_on_an_incline_slides_at_mu_without_dilatancy_in_every_direction(degrees):
    """A 1 x 1 x 0.5 box on a tilting plane slides at tan(theta) = mu = 0.5 whatever the direction, flat: the
    associative cone lifts it by mu |slip| as it slides, the non-associative joint does not open."""
    angle = np.radians(degrees)
    blocks = single_box(1.0, 1.0, 0.5, 0.5, live_force=(np.cos(angle), np.sin(angle), 0.0))
    result = flow(blocks)
    assert result.converged and result.state.alpha == pytest.approx(0.5, rel=1e-7)
    slip = result.state.motion[1]
    assert abs(slip[2]) < 1e-7 * np.hypot(slip[0], slip[1])  # flat
    # it does not turn: a small twist costs dissipation of second order only, so the interior point leaves ~1e-5
    assert np.abs(slip[3:]).max() < 1e-4 * np.hypot(slip[0], slip[1])
    assert np.degrees(np.arctan2(slip[1], slip[0])) == pytest.approx(degrees, abs=1e-3)  # down the incline
    lifted = limit3d.limit_state_3d(blocks).motion[1]
    assert lifted[2] == pytest.approx(0.5 * np.hypot(lifted[0], lifted[1]), rel=1e-6)


@pytest.mark.parametrize("mu", [0.3, 0.6])
@pytest.mark.parametrize("degrees", [0.0, 60.0])
def test_a_sandwiched_block_slides_at_mu_where_the_associative_answer_is_no_collapse(mu, degrees):
    """A box on a fixed base under a fixed cap that only touches it: associative joints must open to slide, which
    the cap forbids (no mechanism); without dilatancy the cap carries nothing and the box slides at mu in every
    direction."""
    angle = np.radians(degrees)
    blocks = boxes_on_a_base([[-1, -1, -0.2], [-0.5, -0.5, 0.0], [-1, -1, 0.5]], [[1, 1, 0], [0.5, 0.5, 0.5],
                                                                                   [1, 1, 0.7]],
                             mu, live_force=(np.cos(angle), np.sin(angle), 0.0))
    cap = np.arange(blocks.n_block) == 2
    blocks = blocks._replace(role=np.where(cap, blocks.role[0], blocks.role), fixed=blocks.fixed | cap[:, None],
                             dead=np.where(cap[:, None], 0.0, blocks.dead), live=np.where(cap[:, None], 0.0, blocks.live))
    with pytest.raises(mf.SolveError, match="can carry any multiple"):
        limit3d.limit_state_3d(blocks)
    result = flow(blocks)
    assert np.isnan(result.alpha_associative)
    assert result.converged and result.state.alpha == pytest.approx(mu, rel=1e-6)
    normal = np.einsum("pd,pd->p", result.state.point_force, blocks.contacts.normal[blocks.contacts.point_interface()])
    on_the_cap = blocks.contacts.point_interface() == np.flatnonzero((blocks.contacts.sides == 2).any(axis=1))[0]
    assert np.abs(normal[on_the_cap]).max() < 1e-6 * np.abs(blocks.dead[:, 2]).sum()  # no clamping force


def test_the_sandwiched_wall_unit_built_in_3d_slides_as_in_the_plane(walls):
    twin = mfp.twin(capped_unit(walls, mu=0.5))
    with pytest.raises(mf.SolveError, match="can carry any multiple"):
        mf.solve(twin, "la")
    result = mf.solve(twin, "la", {"flow": "nonassociative"})
    assert float(result.collapse_multiplier) == pytest.approx(0.5, rel=1e-6)
    assert result.attrs["flow_rule"] == "nonassociative" and result.attrs["la_flow_converged"] == 1
    assert set(result.interface_state.values.tolist()) == {mfp.flags("interface_state")["slide"]}


def test_a_block_twisted_on_its_support_turns_at_the_friction_of_its_corners():
    """Each base corner keeps the capacity of its share of the weight, W / 4 at a / sqrt(2) from the axis."""
    mu = 0.6
    result = flow(single_box(1.0, 1.0, 0.5, mu, live_moment=(0.0, 0.0, 1.0)))
    assert result.converged and result.state.alpha == pytest.approx(mu / np.sqrt(2.0), rel=1e-7)


@pytest.mark.parametrize("degrees, expected", [(0.0, 0.3 / 1.2), (90.0, 0.5 / 1.2)])
def test_a_slender_block_overturns_as_with_associative_joints(degrees, expected):
    """Rocking needs no slip: the non-associative alpha is the associative one, b / h."""
    angle = np.radians(degrees)
    result = flow(single_box(0.3, 0.5, 1.2, 0.8, live_force=(np.cos(angle), np.sin(angle), 0.0)))
    assert result.converged and result.state.alpha == pytest.approx(expected, rel=1e-7)
    assert result.alpha_associative == pytest.approx(expected, rel=1e-7)


def test_a_failed_exact_finish_reports_the_regularised_fixed_point_and_says_so(monkeypatch):
    """The regularised programmes take Test 8C's twin to a fixed point, then the finish's selection QP fails
    (Clarabel's iteration cap, say): the regularised fixed point is reported, converged, within the planar
    sequence's alpha to a few flow tolerances, and the result says the finish failed."""
    from masonryfw_la import nonassociative

    model = mfp.twin(mf.open_model("test-8c"))
    exact = mf.solve(model, "la", {"flow": "nonassociative"})

    def failing(*args):
        raise mf.SolveError("la: the least-compression contact forces were not found (Clarabel: MaxIterations)")

    monkeypatch.setattr(nonassociative, "least_squared_forces", failing)
    result = mf.solve(model, "la", {"flow": "nonassociative"})
    assert result.attrs["la_flow_converged"] == 1 and "stop_reason" not in result.attrs
    assert "exact finish by programme + QP: failed at programme" in result.attrs["la_flow_selection"]
    assert "exact finish by programme + QP (docs/la.md)" in exact.attrs["la_flow_selection"]
    assert result.attrs["la_flow_iterations"] < exact.attrs["la_flow_iterations"]
    assert float(result.collapse_multiplier) == pytest.approx(float(exact.collapse_multiplier), abs=5e-6)


@pytest.mark.parametrize("name, tolerance", [("test-12c", 2e-6), ("test-8c", 5e-6), ("panel-1", 5e-5)])
def test_every_wall_built_one_block_thick_in_3d_gives_the_planar_nonassociative_alpha(name, tolerance):
    """The planar sequence (two ends per joint) against the 3D one (four vertices, Coulomb's cone, six velocities
    per block): each stops within its tolerance of a fixed point, so the two agree to a few of them (measured:
    3.7e-7 to 8.1e-7 on Test 12C, 2.1e-6 on Test 8C, 1.8e-5 on Panel 1)."""
    model = mf.open_model(name)
    planar = mf.solve(model, "la", {"flow": "nonassociative"})
    spatial = mf.solve(mfp.twin(model), "la", {"flow": "nonassociative"})
    assert spatial.attrs["la_flow_converged"] == 1
    assert float(spatial.collapse_multiplier) == pytest.approx(float(planar.collapse_multiplier), abs=tolerance)
    assert float(spatial.collapse_multiplier) <= spatial.attrs["la_alpha_associative"] + 1e-7


def test_the_forces_are_in_equilibrium_within_the_capacities_of_their_own_normal_forces():
    """The static check of the associative tests, from the definitions, on Test 12C's twin: every block's six
    equations, and friction within mu N up to the sequence's force tolerance (1e-3 W)."""
    blocks = limit3d.blocks_of(mf.checked_model(mfp.twin(mf.open_model("test-12c"))))
    result = flow(blocks)
    residual, excess, weight = static_residuals(blocks, result.state)
    assert np.abs(residual[:, :3]).max() < 1e-7 * weight
    assert np.abs(residual[:, 3:]).max() < 1e-7 * weight * blocks.scale
    assert excess.max() < 1e-3 * weight


def test_the_same_wall_in_mm_and_in_another_block_order():
    model = mf.open_model("test-8c")
    reference = float(mf.solve(mfp.twin(model), "la", {"flow": "nonassociative"}).collapse_multiplier)
    rng = np.random.default_rng(5)
    shuffled = mt.permuted(model, rng.permutation(model.sizes["block"]), rng.permutation(model.sizes["interface"]))
    for other in (shuffled, mt.scaled(model, 1000.0)):
        alpha = float(mf.solve(mfp.twin(other), "la", {"flow": "nonassociative"}).collapse_multiplier)
        assert alpha == pytest.approx(reference, abs=5e-6)


def test_a_sequence_that_wanders_says_so_and_stays_below_the_associative_bound(caplog):
    """The corner building: no fixed point to the tolerance (the sequence roams alpha 0.1343-0.1348, its forces
    moving by 1e-3 W); it stops, says so with the range, and reports an iterate in equilibrium."""
    model = mt.corner_building()
    result = mf.solve(model, "la", {"flow": "nonassociative"})
    assert result.attrs["la_flow_converged"] == 0
    assert "wanders: alpha between" in result.attrs["stop_reason"] and "wanders" in caplog.text
    associative = mf.solve(model, "la")
    assert float(result.collapse_multiplier) < float(associative.collapse_multiplier) - 1e-3
    assert float(result.moving_support_reaction) > float(associative.moving_support_reaction)
    blocks = limit3d.blocks_of(mf.checked_model(model))
    residual, _, weight = static_residuals(blocks, nonassociative3d.solve(blocks, {**NONASSOCIATIVE,
                                                                                    "flow_iterations": 3},
                                                                           mfp.no_progress).state)
    assert np.abs(residual[:, :3]).max() < 1e-7 * weight


def test_a_pyramid_is_refused():
    with pytest.raises(mf.SolveError, match="non-associative friction is solved on Coulomb's cone"):
        mf.solve(mt.corner_building(), "la", {"flow": "nonassociative", "pyramid_sides": 8})


def test_a_second_start_from_zero_forces_ends_at_the_same_alpha_on_a_twin():
    result = mf.solve(mfp.twin(mf.open_model("test-8c")), "la", {"flow": "nonassociative", "flow_starts": 2})
    assert result.attrs["la_flow_starts_agree"] == 1
    assert result.attrs["la_flow_alpha_from_zero"] == pytest.approx(float(result.collapse_multiplier), abs=1e-5)
