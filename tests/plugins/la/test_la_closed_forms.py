"""Collapse multipliers against closed forms and a published value, on every backend."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw.plugin_api as mfp

BACKENDS = ("highs", "clarabel", "osqp")
STATE = mfp.flags("interface_state")


def single_unit(walls, b, h, **material):
    """A b x h unit on a wide fixed base (block 0 = base, block 1 = unit), tilting load."""
    role = walls.ROLE
    return walls.rect_model(
        [(-1.0, -0.2, 2.0, 0.0), (0.0, 0.0, b, h)], [role["fixed_support"], role["unit"]], **material
    )


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(
    "b, h, mu, regime",
    [(0.4, 1.0, 0.65, "rocking"), (0.3, 0.6, 0.6, "rocking"), (1.0, 0.5, 0.4, "sliding"), (0.6, 0.8, 0.3, "sliding")],
)
def test_la_single_unit_under_its_weight_sideways(walls, backend, b, h, mu, regime):
    """alpha = min(b/h, mu): rocking about the toe (b/h) or sliding with dilatancy (mu)."""
    result = walls.solve(single_unit(walls, b, h, friction=mu), solver=backend)
    assert float(result.collapse_multiplier) == pytest.approx(min(b / h, mu), rel=1e-7)
    u = mfp.block_motion(result)[1]
    base_joint = result.interface_state.values[0]
    if regime == "rocking":  # turns clockwise, the heel lifts, nothing slides
        assert u[2] < 0
        assert base_joint == STATE["open"]
    else:  # translates right and up by mu (dilatancy), no rotation
        assert u[2] == pytest.approx(0.0, abs=1e-6)
        assert u[1] == pytest.approx(mu * u[0], rel=1e-6)
        assert base_joint == STATE["slide"]


def unit_on_two_supports(walls, a, b=1.0, h=0.5):
    """A unit of width b over a fixed support [0, a] and a moving support [a, b]."""
    role = walls.ROLE
    return walls.rect_model(
        [(0.0, -0.2, a, 0.0), (a, -0.2, b, 0.0), (0.0, 0.0, b, h)],
        [role["fixed_support"], role["moving_support"], role["unit"]],
        loading="settlement",
    )


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("a", [0.1, 0.2, 0.35, 0.45, 0.5, 0.7])
def test_la_unit_over_a_settling_support(walls, backend, a):
    """alpha = 1 if the centroid is over the fixed part (a >= b/2), else 1 - b(b/2 - a)/(b - a)^2.

    The smallest reaction the moving support can give: the unit pivots on the fixed
    support's edge x = a and the moving support pushes at x = b.
    """
    b = 1.0
    expected = 1.0 if a >= b / 2 else 1.0 - b * (b / 2 - a) / (b - a) ** 2
    model = unit_on_two_supports(walls, a, b)
    result = walls.solve(model, solver=backend)
    assert float(result.collapse_multiplier) == pytest.approx(expected, abs=1e-7)
    # the moving support moves a unit distance down (docs/format.md normalisation)
    np.testing.assert_allclose(mfp.block_motion(result)[1], [0.0, -1.0, 0.0], atol=1e-12)
    dead_reaction = float(model.dead_load.values[1, 1])
    assert float(result.moving_support_reaction) == pytest.approx(
        (1.0 - expected) * dead_reaction, abs=1e-5 * dead_reaction
    )


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(
    "mu, cohesion, tension, regime",
    [(0.4, 200.0, 0.0, "sliding"), (0.8, 1000.0, 500.0, "rocking"), (0.8, 300.0, 1000.0, "rocking"), (0.0, 500.0, 100.0, "sliding")],
)
def test_la_cohesion_and_tensile_strength(walls, backend, mu, cohesion, tension, regime):
    """A cohesive joint under a b x h unit pushed sideways by its weight W.

    Sliding: alpha W = mu W + c b s. Rocking about the toe: the heel opens by
    theta b, and the tension (capped at c / mu by Coulomb's cone) dissipates
    ft s theta b^2 / 2: alpha = b/h + ft s b^2 / (W h). The answer is the smaller.
    """
    b, h, s, gamma = 0.5, 1.0, 0.1, 12e3
    weight = gamma * b * h * s
    model = single_unit(walls, b, h, friction=mu, cohesion=cohesion, tensile_strength=tension, thickness=s)
    ft = min(tension, cohesion / mu) if mu > 0 else tension
    rocking = b / h + ft * s * b**2 / (weight * h)
    sliding = mu + cohesion * b * s / weight
    assert (rocking < sliding) == (regime == "rocking")
    result = walls.solve(model, solver=backend)
    assert float(result.collapse_multiplier) == pytest.approx(min(rocking, sliding), rel=1e-7)
    # the joint's resultant: shear = -alpha W (resisting), normal = W, tension >= -ft * area
    alpha = float(result.collapse_multiplier)
    normal = result.interface_normal_force.values[0]
    assert result.interface_shear_force.values[0].sum() == pytest.approx(-alpha * weight, rel=1e-6)
    assert normal.sum() == pytest.approx(weight, rel=1e-6)
    assert normal.min() >= -ft * b * s / 2 * (1 + 1e-6) - 1e-6 * weight


def ferris_tin_loi_wall_1(walls, backend):
    model = walls.ferris_tin_loi_wall()
    assert model.sizes["block"] == 34 and np.ptp(model.node_x.values) == pytest.approx(2.4)  # 33 units + base
    return walls.solve(model, solver=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_la_ferris_tin_loi_wall_1(walls, backend):
    """Published lambda = 0.643 (associative friction)."""
    result = ferris_tin_loi_wall_1(walls, backend)
    assert float(result.collapse_multiplier) == pytest.approx(0.643, abs=1e-3)


@pytest.mark.parametrize("thickness_ratio, stands", [(0.107, False), (0.108, True)])
def test_la_semicircular_arch_stands_from_milankovitchs_thickness(thickness_ratio, stands):
    """A semicircular arch carries its own weight only from t/R = 0.1075 on (Milankovitch 1907); with 40
    voussoirs la puts the limit between 0.107 and 0.108. With the right springing moving out, alpha is minus
    the least thrust over the springing's share of the weight (docs/la.md)."""
    import masonryfw as mf
    import masonryfw.testing as mt

    arch = mt.arch_model(thickness_ratio)
    if not stands:
        with pytest.raises(mf.SolveError, match="dead load alone cannot be carried"):
            mf.solve(arch, "la", {})
        return
    result = mf.solve(arch, "la", {})
    share = float(arch.dead_load.values[-1, 1])
    thrust = float(result.moving_support_reaction)
    assert float(result.collapse_multiplier) == pytest.approx(-thrust / share, rel=1e-6)
