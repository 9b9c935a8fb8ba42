"""Benchmark of the jmm solver: return mapping, assembly, linear solve, and whole runs to the plateau.

Run from the benchmarks folder: ``python bench_jmm.py [case[:option=value,...] ...]`` (whole runs;
default: test-12c facade-3). The kernels are timed on Facade 3 (the largest wall). Writes the ``jmm`` section of
docs/benchmarks.md.
"""
from __future__ import annotations

import statistics
import sys
import time

import numpy as np

import masonryfw as mf
from masonryfw_jmm.material import JointStrength, ReturnMap, elastic_matrix
from masonryfw_jmm.newton import NewtonSolver, State
from masonryfw_jmm.problem import build_problem
from masonryfw_jmm.options import OPTIONS

from _report import write_section


def median_time(function, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def kernels(case: str) -> list[str]:
    options = {o.name: o.default for o in OPTIONS}
    model = mf.derive_geometry(mf.open_model(case))
    problem = build_problem(model, options)
    newton = NewtonSolver(problem)
    state = State.initial(problem)
    trials = np.random.default_rng(0).normal(size=(problem.disc.n_points, 3))
    K = problem.disc.stiffness(state.tangent)
    free = newton.free
    rhs = np.ones(free.size)
    newton._solve(K[free][:, free], rhs)  # the ordering is computed once
    rows = [
        ("return mapping (all quadrature points, random trials)", median_time(lambda: problem.return_map(trials))),
        ("strains + internal forces", median_time(lambda: problem.disc.internal_force(problem.disc.strain(state.u)))),
        ("tangent stiffness assembly (fixed pattern)", median_time(lambda: problem.disc.stiffness(state.tangent))),
        ("sparse LU solve (RCM + SuperLU)", median_time(lambda: newton._solve(K[free][:, free], rhs), 3)),
    ]
    head = f"**{model.attrs['title']}**, P2, {problem.disc.ndof} DOFs, {problem.disc.n_points} quadrature points:\n\n"
    return [head + "| kernel | median time [s] |\n|---|---|\n" + "\n".join(f"| {n} | {t:.4f} |" for n, t in rows)]


def big_return_map() -> str:
    rmap = ReturnMap(JointStrength(0.4, 0.4, beta=0.8), elastic_matrix(2.4, 0.2))
    trials = np.random.default_rng(1).normal(size=(400_000, 3))
    return f"Return mapping of 400 000 random trial stresses (c = 0, 4 faces, 14 active sets): {median_time(lambda: rmap(trials), 3):.2f} s."


def whole_run(spec: str) -> str:
    """``case`` or ``case:name=value,name=value`` (jmm options)."""
    case, _, given = spec.partition(":")
    options = dict(item.split("=", 1) for item in given.split(",") if item)
    model = mf.open_model(case)
    start = time.perf_counter()
    result = mf.solve(model, "jmm", options)
    seconds = time.perf_counter() - start
    reaction = result.step_reaction.values
    iterations = result.step_newton_iterations.values[1:]
    return (f"| {result.attrs['title']} {given} | {result.attrs['jmm_dofs']} | {seconds:.0f} | {reaction.size - 1} | "
            f"{iterations.mean():.1f} | {reaction[0]:.1f} | {reaction[-1]:.1f} | {result.attrs['jmm_stop_reason']} |")


def main() -> None:
    cases = sys.argv[1:] or ["test-12c", "facade-3"]
    parts = [big_return_map()] + kernels("facade-3")
    runs = [whole_run(case) for case in cases]
    parts.append(
        "Whole runs with the default options (gravity, then settlement to the reaction plateau):\n\n"
        "| wall | DOFs | time [s] | settlement steps | mean Newton iterations per step | dead reaction [N] "
        "| plateau [N] | stop |\n|---|---|---|---|---|---|---|---|\n" + "\n".join(runs)
    )
    write_section("jmm", "jmm: continuum FE with the Jointed Masonry Model", "\n\n".join(parts))


if __name__ == "__main__":
    main()
