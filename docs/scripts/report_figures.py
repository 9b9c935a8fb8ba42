"""Every plot kind and the HTML report for Test 12C and Facade 3, solved by la, fdem and jmm.

Writes ``docs/img/report/<case>-<kind>[-<solver>].png``, ``docs/img/report/<case>-history.csv`` and
``docs/report/<case>.html`` (the results are solved with the solvers' defaults into a temporary
folder, as ``masonryfw solve`` would write them), and prints the run times. Run from the project
root: ``python docs/scripts/report_figures.py [case ...]``.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import masonryfw as mf  # noqa: E402
import masonryfw.plugin_api as mfp
from masonryfw_compare import drawable_kinds, report_html  # noqa: E402

DOCS = Path(__file__).resolve().parents[1]
IMAGES = DOCS / "img" / "report"
REPORTS = DOCS / "report"
SOLVERS = ("la", "fdem", "jmm")
DPI = 110


def case_figures(case: str, folder: Path) -> None:
    """Solve ``case`` with every solver, draw every kind, write the report."""
    model = mf.open_model(case)
    paths, results = [], []
    for solver in SOLVERS:
        start = time.perf_counter()
        result = mf.solve(model, solver)
        path = folder / f"{case}.{solver}.nc"
        mf.save(result, path)
        paths.append(str(path))
        results.append(mf.open_dataset(path))
        print(f"{case} {solver}: {time.perf_counter() - start:.1f} s", flush=True)
    mf.save_figure(mf.render([model], "model"), IMAGES / f"{case}-model.png", dpi=DPI)
    for solver, result in zip(SOLVERS, results):
        for kind in drawable_kinds(result):
            mf.save_figure(mf.render([result], kind), IMAGES / f"{case}-{kind}-{solver}.png", dpi=DPI)
    incremental = [r for r in results if "step_settlement" in r]
    mf.save_figure(mf.render(results, "history"), IMAGES / f"{case}-history.png", dpi=DPI)
    mf.save_figure(mf.render(results, "history", {"xscale": "log"}), IMAGES / f"{case}-history-log.png", dpi=DPI)
    mf.save_figure(mf.render(incremental, "history", {"quantity": "damage"}), IMAGES / f"{case}-damage.png", dpi=DPI)
    mf.save_figure(mf.render(results, "compare"), IMAGES / f"{case}-compare.png", dpi=DPI)
    header, rows = mf.plot_table(results, "history")
    mfp.save_text(mfp.csv_text(header, rows), IMAGES / f"{case}-history.csv")
    start = time.perf_counter()
    command = f"masonryfw report {' '.join(f'{case}.{s}.nc' for s in SOLVERS)} -o {case}.html"
    text = report_html(paths, command)
    mfp.save_text(text.replace(str(folder) + "/", ""), REPORTS / f"{case}.html")
    print(f"{case} report: {time.perf_counter() - start:.1f} s, {len(text) / 1e6:.2f} MB", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("cases", nargs="*", default=["test-12c", "facade-3"])
    args = parser.parse_args()
    IMAGES.mkdir(parents=True, exist_ok=True)
    REPORTS.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as folder:
        for case in args.cases:
            case_figures(case, Path(folder))


if __name__ == "__main__":
    main()
