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

Run: ``python benchmarks/bench_fdem.py`` (a few minutes).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import masonryfw as mf

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import write_section  # noqa: E402

ROLE = mf.flags("block_role")
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
    return float(model.dead_load.values[model.block_role.values == ROLE["moving_support"], 1].sum())


def throughput_row(case: str, options: dict) -> str:
    model = mf.open_model(case)
    result, seconds = timed(model, options)
    steps = result.attrs["fdem_steps"]
    pairs = result.attrs["fdem_face_pairs"]
    settled = 1e3 * result.step_settlement.values[-1]
    return (f"| {case} | {int((model.block_role.values < 2).sum())} | {options or 'defaults'} | {settled:.1f} | "
            f"{result.attrs['fdem_stop_reason']} | {steps} | {result.attrs['fdem_dt_s']:.2e} | {seconds:.1f} | "
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
    sweep = [
        "| option | time [s] | steps | R min / R0 | R end / R0 | crack F1 vs default | ARI vs default | max energy error |",
        "|---|---|---|---|---|---|---|---|",
        *sweep_rows("test-12c"),
    ]
    body = (
        "Rigid mode, serial numba kernels (`@njit(cache=True)`), compile time excluded. "
        "R0 = the moving support's dead reaction (uniform distribution, the paper's loading).\n\n"
        "### Throughput\n\n" + "\n".join(throughput) + "\n\n"
        "### Sleeping blocks at rest\n\n" + "\n".join(sleeping) + "\n\n"
        "### Run time against error (Test 12C, 12 mm, no plateau stop; one option changed at a time)\n\n"
        + "\n".join(sweep) + "\n\n"
        "Not measured: the deformable (CST) mode is not implemented (see docs/fdem.md).\n"
    )
    write_section("fdem", "fdem: rigid-block explicit DEM", body)
    print(body)


if __name__ == "__main__":
    main()
