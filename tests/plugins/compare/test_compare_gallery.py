"""The gallery's agreement table and pictures, from hand-made results and (slow) from real solves."""
from __future__ import annotations

import pytest
from click.testing import CliRunner
from PIL import Image

import masonryfw as mf
from masonryfw_compare.commands import gallery_command
from masonryfw_compare.gallery import CaseOutcome, Run, agreement_markdown, case_figure, planned_runs


def _outcome(build, results) -> CaseOutcome:
    model = build.grid_model()
    shifted = build.la_result(model, 4, cracked=build.head_line(model, 4), backend="clarabel")
    la = results["la"]
    pairs = [("la (highs)", "la (clarabel)", mf.compare(la, shifted, "crack")),
             ("la (highs)", "jmm", mf.compare(la, results["jmm"], "crack"))]
    return CaseOutcome("grid", "Grid wall", [la, shifted, results["jmm"]], [("la (osqp)", "OSQP failed")],
                       pairs, {"la (highs)": 0.25, "la (clarabel)": 0.5})


def test_agreement_table_holds_the_scores_and_says_what_is_missing(build, results):
    runs = [Run("la (highs)", "la"), Run("la (clarabel)", "la"), Run("la (osqp)", "la")]
    text = agreement_markdown([_outcome(build, results)], runs, ["fdem", "jmm"])
    assert text.startswith("# Agreement between methods")
    assert "masonryfw gallery -o docs/gallery --agreement docs/agreement.md" in text
    assert "await fdem and jmm" in text
    assert "In this run 1 of 2 pairs found the same failure" in text
    assert "Lowest F1: 0.00 (Grid wall, la (highs) vs la (clarabel))." in text
    assert "Failed solves (left out of the table): la (osqp) on Grid wall (OSQP failed)." in text
    rows = [line for line in text.splitlines() if line.startswith("| Grid wall |")]
    # la (highs) vs its crack shifted one column right (4 x 6 grid, crack after column 3 vs 4):
    # 4 cracks each, none shared; Spearman of the 0/1 indicators = phi = (0*36 - 4*4) / sqrt(4*40*4*40) = -0.1;
    # ARI of [[12, 0], [4, 8]]: (100 - 132*148/276) / (140 - 132*148/276) = 0.42;
    # cosine sqrt(2/3) = 0.82; locus 0.2 m over the diagonal 1.3 m
    assert rows[0] == (
        "| Grid wall | la (highs) | la (clarabel) | 0.3000 | 0.3000 | 4/4/0 | 0.00 | 0.00 | 0.00 | -0.10 | "
        "0.42 | 0.82 | 0.154 |"
    )
    # la vs jmm: the same crack_indicator; no multiplier, partition or mechanism in jmm ("-")
    assert rows[1].endswith("| - | - | 4/4/4 | 1.00 | 1.00 | 1.00 | 1.00 | - | - | 0.084 |")
    assert rows[2] == "| Grid wall | 0.25 | 0.50 | failed (OSQP failed) |"


def test_planned_runs_cover_the_installed_methods():
    runs, missing = planned_runs()
    solvers = {r.solver for r in runs}
    assert solvers | set(missing) == {"la", "fdem", "jmm"} and not solvers & set(missing)
    if "la" in solvers:
        assert [r.options for r in runs if r.solver == "la"] == [{"solver": b} for b in ("highs", "clarabel", "osqp")]


def test_case_figure_has_one_panel_per_result(build, results, tmp_path):
    path = case_figure(_outcome(build, results), tmp_path / "grid.png")
    with Image.open(path) as image:
        width, height = image.size
    assert (width, height) == (3 * 4.5 * 110, 4.5 * 110)


@pytest.mark.slow
def test_the_gallery_command_solves_draws_and_scores_a_bundled_wall(tmp_path):
    outcome = CliRunner().invoke(
        gallery_command, ["-o", str(tmp_path / "gallery"), "--agreement", str(tmp_path / "agreement.md"),
                          "--case", "test-12c"],
    )
    assert outcome.exit_code == 0, outcome.output
    assert (tmp_path / "gallery" / "test-12c.png").stat().st_size > 10_000
    text = (tmp_path / "agreement.md").read_text()
    assert "| Test 12C | la (highs) | la (clarabel) |" in text
