"""Plastic points of the continuum (jmm) beside the LA mechanism, and the reaction history.

Writes ``docs/img/jmm/<case>_compare.png`` (LA mechanism | jmm plastic points, blue tensile,
grey shear, as in the paper's figures) and ``docs/img/jmm/<case>_history.png``, and prints a
markdown table of the numbers (for docs/jmm.md). Run from the project root:
``python docs/scripts/jmm_figures.py [--option name=value ...] [case ...]``.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import masonryfw as mf  # noqa: E402

OUT = Path(__file__).resolve().parents[1] / "img" / "jmm"


def figures(case: str, options: dict) -> dict:
    """Solve ``case`` with la and jmm, draw both figures, return the numbers for the table."""
    model = mf.open_model(case)
    la = mf.solve(model, "la")
    start = time.perf_counter()
    jmm = mf.solve(model, "jmm", options)
    seconds = time.perf_counter() - start
    mf.save_figure(mf.render([la, jmm], "compare"), OUT / f"{case}_compare.png", dpi=110)
    mf.save_figure(mf.render([jmm], "history"), OUT / f"{case}_history.png", dpi=110)
    reaction = jmm.step_reaction.values
    return {
        "case": case, "alpha_la": float(la.collapse_multiplier), "dead": float(reaction[0]),
        "plateau": float(reaction[-1]), "alpha_jmm": float(1 - reaction[-1] / reaction[0]),
        "settlement_mm": float(jmm.step_settlement.values[-1] * 1e3), "steps": int(reaction.size - 1),
        "newton": float(jmm.attrs["jmm_mean_newton_iterations"]), "dofs": int(jmm.attrs["jmm_dofs"]),
        "seconds": seconds, "stop": jmm.attrs["stop_reason"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("cases", nargs="*", default=list(mf.bundled_cases()))
    parser.add_argument("--option", action="append", default=[], help="jmm option name=value")
    args = parser.parse_args()
    options = dict(item.split("=", 1) for item in args.option)
    print("| case | LA alpha | jmm: dead reaction [N] | plateau [N] | 1 - plateau/dead | settlement [mm] "
          "| steps | mean Newton it. | DOFs | time [s] | stop |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases:
        row = figures(case, options)
        print(f"| {row['case']} | {row['alpha_la']:.3f} | {row['dead']:.1f} | {row['plateau']:.1f} | "
              f"{row['alpha_jmm']:.3f} | {row['settlement_mm']:.4f} | {row['steps']} | {row['newton']:.1f} | "
              f"{row['dofs']} | {row['seconds']:.0f} | {row['stop']} |", flush=True)


if __name__ == "__main__":
    main()
