"""End to end: ``masonryfw solve facade-3 --plugin la`` as a user runs it (process start to file written).

Measured twice: as after ``pip install .`` (dask absent), and with dask importable
(``pip install ".[sweep]"``), because xarray imports ``dask.array`` to recognise
array types whenever dask is installed.

``python bench_cli.py --vs /path/to/other/python`` also times another installation (an
earlier version, say) in alternating runs, A B A B ..., and reports the ratio pair by pair:
pairing keeps the ratio meaningful when the machine's speed drifts.
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
from _report import write_section  # noqa: E402

RUNS = 10
BLOCK_DASK = "import sys; sys.modules['dask'] = None; "


def _time(python: str, prelude: str, out: Path) -> float:
    code = prelude + (
        "from masonryfw.cli import main; "
        f"main(['solve', 'facade-3', '--plugin', 'la', '-o', {str(out)!r}, '--no-progress'])"
    )
    start = time.perf_counter()
    subprocess.run([python, "-c", code], check=False, capture_output=True)
    return time.perf_counter() - start


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
        f"{RUNS} runs, load average {load:.2f} at the start. Target: < 1.5 s.\n\n"
        "| environment | median [s] | min [s] | max [s] |\n|---|---:|---:|---:|\n" + "\n".join(rows) + paired +
        "\n\nWith dask installed, xarray imports `dask.array` when it builds variables (about 1 s); "
        "the sweep extra is the only part of masonryfw that needs dask."
    )
    write_section("cli", "End to end: one LA solve from the command line", body)


if __name__ == "__main__":
    main()
