"""The gallery's agreement table and pictures, from hand-made results and (slow) from real solves."""
from __future__ import annotations

import pytest
from click.testing import CliRunner
from PIL import Image

import masonryfw as mf
from masonryfw_compare.commands import gallery_command
from masonryfw_compare.gallery import (
    CaseOutcome,
    Run,
    agreement_markdown,
    case_figure,
    compared_pairs,
    gallery_command_line,
    headline,
    parse_method_options,
    parse_skips,
    planned_runs,
    run_gallery,
)


def _outcome(build, results) -> CaseOutcome:
    model = build.grid_model()
    shifted = build.la_result(model, 4, cracked=build.head_line(model, 4), backend="clarabel")
    la = results["la"]
    pairs = [("la (highs)", "la (clarabel)", mf.compare(la, shifted, "crack")),
             ("la (highs)", "jmm", mf.compare(la, results["jmm"], "crack"))]
    return CaseOutcome("grid", "Grid wall", [la, shifted, results["jmm"]], [("la (osqp)", "OSQP failed")],
                       pairs, {"la (highs)": 0.25, "la (clarabel)": 0.5})


def test_agreement_table_holds_the_scores_and_says_what_is_missing(build, results):
    runs = [Run("la (highs)", "la", {"solver": "highs"}), Run("la (clarabel)", "la", {"solver": "clarabel"}),
            Run("la (osqp)", "la", {"solver": "osqp"}), Run("jmm", "jmm", {"max_steps": "40"})]
    command = "masonryfw gallery -o docs/gallery --agreement docs/agreement.md --option jmm.max_steps=40"
    text = agreement_markdown([_outcome(build, results)], runs, command)
    assert text.startswith("# Agreement between methods")
    assert f"\n    {command}\n" in text
    assert "Methods run: jmm, la." in text
    assert 'Solver options other than the defaults: jmm: `{"max_steps": "40"}`.' in text
    assert "In this run 1 of 2 pairs found the same failure" in text
    assert "Lowest F1: 0.00 (Grid wall, la (highs) vs la (clarabel))." in text
    assert "Failed solves (left out of the table): la (osqp) on Grid wall (OSQP failed)." in text
    method_part, backend_part = text.split("## LA backends against each other")
    method_rows = [line for line in method_part.splitlines() if line.startswith("| Grid wall |")]
    rows = [line for line in backend_part.splitlines() if line.startswith("| Grid wall |")]
    # la (highs) vs its crack shifted one column right (4 x 6 grid, crack after column 3 vs 4):
    # 4 cracks each, none shared; Spearman of the 0/1 indicators = phi = (0*36 - 4*4) / sqrt(4*40*4*40) = -0.1;
    # ARI of [[12, 0], [4, 8]]: (100 - 132*148/276) / (140 - 132*148/276) = 0.42;
    # cosine sqrt(2/3) = 0.82; locus 0.2 m over the diagonal 1.3 m
    assert rows[0] == (
        "| Grid wall | la (highs) | la (clarabel) | 0.3000 | 0.3000 | 4/4/0 | 0.00 | 0.00 | 0.00 | -0.10 | "
        "0.42 | 0.82 | 0.154 |"
    )
    # la vs jmm, in the method table only: la's alpha 0.3; jmm's reaction 100 -> 90 N, drop 0.100;
    # the same crack_indicator; no partition or mechanism in jmm ("-")
    assert method_rows == [
        "| Grid wall | la (highs) | jmm | alpha 0.3000 | drop 0.100 | 4/4/4 | 1.00 | 1.00 | 1.00 | 1.00 | - | - "
        "| 0.084 |"
    ]
    assert rows[1] == "| Grid wall | 0.25 | 0.50 | failed (OSQP failed) | - |"


def test_headline_is_alpha_or_the_reaction_drop(results):
    assert headline(results["la"]) == "alpha 0.3000"
    # fdem fake: R = 100 exp(-s / 1 mm) up to s = 5 mm, so 1 - R_min/R_dead = 1 - exp(-5) = 0.993
    assert headline(results["fdem"]) == "drop 0.993"
    # jmm fake: R = 100 - 10 sqrt(s / 5 mm), 100 N -> 90 N
    assert headline(results["jmm"]) == "drop 0.100"
    assert headline(results["jmm"].assign_attrs(stop_reason="reaction plateau")) == "drop 0.100"
    assert headline(results["jmm"].assign_attrs(stop_reason="max_steps (40) reached")) == (
        "drop 0.100 (max_steps (40) reached)")


def test_only_backends_of_one_method_and_the_leads_of_methods_are_paired():
    labels = ["la (highs)", "la (clarabel)", "la (osqp)", "fdem", "jmm"]
    # 3 backend pairs + la (highs)/fdem, la (highs)/jmm, fdem/jmm; never la (clarabel) vs fdem
    assert compared_pairs(labels) == [(0, 1), (0, 2), (0, 3), (0, 4), (1, 2), (3, 4)]
    assert compared_pairs(["la (clarabel)", "jmm"]) == [(0, 1)]


def test_method_options_and_skips_are_parsed_and_bad_ones_named():
    assert parse_method_options(["jmm.mesh_size=0.05", "jmm.max_steps=40", "fdem.mode=rigid"]) == {
        "jmm": {"mesh_size": "0.05", "max_steps": "40"}, "fdem": {"mode": "rigid"}}
    assert parse_skips(["jmm:facade-1", "fdem:panel-2"]) == {("jmm", "facade-1"), ("fdem", "panel-2")}
    with pytest.raises(mf.PluginError, match="'max_steps=40' is not METHOD.KEY=VALUE"):
        parse_method_options(["max_steps=40"])
    with pytest.raises(mf.PluginError, match="unknown method 'fem' \\(did you mean 'fdem'\\?\\); valid methods: "):
        parse_method_options(["fem.max_steps=40"])
    with pytest.raises(mf.PluginError, match="'jmm-facade-1' is not METHOD:CASE"):
        parse_skips(["jmm-facade-1"])


def test_planned_runs_follow_the_chosen_methods_and_check_their_options():
    runs = planned_runs(["jmm", "la"], {"jmm": {"max_steps": "40"}, "la": {"solver": "highs"}})
    assert runs == [Run("jmm", "jmm", {"max_steps": "40"}), Run("la", "la", {"solver": "highs"})]
    with pytest.raises(mf.PluginError, match="solver 'jmm': unknown option 'mesh_sise' \\(did you mean 'mesh_size'"):
        planned_runs(["jmm"], {"jmm": {"mesh_sise": "0.05"}})
    with pytest.raises(mf.PluginError, match="option 'max_steps' = 'many': not an int"):
        planned_runs(["jmm"], {"jmm": {"max_steps": "many"}})
    with pytest.raises(mf.PluginError, match="options given for fdem, which is not among the methods run"):
        planned_runs(["la"], {"fdem": {"mode": "rigid"}})
    with pytest.raises(mf.PluginError, match="unknown method 'fem'"):
        planned_runs(["fem"])


def test_command_line_reproduces_the_choices():
    line = gallery_command_line("docs/gallery", "docs/agreement.md", ["la", "jmm"], ["jmm.mesh_size=0.05"],
                                ["jmm:facade-1"], ["test-8c"], "my notes.md")
    assert line == ("masonryfw gallery -o docs/gallery --agreement docs/agreement.md --method la --method jmm "
                    "--option jmm.mesh_size=0.05 --skip jmm:facade-1 --case test-8c --notes 'my notes.md'")


def test_a_skipped_method_is_reported_and_not_run(tmp_path):
    lines = []
    (tmp_path / "notes.md").write_text("Test 8C: nothing to compare.\n")
    written = run_gallery(tmp_path / "g", tmp_path / "agreement.md", ["test-8c"], echo=lines.append,
                          methods=["la"], options=["la.solver=highs"], skips=["la:test-8c"], command="CMD",
                          notes=tmp_path / "notes.md")
    assert written == [tmp_path / "agreement.md"] and (tmp_path / "g").is_dir()
    assert "  la: skipped" in lines
    text = (tmp_path / "agreement.md").read_text()
    assert "| Test 8C | skipped (--skip) |" in text
    assert "Not run (--skip): la on Test 8C." in text
    assert "\n## Discussion\n\nTest 8C: nothing to compare.\n" in text
    with pytest.raises(mf.MasonryError, match="--skip names unknown case"):
        run_gallery(tmp_path / "g", tmp_path / "a.md", ["test-8c"], echo=lines.append, skips=["la:test-99"])


def test_planned_runs_cover_the_installed_gallery_solvers_and_their_variants():
    runs = planned_runs()
    gallery = [record.name for record in mf.installed_solvers() if record.gallery]
    assert sorted({r.solver for r in runs}) == sorted(gallery) == ["fdem", "jmm", "la"]
    assert [(r.label, r.options) for r in runs if r.solver == "la"] == [
        (f"la ({b})", {"solver": b}) for b in ("highs", "ipm", "clarabel", "osqp")]


def test_case_figure_has_one_panel_per_result(build, results, tmp_path):
    path = case_figure(_outcome(build, results), tmp_path / "grid.png")
    with Image.open(path) as image:
        width, height = image.size
    # three 4.5-inch panels at 110 dpi, cropped to what is drawn (no more than the page, a little less)
    assert 0.8 * 3 * 4.5 * 110 < width <= 3 * 4.5 * 110 and 0.8 * 4.5 * 110 < height <= 4.5 * 110
    assert width / height == pytest.approx(3.0, rel=0.1)


@pytest.mark.slow
def test_the_gallery_command_solves_draws_and_scores_a_bundled_wall(tmp_path):
    arguments = ["-o", str(tmp_path / "gallery"), "--agreement", str(tmp_path / "agreement.md"),
                 "--method", "la", "--method", "fdem", "--case", "test-12c"]
    outcome = CliRunner().invoke(gallery_command, arguments)
    assert outcome.exit_code == 0, outcome.output
    assert (tmp_path / "gallery" / "test-12c.png").stat().st_size > 10_000
    text = (tmp_path / "agreement.md").read_text()
    assert "    masonryfw gallery " + " ".join(arguments) + "\n" in text
    assert "| Test 12C | la (highs) | la (clarabel) |" in text
    assert "| Test 12C | la (highs) | fdem | alpha " in text


def test_the_command_passes_methods_and_options_and_writes_its_own_line(tmp_path):
    arguments = ["-o", str(tmp_path / "gallery"), "--agreement", str(tmp_path / "agreement.md"),
                 "--method", "la", "--option", "la.solver=highs", "--case", "test-8c"]
    outcome = CliRunner().invoke(gallery_command, arguments)
    assert outcome.exit_code == 0, outcome.output
    assert "  la: " in outcome.output and "clarabel" not in outcome.output
    text = (tmp_path / "agreement.md").read_text()
    assert "    masonryfw gallery " + " ".join(arguments) + "\n" in text
    assert "| wall | la |\n|---|---|\n| Test 8C | " in text
    # a misspelt option fails before any wall is solved
    bad = CliRunner().invoke(gallery_command, [*arguments[:4], "--option", "la.solvr=highs"])
    assert bad.exit_code != 0 and "unknown option 'solvr'" in str(bad.exception)
