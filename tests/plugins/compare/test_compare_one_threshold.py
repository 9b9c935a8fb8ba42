"""One crack threshold: the mechanism and cracks plots, the comparator, the report's key numbers and the
diagnosis's survey find the same cracked joints on one result, at the core's threshold and at a user's.

The reference is computed here by hand from the relative motion at the joints (docs/format.md): a joint
between two blocks that are not both supports is cracked where its largest end motion
``|(max(opening, 0), slip)|`` is more than the threshold times the largest such motion.
"""
from __future__ import annotations

import re

import numpy as np
import pytest
from click.testing import CliRunner
from matplotlib.collections import LineCollection

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.cli import cli
from masonryfw_diagnose.synthetic import visible_cracks

SUPPORT_ROLES = [mfp.flags("block_role")["fixed_support"], mfp.flags("block_role")["moving_support"]]


@pytest.fixture(scope="module", params=["la", "fdem"])
def result(request):
    return mf.solve(mf.open_model("test-12c"), request.param)


def cracked_by_hand(result, threshold: float) -> np.ndarray:
    opening, slip = result.interface_opening.values, result.interface_slip.values
    motion = np.hypot(np.maximum(opening, 0.0), slip).max(axis=1)
    support = np.isin(result.block_role.values, SUPPORT_ROLES)
    masonry = ~support[result.interface_blocks.values].all(axis=1)
    return masonry & (motion > threshold * motion[masonry].max())


def mechanism_count(result, options: dict) -> int:
    legend = mf.render([result], "mechanism", options).axes[0].get_legend()
    found = [re.fullmatch(r"cracked joints \((\d+)\)", text.get_text()) for text in legend.get_texts()]
    return int(next(m for m in found if m).group(1))


def cracks_count(result, options: dict) -> int:
    axes = mf.render([result], "cracks", options).axes[0]
    return sum(len(c.get_segments()) for c in axes.collections if isinstance(c, LineCollection))


@pytest.mark.parametrize("threshold", [None, 0.05, 0.3])
def test_plots_comparator_and_survey_count_the_same_cracks(result, threshold):
    options = {} if threshold is None else {"threshold": threshold}
    expected = cracked_by_hand(result, mf.CRACK_THRESHOLD if threshold is None else threshold)
    assert 3 <= expected.sum() < expected.size  # a real pattern, neither nothing nor everything
    assert mechanism_count(result, options) == expected.sum()
    assert cracks_count(result, options) == expected.sum()
    assert mf.compare(result, result, "crack", options).crack_count_a.item() == expected.sum()
    assert np.array_equal(mf.cracked_joints(result, *options.values()), expected)
    inner = ~np.isin(result.block_role.values, SUPPORT_ROLES)[result.interface_blocks.values].any(axis=1)
    assert np.array_equal(visible_cracks(result, *options.values()), np.flatnonzero(expected & inner))


def test_the_report_counts_the_cracks_of_the_core_threshold(result, tmp_path):
    mf.save(result, tmp_path / "r.nc")
    done = CliRunner().invoke(cli, ["report", str(tmp_path / "r.nc"), "-o", str(tmp_path / "r.html"), "--no-progress"])
    assert done.exit_code == 0, done.output
    row = re.search(r"<th[^>]*>cracked joints</th>\s*<td[^>]*>(\d+)</td>", (tmp_path / "r.html").read_text())
    assert row is not None and int(row.group(1)) == cracked_by_hand(result, 0.1).sum()
