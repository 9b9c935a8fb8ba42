"""Solve the drawn example walls with every solver; draw the pictures and the table of docs/import.md.

Writes ``docs/import/<name>-model.png`` (``plot --kind model``), ``docs/import/<name>-compare.png``
(the results side by side with the compare plugin's scores) and the table between the
``<!-- begin:results -->`` and ``<!-- end:results -->`` marks of docs/import.md.
Run from the project root: ``python docs/scripts/import_figures.py [name ...]``.
"""
from __future__ import annotations

import argparse
import math
import re
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import masonryfw as mf  # noqa: E402
import masonryfw.plugin_api as mfp

DOCS = Path(__file__).resolve().parents[1]
OUT = DOCS / "import"
SOLVERS = ("la", "fdem", "jmm", "jmm-limit")
#: LACT3's published tilting-table angles [deg] (LACT3_SolverTest.m).
PUBLISHED = {"lact3-wall": 16.73, "lact3-portal": 27.30, "lact3-arch": 17.10}


def headline(result) -> str:
    """alpha for a tilt (a load factor), else the smallest (or collapse) reaction."""
    numbers = {k.name: k.value for k in mf.key_numbers(result)}
    if "minimum_reaction" in numbers:
        return f"R_min {numbers['minimum_reaction']:.4g} N"
    if "collapse_reaction" in numbers:
        return f"alpha {numbers['alpha']:.4f} (R {numbers['collapse_reaction']:.4g} N)"
    return f"alpha {numbers['alpha']:.4f}"


def run(name: str) -> str:
    model = mf.open_model(name)
    mf.render([model], "model", {"numbers": False}).savefig(OUT / f"{name}-model.png", dpi=90)
    results, cells = [], []
    for solver in SOLVERS:
        start = time.perf_counter()
        try:
            result = mf.solve(model, solver)
        except mf.MasonryError as exc:
            cells.append(f"failed: {str(exc).splitlines()[0][:60]}")
            continue
        cells.append(f"{headline(result)}, {time.perf_counter() - start:.1f} s")
        results.append(result)
    mf.render(results, "compare").savefig(OUT / f"{name}-compare.png", dpi=80)
    published = f"tan({PUBLISHED[name]} deg) = {math.tan(math.radians(PUBLISHED[name])):.4f}" if name in PUBLISHED else "-"
    blocks = int(mfp.masonry_blocks(model.block_role.values).sum())
    return f"| {name} | {blocks} | {published} | " + " | ".join(cells) + " |"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("names", nargs="*", default=list(mf.DRAWN_NAMES))
    names = parser.parse_args().names
    OUT.mkdir(parents=True, exist_ok=True)
    rows = [run(name) for name in names]
    table = ("| example | blocks | published | la | fdem | jmm | jmm-limit |\n|---|---|---|---|---|---|---|\n"
             + "\n".join(rows))
    page = DOCS / "import.md"
    text = page.read_text(encoding="utf-8")
    text = re.sub(r"<!-- begin:results -->.*<!-- end:results -->",
                  f"<!-- begin:results -->\n{table}\n<!-- end:results -->", text, flags=re.S)
    page.write_text(text, encoding="utf-8")
    print(table)


if __name__ == "__main__":
    main()
