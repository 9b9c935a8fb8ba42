"""Interface detection against hand counts, hand-computed end points and a brute-force reference."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from masonryfw import ModelError
from masonryfw.geometry.interfaces import detect_interfaces


def polygons_layout(polygons):
    """CF ragged layout (node_x, node_y, block_node_count) of a list of vertex lists."""
    x = np.array([p[0] for poly in polygons for p in poly], dtype=float)
    y = np.array([p[1] for poly in polygons for p in poly], dtype=float)
    return x, y, np.array([len(poly) for poly in polygons], dtype=np.int64)


def box(x0, x1, y0, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def running_bond(courses, units, length=2.0, height=1.0):
    """Even courses: ``units`` full units; odd courses: half, units - 1 full, half."""
    boxes = []
    for r in range(courses):
        if r % 2 == 0:
            joints = np.arange(units + 1) * length
        else:
            joints = np.concatenate(([0.0], np.arange(units) * length + length / 2, [units * length]))
        boxes += [box(a, b, r * height, (r + 1) * height) for a, b in zip(joints[:-1], joints[1:])]
    return boxes


def running_bond_count(courses, units):
    """Hand-derived interface count of :func:`running_bond`.

    Head joints: units - 1 in each even course, units in each odd course. A bed
    joint between courses with n_a and n_b blocks splits the wall length at
    (n_a - 1) + (n_b - 1) distinct inner points, hence n_a + n_b - 1 = 2 units pieces.
    """
    even, odd = (courses + 1) // 2, courses // 2
    return even * (units - 1) + odd * units + (courses - 1) * 2 * units


def as_rows(result):
    """Interfaces as a list of (side0, side1, (x0, y0), (x1, y1))."""
    return [
        (int(b[0]), int(b[1]), (float(x[0]), float(y[0])), (float(x[1]), float(y[1])))
        for b, x, y in zip(result["blocks"], result["x"], result["y"])
    ]


def test_two_course_running_bond_hand_counted_end_points():
    # Blocks: 0 [0,2]x[0,1], 1 [2,4]x[0,1]; 2 [0,1], 3 [1,3], 4 [3,4] in y [1,2].
    result = detect_interfaces(*polygons_layout(running_bond(2, 2)))
    assert as_rows(result) == [
        (0, 1, (2.0, 1.0), (2.0, 0.0)),  # head: left block is side 0, n=+x, t=-y: top first
        (0, 2, (0.0, 1.0), (1.0, 1.0)),  # bed: lower block is side 0, n=+y, t=+x: left first
        (0, 3, (1.0, 1.0), (2.0, 1.0)),
        (1, 3, (2.0, 1.0), (3.0, 1.0)),
        (1, 4, (3.0, 1.0), (4.0, 1.0)),
        (2, 3, (1.0, 2.0), (1.0, 1.0)),
        (3, 4, (3.0, 2.0), (3.0, 1.0)),
    ]
    assert result["blocks"].dtype == np.int64
    assert result["x"].shape == result["y"].shape == (7, 2)


@pytest.mark.parametrize("courses, units", [(1, 1), (2, 2), (5, 4), (6, 5), (20, 15)])
def test_running_bond_count_formula(courses, units):
    result = detect_interfaces(*polygons_layout(running_bond(courses, units)))
    assert len(result["blocks"]) == running_bond_count(courses, units)


def test_stack_bond_three_by_two():
    # 3 courses x 2 columns of unit squares: heads 3, beds 2 x 2 = 4.
    boxes = [box(c, c + 1, r, r + 1) for r in range(3) for c in range(2)]
    rows = as_rows(detect_interfaces(*polygons_layout(boxes)))
    assert len(rows) == 7
    assert (0, 1, (1.0, 1.0), (1.0, 0.0)) in rows
    assert (0, 2, (0.0, 1.0), (1.0, 1.0)) in rows
    assert (3, 5, (1.0, 2.0), (2.0, 2.0)) in rows


def test_millimetre_coordinates_give_the_same_topology():
    walls = polygons_layout(running_bond(4, 3))
    metres = detect_interfaces(*walls)
    millimetres = detect_interfaces(walls[0] * 1000, walls[1] * 1000, walls[2])
    np.testing.assert_array_equal(metres["blocks"], millimetres["blocks"])
    np.testing.assert_allclose(millimetres["x"], 1000 * metres["x"])
    np.testing.assert_allclose(millimetres["y"], 1000 * metres["y"])


def test_wall_far_from_the_origin():
    x, y, counts = polygons_layout(running_bond(4, 3))
    near = detect_interfaces(x, y, counts)
    far = detect_interfaces(x + 3.0e5, y + 1.0e5, counts)
    np.testing.assert_array_equal(near["blocks"], far["blocks"])
    np.testing.assert_allclose(far["x"] - 3.0e5, near["x"], atol=1e-9)


def test_voussoir_pair_inclined_joint():
    # Common edge from (2, 0) to (1.5, 2); the left block's outward normal is
    # (2, 0.5)/sqrt(4.25) (n_x > 0, so it is side 0); t = (0.5, -2)/sqrt(4.25):
    # t.(1.5, 2) = -3.25 < t.(2, 0) = 1, so (1.5, 2) is end 0.
    left = [(0, 0), (2, 0), (1.5, 2), (0, 2)]
    right = [(2, 0), (4, 0), (4, 2), (1.5, 2)]
    assert as_rows(detect_interfaces(*polygons_layout([left, right]))) == [(0, 1, (1.5, 2.0), (2.0, 0.0))]
    # The order of the blocks in the file does not change which block is side 0.
    assert as_rows(detect_interfaces(*polygons_layout([right, left]))) == [(1, 0, (1.5, 2.0), (2.0, 0.0))]


def test_triangle_on_a_rectangle():
    rows = as_rows(detect_interfaces(*polygons_layout([box(0, 4, 0, 1), [(1, 1), (3, 1), (2, 2)]])))
    assert rows == [(0, 1, (1.0, 1.0), (3.0, 1.0))]


def test_corner_to_corner_touch_is_no_interface():
    # Diagonal neighbours: the collinear edges only meet at the point (1, 1).
    assert len(detect_interfaces(*polygons_layout([box(0, 1, 0, 1), box(1, 2, 1, 2)]))["blocks"]) == 0


def test_clockwise_polygon_still_found():
    clockwise = box(1, 2, 0, 1)[::-1]
    assert as_rows(detect_interfaces(*polygons_layout([box(0, 1, 0, 1), clockwise]))) == [
        (0, 1, (1.0, 1.0), (1.0, 0.0))
    ]


@pytest.mark.parametrize("gap_in_tol, found", [(0.0, True), (0.5, True), (0.99, True), (2.0, False), (10.0, False)])
def test_gap_between_edges_against_default_tolerance(gap_in_tol, found):
    # Default tol = 1e-6 x bounding-box diagonal, here hypot(2, 1) (the gap barely changes it).
    tol = 1e-6 * np.hypot(2.0, 1.0)
    gap = gap_in_tol * tol
    result = detect_interfaces(*polygons_layout([box(0, 1, 0, 1), box(1 + gap, 2 + gap, 0, 1)]))
    assert (len(result["blocks"]) == 1) is found


@pytest.mark.parametrize("overlap_in_tol, found", [(0.5, False), (2.0, True)])
def test_overlap_shorter_than_tolerance_is_dropped(overlap_in_tol, found):
    tol = 1e-3
    shift = 1.0 - overlap_in_tol * tol  # right block raised: common head segment of overlap_in_tol * tol
    result = detect_interfaces(*polygons_layout([box(0, 1, 0, 1), box(1, 2, shift, 1 + shift)]), tol=tol)
    assert (len(result["blocks"]) == 1) is found


def rotate(x, y, degrees, about=(0.3, -0.7)):
    a = np.radians(degrees)
    dx, dy = x - about[0], y - about[1]
    return about[0] + np.cos(a) * dx - np.sin(a) * dy, about[1] + np.sin(a) * dx + np.cos(a) * dy


def unordered(result):
    """Orientation-free form: {block pair: sorted end points rounded}."""
    out = {}
    for b, x, y in zip(result["blocks"], result["x"], result["y"]):
        key = tuple(sorted(int(i) for i in b))
        ends = tuple(sorted((round(float(px), 9), round(float(py), 9)) for px, py in zip(x, y)))
        out.setdefault(key, []).append(ends)
    return {k: sorted(v) for k, v in out.items()}


@pytest.mark.parametrize("degrees", [30.0, 90.0, -45.0, 1e-9])
def test_rotated_wall_has_the_rotated_interfaces(degrees):
    x, y, counts = polygons_layout(running_bond(5, 4))
    plain = detect_interfaces(x, y, counts)
    rx, ry = rotate(x, y, degrees)
    rotated = detect_interfaces(rx, ry, counts)
    px, py = rotate(plain["x"], plain["y"], degrees)
    expected = unordered({"blocks": plain["blocks"], "x": px, "y": py})
    assert unordered(rotated) == expected
    assert_orientation_rule(rotated, rx, ry, counts)


def assert_orientation_rule(result, x, y, counts, angle_tol=1e-6):
    """Side 0's outward normal has angle in (-90, 90] deg; end 0 comes first along t = (n_y, -n_x)."""
    start = np.concatenate(([0], np.cumsum(counts)))
    cx = np.array([x[a:b].mean() for a, b in zip(start[:-1], start[1:])])  # vertex mean: inside a convex block
    cy = np.array([y[a:b].mean() for a, b in zip(start[:-1], start[1:])])
    for (b0, _), ix, iy in zip(result["blocks"], result["x"], result["y"]):
        dx, dy = ix[1] - ix[0], iy[1] - iy[0]
        nx, ny = -dy, dx  # end 1 - end 0 runs along t = (n_y, -n_x), so n = (-t_y, t_x)
        # n must point away from the side-0 block (and so t ordered the ends)
        assert nx * (ix.mean() - cx[b0]) + ny * (iy.mean() - cy[b0]) > 0
        length = np.hypot(nx, ny)
        nx, ny = nx / length, ny / length
        assert nx > angle_tol or (abs(nx) <= angle_tol and ny > 0)


def test_rotation_rule_bed_joint_upper_block_becomes_side0_beyond_90_degrees():
    # Rotating a stack of two blocks by 120 deg turns the bed normal +y into
    # (-sin 120, cos 120) = (-0.87, -0.5), whose angle is outside (-90, 90]:
    # the former upper block (1) becomes side 0.
    x, y, counts = polygons_layout([box(0, 1, 0, 1), box(0, 1, 1, 2)])
    rx, ry = rotate(x, y, 120.0)
    result = detect_interfaces(rx, ry, counts)
    assert result["blocks"].tolist() == [[1, 0]]
    assert_orientation_rule(result, rx, ry, counts)


def random_masonry(courses, seed):
    """Convex quadrilaterals between inclined course lines, with inclined head joints."""
    rng = np.random.default_rng(seed)
    width = 10.0
    levels = np.arange(courses + 1) * 1.0
    slopes = rng.uniform(-0.03, 0.03, courses + 1)
    slopes[0] = 0.0

    def at(r, xv):
        return levels[r] + slopes[r] * xv

    polygons = []
    for r in range(courses):
        n = int(rng.integers(2, 6))
        pitch = width / n  # jitters below pitch / 5 keep the joints from crossing
        inner = np.arange(1, n) * pitch
        bottom_x = np.concatenate(([0.0], inner + rng.uniform(-0.2, 0.2, n - 1) * pitch, [width]))
        top_x = np.concatenate(([0.0], inner + rng.uniform(-0.2, 0.2, n - 1) * pitch, [width]))
        for k in range(n):
            polygons.append([
                (bottom_x[k], at(r, bottom_x[k])),
                (bottom_x[k + 1], at(r, bottom_x[k + 1])),
                (top_x[k + 1], at(r + 1, top_x[k + 1])),
                (top_x[k], at(r + 1, top_x[k])),
            ])
    return polygons


def brute_force_interfaces(polygons, tol):
    """Reference: every pair of blocks, every pair of edges, tested directly."""
    found = {}
    edges = []
    for b, poly in enumerate(polygons):
        p = np.array(poly, dtype=float)
        for i in range(len(p)):
            edges.append((b, p[i], p[(i + 1) % len(p)]))
    for (ba, a0, a1), (bb, b0, b1) in itertools.combinations(edges, 2):
        if ba == bb:
            continue
        da = (a1 - a0) / np.linalg.norm(a1 - a0)
        db = (b1 - b0) / np.linalg.norm(b1 - b0)
        if np.dot(da, db) > -1 + 1e-9:  # must be antiparallel
            continue
        normal = np.array([da[1], -da[0]])
        if abs(np.dot(b0 - a0, normal)) > tol or abs(np.dot(b1 - a0, normal)) > tol:
            continue
        sa = sorted((0.0, np.dot(a1 - a0, da)))
        sb = sorted((np.dot(b0 - a0, da), np.dot(b1 - a0, da)))
        lo, hi = max(sa[0], sb[0]), min(sa[1], sb[1])
        if hi - lo >= tol:
            ends = tuple(sorted((round(float(q[0]), 9), round(float(q[1]), 9)) for q in (a0 + lo * da, a0 + hi * da)))
            found.setdefault(tuple(sorted((ba, bb))), []).append(ends)
    return {k: sorted(v) for k, v in found.items()}


@pytest.mark.parametrize("seed, degrees", [(1, 0.0), (2, 0.0), (3, 0.0), (4, 37.0), (5, -101.0)])
def test_irregular_convex_masonry_matches_brute_force(seed, degrees):
    polygons = [
        list(zip(*rotate(np.array(p)[:, 0], np.array(p)[:, 1], degrees))) for p in random_masonry(6, seed)
    ]
    layout = polygons_layout(polygons)
    tol = 1e-6 * np.hypot(np.ptp(layout[0]), np.ptp(layout[1]))
    result = detect_interfaces(*layout)
    assert unordered(result) == brute_force_interfaces(polygons, tol)
    assert_orientation_rule(result, *layout)


def test_empty_and_isolated_blocks():
    assert detect_interfaces([], [], [])["blocks"].shape == (0, 2)
    assert len(detect_interfaces(*polygons_layout([box(0, 1, 0, 1), box(3, 4, 0, 1)]))["blocks"]) == 0


def test_bad_layout_raises_naming_the_field():
    with pytest.raises(ModelError, match="block_node_count sums to 5"):
        detect_interfaces(np.zeros(4), np.zeros(4), [5])
    with pytest.raises(ModelError, match="block 1: vertex 5"):
        x, y, counts = polygons_layout([box(0, 1, 0, 1), box(1, 2, 0, 1)])
        x[5] = np.nan
        detect_interfaces(x, y, counts)
    with pytest.raises(ModelError, match="tol"):
        detect_interfaces(*polygons_layout([box(0, 1, 0, 1)]), tol=-1.0)


def test_nested_overlapping_edges_on_one_line():
    # A bad model: base blocks 0 [0,4] and 1 [1,2] overlap (1 lies inside 0), 2 is [3,5];
    # block 3 [2.5,6] stands on them. The sweep must not stop at the short edge of
    # block 1: the unit touches 0 on [2.5, 4] and 2 on [3, 5], and not 1.
    polygons = [box(0, 4, 0, 1), box(1, 2, 0, 1), box(3, 5, 0, 1), box(2.5, 6, 1, 2)]
    rows = as_rows(detect_interfaces(*polygons_layout(polygons)))
    assert (0, 3, (2.5, 1.0), (4.0, 1.0)) in rows
    assert (2, 3, (3.0, 1.0), (5.0, 1.0)) in rows
    assert not any(r[:2] == (1, 3) for r in rows)
