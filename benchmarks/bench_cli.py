"""End to end: ``masonryfw solve facade-3 --plugin la`` as a user runs it (process start to file written).

Measured twice: as after ``pip install .`` (dask absent), and with dask importable
(``pip install ".[sweep]"``), because xarray imports ``dask.array`` to recognise
array types whenever dask is installed.
"""
from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import write_section  # noqa: E402

RUNS = 5
BLOCK_DASK = "import sys; sys.modules['dask'] = None; "


def _time(prelude: str, out: Path) -> float:
    code = prelude + (
        "from masonryfw.cli import main; "
        f"main(['solve', 'facade-3', '--plugin', 'la', '-o', {str(out)!r}, '--no-progress'])"
    )
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=False, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, prelude in (("`pip install .` (no dask)", BLOCK_DASK), ("dask installed", "")):
            times = [_time(prelude, Path(tmp) / f"f3-{i}.nc") for i in range(RUNS)]
            rows.append(f"| {label} | {statistics.median(times):.2f} | {min(times):.2f} | {max(times):.2f} |")
    body = (
        "`masonryfw solve facade-3 --plugin la` (482 blocks: build from the bundled spec, check, "
        "LP, check of the result, compressed netCDF write), process start to exit, "
        f"{RUNS} runs. Target: < 1.5 s.\n\n"
        "| environment | median [s] | min [s] | max [s] |\n|---|---:|---:|---:|\n" + "\n".join(rows) +
        "\n\nWith dask installed, xarray imports `dask.array` when it builds variables (about 1 s); "
        "the sweep extra is the only part of masonryfw that needs dask."
    )
    write_section("cli", "End to end: one LA solve from the command line", body)


if __name__ == "__main__":
    main()
