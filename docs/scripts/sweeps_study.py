"""The worked study of docs/sweeps.md: Facade 1's collapse multiplier against the settling zone.

Facade 1 (bundled case ``facade-1``) is put on three supports: fixed, settling,
fixed. The settling zone of length L starts at x = a; one sweep point per
(a, L), a in 0.10 .. 1.40 - L m (step 0.05 m, so both fixed supports keep at
least 0.1 m), L in 0.2, 0.3, 0.4, 0.5 m. The four support ends move together,
so the sweep is a ``--zip`` over four keys. Every point is an LA solve (clarabel backend)
on a local dask cluster; results go to a store, so a re-run only redraws.

    python docs/scripts/sweeps_study.py [--workers N] [--store DIR]

Writes docs/img/sweeps/facade-1-settling-zone.png and prints the table of the doc.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import masonryfw as mf
from masonryfw_sweep import dask_client, failed_points, plan_sweep, run_sweep

ROOT = Path(__file__).resolve().parents[2]
IMAGE = ROOT / "docs" / "img" / "sweeps" / "facade-1-settling-zone.png"
LENGTHS = (0.2, 0.3, 0.4, 0.5)
STEP = 0.05
MARGIN = 0.1  # shortest fixed support at either end [m]


def three_supports(spec: dict) -> dict:
    """``spec`` with its supports replaced by fixed | settling | fixed (positions set by the sweep)."""
    width = spec["wall"]["width"]
    return {
        **spec,
        "supports": {
            "left": {"kind": "fixed", "start": 0.0, "end": 0.5},
            "settling": {"kind": "moving", "start": 0.5, "end": 0.8, "motion": "translation"},
            "right": {"kind": "fixed", "start": 0.8, "end": width},
        },
    }


def zone_params(width: float) -> list[str]:
    """The four zipped ``--param`` of every (start a, length L) with both fixed supports >= MARGIN."""
    starts, ends = [], []
    for length in LENGTHS:
        count = int(round((width - 2 * MARGIN - length) / STEP)) + 1
        a = np.round(MARGIN + STEP * np.arange(count), 10)
        starts += a.tolist()
        ends += np.round(a + length, 10).tolist()
    as_list = lambda values: ",".join(f"{v:g}" for v in values)  # noqa: E731
    return [f"supports.left.end={as_list(starts)}", f"supports.settling.start={as_list(starts)}",
            f"supports.settling.end={as_list(ends)}", f"supports.right.start={as_list(ends)}"]


def draw(sweep, spec: dict, path: Path) -> None:
    start = sweep.supports_settling_start.values
    length = np.round(sweep.supports_settling_end.values - start, 10)
    alpha = sweep.alpha.values
    figure = Figure(figsize=(7.5, 5.2), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, height_ratios=(3, 1.3))
    for value in LENGTHS:
        rows = np.isclose(length, value)
        centre = start[rows] + value / 2
        top.plot(centre, alpha[rows], "o-", ms=3.5, label=f"L = {value:g} m")
        bottom.plot(centre, sweep.macro_blocks.values[rows], "o-", ms=3)
    for opening in spec.get("openings", []):
        for axes in (top, bottom):
            axes.axvspan(opening["x"], opening["x"] + opening["width"], color="0.9", zorder=0)
    top.set_ylabel("collapse multiplier $\\alpha$")
    top.set_title("Facade 1 on fixed | settling | fixed supports: LA (clarabel)\n"
                  "grey: door and window columns")
    top.legend(title="settling zone length", fontsize=8)
    top.grid(alpha=0.3)
    bottom.set_ylabel("macro-blocks")
    bottom.set_xlabel("centre of the settling zone x [m]")
    bottom.grid(alpha=0.3)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=130)


def table(sweep) -> str:
    """Markdown: per length, the smallest and largest alpha and where the zone sits."""
    start = sweep.supports_settling_start.values
    length = np.round(sweep.supports_settling_end.values - start, 10)
    alpha = sweep.alpha.values
    lines = ["| L [m] | points | min alpha | zone at min [m] | max alpha | zone at max [m] |", "|---:|---:|---:|---|---:|---|"]
    for value in LENGTHS:
        rows = np.flatnonzero(np.isclose(length, value) & np.isfinite(alpha))
        low, high = rows[np.argmin(alpha[rows])], rows[np.argmax(alpha[rows])]
        lines.append(f"| {value:g} | {rows.size} | {alpha[low]:.4f} | {start[low]:.2f}..{start[low] + value:.2f} "
                     f"| {alpha[high]:.4f} | {start[high]:.2f}..{start[high] + value:.2f} |")
    return "\n".join(lines)


def mirror_gap(sweep, width: float) -> float:
    """Largest difference of alpha between a zone a..a+L and its mirror image width-a-L..width-a."""
    start = np.round(sweep.supports_settling_start.values, 10)
    end = np.round(sweep.supports_settling_end.values, 10)
    alpha = dict(zip(zip(start, end), sweep.alpha.values))
    gaps = [abs(value - alpha[(np.round(width - e, 10), np.round(width - a, 10))])
            for (a, e), value in alpha.items() if np.isfinite(value)]
    return max(gaps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--store", type=Path, default=ROOT / "build" / "sweeps" / "facade-1.store")
    args = parser.parse_args()
    spec = three_supports(mf.load_spec(mf.bundled_spec_path("facade-1")))
    plan = plan_sweep(spec, "la", zone_params(spec["wall"]["width"]), {"solver": "clarabel"}, zipped=True)
    args.store.mkdir(parents=True, exist_ok=True)
    with dask_client(workers=args.workers) as client:
        sweep = run_sweep(plan, client, args.store, args.store.parent)
    mf.save(sweep, args.store.parent / "facade-1-settling-zone.nc", command="docs/scripts/sweeps_study.py")
    draw(sweep, spec, IMAGE)
    print(f"{sweep.status.size} points, {int((sweep.status == 0).sum())} solved, "
          f"{int(sweep.from_store.sum())} from the store; wall time of the solves "
          f"{float(sweep.wall_time_s.sum()):.1f} s")
    for where, message in failed_points(sweep):
        print(f"failed: {where}: {message}")
    print(table(sweep))
    print(f"mirror check (Facade 1 is symmetric about x = 0.75 m): max |alpha(zone) - alpha(mirrored zone)| = "
          f"{mirror_gap(sweep, spec['wall']['width']):.2e}")
    print(f"wrote {IMAGE.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
