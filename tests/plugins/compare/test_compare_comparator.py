"""The ``crack`` comparator on hand-made results: identity, exact scores, monotone decay, refusals."""
from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp


def compare(a, b, options):
    """The crack comparator through the core (options resolved and checked there)."""
    return mf.compare(a, b, "crack", options)


SIMILARITIES = (
    "crack_precision", "crack_recall", "crack_f1", "crack_jaccard", "crack_overlap",
    "crack_spearman", "macro_block_ari", "mechanism_cosine",
)
DISTANCES = ("locus_distance_a_to_b", "locus_distance_b_to_a", "locus_distance")


def _with_cracks(result: xr.Dataset, indicator: np.ndarray) -> xr.Dataset:
    """``result`` with a hand-made ``crack_indicator`` and without the joint motions it would be derived from
    (the comparison's threshold then applies to the indicator itself, :func:`masonryfw.at_threshold`)."""
    bare = result.drop_vars(["interface_opening", "interface_slip"])
    return bare.assign(crack_indicator=("interface", np.asarray(indicator, dtype=float),
                                        mfp.variable_attrs("crack_indicator")))


@pytest.mark.parametrize("kind", ["la", "fdem", "jmm"])
def test_a_result_against_itself_scores_one_everywhere(results, kind):
    scored = compare(results[kind], results[kind], {})
    present = [n for n in SIMILARITIES if n in scored]
    expected = {"la": SIMILARITIES, "fdem": SIMILARITIES, "jmm": SIMILARITIES[:6]}[kind]
    assert present == list(expected)
    for name in present:
        assert scored[name].item() == pytest.approx(1.0), name
    for name in DISTANCES:
        assert scored[name].item() == pytest.approx(0.0, abs=1e-12), name


def test_scores_not_computable_are_absent_never_nan(results):
    scored = compare(results["la"], results["jmm"], {})
    assert "macro_block_ari" not in scored and "mechanism_cosine" not in scored
    assert "collapse_multiplier_a" not in scored  # only la has a multiplier
    assert all(np.isfinite(scored[n].values) for n in scored.data_vars)
    assert all(scored[n].ndim == 0 for n in scored.data_vars)


def test_hand_made_patterns_give_the_hand_computed_scores(model, build):
    # on ten head joints h (all of length H): A = {h0, h1, h2, h3, h9}, B = {h1, h2, h5, h9} at threshold 0.1
    # (0.09 and 0.05 stay intact)
    h = np.flatnonzero(model.interface_kind.values == mfp.flags("interface_kind")["head"])[:10]
    a = np.zeros(model.sizes["interface"])
    a[h[[0, 1, 2, 3, 4, 9]]] = [0.9, 0.5, 0.2, 0.15, 0.05, 0.11]
    b = np.zeros(model.sizes["interface"])
    b[h[[1, 2, 3, 5, 9]]] = [0.3, 0.8, 0.09, 0.5, 0.2]
    base = build.la_result(model)
    s = compare(_with_cracks(base, a), _with_cracks(base, b), {"threshold": 0.1})
    assert (s.crack_count_a.item(), s.crack_count_b.item(), s.crack_count_both.item()) == (5, 4, 3)
    assert s.crack_precision.item() == pytest.approx(3 / 4)
    assert s.crack_recall.item() == pytest.approx(3 / 5)
    assert s.crack_f1.item() == pytest.approx(2 / 3)
    assert s.crack_jaccard.item() == pytest.approx(1 / 2)
    # all of one length: overlap = sum min / sum max, of the indicators at the threshold (0.09 and 0.05 are 0)
    assert s.crack_overlap.item() == pytest.approx((0.3 + 0.2 + 0.11) / (0.9 + 0.5 + 0.8 + 0.15 + 0.5 + 0.2))
    at_half = compare(_with_cracks(base, a), _with_cracks(base, b), {"threshold": 0.5})
    # A = {0} (0.5 is not > 0.5), B = {2}
    assert (at_half.crack_count_a.item(), at_half.crack_count_b.item(), at_half.crack_count_both.item()) == (1, 1, 0)


def test_moving_k_cracks_elsewhere_lowers_the_scores_exactly_and_monotonically(build):
    model = build.grid_model(rows=6, cols=8, split=4)
    bed = np.flatnonzero(model.interface_kind.values == 0)  # all of length B
    base = build.la_result(model)
    n = 6
    cracked = bed[:n]
    spare = bed[n:][::-1]
    rows = []
    for k in range(n + 1):
        moved = np.concatenate([cracked[k:], spare[:k]])
        pattern_a, pattern_b = np.zeros(model.sizes["interface"]), np.zeros(model.sizes["interface"])
        pattern_a[cracked], pattern_b[moved] = 1.0, 1.0
        s = compare(_with_cracks(base, pattern_a), _with_cracks(base, pattern_b), {})
        assert s.crack_f1.item() == pytest.approx((n - k) / n)
        assert s.crack_precision.item() == pytest.approx((n - k) / n)
        assert s.crack_recall.item() == pytest.approx((n - k) / n)
        assert s.crack_jaccard.item() == pytest.approx((n - k) / (n + k))
        assert s.crack_overlap.item() == pytest.approx((n - k) / (n + k))
        rows.append(s.crack_spearman.item())
    assert np.all(np.diff(rows) < 0)


def test_shifting_the_crack_by_k_columns_gives_closed_form_scores(build):
    rows, cols, m = 4, 8, 2
    model = build.grid_model(rows=rows, cols=cols, split=m)
    diagonal = np.hypot(cols * build.B, (rows + 1) * build.H)
    reference = build.la_result(model, m, cracked=build.head_line(model, m))
    ari, cosine, distance = [], [], []
    for k in range(5):
        shifted = build.la_result(model, m + k, cracked=build.head_line(model, m + k))
        s = compare(reference, shifted, {})
        # right part: R (C - m) units in a, R (C - m - k) in b, all in a's right part; unit areas equal
        assert s.mechanism_cosine.item() == pytest.approx(np.sqrt((cols - m - k) / (cols - m)))
        # every point of one vertical crack line is k B from the other
        assert s.locus_distance_a_to_b.item() == pytest.approx(k * build.B / diagonal)
        assert s.locus_distance_b_to_a.item() == pytest.approx(k * build.B / diagonal)
        ari.append(s.macro_block_ari.item())
        cosine.append(s.mechanism_cosine.item())
        distance.append(s.locus_distance.item())
    # k = 1: table [[8, 0], [4, 20]] -> index 224, rows 304, columns 256, C(32, 2) = 496 -> 260/477
    assert ari[1] == pytest.approx(260 / 477)
    assert ari[0] == 1.0
    assert np.all(np.diff(ari) < 0) and np.all(np.diff(cosine) < 0) and np.all(np.diff(distance) > 0)


def test_continuum_plastic_points_are_scored_by_distance_to_the_cracked_joints(model, build):
    """Shear points 0.05 m right of the LA crack line x = 0.6 m, over its whole height."""
    la = build.la_result(model, 3, cracked=build.head_line(model, 3))
    jmm = build.jmm_result(model, crack_column=3, offset=0.05, tensile_top=False)
    s = compare(jmm, la, {})
    diagonal = np.hypot(6 * build.B, 5 * build.H)
    assert s.locus_distance_a_to_b.item() == pytest.approx(0.05 / diagonal)
    # reverse: mean over the crack line (x = 0.6, 0 <= y <= 0.4) of the distance to the nearest plastic
    # point (x = 0.65, y = 0.025 + 0.05 j): dense brute-force integration
    y = (np.arange(40000) + 0.5) / 40000 * 0.4
    plastic_y = 0.025 + 0.05 * np.arange(8)
    nearest = np.min(np.abs(y[:, None] - plastic_y[None, :]), axis=1)
    assert s.locus_distance_b_to_a.item() == pytest.approx(np.mean(np.hypot(0.05, nearest)) / diagonal, rel=2e-3)
    assert s.crack_f1.item() == 1.0  # through the crack_indicator mapping


def test_results_of_different_models_are_refused(model, build):
    other = build.grid_model(cols=7)
    with pytest.raises(mf.ModelError, match=r"different models: 26 vs 30 blocks"):
        compare(build.la_result(model), build.la_result(other), {})
    stiffer = build.la_result(model)
    friction = stiffer.interface_friction.values.copy()
    friction[5] = 0.6
    stiffer = stiffer.assign(interface_friction=stiffer.interface_friction.copy(data=friction))
    with pytest.raises(mf.ModelError, match=r"interface_friction differs at interface 5 \(0.4 vs 0.6\)"):
        compare(build.la_result(model), stiffer, {})
    renamed = build.la_result(model).assign_attrs(title="Another title")
    assert compare(build.la_result(model), renamed, {}).crack_f1.item() == 1.0  # the title is not the model


def test_bad_options_are_refused(results):
    with pytest.raises(mf.PluginError, match=r"option 'threshold' = 1.5: must be >= 0 and < 1"):
        compare(results["la"], results["la"], {"threshold": 1.5})
    with pytest.raises(mf.PluginError, match="unknown option 'tolerance'; valid options: threshold"):
        compare(results["la"], results["la"], {"tolerance": 1})


def test_through_the_core_the_comparison_is_a_valid_dataset_with_input_hashes(results, tmp_path):
    path = tmp_path / "la.nc"
    mf.save(results["la"], path)
    from_file = mf.open_dataset(path)
    comparison = mf.compare(from_file, results["fdem"], "crack", {"threshold": "0.2"})
    assert mf.check(comparison, kind="comparison") == []
    assert comparison.attrs["input_a_sha256"] == mfp.sha256_file(path)
    assert json.loads(comparison.attrs["comparator_options"]) == {"threshold": 0.2}
    scores = {n: comparison[n].item() for n in comparison.data_vars}
    assert json.loads(json.dumps(scores))["crack_f1"] == 1.0
    saved = tmp_path / "cmp.nc"
    mf.save(comparison, saved)
    assert float(xr.open_dataset(saved).crack_f1) == 1.0
