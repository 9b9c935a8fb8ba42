"""The gallery: every bundled wall solved by every installed method, drawn side by side and scored.

``masonryfw gallery`` writes ``docs/gallery/<case>.png`` (the panels of the
paper's figures 5-15: one per method, the later ones titled with their scores
against the first) and ``docs/agreement.md`` (the pairwise scores of every
wall). The limit analysis is run with each of its three LP backends, whose
mechanisms differ where the optimum is degenerate; fdem and jmm join when
installed.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import xarray as xr

import masonryfw as mf

from .comparison import solver_label
from .records import DEFAULT_THRESHOLD

METHODS = ("la", "fdem", "jmm")
LA_BACKENDS = ("highs", "clarabel", "osqp")
GALLERY_DPI = 110
IDENTICAL_COSINE_GAP = 1e-3
# Columns of the agreement table: (header, comparison variable, number format).
SCORE_COLUMNS = (
    ("alpha A", "collapse_multiplier_a", "{:.4f}"),
    ("alpha B", "collapse_multiplier_b", "{:.4f}"),
    ("cracks A/B/both", None, ""),
    ("F1", "crack_f1", "{:.2f}"),
    ("Jaccard", "crack_jaccard", "{:.2f}"),
    ("overlap", "crack_overlap", "{:.2f}"),
    ("Spearman", "crack_spearman", "{:.2f}"),
    ("ARI", "macro_block_ari", "{:.2f}"),
    ("mech. cos", "mechanism_cosine", "{:.2f}"),
    ("locus d", "locus_distance", "{:.3f}"),
)


@dataclass(frozen=True)
class Run:
    """One way of solving a wall: a solver and its options, shown as ``label``."""

    label: str
    solver: str
    options: dict = field(default_factory=dict)


@dataclass
class CaseOutcome:
    """What the gallery got for one wall."""

    case: str
    title: str
    results: list[xr.Dataset]
    failures: list[tuple[str, str]]
    comparisons: list[tuple[str, str, xr.Dataset]]
    seconds: dict[str, float]


def planned_runs() -> tuple[list[Run], list[str]]:
    """The runs of every installed method among METHODS (la once per backend) and the missing methods."""
    runs, missing = [], []
    for name in METHODS:
        try:
            mf.get_solver(name)
        except mf.PluginError:
            missing.append(name)
            continue
        if name == "la":
            runs += [Run(f"la ({backend})", "la", {"solver": backend}) for backend in LA_BACKENDS]
        else:
            runs.append(Run(name, name))
    return runs, missing


def solve_case(case: str, title: str, runs: list[Run], echo: Callable[[str], None]) -> CaseOutcome:
    """Solve one bundled wall with every run and compare every pair of results."""
    model = mf.open_model(case)
    results, failures, seconds = [], [], {}
    for run in runs:
        start = time.perf_counter()
        try:
            results.append(mf.solve(model, run.solver, run.options))
        except mf.SolveError as exc:
            failures.append((run.label, str(exc).splitlines()[0]))
            echo(f"  {run.label}: failed: {failures[-1][1]}")
            continue
        seconds[run.label] = time.perf_counter() - start
        echo(f"  {run.label}: {seconds[run.label]:.2f} s")
    comparisons = [
        (solver_label(a), solver_label(b), mf.compare(a, b, "crack", {"threshold": DEFAULT_THRESHOLD}))
        for i, a in enumerate(results) for b in results[i + 1:]
    ]
    return CaseOutcome(case, title, results, failures, comparisons, seconds)


def case_figure(outcome: CaseOutcome, path: Path) -> Path | None:
    """The side-by-side panels of one wall (a single result is drawn as its mechanism)."""
    if not outcome.results:
        return None
    if len(outcome.results) == 1:
        figure = mf.render([outcome.results[0]], "mechanism")
    else:
        figure = mf.render(outcome.results, "compare")
    return mf.save_figure(figure, path, dpi=GALLERY_DPI)


def _cell(comparison: xr.Dataset, name: str | None, number: str) -> str:
    if name is None:
        counts = [comparison[n].item() for n in ("crack_count_a", "crack_count_b", "crack_count_both") if n in comparison]
        return "/".join(map(str, counts)) if len(counts) == 3 else "-"
    return number.format(comparison[name].item()) if name in comparison else "-"


def agreement_table(outcomes: list[CaseOutcome]) -> str:
    """Markdown table: one row per wall and pair of results."""
    header = "| wall | A | B | " + " | ".join(h for h, _, _ in SCORE_COLUMNS) + " |"
    rule = "|" + "---|" * (3 + len(SCORE_COLUMNS))
    rows = [
        f"| {o.title} | {la} | {lb} | " + " | ".join(_cell(c, name, fmt) for _, name, fmt in SCORE_COLUMNS) + " |"
        for o in outcomes for la, lb, c in o.comparisons
    ]
    return "\n".join([header, rule, *rows])


def timing_table(outcomes: list[CaseOutcome], runs: list[Run]) -> str:
    """Markdown table of solve wall times [s] per wall and run (failures named)."""
    header = "| wall | " + " | ".join(r.label for r in runs) + " |"
    rule = "|" + "---|" * (1 + len(runs))
    rows = []
    for o in outcomes:
        failed = dict(o.failures)
        cells = [f"{o.seconds[r.label]:.2f}" if r.label in o.seconds else f"failed ({failed.get(r.label, '?')})" for r in runs]
        rows.append(f"| {o.title} | " + " | ".join(cells) + " |")
    return "\n".join([header, rule, *rows])


INTRODUCTION = """\
# Agreement between methods

Regenerated, together with the pictures in `docs/gallery/`, by one command:

    masonryfw gallery -o docs/gallery --agreement docs/agreement.md

Every bundled wall is solved by every installed method; every pair of results
of the same wall is scored by the `crack` comparator of the `compare` plugin
(`masonryfw compare A B --json` gives the same numbers for two result files).
Result A is the reference of a pair.

## The scores

- **cracks A/B/both**: interfaces with `crack_indicator > {threshold}` in A, in B, in both.
  The threshold: `crack_indicator` is normalised to 1 at the joint that takes the
  largest part in the failure; 0.1 keeps every joint moving at least a tenth as
  much as the strongest one (the cracks one sees in an amplified mechanism drawing)
  and drops the round-off-level motions an interior-point or ADMM solution leaves
  on joints that do not move (1e-6 and below) and the elastic contact
  deformations of an incremental solver. It is the comparator's option `threshold`.
- **F1** = 2|A and B| / (|A| + |B|), **Jaccard** = |A and B| / |A or B| of the cracked
  sets (precision |A and B|/|B| and recall |A and B|/|A| are in the comparison dataset too).
- **overlap** = sum(L min(a, b)) / sum(L max(a, b)) over the interfaces, L the joint
  length, a and b the indicators: threshold-free, the length-weighted Jaccard of 0/1 patterns.
- **Spearman**: rank correlation of the two indicators over all interfaces (threshold-free).
- **ARI**: adjusted Rand index of the two `macro_block` partitions of the masonry
  blocks (support blocks left out: they are boundary conditions); 1 = the same
  macro-blocks, about 0 = chance.
- **mech. cos**: cosine of the two displacement fields in L2 over the masonry area.
  A rigid block's field integrates to A u_c.u_c' + J rz rz' (J its polar moment
  about the centroid), i.e. rotations are scaled by each block's radius of gyration
  sqrt(J/A); the cosine ignores the overall size, so a normalised LA mechanism and a
  physical displacement compare directly. 1 = the same mechanism, 0 = unrelated,
  negative = opposite.
- **locus d**: symmetric mean distance between the failure loci (cracked joints,
  or plastic points of a continuum result), over the model size (bounding-box
  diagonal); 0 = the same place. It needs no shared discretisation, so it scores a
  continuum result against a discrete one.

A score is `-` where it cannot be computed (e.g. no cracked joint in either result).
"""


def _identical(comparison: xr.Dataset) -> bool:
    """Same cracked set, same macro-blocks and the same mechanism (where each is scored)."""
    checks = [("crack_f1", 1.0), ("macro_block_ari", 1.0), ("mechanism_cosine", 1.0 - IDENTICAL_COSINE_GAP)]
    return all(comparison[name].item() >= bound - 1e-12 for name, bound in checks if name in comparison)


def observations(outcomes: list[CaseOutcome]) -> str:
    """What this run found, in numbers: how many pairs agree exactly, the weakest pair, the failures."""
    pairs = [(o.title, la, lb, c) for o in outcomes for la, lb, c in o.comparisons]
    lines = []
    if pairs:
        same = sum(_identical(c) for *_, c in pairs)
        lines.append(
            f"In this run {same} of {len(pairs)} pairs found the same failure (F1 = ARI = 1, "
            f"mechanism cosine > {1 - IDENTICAL_COSINE_GAP})."
        )
        scored = [p for p in pairs if "crack_f1" in p[3]]
        if scored and same < len(pairs):
            title, la, lb, c = min(scored, key=lambda p: p[3].crack_f1.item())
            lines.append(f"Lowest F1: {c.crack_f1.item():.2f} ({title}, {la} vs {lb}).")
    failed = [f"{label} on {o.title} ({message})" for o in outcomes for label, message in o.failures]
    if failed:
        lines.append("Failed solves (left out of the table): " + "; ".join(failed) + ".")
    return " ".join(lines)


def agreement_markdown(outcomes: list[CaseOutcome], runs: list[Run], missing: list[str]) -> str:
    """The whole of docs/agreement.md."""
    parts = [INTRODUCTION.format(threshold=DEFAULT_THRESHOLD)]
    installed = sorted({r.solver for r in runs})
    parts.append("## Status\n")
    parts.append(
        f"Methods installed: {', '.join(installed) or 'none'}. "
        + (f"Not installed (skipped): {', '.join(missing)}." if missing else "All three methods are installed.")
    )
    if missing:
        parts.append(
            "\nThe method-against-method comparisons (la vs fdem, la vs jmm, fdem vs jmm) await "
            f"{' and '.join(missing)}. Until then the table compares the three LP backends of the "
            "limit analysis with each other. They should reach the same collapse multiplier; where the "
            "optimum is degenerate (several mechanisms with the same alpha) each may pick another "
            "mechanism - highs a vertex of the optimal face, clarabel its centre, osqp the "
            "minimum-norm one - and the scores measure how far apart those are."
        )
    found = observations(outcomes)
    if found:
        parts.append("\n" + found)
    parts.append("\n## Pairwise scores\n")
    parts.append(agreement_table(outcomes))
    parts.append("\n## Solve times [s]\n")
    parts.append(timing_table(outcomes, runs))
    options = json.dumps({"threshold": DEFAULT_THRESHOLD})
    parts.append(f"\nComparator options: `{options}`; masonryfw {mf.__version__}.\n")
    return "\n".join(parts)


def run_gallery(
    output: Path,
    agreement: Path,
    cases: list[str] | None = None,
    echo: Callable[[str], Any] = print,
) -> list[Path]:
    """Solve, draw and score every (or the named) bundled wall; returns the files written."""
    bundled = mf.bundled_cases()
    unknown = sorted(set(cases or []) - set(bundled))
    if unknown:
        raise mf.MasonryError(f"unknown case(s) {', '.join(unknown)}; bundled cases: {', '.join(bundled)}")
    runs, missing = planned_runs()
    for name in missing:
        echo(f"skipping {name}: solver not installed")
    if not runs:
        raise mf.PluginError(f"none of the solvers {', '.join(METHODS)} is installed")
    written, outcomes = [], []
    for case in cases or list(bundled):
        echo(f"{case}:")
        outcome = solve_case(case, bundled[case], runs, echo)
        outcomes.append(outcome)
        figure = case_figure(outcome, output / f"{case}.png")
        if figure is not None:
            written.append(figure)
    agreement.parent.mkdir(parents=True, exist_ok=True)
    temporary = agreement.with_name(f".{agreement.name}.tmp")
    temporary.write_text(agreement_markdown(outcomes, runs, missing))
    temporary.replace(agreement)
    return written + [agreement]
