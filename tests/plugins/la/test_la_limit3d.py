"""la in 3D: polyhedra with a friction pyramid, against closed forms, the planar programme and a static check
written from the definitions (not from the programme's matrices)."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt
from masonryfw_la import limit3d

ROLE = mfp.flags("block_role")
WALLS = ("test-12c", "test-8c", "panel-1", "panel-2", "panel-3", "panel-4", "panel-5", "facade-1", "facade-2",
         "facade-3", "facade-1-trough", "tunnel-facade")


def twin_blocks(model) -> limit3d.Blocks3D:
    """The arrays of the checked 3D twin of a planar model."""
    return limit3d.blocks_of(mf.checked_model(mfp.twin(model)))


def boxes_on_a_base(lower, upper, mu, live_force=(0.0, 0.0, 0.0), live_moment=(0.0, 0.0, 0.0),
                    unit_weight=20e3) -> limit3d.Blocks3D:
    """Box units (unit weight 20 kN/m3) on a fixed base box (block 0: the first corners); the live load on every
    unit is its weight times ``live_force`` (a tilting table: ``(tan(theta), 0, 0)``) plus ``live_moment`` x W."""
    poly = mfp.boxes(np.asarray(lower, dtype=float), np.asarray(upper, dtype=float))
    volume, centroid = mfp.volumes_centroids(poly)
    contacts = mfp.find_contacts(poly, 1e-9)
    n = volume.size
    role = np.r_[ROLE["fixed_support"], np.full(n - 1, ROLE["unit"])].astype(np.int8)
    weight = np.where(role == ROLE["unit"], unit_weight * volume, 0.0)
    dead = np.zeros((n, 6))
    dead[:, 2] = -weight
    live = np.c_[weight[:, None] * np.asarray(live_force), weight[:, None] * np.asarray(live_moment)]
    fixed = np.zeros((n, 6), dtype=bool)
    fixed[0] = True
    scale = float(np.linalg.norm(poly.vertices.max(axis=0) - poly.vertices.min(axis=0)))
    return limit3d.Blocks3D(centroid, volume, role, fixed, np.zeros((n, 6)), dead, live, contacts,
                           np.full(contacts.n_interface, mu), scale)


def single_box(b, d, h, mu, **load) -> limit3d.Blocks3D:
    """A b x d x h box (x, y, z) centred on a wider base."""
    return boxes_on_a_base([[-1, -1, -0.2], [-b / 2, -d / 2, 0]], [[1, 1, 0], [b / 2, d / 2, h]], mu, **load)


@pytest.mark.parametrize("degrees", [0.0, 90.0, 45.0, 180.0, -135.0])
def test_a_squat_block_slides_at_mu_in_the_pyramids_directions(degrees):
    """A 1 x 1 x 0.5 box on a tilting plane (live load tan(theta) W sideways) slides at tan(theta) = mu = 0.5 in
    every direction the eight-sided pyramid holds exactly: along, across and diagonally to the joint."""
    angle = np.radians(degrees)
    state = limit3d.limit_state_3d(single_box(1.0, 1.0, 0.5, 0.5, live_force=(np.cos(angle), np.sin(angle), 0.0)),
                                  sides=8)
    assert state.alpha == pytest.approx(0.5, rel=1e-8)
    motion = state.motion[1]
    assert np.abs(motion[3:]).max() < 1e-7 * np.abs(motion[:3]).max()  # it slides, it does not turn
    assert motion[2] == pytest.approx(0.5 * np.hypot(motion[0], motion[1]), rel=1e-6)  # dilatancy mu |slip|


@pytest.mark.parametrize("sides", [4, 8, 16])
def test_half_way_between_the_pyramids_directions_it_slides_at_the_inscribed_polygon(sides):
    """Half-way between two directions of the pyramid the friction force that fits is mu N cos(pi / sides): the
    pyramid is inscribed in Coulomb's cone (safe), and its error there is 1 - cos(pi / sides)."""
    angle = np.pi / sides
    blocks = single_box(1.0, 1.0, 0.5, 0.5, live_force=(np.cos(angle), np.sin(angle), 0.0))
    assert limit3d.limit_state_3d(blocks, sides=sides).alpha == pytest.approx(0.5 * np.cos(np.pi / sides), rel=1e-8)


@pytest.mark.parametrize("degrees, expected", [(0.0, 0.3 / 1.2), (180.0, 0.3 / 1.2), (90.0, 0.5 / 1.2),
                                               (-90.0, 0.5 / 1.2)])
def test_a_slender_block_overturns_at_its_width_over_its_height_both_ways(degrees, expected):
    """A 0.3 x 0.5 x 1.2 box, mu = 0.8: it overturns about the edge of its base at tan(theta) = b / h along x and
    d / h along y (the centroid over the edge)."""
    angle = np.radians(degrees)
    state = limit3d.limit_state_3d(single_box(0.3, 0.5, 1.2, 0.8, live_force=(np.cos(angle), np.sin(angle), 0.0)))
    assert state.alpha == pytest.approx(expected, rel=1e-8)
    turning = np.abs(state.motion[1][3:])  # rx, ry, rz
    assert turning.argmax() == (1 if degrees in (0.0, 180.0) else 0)  # about the base edge across the load


@pytest.mark.parametrize("sides", [8, 0])
def test_a_block_twisted_on_its_support_turns_at_the_friction_of_its_corners(sides):
    """A 1 x 1 x 0.5 box under a moment about z: its four base corners carry W / 4 each, at a / sqrt(2) from the
    axis, sliding across their radius (a direction of the eight-sided pyramid, and of the cone): M = mu W a /
    sqrt(2)."""
    mu = 0.6
    state = limit3d.limit_state_3d(single_box(1.0, 1.0, 0.5, mu, live_moment=(0.0, 0.0, 1.0)), sides=sides)
    assert state.alpha == pytest.approx(mu / np.sqrt(2.0), rel=1e-8)
    motion = state.motion[1]
    assert np.abs(motion[[0, 1, 3, 4]]).max() < 1e-7 * abs(motion[5])  # it turns about its vertical axis


@pytest.mark.parametrize("degrees", [0.0, 22.5, 45.0, 67.5, 101.0])
def test_with_coulombs_cone_it_slides_at_mu_in_every_direction(degrees):
    angle = np.radians(degrees)
    blocks = single_box(1.0, 1.0, 0.5, 0.5, live_force=(np.cos(angle), np.sin(angle), 0.0))
    assert limit3d.limit_state_3d(blocks, sides=0).alpha == pytest.approx(0.5, rel=1e-8)


@pytest.mark.parametrize("sides", [0, 8, 16, 32])
def test_a_rectangular_block_twisted_against_the_cone_and_the_pyramids(sides):
    """A 1 x 0.6 box under a moment about z: its corners, r = sqrt(1 + 0.36) / 2 from the axis, slide across
    their radius (between the pyramid's directions): M = mu W r with the cone; a pyramid is below it by at most
    1 - cos(pi / sides)."""
    mu = 0.6
    exact = mu * np.hypot(1.0, 0.6) / 2
    alpha = limit3d.limit_state_3d(single_box(1.0, 0.6, 0.5, mu, live_moment=(0.0, 0.0, 1.0)), sides=sides).alpha
    if sides == 0:
        assert alpha == pytest.approx(exact, rel=1e-8)
    else:
        assert exact * np.cos(np.pi / sides) * (1 - 1e-9) <= alpha <= exact * (1 + 1e-9)


def static_residuals(blocks: limit3d.Blocks3D, state: limit3d.LimitState3D) -> tuple[np.ndarray, np.ndarray, float]:
    """Every free block's six equilibrium residuals and every vertex's excess over Coulomb's cone, from the
    definitions: the force at each vertex acts on side 1 and, opposite, on side 0, at the vertex."""
    contacts = blocks.contacts
    owner = contacts.point_interface()
    force = state.point_force
    total = blocks.dead + state.alpha * blocks.live
    for side, sign in ((1, 1.0), (0, -1.0)):
        block = contacts.sides[owner, side]
        arm = contacts.points - blocks.centroid[block]
        for k in range(3):
            np.add.at(total[:, k], block, sign * force[:, k])
            np.add.at(total[:, 3 + k], block, sign * np.cross(arm, force)[:, k])
    free = ~mfp.support_blocks(blocks.role)
    normal = np.einsum("pd,pd->p", force, contacts.normal[owner])
    tangential = np.linalg.norm(force - normal[:, None] * contacts.normal[owner], axis=1)
    weight = float(np.abs(blocks.dead[:, 2]).sum())
    return total[free], np.maximum(tangential - blocks.friction[owner] * normal, -normal), weight


@pytest.mark.parametrize("sides", [8, 0])
@pytest.mark.parametrize("case", ["tilted stack", "twisted stack", "panel-5", "facade-2", "corner building",
                                  "corner in english bond", "corner in flemish bond", "corner at 120 degrees",
                                  "corner at 60 degrees"])
def test_the_forces_satisfy_every_blocks_six_equilibrium_equations_and_the_cone(case, sides):
    if case.endswith("stack"):
        lower = [[-1, -1, -0.2], [-0.5, -0.4, 0], [-0.1, -0.3, 0.4], [-0.3, -0.35, 0.8]]
        upper = [[1, 1, 0], [0.5, 0.4, 0.4], [0.7, 0.3, 0.8], [0.5, 0.35, 1.0]]
        load = {"live_force": (0.6, 0.3, 0.0)} if case == "tilted stack" else {"live_moment": (0.0, 0.0, 1.0)}
        blocks = boxes_on_a_base(lower, upper, 0.6, **load)
    elif case.startswith("corner at"):
        blocks = limit3d.blocks_of(mt.corner_building(angle=float(case.split()[2])))
    elif case.startswith("corner"):
        blocks = limit3d.blocks_of(mt.corner_building(case.split()[2] if case.endswith("bond") else "running"))
    else:
        blocks = twin_blocks(mf.open_model(case))
    state = limit3d.limit_state_3d(blocks, sides=sides)
    residual, excess, weight = static_residuals(blocks, state)
    moment_scale = weight * blocks.scale
    assert np.abs(residual[:, :3]).max() < 1e-8 * weight
    assert np.abs(residual[:, 3:]).max() < 1e-8 * moment_scale
    assert excess.max() < 1e-8 * weight


@pytest.mark.parametrize("name", WALLS)
def test_every_bundled_wall_built_one_block_thick_in_3d_gives_the_planar_alpha(name):
    """The planar programme (two ends per joint, dn >= mu |dt| in the plane) against the 3D one (four vertices
    per joint, an eight-sided pyramid, six velocities per block): the same alpha, no motion out of the plane."""
    import masonryfw_la

    model = mf.open_model(name)
    wall = masonryfw_la.Wall.from_model(model)
    planar = masonryfw_la.limit_state(wall, masonryfw_la.wall_scales(model, wall)).alpha
    state = limit3d.limit_state_3d(twin_blocks(model))
    assert state.alpha == pytest.approx(planar, rel=1e-6)
    assert np.abs(state.motion[:, [1, 3, 5]]).max() < 1e-6 * np.abs(state.motion[:, [0, 2]]).max()


def test_the_same_wall_in_mm_and_in_m_and_in_another_block_order(walls):
    """A running-bond wall on a settling support, in m and in mm, and its blocks listed backwards."""
    rects = np.vstack([[(0.0, -0.1, 0.48, 0.0), (0.48, -0.1, 1.2, 0.0)], walls.running_bond(5, 1.2, 0.3, 0.1)])
    roles = [ROLE["fixed_support"], ROLE["moving_support"]] + [ROLE["unit"]] * (len(rects) - 2)
    alphas = [limit3d.limit_state_3d(twin_blocks(walls.rect_model(r, o, loading="settlement",
                                                                 length_unit=unit))).alpha
              for r, o, unit in ((rects, roles, 1.0), (rects, roles, 1000.0), (rects[::-1], roles[::-1], 1.0))]
    assert alphas[1] == pytest.approx(alphas[0], rel=1e-9)
    assert alphas[2] == pytest.approx(alphas[0], rel=1e-9)


def test_joints_with_cohesion_and_too_few_sides_are_refused(walls):
    rects = [(-1.0, -0.2, 2.0, 0.0), (0.0, 0.0, 0.4, 1.0)]
    cohesive = walls.rect_model(rects, [ROLE["fixed_support"], ROLE["unit"]], cohesion=1e4)
    with pytest.raises(mf.SolveError, match="interface 0 has cohesion"):
        twin_blocks(cohesive)
    with pytest.raises(mf.SolveError, match="at least 3 sides"):
        limit3d.limit_state_3d(single_box(1.0, 1.0, 0.5, 0.5, live_force=(1.0, 0.0, 0.0)), sides=2)


def test_the_backend_a_3d_result_names_is_the_one_that_ran():
    """The report's provenance named one backend while its title named another (``"solver": "ipm"`` under "la
    (cone, clarabel)"): the option is automatic, the cone's backend our interior point (or clarabel when asked),
    and asking the cone of an LP backend is refused; a pyramid runs on the backend asked."""
    import json

    from masonryfw.testing import corner_building

    model = corner_building()
    cone = mf.solve(model, "la")
    assert json.loads(cone.attrs["solver_options"])["solver"] is None
    assert cone.attrs["method"] == "cone, ipm" and cone.attrs["la_backend"] == "ipm"
    assert mf.result_label(cone) == "la (cone, ipm)"
    checked = mf.solve(model, "la", {"solver": "clarabel"})
    assert checked.attrs["la_backend"] == "clarabel" and mf.result_label(checked) == "la (cone, clarabel)"
    with pytest.raises(mf.SolveError, match="cone is a second-order cone programme, which ipm and clarabel solve"):
        mf.solve(model, "la", {"solver": "highs"})
    pyramid = mf.solve(model, "la", {"pyramid_sides": 8, "solver": "highs"})
    assert pyramid.attrs["la_backend"] == "highs" and mf.result_label(pyramid) == "la (pyramid of 8 sides, highs)"
