"""Upper bound = lower bound: the mechanism's alpha, the static alpha, and the contact forces.

The equilibrium check recomputes every block's resultant from the reported end
forces with the geometry of the result (independently of the solver's sparse
matrices), so it tests the forces, the sign conventions and the assembly at once.
"""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

BACKENDS = ("ipm", "highs", "clarabel", "osqp")
ROLE = mfp.flags("block_role")
TOL = 1e-6  # relative to the total dead load (forces) and dead load x model size (moments)


def contact_resultants(result) -> np.ndarray:
    """(block, dof) force and moment about the centroid that the contacts exert on every block."""
    blocks = result.interface_blocks.values
    n = np.stack([result.interface_normal_x.values, result.interface_normal_y.values], axis=-1)
    t = np.stack([result.interface_tangent_x.values, result.interface_tangent_y.values], axis=-1)
    normal = result.interface_normal_force.values
    shear = result.interface_shear_force.values
    cx, cy = result.block_centroid_x.values, result.block_centroid_y.values
    out = np.zeros((result.sizes["block"], 3))
    for end in (0, 1):
        on_side1 = normal[:, end, None] * n + shear[:, end, None] * t  # side 0 pushes side 1
        px, py = result.interface_x.values[:, end], result.interface_y.values[:, end]
        for side, sign in ((0, -1.0), (1, 1.0)):
            b = blocks[:, side]
            f = sign * on_side1
            np.add.at(out[:, 0], b, f[:, 0])
            np.add.at(out[:, 1], b, f[:, 1])
            np.add.at(out[:, 2], b, (px - cx[b]) * f[:, 1] - (py - cy[b]) * f[:, 0])
    return out


def cohesive_wall(walls):
    units = walls.running_bond(4, 1.2, 0.4, 0.2)
    rects = np.vstack([(0.0, -0.2, 0.6, 0.0), (0.6, -0.2, 1.2, 0.0), units])
    roles = [ROLE["fixed_support"], ROLE["moving_support"]] + [ROLE["unit"]] * len(units)
    return walls.rect_model(rects, roles, loading="settlement", cohesion=300.0, tensile_strength=200.0)


def model_for(walls, case):
    if case == "ferris":
        return walls.ferris_tin_loi_wall()
    if case == "cohesive":
        return cohesive_wall(walls)
    return mfp.derive_geometry(mf.open_model(case))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", ["ferris", "test-12c", "panel-4", "cohesive"])
def test_la_static_and_kinematic_solutions_agree(walls, case, backend):
    model = model_for(walls, case)
    result = walls.solve(model, solver=backend)
    alpha = float(result.collapse_multiplier)
    weight = np.hypot(*model.dead_load.values[:, :2].T).sum()
    size = mfp.model_scale(model.node_x.values, model.node_y.values)

    # primal (mechanism) alpha = dual (static) alpha
    assert result.attrs["la_alpha_dual"] == pytest.approx(alpha, abs=1e-7)

    # every free block (and the moving supports along their direction) is in equilibrium
    residual = mfp.block_loads(model, "dead") + alpha * mfp.block_loads(model, "live") + contact_resultants(result)
    residual /= np.array([weight, weight, weight * size])
    moving = model.block_role.values == ROLE["moving_support"]
    free = (model.block_fixed.values == 0) & ~moving[:, None]
    assert np.abs(residual[free]).max() < TOL
    if moving.any():
        along = (residual[moving] * model.settlement_direction.values[moving]).sum()
        assert abs(along) < TOL

    # the forces are admissible: no tension beyond the joint's strength, Coulomb's cone
    sides = model.interface_blocks.values
    half_area = 0.5 * model.interface_length.values * model.block_thickness.values[sides].min(axis=1)
    mu = model.interface_friction.values
    cohesion = model.interface_cohesion.values
    tension = np.minimum(model.interface_tensile_strength.values, np.where(mu > 0, cohesion / np.where(mu > 0, mu, 1), np.inf))
    normal = result.interface_normal_force.values
    shear = result.interface_shear_force.values
    assert (normal + (tension * half_area)[:, None]).min() > -TOL * weight
    assert (np.abs(shear) - mu[:, None] * normal - (cohesion * half_area)[:, None]).max() < TOL * weight

    # at every end the contact forces' work on the mechanism is minus the dissipation
    # D = a_t opening + (a_c - mu a_t) |slip| (zero on dry joints): flow rule + complementarity.
    # A contact between two supports is ground against ground, not a joint: no force, no D.
    opening, slip = result.interface_opening.values, result.interface_slip.values
    ground = np.isin(model.block_role.values[sides], [ROLE["fixed_support"], ROLE["moving_support"]]).all(axis=1)
    assert np.all(normal[ground] == 0) and np.all(shear[ground] == 0)
    a_t, a_c = (tension * half_area)[:, None], (cohesion * half_area)[:, None]
    dissipation = np.where(ground[:, None], 0.0, a_t * opening + (a_c - mu[:, None] * a_t) * np.abs(slip))
    work = normal * opening + shear * slip
    scale = weight * np.abs(mfp.block_motion(result)[:, :2]).max()
    assert np.abs(work + dissipation).max() < TOL * scale
    u = mfp.block_motion(result).ravel()
    external = (mfp.block_loads(model, "dead").ravel() + alpha * mfp.block_loads(model, "live").ravel()) @ u
    assert external == pytest.approx(dissipation.sum(), abs=TOL * scale)

    # settlement cases: the moving support carries (1 - alpha) x its dead reaction at collapse
    if moving.any():
        dead_reaction = model.dead_load.values[moving, 1].sum()
        assert float(result.moving_support_reaction) == pytest.approx(
            (1 - alpha) * dead_reaction, abs=TOL * weight
        )
