"""Bad input and ill-posed problems end in a physical message, never a wrong number."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

BACKENDS = ("highs", "clarabel", "osqp")
ROLE = mfp.flags("block_role")


def unit_on_base(walls, **kw):
    return walls.rect_model([(-0.5, -0.2, 1.5, 0.0), (0.0, 0.0, 0.4, 0.8)], [ROLE["fixed_support"], ROLE["unit"]], **kw)


def with_live_load(model, rows):
    """``model`` with the live load replaced by ``{block: (fx, fy)}`` (a new array: the model is checked again)."""
    live = np.zeros_like(model.live_load.values)
    for block, force in rows.items():
        live[block] = force
    return model.assign(live_load=model.live_load.copy(data=live))


def test_la_no_live_load_is_a_model_problem(walls):
    with pytest.raises(mf.ModelError, match="no live load: the collapse multiplier is undefined"):
        walls.solve(with_live_load(unit_on_base(walls), {}))


def test_la_live_load_only_on_held_components(walls):
    model = with_live_load(unit_on_base(walls), {0: (100.0, 0.0)})  # on the fixed support: no work in any mechanism
    with pytest.raises(mf.SolveError, match="no live load"):
        walls.solve(model)


def test_la_unsupported_blocks_are_named(walls):
    rects = [(-0.5, -0.2, 1.5, 0.0), (0.0, 0.0, 0.4, 0.8), (3.0, 1.0, 3.4, 1.2), (3.4, 1.0, 3.8, 1.2)]
    model = walls.rect_model(rects, [ROLE["fixed_support"]] + [ROLE["unit"]] * 3)
    with pytest.raises(mf.SolveError, match=r"blocks 2, 3 are not supported"):
        walls.solve(model)


@pytest.mark.parametrize("backend", BACKENDS)
def test_la_unbounded_multiplier(walls, backend):
    """A live load pressing the unit onto its base: no mechanism lets it do positive work."""
    model = with_live_load(unit_on_base(walls), {1: (0.0, -500.0)})
    with pytest.raises(mf.SolveError, match=r"can carry any multiple of the live load \(unbounded\)"):
        walls.solve(model, solver=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_la_dead_load_alone_collapses(walls, backend):
    """A unit held only by a head joint against a fixed pillar slides down under its own weight.

    The live load pushes another unit, so the hanging one's fall can be scaled
    without bound: no multiplier saves it.
    """
    rects = [(-0.5, -0.2, 2.5, 0.0), (0.0, 0.0, 0.4, 0.8), (0.4, 0.5, 0.8, 0.7), (1.5, 0.0, 1.9, 0.4)]
    model = walls.rect_model(rects, [ROLE["fixed_support"], ROLE["fixed_support"], ROLE["unit"], ROLE["unit"]])
    model = with_live_load(model, {3: tuple(model.live_load.values[3])})
    with pytest.raises(mf.SolveError, match="the dead load alone cannot be carried"):
        walls.solve(model, solver=backend)


def test_la_negative_multiplier_is_a_result(walls):
    """The same hanging unit pushed away by its weight sideways: it needs a pull, alpha = -1/mu.

    Sliding down the head joint dilates it by mu per unit fall, so the live load
    (W to the right) does mu W per unit fall against the weight's W: alpha = -1/mu.
    """
    rects = [(0.0, 0.0, 0.4, 0.8), (0.4, 0.5, 0.8, 0.7)]
    model = walls.rect_model(rects, [ROLE["fixed_support"], ROLE["unit"]], friction=0.5)
    assert float(walls.solve(model).collapse_multiplier) == pytest.approx(-2.0, rel=1e-7)


def test_la_moving_support_without_direction(walls):
    rects = [(0.0, -0.2, 0.5, 0.0), (0.5, -0.2, 1.0, 0.0), (0.0, 0.0, 1.0, 0.5)]
    model = walls.rect_model(rects, [ROLE["fixed_support"], ROLE["moving_support"], ROLE["unit"]], loading="settlement")
    direction = model.settlement_direction.values.copy()
    direction[1] = 0.0
    with pytest.raises(mf.ModelError, match=r"block 1: moving support with settlement_direction 0 0 0"):
        walls.solve(model.assign(settlement_direction=model.settlement_direction.copy(data=direction)))


def test_la_through_the_core(walls):
    """Registered under "la": the core validates options, merges and stamps; the result passes check."""
    model = mf.open_model("panel-3")
    reports = []
    result = mf.solve(model, "la", {"solver": "highs"}, progress=lambda f, msg: reports.append(f))
    assert reports[0] == 0.0 and reports[-1] == 1.0 and reports == sorted(reports)
    assert result.attrs["solver"] == "la" and result.attrs["la_backend"] == "highs"
    assert mf.check(result) == []
    assert str(result.lp_status.values) == "optimal" and int(result.lp_iterations) > 0
    assert set(np.unique(result.interface_state.values)) <= set(mfp.flags("interface_state").values())
    assert 0.0 <= result.crack_indicator.min() and result.crack_indicator.max() == 1.0
    with pytest.raises(mf.PluginError, match="gurobi"):
        mf.solve(model, "la", {"solver": "gurobi"})


@pytest.mark.parametrize("name, value", [("tolerance", -1.0), ("tolerance", 0.0), ("tolerance", 1.5)])
def test_la_option_out_of_range_is_named(walls, name, value):
    model = walls.ferris_tin_loi_wall()
    with pytest.raises(mf.PluginError, match=rf"solver 'la': option '{name}' = {value}: must be > 0 and < 1"):
        walls.solve(model, **{name: value})
