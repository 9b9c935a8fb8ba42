"""Benchmark of la's non-associative friction in 3D against the associative cone it starts from.

The 3D twins of three bundled walls (whose planar non-associative alpha is the reference) and the kit's corner
building: medians of alternating pairs in this process after a warm-up (``--pairs``), the programmes of the
sequence, whether it converged, and where the time goes (the share of the selection QP by Clarabel, which the exact
finish runs, timed inside the same runs; the rest is our interior point's regularised programmes). ``--house`` adds
the bundled house over a tunnel (1,126 blocks, one pair, about 2 minutes).

Run from the benchmarks folder: ``python bench_la_flow3d.py [--house]``. Writes the ``la-flow3d`` section of
docs/benchmarks.md.
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

from _report import write_section

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt
from masonryfw_la import nonassociative

NON = {"flow": "nonassociative"}


class SelectionClock:
    """Seconds spent in the selection QP while it is installed (wraps the function the 3D sequence calls)."""

    def __init__(self):
        self.seconds = 0.0
        self.original = nonassociative.least_squared_forces

    def __enter__(self):
        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return self.original(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - start

        nonassociative.least_squared_forces = timed
        return self

    def __exit__(self, *exc):
        nonassociative.least_squared_forces = self.original


def timed(model, options):
    with SelectionClock() as clock:
        start = time.perf_counter()
        result = mf.solve(model, "la", options)
        return time.perf_counter() - start, clock.seconds, result


def row(name, model, planar, pairs):
    if pairs > 1:
        timed(model, {})
    runs = [(timed(model, {}), timed(model, NON)) for _ in range(pairs)]
    ta = statistics.median(a[0] for a, _ in runs)
    tn = statistics.median(n[0] for _, n in runs)
    selection = statistics.median(n[1] / n[0] for _, n in runs)
    assoc, non = runs[-1][0][2], runs[-1][1][2]
    alpha = float(non.collapse_multiplier)
    reference = "" if planar is None else f"{planar:.7f} ({alpha - planar:+.1e})"
    status = "yes" if non.attrs["la_flow_converged"] else "no: " + non.attrs["stop_reason"].split(" (")[0]
    line = (f"| {name} | {model.sizes['block']} | {float(assoc.collapse_multiplier):.6f} | {alpha:.7f} | "
            f"{reference} | {non.attrs['la_flow_iterations']} | {status} | {ta:.3f} | {tn:.2f} | {tn / ta:.0f} | "
            f"{selection:.0%} |")
    print(line, flush=True)
    return line


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pairs", type=int, default=3, help="alternating pairs per small model")
    parser.add_argument("--house", action="store_true", help="also the house over a tunnel (about 2 minutes)")
    args = parser.parse_args(argv)
    load = os.getloadavg()
    rows = []
    for case in ("test-12c", "test-8c", "panel-1"):
        model = mf.open_model(case)
        planar = float(mf.solve(model, "la", NON).collapse_multiplier)
        rows.append(row(f"{case} (3D twin)", mfp.twin(model), planar, args.pairs))
    rows.append(row("corner building (kit)", mt.corner_building(), None, args.pairs))
    if args.house:
        rows.append(row("house-tunnel", mf.open_model("house-tunnel"), None, 1))
    header = ("| model | blocks | alpha assoc. | alpha non-assoc. | planar non-assoc. (3D - planar) | programmes | "
              "converged | assoc. [s] | non-assoc. [s] | ratio | selection QP share |\n"
              "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|")
    body = f"""
`masonryfw.solve(model, "la", {{"flow": "nonassociative"}})` on 3D models (ipm: each programme regularised by
`w N^2 / 2` in one cone solve, a settled sequence finished with the exact selection QP; flow_tolerance 1e-6) against
the associative cone; load average before: {load[0]:.2f},
{load[1]:.2f}, {load[2]:.2f}. Medians of {args.pairs} alternating pairs after a warm-up (the house: one pair).

{header}
{chr(10).join(rows)}
"""
    write_section("la-flow3d", "la: non-associative friction in 3D", body)
    print(body)


if __name__ == "__main__":
    main()
