"""Benchmark of the ``jmm-limit`` solver (the static LP on the mesh): LP size, times, alpha, against LA.

Run from the benchmarks folder: ``python bench_jmm_limit.py [case ...]`` (default: test-8c test-12c facade-3;
``--incremental`` also runs the incremental solver to its plateau on the same mesh, up to a minute per wall).
Writes the ``jmm_limit`` section of docs/benchmarks.md.
"""
from __future__ import annotations

import os
import statistics
import time

import numpy as np
from _report import command_line, write_section

import masonryfw as mf
import masonryfw.plugin_api as mfp

FLAG = mfp.flags("qp_failure")


def limit_row(case: str, repeat: int, incremental: bool) -> str:
    model = mf.open_model(case)
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = mf.solve(model, "jmm-limit")
        times.append(time.perf_counter() - start)
    a = result.attrs
    flags = np.bincount(result.qp_failure.values, minlength=4)
    la_alpha = float(mf.solve(model, "la").collapse_multiplier)
    plateau = "-"
    if incremental:
        run = mf.solve(model, "jmm")
        plateau = f"{run.step_reaction.values[-1]:.1f} ({1 - run.step_reaction.values[-1] / a['jmm_dead_reaction_n']:.3f})"
    return (f"| {case} | {a['jmm_lp_variables']} | {a['jmm_lp_equalities']} | {a['jmm_lp_inequalities']} | "
            f"{a['jmm_lp_nonzeros']} | {a['jmm_lp_iterations']} | {a['jmm_lp_assembly_time_s']:.2f} | "
            f"{a['jmm_lp_solve_time_s']:.2f} | {statistics.median(times):.2f} | {a['jmm_dead_reaction_n']:.1f} | "
            f"{float(result.moving_support_reaction):.1f} | {float(result.collapse_multiplier):.4f} | {plateau} | "
            f"{la_alpha:.3f} | {flags[FLAG['tensile']]}/{flags[FLAG['shear']]}/{flags[FLAG['tensile_shear']]} |")


def main() -> None:
    parser = command_line(__doc__)
    parser.add_argument("cases", nargs="*", default=["test-8c", "test-12c", "facade-3"], help="bundled walls")
    parser.add_argument("--incremental", action="store_true", help="jmm's incremental run beside each limit LP")
    args = parser.parse_args()
    cases, incremental = args.cases, args.incremental
    load = os.getloadavg()[0]
    rows = [limit_row(case, 3, incremental) for case in cases]
    body = (
        f"Default options (mesh_size = half the unit height = 25 mm, apex_shift 1e-3), Clarabel with QDLDL; "
        f"times are medians of 3 runs, load average {load:.2f} at the start (2 cores shared with other work). "
        "R_0 = W L_moving / L_contact (the paper's settlement dead load, as LA); alpha = 1 - R_min / R_0. "
        "Incremental plateau: `step_reaction[-1]` of a default incremental run on the same mesh (with "
        "`--incremental`), its alpha = 1 - plateau / R_0. "
        "Plastic points: tensile/shear/tensile_shear among 3 points per triangle.\n\n"
        "| wall | LP variables | equalities | inequalities | nonzeros | IPM iterations | assembly [s] | "
        "LP solve [s] | whole solve [s] | R_0 [N] | R_min [N] | alpha (limit) | incremental plateau [N] (alpha) | "
        "LA alpha | plastic t/s/ts |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n" + "\n".join(rows)
    )
    write_section("jmm_limit", "jmm-limit: the static LP of the JMM continuum on the mesh", body)


if __name__ == "__main__":
    main()
