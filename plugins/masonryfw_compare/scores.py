"""Agreement scores between two failure patterns: small pure functions on arrays.

Every function returns ``None`` where its score is undefined (an empty set, a
constant field): the comparison then leaves that score out instead of writing
a NaN that pretends to be a number.
"""
from __future__ import annotations

import numpy as np
from scipy.stats import rankdata


def confusion_scores(cracked_a: np.ndarray, cracked_b: np.ndarray) -> dict[str, float | int]:
    """Counts, precision, recall, F1 and Jaccard of the cracked set of ``b`` against ``a``.

    ``a`` is the reference: precision = |A & B| / |B|, recall = |A & B| / |A|,
    F1 = 2 |A & B| / (|A| + |B|), Jaccard = |A & B| / |A | B|.
    """
    a = np.asarray(cracked_a, dtype=bool)
    b = np.asarray(cracked_b, dtype=bool)
    both, n_a, n_b = int(np.sum(a & b)), int(a.sum()), int(b.sum())
    union = n_a + n_b - both
    scores: dict[str, float | int] = {
        "crack_count_a": n_a,
        "crack_count_b": n_b,
        "crack_count_both": both,
    }
    for name, denominator, numerator in (
        ("crack_precision", n_b, both),
        ("crack_recall", n_a, both),
        ("crack_f1", n_a + n_b, 2 * both),
        ("crack_jaccard", union, both),
    ):
        if denominator > 0:
            scores[name] = numerator / denominator
    return scores


def weighted_overlap(a: np.ndarray, b: np.ndarray, weight: np.ndarray) -> float | None:
    """``sum(w min(a, b)) / sum(w max(a, b))``: the weighted Jaccard (Ruzicka) similarity.

    Threshold-free; equals the length-weighted Jaccard index for 0/1 indicators.
    """
    lower = np.sum(weight * np.minimum(a, b))
    upper = np.sum(weight * np.maximum(a, b))
    return float(lower / upper) if upper > 0 else None


def spearman(a: np.ndarray, b: np.ndarray) -> float | None:
    """Spearman rank correlation: Pearson correlation of the average ranks (ties share a rank)."""
    ra = rankdata(a) - 0.5 * (len(a) + 1)
    rb = rankdata(b) - 0.5 * (len(b) + 1)
    norm = np.sqrt(np.sum(ra * ra) * np.sum(rb * rb))
    return float(np.clip(np.sum(ra * rb) / norm, -1.0, 1.0)) if norm > 0 else None


def _pairs(n: np.ndarray) -> np.ndarray:
    """Number of unordered pairs among ``n`` items."""
    n = np.asarray(n, dtype=float)
    return n * (n - 1) / 2


def adjusted_rand_index(labels_a: np.ndarray, labels_b: np.ndarray) -> float | None:
    """Adjusted Rand index (Hubert and Arabie, 1985) of two partitions of the same items.

    From the contingency table n_ij (items in cluster i of ``a`` and j of ``b``)::

        index    = sum_ij C(n_ij, 2)
        expected = sum_i C(a_i, 2) sum_j C(b_j, 2) / C(n, 2)
        maximum  = (sum_i C(a_i, 2) + sum_j C(b_j, 2)) / 2
        ARI      = (index - expected) / (maximum - expected)

    1 for identical partitions (whatever the labels), about 0 for chance
    agreement. maximum == expected only when both partitions are all singletons
    or both a single cluster, i.e. identical: 1 by convention. None for < 2 items.
    """
    a = np.asarray(labels_a).ravel()
    b = np.asarray(labels_b).ravel()
    if a.size < 2:
        return None
    _, ia = np.unique(a, return_inverse=True)
    _, ib = np.unique(b, return_inverse=True)
    _, cell_counts = np.unique(ia * (ib.max() + 1) + ib, return_counts=True)
    index = _pairs(cell_counts).sum()
    sum_a = _pairs(np.bincount(ia)).sum()
    sum_b = _pairs(np.bincount(ib)).sum()
    expected = sum_a * sum_b / _pairs(a.size)
    maximum = 0.5 * (sum_a + sum_b)
    if maximum == expected:
        return 1.0
    return float((index - expected) / (maximum - expected))


def rigid_field_cosine(u_a, u_b, area, polar_moment) -> float | None:
    """Cosine of two rigid-block displacement fields in L2 over the blocks' area.

    For a block moving by ``u_c`` and rotating by ``rz`` about its centroid, the
    displacement field integrates, because the first moment about the centroid
    vanishes, to ``int u_a . u_b dA = A u_ca . u_cb + J rz_a rz_b`` with J the
    polar moment about the centroid: rotations are scaled by the block's radius
    of gyration sqrt(J / A). The cosine is scale-free, so a normalised mechanism
    and a physical displacement compare directly.
    """
    ua = np.asarray(u_a, dtype=float)
    ub = np.asarray(u_b, dtype=float)

    def inner(p, q):
        return float(np.sum(area * (p[:, 0] * q[:, 0] + p[:, 1] * q[:, 1]) + polar_moment * p[:, 2] * q[:, 2]))

    norm = np.sqrt(inner(ua, ua) * inner(ub, ub))
    return float(np.clip(inner(ua, ub) / norm, -1.0, 1.0)) if norm > 0 else None

