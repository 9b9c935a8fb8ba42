"""The core's result semantics (masonryfw.results.semantics) against independent references."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import xarray as xr
from scipy.sparse.csgraph import connected_components

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt
from masonryfw.plugin_api import connected_components as components


def rectangle_nodes(x0, y0, b, h):
    return np.array([x0, x0 + b, x0 + b, x0]), np.array([y0, y0, y0 + h, y0 + h])


def scipy_labels(n, edges):
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    _, first = np.unique(labels, return_index=True)
    return np.argsort(np.argsort(first))[labels]  # relabelled in order of each component's lowest block


@pytest.mark.parametrize("seed", range(20))
def test_components_match_scipy_on_random_graphs(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 300))
    edges = rng.integers(0, n, size=(int(rng.integers(0, 2 * n)), 2))
    np.testing.assert_array_equal(components(n, edges), scipy_labels(n, edges))


def test_a_long_chain_in_scrambled_order_is_one_component():
    order = np.random.default_rng(1).permutation(5000)
    edges = np.c_[order[:-1], order[1:]]
    assert (components(5000, edges) == 0).all()


def test_labels_follow_the_lowest_block():
    np.testing.assert_array_equal(components(6, np.array([[5, 1], [4, 2], [2, 0]])), [0, 1, 0, 2, 0, 1])


def test_polar_moment_of_a_rectangle_and_a_triangle_far_from_the_origin():
    rx, ry = rectangle_nodes(1e4, -2e3, 0.3, 0.1)
    tx, ty = np.array([5e3, 5e3 + 3.0, 5e3]), np.array([7e3, 7e3, 7e3 + 4.0])
    moment = mfp.polar_moment(np.concatenate([rx, tx]), np.concatenate([ry, ty]), [4, 3])
    assert moment[0] == pytest.approx(0.03 * (0.3**2 + 0.1**2) / 12, rel=1e-9)
    # triangle: J_c = A (a^2 + b^2 + c^2) / 36, sides 3, 4, 5, A = 6
    assert moment[1] == pytest.approx(6 * (9 + 16 + 25) / 36, rel=1e-9)




# ---------------------------------------------------------------- relative motion against closed forms

def two_blocks():
    """A 1 x 0.5 unit B (block 1) on a fixed 1 x 0.2 base A (block 0): one bed joint, ends at x = 0 and x = 1."""
    return mt.rectangles_model([(0.0, -0.2, 1.0, 0.0), (0.0, 0.0, 1.0, 0.5)], ["fixed_support", "unit"],
                               loading="tilt")


def rotation_about(pivot, theta, centroid):
    """Block motion (ux, uy, rz) of a rotation by ``theta`` about ``pivot`` (finite)."""
    c = np.asarray(centroid) - pivot
    moved = pivot + np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]]) @ c
    return np.array([*(moved - centroid), theta])


@pytest.mark.parametrize("theta", [1e-3, 0.3])
def test_finite_rotation_about_a_corner_opens_the_far_end_by_l_sin_theta(theta):
    """B tips about its left bottom corner: end 1 (x = 1) moves by (L (cos - 1), L sin); end 0 stays."""
    model = two_blocks()
    u = np.zeros((2, 3))
    u[1] = rotation_about(np.array([0.0, 0.0]), theta, [0.5, 0.25])
    opening, slip = mfp.relative_motion(model, u, "finite")
    assert opening[0] == pytest.approx([0.0, np.sin(theta)], abs=1e-14)
    assert slip[0] == pytest.approx([0.0, np.cos(theta) - 1.0], abs=1e-14)


def test_a_mechanism_moves_points_by_the_linearised_rotation():
    """The same motion read as a velocity field: opening theta L, no slip, whatever theta's size."""
    model = two_blocks()
    theta = 0.3
    u = np.zeros((2, 3))
    u[1] = (-theta * 0.25, theta * 0.5, theta)  # v_c = w x (c - pivot), c - pivot = (0.5, 0.25)
    opening, slip = mfp.relative_motion(model, u, "small")
    assert opening[0] == pytest.approx([0.0, theta], abs=1e-14)
    assert slip[0] == pytest.approx([0.0, 0.0], abs=1e-14)


def test_side_one_minus_side_zero_with_the_interface_frame():
    """A translation of B by (a, b) over a fixed A: opening b (n = +y), slip a (t = +x) at both ends."""
    model = two_blocks()
    u = np.zeros((2, 3))
    u[1, :2] = (0.02, 0.005)
    for rotations in ("small", "finite"):
        opening, slip = mfp.relative_motion(model, u, rotations)
        assert opening[0] == pytest.approx([0.005, 0.005]) and slip[0] == pytest.approx([0.02, 0.02])


# ---------------------------------------------------------------- states, indicator, macro-blocks

STATE = mfp.flags("interface_state")


def test_states_by_hand():
    """Threshold 0.1; rows: still, tipping, sliding with dilatancy mu = 0.5, sliding and lifting, closing."""
    opening = np.array([[0.0, 0.05], [0.0, 1.0], [0.5, 0.5], [1.0, 0.6], [-1.0, -1.0]])
    slip = np.array([[0.0, 0.0], [0.05, 0.05], [1.0, 1.0], [1.0, 1.0], [0.0, 0.0]])
    associative = mfp.interface_states(opening, slip, 0.5, 0.1)
    assert associative.tolist() == [STATE["intact"], STATE["open"], STATE["slide"], STATE["open_slide"],
                                    STATE["intact"]]
    # without dilatancy the same opening beside a slip is an opening beyond it
    nonassociative = mfp.interface_states(opening, slip, 0.0, 0.1)
    assert nonassociative[2] == STATE["open_slide"]
    assert mfp.joint_motion(opening, slip).tolist() == pytest.approx(
        [0.05, np.hypot(1.0, 0.05), np.hypot(0.5, 1), np.hypot(1, 1), 0.0])  # closing is no motion


def test_crack_indicator_is_relative_to_the_largest_masonry_joint():
    motion = np.array([2.0, 1.0, 0.3, 0.19, 5.0])
    masonry = np.array([True, True, True, True, False])  # the last is ground against ground
    indicator = mfp.crack_indicator(motion, masonry)
    assert indicator.tolist() == pytest.approx([1.0, 0.5, 0.15, 0.0, 0.0])  # 0.19 / 2 is below a tenth
    assert mf.CRACK_THRESHOLD == 0.1
    assert mfp.crack_indicator(motion, masonry, 0.05).tolist() == pytest.approx([1.0, 0.5, 0.15, 0.095, 0.0])


def segment_distances(model, x, y):
    """Exact distance of every point to every interface segment (points, interfaces)."""
    ix, iy = model.interface_x.values, model.interface_y.values
    a = np.stack([ix[:, 0], iy[:, 0]], axis=1)
    d = np.stack([ix[:, 1] - ix[:, 0], iy[:, 1] - iy[:, 0]], axis=1)
    p = np.stack([x, y], axis=1)[:, None, :]
    t = np.clip(((p - a) * d).sum(-1) / (d * d).sum(-1), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * d), axis=-1)


def brick_wall():
    """Two courses of two 0.4 x 0.2 units, the lower half-bond shifted, on a fixed base: 8 joints."""
    rects = [(0.0, -0.1, 0.8, 0.0), (0.0, 0.0, 0.4, 0.2), (0.4, 0.0, 0.8, 0.2),
             (0.0, 0.2, 0.2, 0.4), (0.2, 0.2, 0.6, 0.4), (0.6, 0.2, 0.8, 0.4)]
    return mt.rectangles_model(rects, ["fixed_support"] + ["unit"] * 5, loading="tilt")


@pytest.mark.parametrize("spacing", [0.05, 0.01])
def test_points_go_to_their_nearest_joint_within_half_the_sampling(spacing):
    model = brick_wall()
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 0.8, 2000), rng.uniform(-0.05, 0.4, 2000)
    exact = segment_distances(model, x, y)
    found = mfp.nearest_interface(model, x, y, spacing)
    assert (exact[np.arange(x.size), found] <= exact.min(axis=1) + spacing / 2 + 1e-12).all()
    assert (found == exact.argmin(axis=1)).mean() > (0.95 if spacing == 0.01 else 0.8)


def test_a_continuum_s_crack_indicator_is_the_yielding_share_of_the_nearest_points():
    """Points on a 0.01 grid, yielding in the upper-right unit: its joints get the yielding share by hand."""
    model = brick_wall()
    gx, gy = np.meshgrid(np.arange(0.005, 0.8, 0.01), np.arange(0.005, 0.4, 0.01))
    x, y = gx.ravel(), gy.ravel()
    plastic = (x > 0.6) & (y > 0.2)
    indicator = mfp.plastic_crack_indicator(model, x, y, plastic)
    nearest = segment_distances(model, x, y).argmin(axis=1)
    by_hand = np.array([plastic[nearest == i].mean() if (nearest == i).any() else 0.0
                        for i in range(model.sizes["interface"])])
    base = mfp.masonry_joints(model.block_role.values, model.interface_blocks.values)
    np.testing.assert_allclose(indicator, np.where(base, by_hand, 0.0), atol=0.03)
    assert indicator.max() > 0.3 and (indicator[by_hand == 0] == 0).all()


def test_a_continuum_result_gets_the_core_s_crack_indicator(registered):
    model = brick_wall()
    x, y = np.array([0.7, 0.1]), np.array([0.19, 0.01])  # by the upper-right unit's bed, on the base

    def continuum(model, options, progress):
        return xr.Dataset({"qp_x": ("qp", x), "qp_y": ("qp", y), "qp_failure": ("qp", np.array([2, 0], np.int8))})

    registered(continuum)
    result = mf.solve(model, "tipping")
    cracked = mfp.nearest_interface(model, x[:1], y[:1], 0.01)[0]
    assert np.flatnonzero(result.crack_indicator.values).tolist() == [cracked]
    assert result.crack_indicator.values[cracked] == 1.0


def union_find_groups(n, pairs):
    parent = list(range(n))

    def root(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for a, b in pairs:
        parent[root(a)] = root(b)
    return [root(i) for i in range(n)]


@pytest.mark.parametrize("seed", range(5))
def test_macro_blocks_are_the_groups_joined_by_intact_joints(seed):
    rng = np.random.default_rng(seed)
    n = 40
    pairs = rng.integers(0, n, size=(60, 2))
    state = rng.choice([STATE["intact"], STATE["open"], STATE["slide"]], size=60)
    labels = mfp.macro_blocks(n, pairs, state)
    groups = union_find_groups(n, pairs[state == STATE["intact"]])
    same = np.equal.outer(labels, labels)
    assert np.array_equal(same, np.equal.outer(groups, groups))


# ---------------------------------------------------------------- derived once by mf.solve, for any solver

def test_a_third_party_mechanism_gets_the_core_s_fields(registered):
    """B tips about its left corner: its bed joint opens (state open, indicator 1), B is its own macro-block."""
    theta = 0.01

    def tipping(model, options, progress):
        u = np.zeros((2, 3))
        u[1] = (-theta * 0.25, theta * 0.5, theta)
        return xr.Dataset(mfp.motion_variables(u), attrs={"rotations": "small", "flow_rule": "associative"})

    registered(tipping)
    result = mf.solve(two_blocks(), "tipping")
    assert result.interface_opening.values[0] == pytest.approx([0.0, theta])
    assert result.interface_state.values.tolist() == [STATE["open"]]
    assert result.crack_indicator.values.tolist() == [1.0]
    assert result.macro_block.values.tolist() == [0, 1]


@pytest.mark.parametrize("attrs, returned, message", [
    ({"flow_rule": "associative"}, {}, "without the attribute 'rotations'"),
    ({"rotations": "small", "flow_rule": "associative"}, {"crack_indicator": ("interface", [0.5])},
     "returned crack_indicator with block_displacement"),
])
def test_the_core_refuses_a_mechanism_it_cannot_read(registered, attrs, returned, message):
    def solve(model, options, progress):
        return xr.Dataset({**mfp.motion_variables(np.zeros((2, 3))), **returned}, attrs=attrs)

    registered(solve)
    with pytest.raises(mf.SolveError, match=message):
        mf.solve(two_blocks(), "tipping")


# ---------------------------------------------------------------- key numbers

def history_result(settlement, reaction):
    model = two_blocks()
    return model.assign(step_settlement=("step", settlement), step_reaction=("step", reaction))


def test_key_numbers_of_a_history_by_hand():
    """Gravity at s = 0 (R0 = 100 N), a dip to 40 N at 2 mm, then 50.4, 50, 49.8, 50.3 N: within 1 N of the last from 4 mm."""
    settlement = np.array([0.0, 0.0, 0.001, 0.002, 0.003, 0.004, 0.005, 0.006, 0.007])
    reaction = np.array([0.0, 100.0, 70.0, 40.0, 45.0, 50.4, 50.0, 49.8, 50.3])
    numbers = {n.name: n.value for n in mf.key_numbers(history_result(settlement, reaction))}
    assert numbers["dead_reaction"] == 100.0
    assert (numbers["minimum_reaction"], numbers["minimum_reaction_settlement"]) == (40.0, 0.002)
    assert numbers["plateau_settlement"] == 0.004
    assert numbers["plateau_reaction"] == pytest.approx((50.4 + 50.0 + 49.8 + 50.3) / 4)
    assert numbers["final_settlement"] == 0.007


def test_key_numbers_of_a_limit_analysis_are_alpha_the_dead_reaction_and_the_reaction_at_collapse():
    model = mt.rectangles_model([(0.0, -0.2, 0.5, 0.0), (0.5, -0.2, 1.0, 0.0), (0.0, 0.0, 1.0, 0.5)],
                                ["fixed_support", "moving_support", "unit"])
    result = model.assign(collapse_multiplier=((), 0.25))
    numbers = {n.name: n.value for n in mf.key_numbers(result)}
    r0 = 12e3 * 0.5 * 0.1 * 0.5  # weight times the moving support's half of the contact
    assert numbers == pytest.approx({"alpha": 0.25, "dead_reaction": r0, "collapse_reaction": 0.75 * r0})
