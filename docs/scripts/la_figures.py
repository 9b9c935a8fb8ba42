"""Draw the collapse mechanisms of the bundled walls (docs/img/la/<case>.png).

Deformed blocks coloured by macro-block, cracked joints heavy. Run from the
project root: ``python docs/scripts/la_figures.py [--solver clarabel] [case ...]``.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402

import masonryfw as mf  # noqa: E402

OUT = Path(__file__).resolve().parents[1] / "img" / "la"
DISPLAY_SHIFT = 0.06  # largest drawn block displacement, as a fraction of the wall size


def deformed_polygons(result, scale: float) -> list[np.ndarray]:
    """Block polygons moved rigidly by ``scale`` times the mechanism."""
    counts = result.block_node_count.values
    start = mf.block_offsets(counts)
    x, y = result.node_x.values, result.node_y.values
    u = mf.block_motion(result) * scale
    cx, cy = result.block_centroid_x.values, result.block_centroid_y.values
    owner = mf.node_block(counts)
    dx = u[owner, 0] - u[owner, 2] * (y - cy[owner])
    dy = u[owner, 1] + u[owner, 2] * (x - cx[owner])
    return [np.c_[x[a:b] + dx[a:b], y[a:b] + dy[a:b]] for a, b in zip(start[:-1], start[1:])]


def joint_segments(result, scale: float, cracked: np.ndarray) -> np.ndarray:
    """Cracked joints drawn on the side-0 block's deformed position, shape (k, 2, 2)."""
    side0 = result.interface_blocks.values[cracked, 0]
    u = mf.block_motion(result)[side0] * scale
    cx, cy = result.block_centroid_x.values[side0], result.block_centroid_y.values[side0]
    px, py = result.interface_x.values[cracked], result.interface_y.values[cracked]
    dx = u[:, :1] - u[:, 2:3] * (py - cy[:, None])
    dy = u[:, 1:2] + u[:, 2:3] * (px - cx[:, None])
    return np.stack([px + dx, py + dy], axis=-1)


def draw(result, ax) -> None:
    """One mechanism on ``ax``."""
    size = mf.model_scale(result.node_x.values, result.node_y.values)
    translation = np.hypot(*mf.block_motion(result)[:, :2].T).max()
    scale = DISPLAY_SHIFT * size / translation if translation > 0 else 0.0
    polys = deformed_polygons(result, scale)
    macro = result.macro_block.values
    cmap = plt.get_cmap("tab20")
    role = result.block_role.values
    support = np.isin(role, [mf.flags("block_role")[k] for k in ("fixed_support", "moving_support")])
    colours = np.where(support[:, None], (0.6, 0.6, 0.6, 1.0), cmap(macro % 20))
    ax.add_collection(PolyCollection(polys, facecolors=colours, edgecolors="k", linewidths=0.3))
    crack = result.crack_indicator.values
    cracked = np.flatnonzero(crack > 0)
    if cracked.size:
        segs = joint_segments(result, scale, cracked)
        ax.add_collection(LineCollection(segs, colors="crimson", linewidths=0.8 + 2.2 * crack[cracked]))
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(
        f"{result.attrs.get('title', '')}: alpha = {float(result.collapse_multiplier):.4f}, "
        f"{int(macro.max()) + 1} macro-blocks",
        fontsize=9,
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("cases", nargs="*", help="bundled case names (default: all)")
    parser.add_argument("--solver", default="clarabel")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for case in args.cases or list(mf.bundled_cases()):
        result = mf.solve(mf.open_model(case), "la", {"solver": args.solver})
        fig, ax = plt.subplots(figsize=(6, 4.5), dpi=120)
        draw(result, ax)
        fig.tight_layout()
        fig.savefig(args.out / f"{case}.png")
        plt.close(fig)
        print(args.out / f"{case}.png")


if __name__ == "__main__":
    main()
