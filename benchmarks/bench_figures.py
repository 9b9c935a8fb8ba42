"""Figures and reports against wall size: ``masonryfw plot`` and ``masonryfw report`` as a user runs them.

For walls of about 300, 1,000 and 3,000 units (bench_scale's running bond, the right 40 % of the
base settling), one la result each; then, in fresh processes (start to exit, import included),
the mechanism, forces and cracks plots as PNG and the report, ``RUNS`` times each, and the sizes
of the mechanism and forces drawings as PNG and as SVG (why the report embeds PNGs).
"""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import command_line, write_section  # noqa: E402
from _walls import scale_spec  # noqa: E402

import masonryfw as mf  # noqa: E402

SIZES = (300, 1000, 3000)
RUNS = 3
KINDS = ("mechanism", "forces", "cracks")


def _seconds(args: list[str], cwd: Path) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "masonryfw", *args], cwd=cwd, check=True, capture_output=True)
    return time.perf_counter() - start


def _median(args: list[str], cwd: Path) -> float:
    return statistics.median(_seconds(args, cwd) for _ in range(RUNS))


def main() -> None:
    load = os.getloadavg()[0]
    rows, sizes = [], []
    with tempfile.TemporaryDirectory() as folder:
        cwd = Path(folder)
        for units in SIZES:
            model = mf.build(scale_spec(units))
            blocks = model.sizes["block"]
            mf.save(mf.solve(model, "la"), cwd / f"w{units}.nc")
            times = [_median(["plot", f"w{units}.nc", "--kind", kind, "-o", f"{kind}{units}.png"], cwd)
                     for kind in KINDS]
            report = _median(["report", f"w{units}.nc", "-o", f"r{units}.html", "--no-progress"], cwd)
            rows.append(f"| {blocks:,} | " + " | ".join(f"{t:.2f}" for t in times) +
                        f" | {report:.2f} | {(cwd / f'r{units}.html').stat().st_size / 1e6:.2f} |")
            for kind in ("mechanism", "forces"):
                _seconds(["plot", f"w{units}.nc", "--kind", kind, "-o", f"{kind}{units}.svg"], cwd)
                png, svg = ((cwd / f"{kind}{units}{s}").stat().st_size / 1e3 for s in (".png", ".svg"))
                sizes.append(f"| {blocks:,} | {kind} | {png:.0f} | {svg:.0f} |")
            print(rows[-1], flush=True)
    body = (
        f"One la result per wall; every command a fresh process (start to exit), median of {RUNS}, load "
        f"average {load:.2f} at the start. The report holds the model, mechanism, cracks and forces "
        "figures of one result.\n\n"
        "| blocks | mechanism [s] | forces [s] | cracks [s] | report [s] | report [MB] |\n"
        "|---:|---:|---:|---:|---:|---:|\n" + "\n".join(rows) +
        "\n\nThe same drawings as PNG (100 dpi, the default) and as SVG:\n\n"
        "| blocks | kind | PNG [kB] | SVG [kB] |\n|---:|---|---:|---:|\n" + "\n".join(sizes)
    )
    write_section("figures", "Figures and reports against wall size", body)


if __name__ == "__main__":
    command_line(__doc__).parse_args()
    main()
