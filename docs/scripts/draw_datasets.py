"""Draw the bundled walls (``datasets/img/<name>.png``) and print the README table.

Run from anywhere: ``python docs/scripts/draw_datasets.py [--out DIR]``.
Blocks are outlined; lintels and supports are coloured; a moving support is
marked with an arrow along its settlement direction.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

import masonryfw  # noqa: E402
import masonryfw.plugin_api as mfp  # noqa: E402

FILL = {"unit": "#f3e3c8", "lintel": "#8c6d46", "fixed_support": "#9e9e9e", "moving_support": "#e0a020"}
WIDTH_PX = 600
MAX_HEIGHT_PX = 720
DPI = 100


def block_polygons(ds) -> list[np.ndarray]:
    """Vertex arrays of every block (ragged layout split at the block offsets)."""
    points = np.stack((ds.node_x.values, ds.node_y.values), axis=1)
    return np.split(points, mfp.block_offsets(ds.block_node_count.values)[1:-1])


def draw(ds, path: Path) -> None:
    roles = {value: name for name, value in mfp.ROLE.items()}
    role_names = [roles[int(r)] for r in ds.block_role.values]
    x, y = ds.node_x.values, ds.node_y.values
    span_x, span_y = np.ptp(x), np.ptp(y)
    margin = 0.06 * max(span_x, span_y)
    aspect = (span_y + 2 * margin) / (span_x + 2 * margin)
    width_px = min(WIDTH_PX, MAX_HEIGHT_PX / aspect)
    fig, ax = plt.subplots(figsize=(width_px / DPI, width_px / DPI * aspect), dpi=DPI)
    polygons = block_polygons(ds)
    ax.add_collection(PolyCollection(polygons, facecolors=[FILL[r] for r in role_names],
                                     edgecolors="#303030", linewidths=0.6))
    moving = np.flatnonzero(ds.block_role.values == mfp.ROLE["moving_support"])
    for block in moving:
        direction = ds.settlement_direction.values[block, :2]
        start = np.array([ds.block_centroid_x.values[block], polygons[block][:, 1].min()])
        arrow = 0.9 * margin * direction / np.linalg.norm(direction)
        ax.annotate("", xy=start + arrow, xytext=start,
                    arrowprops={"arrowstyle": "-|>", "color": "#b00000", "lw": 1.6})
    ax.set_xlim(x.min() - margin, x.max() + margin)
    ax.set_ylim(y.min() - margin, y.max() + margin)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(ds.attrs["title"], fontsize=10)
    fig.subplots_adjust(left=0, right=1, bottom=0, top=0.93)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def table_row(name: str, ds, paper_count: str) -> str:
    """One markdown row: case, size, blocks (paper / ours), openings, supports."""
    role = mfp.ROLE
    roles = ds.block_role.values
    masonry = int(np.sum(roles <= role["lintel"]))
    lintels = int(np.sum(roles == role["lintel"]))
    spec = masonryfw.load_spec(ds.attrs["source_spec"])
    scale = 1000.0 if spec.get("length_unit", "m") == "m" else 1.0
    wall = spec["wall"]
    size = f"{wall['width'] * scale:.0f} x {wall['height'] * scale:.0f} x {wall['thickness'] * scale:.0f}"
    openings = ", ".join(
        f"{o['width'] * scale:.0f}x{o['height'] * scale:.0f} @({o['x'] * scale:.0f}, {o['y'] * scale:.0f})"
        for o in spec.get("openings", [])
    ) or "none"
    supports = ", ".join(
        f"{s['kind']} {s['start'] * scale:.0f}-{s['end'] * scale:.0f}" for s in spec["supports"].values()
    )
    return (f"| [{ds.attrs['title']}](img/{name}.png) | {size} | {paper_count} | {masonry - lintels} + {lintels} = "
            f"{masonry} | {openings} | {supports} |")


PAPER_COUNTS = {"test-8c": "~48", "test-12c": "~72", "panel-1": "55", "panel-2": "55", "panel-3": "73",
                "panel-4": "73", "panel-5": "105", "facade-1": "320", "facade-2": "320", "facade-3": "480"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[2] / "datasets" / "img")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    print("| case | wall w x h x t [mm] | blocks, paper | units + lintels, ours | openings w x h @(x, y) [mm] "
          "| supports [mm] |")
    print("|---|---|---|---|---|---|")
    for name in masonryfw.bundled_cases():
        ds = masonryfw.build(masonryfw.bundled_spec_path(name))
        draw(ds, args.out / f"{name}.png")
        print(table_row(name, ds, PAPER_COUNTS[name]))


if __name__ == "__main__":
    main()
