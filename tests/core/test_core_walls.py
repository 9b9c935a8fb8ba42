"""A building's damage wall by wall: each wall's widest crack from the block motions (closed forms: one wall moved
rigidly away from the other opens every joint between them by the motion, and nothing else), each wall's stages 1
and 2, and the building's stages as its worst wall's."""
from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt


@pytest.fixture(scope="module")
def corner():
    """The kit's corner building: wall a along x from the origin, wall b along y from a's end."""
    return mt.corner_building()


def moved_wall(model, wall: int, motion) -> np.ndarray:
    """Block motions (block, 6): every masonry block laid in ``wall`` moved by ``motion`` (six components)."""
    u = np.zeros((model.sizes["block"], 6))
    laid = (model.block_wall.values == wall) & mfp.masonry_blocks(model.block_role.values)
    u[laid] = motion
    return u


def joints_between(model, a: int, b: int) -> np.ndarray:
    walls = model.block_wall.values[model.interface_blocks.values]
    masonry = mfp.masonry_blocks(model.block_role.values)[model.interface_blocks.values].all(axis=1)
    return masonry & (np.sort(walls, axis=1) == sorted((a, b))).all(axis=1)


def test_every_block_of_a_building_is_laid_in_one_of_its_walls(corner):
    walls = corner.block_wall.values
    assert set(np.unique(walls)) == {0, 1} and not mf.check(corner)
    x, y = corner.block_centroid_x.values, corner.block_centroid_y.values
    assert np.abs(y[walls == 0]).max() <= 0.06 + 1e-9  # wall a's blocks on its base line, a leaf thick
    assert np.abs(x[walls == 1] - 1.44).max() <= 0.06 + 1e-9


@pytest.mark.parametrize("scale", [1.0, 1e-3])
@pytest.mark.parametrize("direction", [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0)])
def test_a_wall_moved_away_from_the_other_cracks_both_by_the_motion(corner, scale, direction):
    """Wall b moved by d away from wall a (along x: off a's end; along y: along its own length, off the corner
    blocks of a): every joint between the two opens d or slides, none inside a wall opens, so both walls' widest
    crack is d, at a joint between them whose normal is the motion; a millimetre and a metre alike."""
    d = 2e-3 * scale
    u = moved_wall(corner, 1, [*(d * np.array(direction)), 0.0, 0.0, 0.0])
    cracks = mf.widest_crack(corner, u)
    assert cracks.width == pytest.approx(d, rel=1e-9)
    assert cracks.wall_width == pytest.approx((d, d), rel=1e-9)
    between = joints_between(corner, 0, 1)
    normal = np.c_[corner.interface_normal_x.values, corner.interface_normal_y.values, corner.interface_normal_z.values]
    for joint in cracks.wall_interface:
        assert between[joint] and abs(normal[joint] @ direction) == pytest.approx(1.0)
    assert cracks.base_gap == 0.0  # wall b's base moves along the ground: it slides, it does not lift


def test_a_wall_lifted_off_its_ground_opens_a_base_gap_and_cracks_only_where_it_meets_the_other(corner):
    d = 1e-3
    cracks = mf.widest_crack(corner, moved_wall(corner, 0, [0.0, 0.0, d, 0.0, 0.0, 0.0]))
    assert cracks.base_gap == pytest.approx(d, rel=1e-9)
    assert cracks.wall_width == pytest.approx((d, d), rel=1e-9)  # the corner's bed joints, shared by both walls
    assert all(joints_between(corner, 0, 1)[j] for j in cracks.wall_interface)


def test_a_building_moved_as_one_body_cracks_no_wall(corner):
    u = np.zeros((corner.sizes["block"], 6))
    masonry = mfp.masonry_blocks(corner.block_role.values)
    centre = np.c_[corner.block_centroid_x.values, corner.block_centroid_y.values, corner.block_centroid_z.values]
    turn = np.array([1e-2, -2e-2, 5e-3])  # a finite rotation (its rotation vector), about the origin
    rotation = Rotation.from_rotvec(turn).as_matrix()
    u[masonry, :3] = [1e-3, 2e-3, -3e-3] + centre[masonry] @ (rotation - np.eye(3)).T
    u[masonry, 3:] = turn
    cracks = mf.widest_crack(corner, u)
    assert max(cracks.wall_width) < 1e-14 and cracks.width < 1e-14


def test_each_walls_stage_1_is_the_greenfield_surface_sampled_along_it(corner):
    """Stage 1 of each wall, against the greenfield surface in plan evaluated at 20,001 points along the wall's
    ground extent (not the wall's cut profile that the assessment uses): its largest slope and settlement; the
    building's are the largest of its walls'."""
    ground = mfp.ground_in_plan(corner)
    walls = mfp.assess_walls(corner, 1.0)
    assert list(walls) == ["a", "b"]
    for wall in json.loads(corner.attrs["building_walls"]):
        start, end = np.array(wall["start"]), np.array(wall["end"])
        s = np.linspace(*wall["ground"], 20001)
        rate, _ = ground.greenfield(start + s[:, None] * (end - start) / np.linalg.norm(end - start))
        assert walls[wall["name"]].slope == pytest.approx(np.abs(np.gradient(rate, s)).max(), rel=1e-3)
        assert walls[wall["name"]].greenfield_settlement == pytest.approx(rate.max(), rel=1e-6)
        assert {p.wall for p in walls[wall["name"]].parts} == {wall["name"]}
    building = mfp.assess(corner, 1.0)
    assert building.slope == max(w.slope for w in walls.values())
    assert building.strain == pytest.approx(max(w.strain for w in walls.values()), rel=1e-12)


def test_a_crack_is_placed_in_its_wall_by_course_and_along_the_base_line(corner):
    """The joint between the second and third courses of wall b, half way along: course 2, the midpoint's
    distance along b's base line from its start."""
    z = np.array([mfp.interface_points(corner)[int(corner.interface_node_count.values[:j].sum())][2]
                  for j in range(corner.sizes["interface"])])
    walls = corner.block_wall.values[corner.interface_blocks.values]
    bed = (np.abs(corner.interface_normal_z.values) > 0.5) & (walls == 1).all(axis=1) & np.isclose(z, 0.24)
    joint = int(np.flatnonzero(bed)[0])
    place = mfp.crack_place(corner, joint)
    middle = mfp.interface_points(corner)[int(corner.interface_node_count.values[:joint].sum()):][
        :int(corner.interface_node_count.values[joint])].mean(axis=0)
    assert (place.wall, place.name, place.course) == (1, "b", 2)
    assert place.along == pytest.approx(middle[1], abs=1e-12)  # b runs along y from (1.44, 0)
