"""End to end: ``masonryfw solve facade-3 --plugin la`` as a user runs it (process start to file written).

Measured twice: as after ``pip install .`` (dask absent), and with dask importable
(``pip install ".[sweep]"``), because xarray imports ``dask.array`` to recognise
array types whenever dask is installed.

``python bench_cli.py --vs /path/to/other/python`` also times another installation (an
earlier version, say) in alternating runs, A B A B ..., and reports the ratio pair by pair:
pairing keeps the ratio meaningful when the machine's speed drifts.

The floor it is held to: a bare script that reads the model file with xarray, takes the same LP (its
matrices saved beforehand, not timed) and solves it with Clarabel, then writes the mechanism with NumPy:
what any script reading the data contract and calling a solver pays. It runs in alternation with the
CLI, in pairs.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402
from _report import write_section  # noqa: E402

import masonryfw as mf  # noqa: E402

RUNS = 10
BLOCK_DASK = "import sys; sys.modules['dask'] = None; "


BARE = """
import sys
sys.modules["dask"] = None  # as the CLI runs below: pip install . has no dask
import clarabel, numpy as np, scipy.sparse as sp, xarray as xr
model = xr.load_dataset(sys.argv[1])
lp = np.load(sys.argv[2])
G = sp.csr_matrix((lp["data"], lp["indices"], lp["indptr"]), shape=tuple(lp["shape"]))
A = sp.vstack([sp.csr_matrix(lp["live"][None, :]), -G], format="csc")
b = np.concatenate([[1.0], np.zeros(G.shape[0])])
settings = clarabel.DefaultSettings()
settings.verbose = False
settings.direct_solve_method = "qdldl"
settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-9
solution = clarabel.DefaultSolver(sp.csc_matrix((G.shape[1], G.shape[1])), lp["cost"], A, b,
                                  [clarabel.ZeroConeT(1), clarabel.NonnegativeConeT(G.shape[0])], settings).solve()
np.save(sys.argv[3], np.asarray(solution.x))
print(float(lp["cost"] @ np.asarray(solution.x)), model.sizes["block"])
"""


def _time(python: str, prelude: str, out: Path) -> float:
    code = prelude + (
        "from masonryfw.cli import main; "
        f"main(['solve', 'facade-3', '--plugin', 'la', '-o', {str(out)!r}, '--no-progress'])"
    )
    start = time.perf_counter()
    subprocess.run([python, "-c", code], check=False, capture_output=True)
    return time.perf_counter() - start


def _bare_inputs(folder: Path) -> tuple[Path, Path]:
    """Facade 3's model file and its LP's matrices (what the bare script reads)."""
    from masonryfw_la import assembly

    model = mf.checked_model(mf.open_model("facade-3"))
    wall = assembly.Wall.from_model(model)
    scales = assembly.model_scales(model, wall)
    lp = assembly.assemble(wall, scales, assembly.interface_kinematics(wall, scales))
    G = lp.constraints.tocsr()
    np.savez(folder / "lp.npz", data=G.data, indices=G.indices, indptr=G.indptr, shape=np.array(G.shape),
             live=np.asarray(lp.live, dtype=float), cost=np.asarray(lp.cost, dtype=float))
    mf.save(model, folder / "facade-3.nc")
    return folder / "facade-3.nc", folder / "lp.npz"


def _time_bare(model: Path, lp: Path, out: Path) -> tuple[float, float]:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", BARE, str(model), str(lp), str(out)], check=True,
                          capture_output=True, text=True)
    return time.perf_counter() - start, float(done.stdout.split()[0])


def _row(label: str, times: list[float]) -> str:
    return f"| {label} | {statistics.median(times):.2f} | {min(times):.2f} | {max(times):.2f} |"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--vs", help="another Python with masonryfw installed, timed in alternation (no dask)")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    rows, paired = [], ""
    with tempfile.TemporaryDirectory() as tmp:
        for label, prelude in (("`pip install .` (no dask)", BLOCK_DASK), ("dask installed", "")):
            times = [_time(sys.executable, prelude, Path(tmp) / f"f3-{i}.nc") for i in range(RUNS)]
            rows.append(_row(label, times))
        model, lp = _bare_inputs(Path(tmp))
        bare = [(_time(sys.executable, BLOCK_DASK, Path(tmp) / "c.nc"), *_time_bare(model, lp, Path(tmp) / "x.npy"))
                for _ in range(RUNS)]
        ratios = [cli / script for cli, script, _ in bare]
        with mf.open_dataset(Path(tmp) / "c.nc") as result:
            alpha = float(result.collapse_multiplier)
        floor = (
            f"\n\nAgainst the bare script (module docstring: xarray reads the model file, Clarabel solves the same "
            f"LP), {RUNS} alternating pairs, no dask: the CLI {statistics.median([c for c, _, _ in bare]):.2f} s, "
            f"the script {statistics.median([b for _, b, _ in bare]):.2f} s (medians); ratio CLI/script pair by pair: "
            f"median {statistics.median(ratios):.3f} (min {min(ratios):.3f}, max {max(ratios):.3f}). "
            f"Alpha: the CLI {alpha:.9f}, the script {bare[-1][2]:.9f}."
        )
        if args.vs:
            pairs = [(_time(sys.executable, BLOCK_DASK, Path(tmp) / "a.nc"), _time(args.vs, BLOCK_DASK, Path(tmp) / "b.nc"))
                     for _ in range(RUNS)]
            ratios = [a / b for a, b in pairs]
            paired = (
                f"\n\nAgainst the installation at `{args.vs}` (no dask), {RUNS} alternating pairs: this one "
                f"{statistics.median([a for a, _ in pairs]):.2f} s, that one {statistics.median([b for _, b in pairs]):.2f} s "
                f"(medians); ratio this/that pair by pair: median {statistics.median(ratios):.3f} "
                f"(min {min(ratios):.3f}, max {max(ratios):.3f})."
            )
    body = (
        "`masonryfw solve facade-3 --plugin la` (482 blocks: build from the bundled spec, check, "
        "LP, the core's derived fields, compressed netCDF write), process start to exit, "
        f"{RUNS} runs, load average {load:.2f} at the start. Target: <= the bare script below.\n\n"
        "| environment | median [s] | min [s] | max [s] |\n|---|---:|---:|---:|\n" + "\n".join(rows) + floor + paired +
        "\n\nWith dask installed, xarray imports `dask.array` when it builds variables (about 1 s); "
        "the sweep extra is the only part of masonryfw that needs dask."
    )
    write_section("cli", "End to end: one LA solve from the command line", body)


if __name__ == "__main__":
    main()
