"""Benchmark of the jmm solver: return mapping, assembly, linear solve, and whole runs to the plateau.

Run from the benchmarks folder: ``python bench_jmm.py [case[:option=value,...] ...]`` (whole runs;
default: test-12c facade-3). The kernels are timed on Facade 3 (the largest wall). Writes the ``jmm`` section of
docs/benchmarks.md.
"""
from __future__ import annotations

import statistics
import time

import numpy as np
from _report import command_line, write_section

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_jmm.material import JointStrength, ReturnMap, elastic_matrix
from masonryfw_jmm.newton import NewtonSolver, State
from masonryfw_jmm.options import INCREMENTAL_OPTIONS
from masonryfw_jmm.problem import build_problem

DEFAULT = {o.name: o.default for o in INCREMENTAL_OPTIONS}


def median_time(function, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def kernels(case: str) -> list[str]:
    options = dict(DEFAULT)
    model = mfp.derive_geometry(mf.open_model(case))
    problem = build_problem(model, options)
    newton = NewtonSolver(problem)
    non_associated = NewtonSolver(problem)
    non_associated.symmetric = False  # the LU path that non-associated flow takes
    state = State.initial(problem)
    trials = np.random.default_rng(0).normal(size=(problem.disc.n_points, 3))
    K = problem.disc.stiffness(state.tangent)
    free = newton.free
    rhs = np.ones(free.size)
    newton._solve(K, rhs), non_associated._solve(K, rhs)  # orderings are computed once per run
    rows = [
        ("return mapping (all quadrature points, random trials)", median_time(lambda: problem.return_map(trials))),
        ("strains + internal forces", median_time(lambda: problem.disc.internal_force(problem.disc.strain(state.u)))),
        ("tangent stiffness assembly (fixed pattern)", median_time(lambda: problem.disc.stiffness(state.tangent))),
        ("sparse Cholesky factor + solve (CHOLMOD: associated flow, the default)",
         median_time(lambda: newton._solve(K, rhs), 3)),
        ("sparse LU factor + solve (RCM + SuperLU: non-associated flow)",
         median_time(lambda: non_associated._solve(K, rhs), 3)),
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
            f"{iterations.mean():.1f} | {reaction[0]:.1f} | {reaction[-1]:.1f} | {result.attrs['stop_reason']} |")


CONVERGENCE_SETTLEMENT = 1e-5  # m: past the 1 % plateau of Test 12C (6.5e-6 m at 25 mm), where R creeps slowly
MESH_SIZES = (0.05, 0.035, 0.025, 0.0175)  # m
FIRST_INCREMENTS = (0.2, 0.1, 0.05, 0.025)  # of the elastic unloading settlement; later steps grow from it


def fixed_settlement_run(case: str, **given):
    """A run to CONVERGENCE_SETTLEMENT with the plateau stop off: the result and its run time."""
    options = {"settlement": CONVERGENCE_SETTLEMENT, "plateau_slope": 1e-12, "max_steps": 1000, **given}
    start = time.perf_counter()
    result = mf.solve(mf.open_model(case), "jmm", options)
    seconds = time.perf_counter() - start
    if not np.isclose(result.step_settlement.values[-1], CONVERGENCE_SETTLEMENT):
        raise RuntimeError(f"{case} {given}: stopped early ({result.attrs['stop_reason']})")
    return result, seconds


COLUMNS = "| steps | reaction [N] | {} | cracked joints | F1 | locus distance | time [s] | mean Newton iterations |"


def cells(result, seconds: float, difference: str, finest) -> str:
    """Table cells of one run: reaction, ``difference``, and its crack pattern scored against ``finest``."""
    iterations = result.step_newton_iterations.values[1:]
    score = mf.compare(result, finest)
    return (f"{iterations.size} | {float(result.step_reaction.values[-1]):.2f} | {difference} | "
            f"{int(score.crack_count_a)} | {float(score.crack_f1):.2f} | {float(score.locus_distance):.3f} | "
            f"{seconds:.1f} | {iterations.mean():.1f} |")


def convergence(case: str = "test-12c") -> str:
    """Reaction and plastic-zone pattern at a fixed settlement against mesh size and first load step.

    The reaction's reference is independent of the incremental solver: the static limit LP
    on the same continuum (the jmm-limit solver), whose value on Test 12C is the closed-form wedge
    reaction W_moving - gamma t h^2 tan(phi) / 2 (docs/jmm.md). The pattern is the
    crack_indicator on the block model's joints (mesh-independent), scored by the compare
    plugin against the finest run's.
    """
    start = time.perf_counter()
    collapse = mf.solve(mf.open_model(case), "jmm-limit")
    limit_seconds = time.perf_counter() - start
    reference = float(collapse.moving_support_reaction)
    mesh = {h: fixed_settlement_run(case, mesh_size=h) for h in MESH_SIZES}
    finest = mesh[MESH_SIZES[-1]][0]
    rows = []
    for h, (result, seconds) in mesh.items():
        r = float(result.step_reaction.values[-1])
        rows.append(f"| {h * 1000:.1f} | {result.attrs['jmm_dofs']} | "
                    + cells(result, seconds, f"{(r - reference) / reference:+.2%}", finest))
    steps = {f: fixed_settlement_run(case, first_increment=f) for f in FIRST_INCREMENTS}
    smallest = steps[FIRST_INCREMENTS[-1]][0]
    r_smallest = float(smallest.step_reaction.values[-1])
    step_rows = []
    for f, (result, seconds) in steps.items():
        r = float(result.step_reaction.values[-1])
        step_rows.append(f"| {f} | " + cells(result, seconds, f"{(r - r_smallest) / r_smallest:+.3%}", smallest))
    return (
        f"**Convergence on Test 12C**: reaction on the moving support at a settlement of "
        f"{CONVERGENCE_SETTLEMENT * 1000:.3f} mm (the plateau stop turned off, so every run ends at the same "
        f"settlement), against the collapse reaction of the same continuum from the static limit LP "
        f"(`jmm-limit`, 25 mm: {reference:.2f} N in {limit_seconds:.1f} s; the closed-form wedge gives 345.61 N "
        "at apex_shift 0). Displacement elements let the wall arch too easily, so the reaction comes out "
        "low and rises towards the collapse value as the mesh is refined; the cells follow the 200 x 50 mm "
        "units, so the nominal sizes are not a geometric sequence. The plastic-zone pattern is the "
        "`crack_indicator` (points yielding in the last step, mapped onto the joints; cracked above 0.1) "
        "scored by the `compare` plugin against the finest run: F1 of the cracked joints and the locus "
        "distance (fraction of the wall size).\n\n"
        "| mesh size [mm] | DOFs " + COLUMNS.format("vs collapse") + "\n" + "|---" * 10 + "|\n" + "\n".join(rows) +
        "\n\nLoad-step size at the default mesh (the first increment, in elastic unloading settlements; later "
        f"increments grow by 1.5 after steps of <= {DEFAULT['target_iterations']} Newton iterations; differences "
        "against the smallest):\n\n"
        "| first_increment " + COLUMNS.format("difference") + "\n" + "|---" * 9 + "|\n" + "\n".join(step_rows)
    )


TOLERANCES = (1e-5, 1e-4, 1e-3, 1e-2)  # the first is the reference


def tolerance_study(case: str = "test-12c") -> str:
    """The reaction history against the Newton tolerance: run time against error.

    Each run's reactions are compared with the tightest run's history interpolated at the
    same settlements (the step sizes adapt to the Newton work, so the steps differ).
    """
    runs = {t: fixed_settlement_run(case, tolerance=t, target_iterations=12) for t in TOLERANCES}
    reference = runs[TOLERANCES[0]][0]
    rows = []
    for t, (result, seconds) in runs.items():
        s, r = result.step_settlement.values[1:], result.step_reaction.values[1:]
        exact = np.interp(s, reference.step_settlement.values, reference.step_reaction.values)
        iterations = result.step_newton_iterations.values[1:]
        rows.append(f"| {t:g} | {iterations.size} | {iterations.sum()} | {iterations.mean():.1f} | {seconds:.1f} | "
                    f"{r[-1]:.3f} | {np.abs(r / exact - 1).max():.1e} |")
    return (
        f"**Newton tolerance** on {reference.attrs['title']} (`||free residual|| / ||gravity load||`), to "
        f"{CONVERGENCE_SETTLEMENT * 1000:.3f} mm with the plateau stop off and `target_iterations` 12 (so that the "
        "tight tolerances are not cut to tiny steps); the error is the largest relative "
        f"difference of the reaction history from the tolerance-{TOLERANCES[0]:g} run's, interpolated at the same "
        "settlements:\n\n"
        "| tolerance | steps | Newton iterations | per step | time [s] | final reaction [N] | reaction error |\n"
        "|---|---|---|---|---|---|---|\n" + "\n".join(rows)
    )


TARGETS = (3, 4, 6, 8, 12)


def step_control(case: str = "facade-3") -> str:
    """Whole runs to the plateau against target_iterations: mean iterations per step against run time."""
    rows = []
    for target in TARGETS:
        start = time.perf_counter()
        result = mf.solve(mf.open_model(case), "jmm", {"target_iterations": target})
        seconds = time.perf_counter() - start
        iterations = result.step_newton_iterations.values[1:]
        rows.append(f"| {target} | {iterations.size} | {iterations.sum()} | {iterations.mean():.1f} | {seconds:.0f} | "
                    f"{result.step_settlement.values[-1] * 1000:.4f} | {result.step_reaction.values[-1]:.1f} |")
    return (
        f"**Step control** on {result.attrs['title']} ({result.attrs['jmm_dofs']} DOFs), default options to the "
        "reaction plateau: increments grow by 1.5 after steps of at most `target_iterations` Newton iterations "
        "and halve after more than twice as many. Smaller steps lower the iterations per step and raise "
        "the total:\n\n"
        "| target_iterations | steps | Newton iterations | per step | time [s] | stop settlement [mm] | plateau [N] |\n"
        "|---|---|---|---|---|---|---|\n" + "\n".join(rows)
    )


def main() -> None:
    parser = command_line(__doc__)
    parser.add_argument("cases", nargs="*", default=["test-12c", "facade-3"], help="bundled walls to run whole")
    cases = parser.parse_args().cases
    parts = [big_return_map()] + kernels("facade-3") + [convergence(), tolerance_study(), step_control()]
    runs = [whole_run(case) for case in cases]
    parts.append(
        "Whole runs with the default options (gravity, then settlement to the reaction plateau):\n\n"
        "| wall | DOFs | time [s] | settlement steps | mean Newton iterations per step | dead reaction [N] "
        "| plateau [N] | stop |\n|---|---|---|---|---|---|---|---|\n" + "\n".join(runs)
    )
    write_section("jmm", "jmm: continuum FE with the Jointed Masonry Model", "\n\n".join(parts))


if __name__ == "__main__":
    main()
