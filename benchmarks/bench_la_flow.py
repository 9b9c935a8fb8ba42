"""Benchmark of la's non-associative flow rule against the associative solve it starts from.

The ten bundled walls (median of 3 alternating pairs in this process, after a warm-up) and
the running-bond settlement wall of 1,000 units (bench_la.py's, one pair; at 10,000 units the
sequence would take well over 20 minutes, so it is not run):
time, LPs of the sequence, alpha both ways; and, on Facade 3, run time against error: the
flow tolerance loosened, alpha against the converged one.
Run from the benchmarks folder: ``python bench_la_flow.py``. Writes the ``la-flow`` section of
docs/benchmarks.md.
"""
from __future__ import annotations

import os
import statistics
import sys
import time

from _report import write_section

import masonryfw as mf

sys.path.insert(0, os.path.dirname(__file__))
from bench_la import SIZES, running_bond_spec  # noqa: E402

PAIRS = 3
NON = {"flow": "nonassociative"}


def timed(model, options):
    start = time.perf_counter()
    result = mf.solve(model, "la", options)
    return time.perf_counter() - start, result


def pair_rows(models, pairs):
    rows = []
    for name, model in models:
        timed(model, {})
        a_times, n_times = [], []
        for _ in range(pairs):
            a, assoc = timed(model, {})
            n, non = timed(model, NON)
            a_times.append(a)
            n_times.append(n)
        ta, tn = statistics.median(a_times), statistics.median(n_times)
        rows.append(f"| {name} | {model.sizes['block']} | {float(assoc.collapse_multiplier):.5f} | "
                    f"{float(non.collapse_multiplier):.5f} | {non.attrs['la_flow_iterations']} | {ta:.3f} | {tn:.3f} | "
                    f"{tn / ta:.1f} |")
        print(rows[-1], flush=True)
    return rows


def tolerance_rows(model):
    _, reference = timed(model, {**NON, "flow_tolerance": 1e-9, "flow_iterations": 300})
    exact = float(reference.collapse_multiplier)
    rows = []
    for tolerance in (1e-3, 1e-4, 1e-5, 1e-6):
        seconds, result = timed(model, {**NON, "flow_tolerance": tolerance})
        rows.append(f"| {tolerance:g} | {result.attrs['la_flow_iterations']} | {seconds:.2f} | "
                    f"{float(result.collapse_multiplier):.7f} | {abs(float(result.collapse_multiplier) - exact):.1e} |")
        print(rows[-1], flush=True)
    return exact, reference.attrs["la_flow_iterations"], rows


def main() -> None:
    load = os.getloadavg()
    walls = [(case, mf.open_model(case)) for case in mf.CASE_NAMES]
    ten = pair_rows(walls, PAIRS)
    big = pair_rows([(f"running bond, {size:,} units", mf.build(running_bond_spec(*SIZES[size])))
                     for size in (1_000,)], 1)
    exact, lps, tolerance = tolerance_rows(mf.open_model("facade-3"))
    header = ("| wall | blocks | alpha assoc. | alpha non-assoc. | LPs | assoc. [s] | non-assoc. [s] | ratio |\n"
              "|---|---:|---:|---:|---:|---:|---:|---:|")
    body = f"""
`masonryfw.solve(model, "la", {{"flow": "nonassociative"}})` (ipm backend, flow_tolerance 1e-6) against the
associative solve; load average before: {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f}. Ten walls: medians of
{PAIRS} alternating pairs after a warm-up; the running-bond wall: one pair (10,000 units not run: the
selection QP alone takes about 2 s a sequence step at 1,000 units).

{header}
{chr(10).join(ten + big)}

Run time against error on Facade 3 (reference: flow_tolerance 1e-9, {lps} LPs, alpha {exact:.8f}):

| flow_tolerance | LPs | time [s] | alpha | error |
|---:|---:|---:|---:|---:|
{chr(10).join(tolerance)}
"""
    write_section("la-flow", "la: non-associative friction", body)
    print(body)


if __name__ == "__main__":
    main()
