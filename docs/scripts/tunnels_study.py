"""The route study of docs/tunnels.md: the bundled facade over a tunnel whose axis and volume loss move.

The bundled ``tunnel-facade`` (8 m x 6 m, three windows a storey, a 6 m tunnel 15 m deep,
K = 0.5, i = 7.5 m) solved by fdem to each trough's S_max (the model's settlement_target,
the default) over a grid of the tunnel axis' position and the volume loss (dask sweeps,
results in a store: a re-run only redraws); the same facade without openings on half the
grid. Every result carries the engineers' stages 1 and 2 beside fdem's damage, so the
chart puts the LTSM category and fdem's side by side.

    python docs/scripts/tunnels_study.py [--workers N] [--store DIR]

Writes docs/img/tunnels/*.png and prints the tables of the doc.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from _studies import arguments, run_plan, values
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure

import masonryfw as mf
from masonryfw_sweep import dask_client, plan_sweep

ROOT = Path(__file__).resolve().parents[2]
IMAGES = ROOT / "docs" / "img" / "tunnels"
CENTERS = (-8.0, -4.0, 0.0, 4.0, 8.0, 12.0, 16.0)  # the tunnel axis [m]; the facade spans 0 .. 8 m
VOLUME_LOSSES = (0.5, 1.0, 2.0, 3.0)  # V_L [%]
PLAIN_LOSSES = (1.0, 3.0)
COLOURS = ("#1a9850", "#91cf60", "#fee08b", "#fc8d59", "#d73027", "#7f0000")


def facade(openings: bool = True) -> dict:
    spec = mf.load_spec(mf.bundled_spec_path("tunnel-facade"))
    if not openings:
        spec = {**{k: v for k, v in spec.items() if k != "openings"}, "title": "Plain facade over a tunnel"}
    return spec


def sweep(client, store: Path, name: str, spec: dict, losses) -> object:
    return run_plan(client, store, name, plan_sweep(spec, "fdem", [f"settlement.center={values(CENTERS)}",
                                                                   f"settlement.volume_loss={values(losses)}"], {}))


def draw_chart(result, path: Path, title: str) -> None:
    """The damage category against the tunnel axis and the volume loss: LTSM beside fdem."""
    figure = Figure(figsize=(9.0, 3.8), layout="constrained")
    axes = figure.subplots(1, 2, sharey=True)
    cmap, norm = ListedColormap(COLOURS), BoundaryNorm(np.arange(-0.5, 6.5), 6)
    x, y = result.settlement_center.values, result.settlement_volume_loss.values
    for ax, name, label in ((axes[0], "ltsm_category", "stage 2: LTSM (4 = severe to very severe)"),
                            (axes[1], "damage_category", "stage 3: fdem, widest crack")):
        grid = result[name].transpose("settlement_volume_loss", "settlement_center").values
        mesh = ax.pcolormesh(np.arange(x.size + 1) - 0.5, np.arange(y.size + 1) - 0.5, grid, cmap=cmap, norm=norm)
        for j in range(y.size):
            for i in range(x.size):
                ax.text(i, j, f"{int(grid[j, i])}", ha="center", va="center", fontsize=9)
        ax.set_xticks(range(x.size), [f"{v:g}" for v in x])
        ax.set_xlabel("tunnel axis x0 [m] (the facade: 0 .. 8 m)")
        ax.set_title(label, fontsize=10)
    axes[0].set_yticks(range(y.size), [f"{v:g}" for v in y])
    axes[0].set_ylabel("volume loss V_L [%]")
    bar = figure.colorbar(mesh, ax=axes, ticks=range(6), fraction=0.04)
    bar.set_label("damage category")
    figure.suptitle(title, fontsize=11)
    figure.savefig(path, dpi=130)


def table(result) -> str:
    lines = ["| x0 [m] | V_L [%] | S_max [mm] | stage 1 slope, settlement | LTSM strain [%] / cat. | "
             "fdem widest crack [mm] / cat. | where (x, y) [m] |", "|---:|---:|---:|---|---:|---:|---|"]
    for x0 in result.settlement_center.values:
        for loss in result.settlement_volume_loss.values:
            row = result.sel(settlement_center=x0, settlement_volume_loss=loss)
            screen = "screened out" if float(row.screened_out) else "assess"
            lines.append(f"| {x0:g} | {loss:g} | {1e3 * float(row.final_settlement):.1f} | 1/"
                         f"{1 / float(row.greenfield_slope):.0f}, {1e3 * float(row.greenfield_settlement):.1f} mm: "
                         f"{screen} | {100 * float(row.ltsm_strain):.3f} / {int(row.ltsm_category)} | "
                         f"{1e3 * float(row.crack_width):.2f} / {int(row.damage_category)} | "
                         f"({float(row.crack_x):.3g}, {float(row.crack_y):.3g}) |")
    return "\n".join(lines)


def main() -> None:
    args = arguments(__doc__.splitlines()[0], ROOT / "build" / "sweeps" / "tunnels")
    IMAGES.mkdir(parents=True, exist_ok=True)
    with dask_client(workers=args.workers) as client:
        route = sweep(client, args.store, "route", facade(), VOLUME_LOSSES)
        plain = sweep(client, args.store, "plain", facade(openings=False), PLAIN_LOSSES)
    draw_chart(route, IMAGES / "route-study.png", "Facade over a tunnel (i = 7.5 m): damage category by stage")
    draw_chart(plain, IMAGES / "route-study-plain.png", "The same facade without openings")
    model = mf.open_model("tunnel-facade")
    mf.save_figure(mf.render([model], "model"), IMAGES / "tunnel-facade-model.png", dpi=110)
    result = mf.solve(model, "fdem")
    mf.save(result, args.store / "tunnel-facade.fdem.nc", command="docs/scripts/tunnels_study.py")
    mf.save_figure(mf.render([result], "ltsm"), IMAGES / "tunnel-facade-ltsm.png", dpi=120)
    mf.save_figure(mf.render([result], "mechanism"), IMAGES / "tunnel-facade-mechanism.png", dpi=110)
    print(mf.stages_text(result))
    print(table(route))
    print(table(plain))
    print(f"wrote {IMAGES.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
