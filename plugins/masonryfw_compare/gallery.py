"""The gallery: every bundled wall solved by every installed method, drawn side by side and scored.

``masonryfw gallery`` writes ``docs/gallery/<case>.png`` (the panels of the
paper's figures 5-15: one per run, the later ones titled with their scores
against the first) and ``docs/agreement.md``: each method's first run scored
against the other methods' (with each method's headline number), and the
limit analysis's LP backends, whose mechanisms may differ where the
optimum is degenerate, against each other. ``--method``, ``--option
METHOD.KEY=VALUE`` and ``--skip METHOD:CASE`` choose what runs; the command
line is written at the top of the agreement file.
"""
from __future__ import annotations

import json
import shlex
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

GALLERY_DPI = 110
IDENTICAL_COSINE_GAP = 1e-3
SKIPPED = "skipped (--skip)"
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


def installed_methods() -> dict[str, mfp.Solver]:
    """Every installed solver by name, in name order."""
    return {record.name: record for record in mf.installed_solvers()}


def gallery_methods() -> list[str]:
    """The installed solvers that run in the gallery by default (their record's ``gallery``)."""
    return [name for name, record in installed_methods().items() if record.gallery]


def _known_method(method: str, what: str) -> None:
    installed = installed_methods()
    if method not in installed:
        raise mf.PluginError(f"{what}: {mfp.unknown_name_message('method', method, list(installed))}")


def parse_method_options(pairs: list[str] | tuple[str, ...]) -> dict[str, dict[str, str]]:
    """``["jmm.mesh_size=0.05", ...]`` as ``{"jmm": {"mesh_size": "0.05"}}`` (values are parsed by the solver)."""
    options: dict[str, dict[str, str]] = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        method, dot, name = key.strip().partition(".")
        if not sep or not dot or not name:
            raise mf.PluginError(f"gallery option {pair!r} is not METHOD.KEY=VALUE (e.g. jmm.max_steps=40)")
        _known_method(method, f"gallery option {pair!r}")
        options.setdefault(method, {})[name] = value
    return options


def parse_skips(pairs: list[str] | tuple[str, ...]) -> set[tuple[str, str]]:
    """``["jmm:facade-1", ...]`` as ``{("jmm", "facade-1")}``: the method is not run on that wall."""
    skips = set()
    for pair in pairs:
        method, sep, case = pair.partition(":")
        if not sep or not case:
            raise mf.PluginError(f"gallery skip {pair!r} is not METHOD:CASE (e.g. jmm:facade-3)")
        _known_method(method, f"gallery skip {pair!r}")
        skips.add((method, case))
    return skips


def planned_runs(methods: list[str] | tuple[str, ...] | None = None,
                 options: dict[str, dict[str, str]] | None = None) -> list[Run]:
    """The runs of the chosen methods (default: the installed gallery solvers), in the order given.

    A solver that declares variants (la: one per LP backend) runs once per
    variant, unless the given options set one of the variants' options
    (``la.solver=highs``). Every method's options are checked against the
    solver's declared rules here, before any wall is solved, so a misspelt name
    fails at once.
    """
    chosen = list(dict.fromkeys(methods or gallery_methods()))
    for method in chosen:
        _known_method(method, "gallery --method")
    options = options or {}
    unused = sorted(set(options) - set(chosen))
    if unused:
        raise mf.PluginError(f"gallery options given for {', '.join(unused)}, which is not among the methods run")
    installed = installed_methods()
    runs = []
    for name in chosen:
        solver, given = installed[name], options.get(name, {})
        mfp.resolve_options(f"solver {name!r}", solver.options, given)
        varied = {key for variant in solver.variants for key in variant.options}
        if solver.variants and not varied & set(given):
            runs += [Run(f"{name} ({v.label})", name, {**given, **v.options}) for v in solver.variants]
        else:
            runs.append(Run(name, name, dict(given)))
    return runs


def method_of(label: str) -> str:
    """The solver of a run label (``la (highs)`` -> ``la``)."""
    return label.split(" (")[0]


def compared_pairs(labels: list[str]) -> list[tuple[int, int]]:
    """Indices of the pairs to score: every pair of runs of the same method (la's backends),
    and each method's first run against every other method's first run."""
    first: dict[str, int] = {}
    for i, label in enumerate(labels):
        first.setdefault(method_of(label), i)
    leads = list(first.values())
    same = [(i, j) for i in range(len(labels)) for j in range(i + 1, len(labels))
            if method_of(labels[i]) == method_of(labels[j])]
    cross = [(i, j) for k, i in enumerate(leads) for j in leads[k + 1:]]
    return sorted(same + cross)


def solve_case(
    case: str, title: str, runs: list[Run], echo: Callable[[str], None], skipped: set[tuple[str, str]] = frozenset()
) -> CaseOutcome:
    """Solve one bundled wall with every run (but the skipped methods) and score the pairs of compared_pairs."""
    model = mf.open_model(case)
    results, failures, seconds = [], [], {}
    for run in runs:
        if (run.solver, case) in skipped:
            failures.append((run.label, SKIPPED))
            echo(f"  {run.label}: skipped")
            continue
        start = time.perf_counter()
        try:
            results.append(mf.solve(model, run.solver, run.options))
        except mf.SolveError as exc:
            failures.append((run.label, str(exc).splitlines()[0]))
            echo(f"  {run.label}: failed: {failures[-1][1]}")
            continue
        seconds[run.label] = time.perf_counter() - start
        echo(f"  {run.label}: {seconds[run.label]:.2f} s")
    labels = [mf.result_label(r) for r in results]
    comparisons = [
        (labels[i], labels[j], mf.compare(results[i], results[j], "crack", {"threshold": mf.CRACK_THRESHOLD}))
        for i, j in compared_pairs(labels)
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


def headline(result: xr.Dataset) -> str:
    """A method's own number: the collapse multiplier alpha (la) or the reaction drop 1 - R_min/R_dead (fdem, jmm).

    From the core's key numbers (:func:`masonryfw.key_numbers`). A run that
    stopped for another reason than a reaction plateau says why (its drop may
    still be growing).
    """
    numbers = {n.name: n.value for n in mf.key_numbers(result)}
    if "alpha" in numbers:
        return f"alpha {numbers['alpha']:.4f}"
    if "minimum_reaction" in numbers and numbers.get("dead_reaction"):
        reason = str(result.attrs.get("stop_reason", ""))
        note = f" ({reason})" if reason and "plateau" not in reason else ""
        return f"drop {1.0 - numbers['minimum_reaction'] / numbers['dead_reaction']:.3f}{note}"
    return "-"


def _pairs(outcomes: list[CaseOutcome], same_method: bool) -> list[tuple[CaseOutcome, str, str, xr.Dataset]]:
    return [(o, la, lb, c) for o in outcomes for la, lb, c in o.comparisons
            if (method_of(la) == method_of(lb)) == same_method]


def _table(header: list[str], rows: list[str]) -> str:
    return "\n".join(["| " + " | ".join(header) + " |", "|" + "---|" * len(header), *rows])


def agreement_table(outcomes: list[CaseOutcome]) -> str:
    """Markdown table of the method-against-method pairs: one row per wall and pair, with each method's headline."""
    columns = [c for c in SCORE_COLUMNS if not c[0].startswith("alpha")]
    rows = []
    for o, la, lb, c in _pairs(outcomes, same_method=False):
        by_label = {mf.result_label(r): r for r in o.results}
        cells = [o.title, la, lb, headline(by_label[la]) if la in by_label else "-",
                 headline(by_label[lb]) if lb in by_label else "-", *(_cell(c, name, fmt) for _, name, fmt in columns)]
        rows.append("| " + " | ".join(cells) + " |")
    return _table(["wall", "A", "B", "A's number", "B's number", *(h for h, _, _ in columns)], rows)


def backend_table(outcomes: list[CaseOutcome]) -> str:
    """Markdown table of the pairs of runs of one method (la's LP backends): one row per wall and pair."""
    rows = [
        f"| {o.title} | {la} | {lb} | " + " | ".join(_cell(c, name, fmt) for _, name, fmt in SCORE_COLUMNS) + " |"
        for o, la, lb, c in _pairs(outcomes, same_method=True)
    ]
    return _table(["wall", "A", "B", *(h for h, _, _ in SCORE_COLUMNS)], rows)


def timing_table(outcomes: list[CaseOutcome], runs: list[Run]) -> str:
    """Markdown table of solve wall times [s] per wall and run (failures named)."""
    header = "| wall | " + " | ".join(r.label for r in runs) + " |"
    rule = "|" + "---|" * (1 + len(runs))
    rows = []
    for o in outcomes:
        failed = dict(o.failures)
        cells = [f"{o.seconds[r.label]:.2f}" if r.label in o.seconds
                 else SKIPPED if failed.get(r.label) == SKIPPED
                 else f"failed ({failed[r.label]})" if r.label in failed else "-" for r in runs]
        rows.append(f"| {o.title} | " + " | ".join(cells) + " |")
    return "\n".join([header, rule, *rows])


INTRODUCTION = """\
# Agreement between methods

Regenerated, together with the pictures in `docs/gallery/`, by one command:

    {command}

Every bundled wall is solved by every chosen method (`--method`, default every
installed solver that declares itself a gallery method) with the options named on that command line
(`--option METHOD.KEY=VALUE`; the others are the solvers' defaults, see
`masonryfw plugins`); `--skip METHOD:CASE` leaves a method out on a wall. Each
method's first run is scored against every other method's (the main table), and
the runs of one method against each other (la's LP backends, the second
table), by the `crack` comparator of the `compare` plugin (`masonryfw compare A B
--json` gives the same numbers for two result files). Result A is the reference
of a pair.

## The scores

- **A's / B's number**: each method's headline: the collapse multiplier **alpha** of
  the limit analysis (the share of the moving support's dead load W L_m / L_total,
  docs/architecture.md, it can lose before a mechanism forms), the reaction **drop** 1 - R_min/R_dead of the
  incremental methods (R_dead the moving support's reaction after gravity, R_min
  the smallest of the settlement history). Both measure how much of its load the
  settling support sheds at collapse, so they are comparable, though not equal
  by construction.
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
  length, a and b the indicators (each 0 on intact joints): the length-weighted Jaccard of 0/1 patterns,
  weighted by how much each joint moves.
- **Spearman**: rank correlation of the two indicators over all interfaces.
- **ARI**: adjusted Rand index of the two `macro_block` partitions of the masonry
  blocks (support blocks left out: they are boundary conditions); 1 = the same
  macro-blocks, about 0 = chance.
- **mech. cos**: cosine of the two displacement fields in L2 over the masonry area.
  A rigid block's field integrates to A u_c.u_c' + J rz rz' (J its polar moment
  about the centroid), i.e. rotations are scaled by each block's radius of gyration
  sqrt(J/A); the cosine ignores the overall size, so a normalised LA mechanism and a
  physical displacement compare directly. 1 = the same mechanism, 0 = unrelated,
  negative = opposite. A continuum result (jmm) has block motions too: the displacement
  increment of its last steps projected onto each block's rigid motions
  (`masonryfw.rigid_fit`), from which its macro-blocks and cracks are derived as for the
  discrete methods.
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
    failed = [f"{label} on {o.title} ({message})" for o in outcomes for label, message in o.failures
              if message != SKIPPED]
    if failed:
        lines.append("Failed solves (left out of the table): " + "; ".join(failed) + ".")
    skipped = [f"{label} on {o.title}" for o in outcomes for label, message in o.failures if message == SKIPPED]
    if skipped:
        lines.append("Not run (--skip): " + "; ".join(skipped) + ".")
    return " ".join(lines)


DEFAULT_COMMAND = "masonryfw gallery -o docs/gallery --agreement docs/agreement.md"


def gallery_command_line(
    output: str, agreement: str, methods: list[str] | tuple[str, ...] = (), options: list[str] | tuple[str, ...] = (),
    skips: list[str] | tuple[str, ...] = (), cases: list[str] | tuple[str, ...] = (), notes: str | None = None,
) -> str:
    """The one shell command that regenerates a gallery with these choices."""
    words = ["masonryfw", "gallery", "-o", str(output), "--agreement", str(agreement)]
    for flag, values in (("--method", methods), ("--option", options), ("--skip", skips), ("--case", cases)):
        for value in values:
            words += [flag, value]
    if notes is not None:
        words += ["--notes", str(notes)]
    return shlex.join(words)


def agreement_markdown(outcomes: list[CaseOutcome], runs: list[Run], command: str = DEFAULT_COMMAND,
                       notes: str = "") -> str:
    """The whole of docs/agreement.md (``notes``: hand-written markdown put in as its Discussion section)."""
    parts = [INTRODUCTION.format(threshold=mf.CRACK_THRESHOLD, command=command)]
    installed = sorted({r.solver for r in runs})
    parts.append("## Status\n")
    parts.append(f"Methods run: {', '.join(installed) or 'none'}.")
    varied = {key for r in runs for v in installed_methods()[r.solver].variants for key in v.options}
    options = {r.solver: {k: v for k, v in r.options.items() if k not in varied} for r in runs}
    given = "; ".join(f"{m}: `{json.dumps(o)}`" for m, o in options.items() if o)
    parts.append(f"\nSolver options other than the defaults: {given or 'none'}.")
    if len(installed) < 2:
        parts.append(
            "\nWith a single method there is no method-against-method comparison; the second table "
            "compares the LP backends of the limit analysis with each other."
        )
    parts.append(
        "\nThe LP backends should reach the same collapse multiplier; where the optimum is "
        "degenerate (several mechanisms with the same alpha) each may pick another mechanism - "
        "highs a vertex of the optimal face, ipm and clarabel its centre, osqp the minimum-norm one - and "
        "the second table measures how far apart those are."
    )
    found = observations(outcomes)
    if found:
        parts.append("\n" + found)
    parts.append("\n## Method against method\n")
    parts.append(agreement_table(outcomes))
    parts.append("\n## LA backends against each other\n")
    parts.append(backend_table(outcomes))
    if notes.strip():
        parts.append("\n## Discussion\n")
        parts.append(notes.strip())
    parts.append("\n## Solve times [s]\n")
    parts.append(timing_table(outcomes, runs))
    comparator = json.dumps({"threshold": mf.CRACK_THRESHOLD})
    parts.append(f"\nComparator options: `{comparator}`; masonryfw {mf.__version__}.\n")
    return "\n".join(parts)


def run_gallery(
    output: Path,
    agreement: Path,
    cases: list[str] | None = None,
    echo: Callable[[str], Any] = print,
    methods: list[str] | None = None,
    options: list[str] | tuple[str, ...] = (),
    skips: list[str] | tuple[str, ...] = (),
    command: str = DEFAULT_COMMAND,
    notes: Path | None = None,
) -> list[Path]:
    """Solve, draw and score every (or the named) bundled wall with the chosen methods; returns the files written.

    ``options`` are ``METHOD.KEY=VALUE`` strings, ``skips`` ``METHOD:CASE`` strings;
    ``command`` is written at the top of the agreement file, the markdown file
    ``notes`` (the discussion of a run's disagreements) as its Discussion section.
    """
    bundled = mf.bundled_cases()
    unknown = sorted(set(cases or []) - set(bundled))
    if unknown:
        raise mf.MasonryError(f"unknown case(s) {', '.join(unknown)}; bundled cases: {', '.join(bundled)}")
    skipped = parse_skips(skips)
    unknown_skips = sorted({case for _, case in skipped} - set(bundled))
    if unknown_skips:
        raise mf.MasonryError(
            f"--skip names unknown case(s) {', '.join(unknown_skips)}; bundled cases: {', '.join(bundled)}")
    runs = planned_runs(methods, parse_method_options(options))
    if not runs:
        raise mf.PluginError("no gallery solver is installed")
    notes_text = notes.read_text() if notes is not None else ""
    mfp.check_output_path(agreement)
    if not output.is_dir():
        mfp.check_output_path(output)  # its folder exists and is writable: the gallery folder is made in it
    output.mkdir(exist_ok=True)
    written, outcomes = [], []
    for case in cases or list(bundled):
        echo(f"{case}:")
        outcome = solve_case(case, bundled[case], runs, echo, skipped)
        outcomes.append(outcome)
        figure = case_figure(outcome, output / f"{case}.png")
        if figure is not None:
            written.append(figure)
    temporary = agreement.with_name(f".{agreement.name}.tmp")
    temporary.write_text(agreement_markdown(outcomes, runs, command, notes_text))
    temporary.replace(agreement)
    return written + [agreement]
