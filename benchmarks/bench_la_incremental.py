"""Benchmark of la-incremental: the time per increment against the block count, whole runs against fdem's on
the same walls (the same settlement, one alternating pair each, this process), and the settlement at collapse
against the step (the default and a quarter of it).

- Per increment: the running-bond settlement walls of about 300, 1,000 and 2,400 units (the paper's material),
  ten increments each (two LPs, the contacts found again, the history record).
- Against fdem: Test 12C to 60 mm, Facade 3 to 180 mm (a tenth of their heights, where neither falls), the
  semicircular arch of t/R = 0.15 spreading to 0.2 m (it falls at about 0.13 m) and the running-bond wall of
  2,432 blocks to 60 mm; fdem with
  ``plateau_tolerance = 0`` so that both run to the same end.
- Convergence: the settlement (spread) at collapse of Panel 4, Panel 5 and the arches of t/R = 0.15 and 0.2,
  and the reactions of Test 12C at 60 mm and Facade 3 at 180 mm, with ``step`` 0.05 (the default), a quarter of
  it, 0.02, and the fine steps 0.01, 0.0075 and 0.005; the default against a quarter and against the median of
  the fine steps (a quarter of a step can pick another branch where two parts are about to fall).

Run from the benchmarks folder: ``python bench_la_incremental.py``. Writes the ``la-incremental`` section of
docs/benchmarks.md.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np
from _report import command_line, write_section

import masonryfw as mf
import masonryfw.testing as mt

sys.path.insert(0, os.path.dirname(__file__))
from _walls import running_bond_spec  # noqa: E402

SIZES = ((12, 25), (22, 45), (36, 67))  # courses x units per course: about 300, 1,000 and 2,400 units
DEFAULT_STEP = 0.05  # la-incremental's option step
QUARTER = DEFAULT_STEP / 4
FINE_STEPS = (0.01, 0.0075, 0.005)


def timed(model, solver, options):
    start = time.perf_counter()
    result = mf.solve(model, solver, options)
    return time.perf_counter() - start, result


def per_increment() -> list[str]:
    rows = ["| units | blocks | s per increment | contacts | increments |", "|---|---|---|---|---|"]
    for courses, per_course in SIZES:
        model = mf.build(mf.dump_toml(running_bond_spec(courses, per_course)))
        seconds, result = timed(model, "la-incremental", {"increments": 10})
        units = int((model.block_role.values == 0).sum())
        rows.append(f"| {units:,} | {model.sizes['block']:,} | {seconds / (result.sizes['step'] - 1):.3f} | "
                    f"{int(result.step_contacts.values[-1]):,} | {result.sizes['step'] - 1} |")
        print(rows[-1], flush=True)
    return rows


def arch(thickness_ratio: float):
    model = mt.arch_model(thickness_ratio)
    model["block_young_modulus"] = ("block", np.full(model.sizes["block"], 5e9), {"units": "Pa", "long_name": "E"})
    model["block_poisson_ratio"] = ("block", np.full(model.sizes["block"], 0.2), {"units": "1", "long_name": "nu"})
    return model


def against_fdem() -> list[str]:
    rows = ["| wall | to | la-incremental | fdem | fdem / la-incremental | increments |", "|---|---|---|---|---|---|"]
    for name, model, target in (("Test 12C", mf.open_model("test-12c"), 0.06),
                                ("Facade 3", mf.open_model("facade-3"), 0.18),
                                ("arch t/R 0.15, spreading", arch(0.15), 0.2),
                                ("running bond, 2,432 blocks", mf.build(mf.dump_toml(running_bond_spec(*SIZES[-1]))),
                                 0.06)):
        ours, result = timed(model, "la-incremental", {"settlement": target})
        theirs, _ = timed(model, "fdem", {"settlement": target, "plateau_tolerance": 0.0})
        rows.append(f"| {name} | {target * 1e3:.0f} mm | {ours:.1f} s | {theirs:.1f} s | {theirs / ours:.2f} | "
                    f"{result.sizes['step'] - 1} |")
        print(rows[-1], flush=True)
    return rows


def convergence() -> list[str]:
    steps = (DEFAULT_STEP, QUARTER, 0.02, *FINE_STEPS)
    rows = ["| case | " + " | ".join(f"step {s:g}" for s in steps) + " | default against a quarter | default "
            "against the fine steps' median |", "|---|" + "---|" * (len(steps) + 2)]
    cases = (("Panel 4, settlement at collapse", mf.open_model("panel-4"), {}, "settlement_capacity"),
             ("Panel 5, settlement at collapse", mf.open_model("panel-5"), {}, "settlement_capacity"),
             ("arch t/R 0.15, spread at collapse", arch(0.15), {"settlement": 0.5}, "settlement_capacity"),
             ("arch t/R 0.2, spread at collapse", arch(0.2), {"settlement": 0.5}, "settlement_capacity"),
             ("Test 12C, reaction at 60 mm", mf.open_model("test-12c"), {}, "step_reaction"),
             ("Facade 3, reaction at 180 mm", mf.open_model("facade-3"), {}, "step_reaction"))
    for name, model, options, key in cases:
        values = []
        for step in steps:
            result = mf.solve(model, "la-incremental", {**options, "step": step})
            values.append(float(np.atleast_1d(result[key].values)[-1]) if key in result else float("nan"))
        unit = "N" if key == "step_reaction" else "mm"
        scale = 1.0 if unit == "N" else 1e3
        shown = [f"{v * scale:.2f} {unit}" if np.isfinite(v) else "no collapse claimed" for v in values]
        fine = float(np.median(values[-len(FINE_STEPS):]))
        rows.append(f"| {name} | {' | '.join(shown)} | {relative_change(values[0], values[1])} | "
                    f"{relative_change(values[0], fine)} |")
        print(rows[-1], flush=True)
    return rows


def relative_change(value: float, reference: float) -> str:
    return f"{(value - reference) / reference:+.2%}" if np.isfinite([value, reference]).all() else "-"


def main() -> None:
    command_line(__doc__).parse_args()
    body = ["Time per increment against the block count (ten increments):", "", *per_increment(), "",
            "Whole runs against fdem (one pair each, quiet machine):", "", *against_fdem(), "",
            "The settlement at collapse against the step:", "", *convergence()]
    write_section("la-incremental", "la-incremental: per increment, against fdem, against the step", "\n".join(body))


if __name__ == "__main__":
    main()
