"""The score functions against hand computations and independent formulations."""
from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest
from scipy.stats import spearmanr

import masonryfw.plugin_api as mfp
from masonryfw_compare import scores
from masonryfw_compare.shapes import distance_to_segments


def pair_counting_ari(a, b) -> float:
    """ARI from the pair confusion matrix, by enumerating every pair (Steinley 2004 form).

    TP: pairs together in both; FP: together in b only; FN: in a only; TN: in neither.
    ARI = 2 (TP TN - FN FP) / ((TP + FN)(FN + TN) + (TP + FP)(FP + TN)).
    """
    tp = fp = fn = tn = 0
    for i, j in combinations(range(len(a)), 2):
        same_a, same_b = a[i] == a[j], b[i] == b[j]
        tp += same_a and same_b
        fn += same_a and not same_b
        fp += same_b and not same_a
        tn += not same_a and not same_b
    return 2.0 * (tp * tn - fn * fp) / ((tp + fn) * (fn + tn) + (tp + fp) * (fp + tn))


def test_confusion_scores_of_a_hand_made_pair():
    # A = {0, 1, 2, 3, 9}, B = {1, 2, 5, 9} at threshold 0.1; A & B = {1, 2, 9}
    a = np.array([0.9, 0.5, 0.2, 0.15, 0.05, 0, 0, 0, 0, 0.11])
    b = np.array([0, 0.3, 0.8, 0.09, 0, 0.5, 0, 0, 0, 0.2])
    s = scores.confusion_scores(a > 0.1, b > 0.1)
    assert (s["crack_count_a"], s["crack_count_b"], s["crack_count_both"]) == (5, 4, 3)
    assert s["crack_precision"] == pytest.approx(3 / 4)
    assert s["crack_recall"] == pytest.approx(3 / 5)
    assert s["crack_f1"] == pytest.approx(2 / 3)  # 2*3 / (5 + 4)
    assert s["crack_jaccard"] == pytest.approx(3 / 6)


def test_undefined_set_scores_are_left_out():
    none = np.zeros(5, dtype=bool)
    some = np.array([1, 0, 0, 1, 0], dtype=bool)
    both_empty = scores.confusion_scores(none, none)
    assert set(both_empty) == {"crack_count_a", "crack_count_b", "crack_count_both"}
    only_b = scores.confusion_scores(none, some)
    assert only_b["crack_precision"] == 0 and only_b["crack_f1"] == 0 and only_b["crack_jaccard"] == 0
    assert "crack_recall" not in only_b


def test_weighted_overlap_by_hand():
    # min: 0.5*1 + 0.25*2 = 1; max: 1*1 + 1*2 = 3
    assert scores.weighted_overlap(np.array([0.5, 1.0]), np.array([1.0, 0.25]), np.array([1.0, 2.0])) == pytest.approx(1 / 3)
    assert scores.weighted_overlap(np.zeros(3), np.zeros(3), np.ones(3)) is None


def test_spearman_by_hand_and_against_scipy_with_ties():
    # no ties: rho = 1 - 6 sum d^2 / (n (n^2 - 1)) = 1 - 6*4 / (5*24) = 0.8
    assert scores.spearman(np.array([1, 2, 3, 4, 5.0]), np.array([2, 1, 4, 3, 5.0])) == pytest.approx(0.8)
    rng = np.random.default_rng(3)
    a = rng.integers(0, 4, 40) / 4.0  # many ties, like thresholded indicators
    b = np.clip(a + rng.normal(0, 0.3, 40), 0, 1).round(1)
    assert scores.spearman(a, b) == pytest.approx(spearmanr(a, b).statistic, abs=1e-12)
    assert scores.spearman(np.ones(4), np.arange(4.0)) is None


def test_adjusted_rand_index_of_a_hand_made_contingency_table():
    # table [[2, 1, 0], [0, 1, 2]]: index = 1 + 1 = 2; rows 2*C(3,2) = 6; columns 3*C(2,2) = 3;
    # expected = 6*3/C(6,2) = 1.2; maximum = 4.5; ARI = (2 - 1.2) / (4.5 - 1.2) = 8/33
    a = [0, 0, 0, 1, 1, 1]
    b = [0, 0, 1, 1, 2, 2]
    assert scores.adjusted_rand_index(a, b) == pytest.approx(8 / 33)
    assert scores.adjusted_rand_index(a, [7, 7, 7, 3, 3, 3]) == 1.0  # labels do not matter
    assert scores.adjusted_rand_index(np.arange(6), np.arange(6)[::-1]) == 1.0  # all singletons
    assert scores.adjusted_rand_index([0], [0]) is None


def test_adjusted_rand_index_matches_pair_counting():
    rng = np.random.default_rng(7)
    for _ in range(5):
        a, b = rng.integers(0, 4, 30), rng.integers(0, 5, 30)
        assert scores.adjusted_rand_index(a, b) == pytest.approx(pair_counting_ari(a, b), abs=1e-12)


def _rectangle_nodes(x0, y0, b, h):
    return np.array([x0, x0 + b, x0 + b, x0]), np.array([y0, y0, y0 + h, y0 + h])


def test_rigid_field_cosine_equals_the_integral_of_the_displacement_fields():
    """Reference: midpoint-rule integration of u_a . u_b over a fine grid inside each block."""
    b, h = np.array([0.4, 0.2]), np.array([0.1, 0.3])
    x0, y0 = np.array([0.0, 0.4]), np.array([0.0, 0.0])
    nodes = [_rectangle_nodes(*args) for args in zip(x0, y0, b, h)]
    node_x = np.concatenate([n[0] for n in nodes])
    node_y = np.concatenate([n[1] for n in nodes])
    cx, cy = x0 + b / 2, y0 + h / 2
    u_a = np.array([[0.0, -1.0, 0.5], [0.2, -0.7, -1.5]])
    u_b = np.array([[0.1, -0.8, -0.3], [0.0, -1.0, 2.0]])
    n = 200
    s = (np.arange(n) + 0.5) / n
    inner = {}
    for name, (p, q) in {"ab": (u_a, u_b), "aa": (u_a, u_a), "bb": (u_b, u_b)}.items():
        total = 0.0
        for k in range(2):
            gx, gy = np.meshgrid(x0[k] + b[k] * s, y0[k] + h[k] * s)
            owner = np.full(gx.size, k)
            pa = mfp.point_motion(p, cx, cy, gx.ravel(), gy.ravel(), owner)
            pb = mfp.point_motion(q, cx, cy, gx.ravel(), gy.ravel(), owner)
            total += np.sum(pa[0] * pb[0] + pa[1] * pb[1]) * b[k] * h[k] / n**2
        inner[name] = total
    reference = inner["ab"] / np.sqrt(inner["aa"] * inner["bb"])
    area = b * h
    polar = mfp.polar_moment(node_x, node_y, [4, 4])
    assert scores.rigid_field_cosine(u_a, u_b, area, polar) == pytest.approx(reference, rel=1e-5)
    assert scores.rigid_field_cosine(u_a, 3.0 * u_a, area, polar) == pytest.approx(1.0)
    assert scores.rigid_field_cosine(u_a, -u_a, area, polar) == pytest.approx(-1.0)
    assert scores.rigid_field_cosine(u_a, np.zeros_like(u_a), area, polar) is None


def test_distance_to_segments_by_hand():
    seg_x = np.array([[-1.0, 1.0], [5.0, 5.0]])
    seg_y = np.array([[0.0, 0.0], [-1.0, 1.0]])
    px = np.array([0.0, 3.0, 4.0, 5.0])
    py = np.array([1.0, 0.0, 3.0, 0.5])
    # above the first; 2 from its end (x=1) vs 2 from the second; 2 above (5, 1) -> hypot(1, 2); on the second
    expected = [1.0, 2.0, np.hypot(1.0, 2.0), 0.0]
    assert distance_to_segments(px, py, seg_x, seg_y, chunk_bytes=100) == pytest.approx(expected)
