"""Time the fdem solver and measure what its accuracy knobs cost and change.

1. Throughput: Test 12C to 20 mm of settlement and Facade 3 with the default options
   (wall time, steps, face-pair updates per second). Single runs (each takes seconds).
2. Sleeping on Facade 3 (most of the wall never moves), 10 mm without the plateau stop (so
   both runs do the same steps): time, sleeping blocks at the end, reaction and crack
   pattern with and without it.
3. Run time against error on Test 12C (12 mm target, no plateau stop): for the dt safety
   factor, the loading rate, the local damping and the contact stiffness, the time, the
   lowest and final reaction over R0, and the crack pattern against the default run
   (crack F1, macro-block ARI of the ``compare`` plugin).

4. Threads: one against two, alternating pairs on Test 12C and Facade 3.
5. The deformable mode: element-steps per second of the CST update (the kernel alone and the
   whole explicit step), and Test 12C in both modes.

Run: ``python benchmarks/bench_fdem.py`` (a few minutes); ``--deformable`` for part 5 only.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import masonryfw as mf
import masonryfw.plugin_api as mfp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import command_line, write_section  # noqa: E402

ROLE = mfp.flags("block_role")
SWEEPS = {
    "dt_safety": (0.15, 0.3, 0.4),
    "loading_rate": (1e-3, 2e-3, 5e-3),
    "damping": (0.5, 0.7, 0.9),
    "penetration_ratio": (3e-5, 1e-4, 3e-4),
}
DEFAULTS = {o.name: o.default for o in mf.get_solver("fdem").options}


def timed(model, options):
    clock = time.perf_counter()
    result = mf.solve(model, "fdem", options)
    return result, time.perf_counter() - clock


def dead_reaction(model) -> float:
    return mf.dead_reaction(model)


def throughput_row(case: str, options: dict) -> str:
    model = mf.open_model(case)
    result, seconds = timed(model, options)
    steps = result.attrs["fdem_steps"]
    pairs = result.attrs["fdem_face_pairs"]
    settled = 1e3 * result.step_settlement.values[-1]
    return (f"| {case} | {int(mfp.masonry_blocks(model.block_role.values).sum())} | {options or 'defaults'} | {settled:.1f} | "
            f"{result.attrs['stop_reason']} | {steps} | {result.attrs['fdem_dt_s']:.2e} | {seconds:.1f} | "
            f"{seconds / steps * 1e6:.0f} | {pairs * steps / seconds / 1e6:.1f} |")


def sleep_rows(case: str) -> list[str]:
    model = mf.open_model(case)
    r0 = dead_reaction(model)
    base = {"settlement": 0.01, "plateau_tolerance": 0.0}
    reference, base_time = timed(model, base)
    rows = []
    for share in (0.0, 0.01, 0.05):
        result, seconds = (reference, base_time) if share == 0 else timed(model, base | {"sleep": share})
        scores = mf.compare(reference, result)
        phase = result.step_phase.values == 1
        rows.append(
            f"| {case} | {share:g} | {seconds:.1f} | {base_time / seconds:.2f} | {result.attrs['fdem_asleep_blocks']} | "
            f"{result.step_reaction.values[phase].min() / r0:.3f} | {result.step_reaction.values[-1] / r0:.3f} | "
            f"{scores.crack_f1.item():.2f} | {scores.macro_block_ari.item():.2f} | "
            f"{abs(result.step_energy_error.values).max():.1e} |")
    return rows


def thread_rows(case: str, pairs: int = 5) -> list[str]:
    """One thread against two (option threads) as a user runs them: whole CLI processes in alternating
    pairs (in one process, numba's thread team outlives a run and skews the next one); medians, the ratio
    pair by pair, and whether the two trajectories are the same bit for bit."""
    import subprocess
    import tempfile

    import numpy as np

    times: dict[int, list[float]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(pairs):
            for threads in (1, 2):
                out = Path(folder, f"{threads}.nc")
                out.unlink(missing_ok=True)
                clock = time.perf_counter()
                subprocess.run([sys.executable, "-m", "masonryfw", "solve", case, "--plugin", "fdem", "--option",
                                f"threads={threads}", "-o", str(out), "--no-progress"], check=True,
                               capture_output=True)
                times[threads].append(time.perf_counter() - clock)
        one, two = (mf.open_dataset(Path(folder, f"{k}.nc")).load() for k in (1, 2))
    same = bool(np.array_equal(one.block_displacement.values, two.block_displacement.values))
    ratios = [a / b for a, b in zip(times[1], times[2])]
    return [f"| {case} | {one.attrs['fdem_face_pairs']} | {float(np.median(times[1])):.2f} | "
            f"{float(np.median(times[2])):.2f} | {float(np.median(ratios)):.2f} ({min(ratios):.2f}-{max(ratios):.2f}) "
            f"| {'yes' if same else 'NO'} |"]


def sweep_rows(case: str) -> list[str]:
    model = mf.open_model(case)
    base = {"plateau_tolerance": 0.0}
    reference, _ = timed(model, base)
    r0 = dead_reaction(model)
    rows = []
    for name, values in SWEEPS.items():
        for value in values:
            options = base | {name: value}
            result, seconds = timed(model, options)
            phase = result.step_phase.values == 1
            scores = mf.compare(reference, result)
            mark = " (default)" if value == DEFAULTS[name] else ""
            print(name, value, seconds, flush=True)
            rows.append(
                f"| {name} = {value:g}{mark} | {seconds:.1f} | {result.attrs['fdem_steps']} | "
                f"{result.step_reaction.values[phase].min() / r0:.3f} | {result.step_reaction.values[-1] / r0:.3f} | "
                f"{scores.crack_f1.item():.2f} | {scores.macro_block_ari.item():.2f} | "
                f"{abs(result.step_energy_error.values).max():.1e} |")
    return rows


def main() -> None:
    mf.solve(mf.open_model("test-8c"), "fdem", {"settlement": 1e-4})  # numba compile / cache load
    print("throughput", flush=True)
    throughput = [
        "| case | units | options | settlement [mm] | stop | steps | dt [s] | wall time [s] | us / step | M face-pair updates / s |",
        "|---|---|---|---|---|---|---|---|---|---|",
        throughput_row("test-12c", {"settlement": 0.02, "plateau_tolerance": 0.0}),
        throughput_row("facade-3", {}),
    ]
    print("sleeping", flush=True)
    sleeping = [
        "| case | sleep (share of the settlement speed) | time [s] | speed-up | blocks asleep at the end | R min / R0 | "
        "R end / R0 | crack F1 vs no sleep | ARI vs no sleep | max energy error |",
        "|---|---|---|---|---|---|---|---|---|---|",
        *sleep_rows("facade-3"),
    ]
    print("threads", flush=True)
    threads = [
        "| case | face pairs | 1 thread, whole process [s] | 2 threads [s] | speed-up, median of 5 pairs (range) | "
        "same trajectory, bit for bit |",
        "|---|---|---|---|---|---|",
        *thread_rows("test-12c"),
        *thread_rows("facade-3"),
    ]
    sweep = [
        "| option | time [s] | steps | R min / R0 | R end / R0 | crack F1 vs default | ARI vs default | max energy error |",
        "|---|---|---|---|---|---|---|---|",
        *sweep_rows("test-12c"),
    ]
    body = (
        "Rigid mode, numba kernels (`@njit(cache=True)`, the contact and block loops `parallel=True` on "
        f"{os.cpu_count()} cores), compile time excluded. "
        "R0 = the moving support's dead reaction (uniform distribution, the paper's loading).\n\n"
        "### Throughput\n\n" + "\n".join(throughput) + "\n\n"
        "### Threads (option `threads`; default: one below 300 blocks, from 300 the faster count as measured during the run)\n\n" + "\n".join(threads) + "\n\n"
        "### Sleeping blocks at rest\n\n" + "\n".join(sleeping) + "\n\n"
        "### Run time against error (Test 12C, 12 mm, no plateau stop; one option changed at a time)\n\n"
        + "\n".join(sweep) + "\n\n"
        "The deformable (CST) mode: see the next section.\n"
    )
    write_section("fdem", "fdem: rigid-block explicit DEM", body)
    print(body)
    deformable_main()


def grid_mesh(columns: int, rows: int):
    """A structured mesh of the unit square, every cell split into two triangles (a plain CST mesh
    of ``2 columns rows`` elements, node order row-major)."""
    import numpy as np

    from masonryfw_fdem.deformable import shape_gradients

    x, y = np.meshgrid(np.linspace(0, 1, columns + 1), np.linspace(0, 1, rows + 1))
    node = np.arange(x.size).reshape(rows + 1, columns + 1)
    a, b, c, d = node[:-1, :-1].ravel(), node[:-1, 1:].ravel(), node[1:, 1:].ravel(), node[1:, :-1].ravel()
    triangles = np.concatenate((np.stack((a, b, c), 1), np.stack((a, c, d), 1))).astype(np.int64)
    order = np.argsort(triangles[:, 0], kind="stable")  # neighbouring elements share cached nodes
    triangles = triangles[order]
    grad_x, grad_y, area = shape_gradients(x.ravel(), y.ravel(), triangles)
    return x.ravel(), y.ravel(), triangles, grad_x, grad_y, area


def cst_rows(repeats: int = 5) -> list[str]:
    """Element-steps per second of the CST internal-force kernel alone, and of the whole
    deformable step (forces + central-difference update of the nodes, no contacts)."""
    import numpy as np

    from masonryfw_fdem import deformable, kernels

    rows = []
    for columns in (16, 300):
        x0, y0, triangles, grad_x, grad_y, area = grid_mesh(columns, columns)
        n_tri, n_node = triangles.shape[0], x0.size
        young, nu, on = np.full(n_tri, 100.0), np.full(n_tri, 0.2), np.ones(n_tri, np.bool_)
        rng = np.random.default_rng(0)
        x, y = x0 + 1e-4 * rng.normal(size=n_node), y0 + 1e-4 * rng.normal(size=n_node)
        force = np.zeros((n_node, 2))
        steps = max(1, int(2e7 // n_tri))
        # the kernel the time loop runs: element constants packed once, then one call per step
        packed = deformable.element_constants(triangles, grad_x, grad_y, area, young, nu, on)
        deformable.cst_element_forces(x, y, *packed, force)  # compile
        kernel = []
        for _ in range(repeats):
            clock = time.perf_counter()
            for _ in range(steps):
                deformable.cst_element_forces(x, y, *packed, force)
            kernel.append(time.perf_counter() - clock)
        kernel_rate = n_tri * steps / float(np.median(kernel))
        # the full step: mesh only (no contacts, no supports), damping on, gravity
        mass = np.bincount(triangles.ravel(), weights=np.repeat(area / 3, 3), minlength=n_node)
        node_block = np.zeros(n_node, np.int64)
        no_faces, face_rows = np.zeros((0, 4), np.int64), np.zeros((0, 2))
        load = np.zeros((n_node, 2))
        load[:, 1] = -mass
        full = []
        for _ in range(repeats):
            vel = np.zeros((n_node, 2))
            xs, ys = x.copy(), y.copy()
            mesh = deformable.Mesh(x0, y0, node_block, triangles, grad_x, grad_y, area, young, nu, mass, 1 / mass,
                                   np.zeros(n_node, np.bool_), on)
            bodies = kernels.Bodies(np.zeros((1, 3)), np.ones(1), x0[:1], y0[:1], np.array([0, 0]),
                                    np.ones((1, 3)), np.zeros(1), np.zeros((1, 3), np.bool_), np.zeros(1, np.bool_),
                                    np.zeros(1, np.bool_), np.zeros((1, 3)))
            pairs = kernels.Pairs(no_faces, np.zeros((0, 4)), face_rows, face_rows.astype(np.int64),
                                  face_rows.copy(), face_rows.copy(), np.zeros((0, 4)))
            motion = deformable.NodeMotion(xs, ys, vel, x0.copy(), y0.copy(), np.zeros(kernels.N_ACC))
            loading = kernels.Loading(load, 0.0, np.zeros_like(load), 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
            stepping = kernels.Stepping(1e-4, 0.7, 1e300, 0.0, 0, 0.0)
            args = (bodies, mesh, pairs, kernels.ContactLaw(1.0, 0.5, 0.0, 0.2), motion, loading, stepping,
                    np.zeros((1, 3)))
            deformable.advance(1, *args)  # compile
            clock = time.perf_counter()
            deformable.advance(steps, *args)
            full.append(time.perf_counter() - clock)
        full_rate = n_tri * steps / float(np.median(full))
        rows.append(f"| {n_tri} | {n_node} | {steps} | {kernel_rate / 1e6:.0f} | {full_rate / 1e6:.0f} |")
        print(rows[-1], flush=True)
    return rows


def mode_rows(case: str) -> list[str]:
    """The same wall in both modes (paper E and nu), defaults otherwise."""
    model = mf.open_model(case)
    r0 = dead_reaction(model)
    rigid, rigid_time = timed(model, {})
    rows = []
    for mode in ("rigid", "deformable"):
        result, seconds = (rigid, rigid_time) if mode == "rigid" else timed(model, {"mode": mode})
        phase = result.step_phase.values == 1
        scores = mf.compare(rigid, result)
        rows.append(
            f"| {case} | {mode} | {result.attrs['fdem_steps']} | {result.attrs['fdem_dt_s']:.2e} | {seconds:.1f} | "
            f"{result.attrs['stop_reason']} | {result.step_reaction.values[phase].min() / r0:.3f} | "
            f"{result.step_reaction.values[-1] / r0:.3f} | {scores.crack_f1.item():.2f} | "
            f"{scores.macro_block_ari.item():.2f} | {abs(result.step_energy_error.values).max():.1e} |")
        print(rows[-1], flush=True)
    return rows


def deformable_main() -> None:
    mf.solve(mf.open_model("test-8c"), "fdem", {"settlement": 1e-4, "mode": "deformable"})  # compile / cache
    kernel = [
        "| elements | nodes | steps | M element-steps / s, CST forces only | M element-steps / s, whole step |",
        "|---|---|---|---|---|",
        *cst_rows(),
    ]
    modes = [
        "| case | mode | steps | dt [s] | wall time [s] | stop | R min / R0 | R end / R0 | crack F1 vs rigid | "
        "ARI vs rigid | max energy error |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
        *mode_rows("test-12c"),
    ]
    body = (
        "`mode=deformable`: every block a fan of constant-strain triangles (Green-Lagrange strain, "
        "plane stress), the rigid mode's joints on the boundary nodes. Serial numba, one core, "
        "compile time excluded.\n\n"
        "### CST update throughput (structured mesh of the unit square, no contacts)\n\n"
        + "\n".join(kernel) + "\n\n"
        f"Load average while measuring: {os.getloadavg()[0]:.1f} on 2 cores (other jobs share them). "
        "The target set for the CST kernel is >= 60 M element-steps / s per core.\n\n"
        "### Rigid against deformable on a paper wall (E = 1.14 GPa, nu = 0.2 from the model)\n\n"
        + "\n".join(modes) + "\n"
    )
    write_section("fdem-deformable", "fdem: deformable (CST) mode", body)
    print(body)


if __name__ == "__main__":
    parser = command_line(__doc__)
    parser.add_argument("--deformable", action="store_true", help="part 5 only: the deformable mode")
    if parser.parse_args().deformable:
        deformable_main()
    else:
        main()
