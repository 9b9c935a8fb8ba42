"""The worked study of docs/settlements.md: Facade 1 over a greenfield trough, la, fdem and jmm, and the
convergence of the damage with the support segments.

Facade 1 (bundled case ``facade-1``) loses its two support ranges for a Gaussian
trough (i = 0.25 m, the default segments of a quarter unit, cutoff 0.05). Three
dask sweeps, each point one solve, results in a store (a re-run only redraws):

- fdem over the trough axis x0 (0.75 m: under the middle pier, sagging; 1.5 m:
  under the right end, hogging; and between) and S_max (2, 5, 10, 20 mm), run to
  S_max (``plateau_tolerance=0``): the widest crack and its damage category;
- la over x0 (0.30 .. 1.50 m every 0.05 m): alpha and the collapse reaction;
- jmm over the same x0 as fdem, to its reaction plateau.

Then the two fdem runs at 20 mm for the sagging and the hogging axis are drawn, and
a fourth sweep runs fdem at the sagging and the hogging axis with segments of 2, 1,
1/2, 1/4, 1/8, 1/16 and 1/32 unit lengths (the convergence table), and the two-storey facade of
``docs/scripts/two-storey-facade.toml`` (8 m x 6 m, i = 7.5 m, axis 2 m beyond its right end, S_max = 15
mm) at three segment lengths.

    python docs/scripts/settlements_study.py [--workers N] [--store DIR]

Writes docs/img/settlements/*.png and prints the tables of the doc.
"""
from __future__ import annotations

from pathlib import Path

from _studies import arguments, run_plan, values
from matplotlib.figure import Figure

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_sweep import dask_client, plan_sweep

ROOT = Path(__file__).resolve().parents[2]
IMAGES = ROOT / "docs" / "img" / "settlements"
TROUGH = {"profile": "gaussian", "center": 0.75, "width": 0.25, "cutoff": 0.05}
UNIT = 0.1  # Facade 1's unit length [m]
SEGMENTS = (2.0, 1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125)  # unit lengths
AXES = (0.75, 1.0, 1.25, 1.5)
S_MAX = (0.002, 0.005, 0.01, 0.02)


def trough_spec() -> dict:
    spec = mf.load_spec(mf.bundled_spec_path("facade-1"))
    del spec["supports"]
    return {**spec, "title": "Facade 1 over a trough", "settlement": dict(TROUGH)}


def sweep(client, store: Path, solver: str, params: list[str], options: dict):
    return run_plan(client, store, solver, plan_sweep(trough_spec(), solver, params, options))


def reaction_minimum(store: Path, fdem, x0: float) -> float:
    """fdem's smallest settlement reaction in its settlement phase, at S_max = 20 mm."""
    result = mf.open_dataset(store / str(fdem.sel(settlement_center=x0, option_settlement=S_MAX[-1]).result_path.values))
    return float(result.step_reaction.values[result.step_phase.values == 1].min())


def reaction_last(store: Path, jmm, x0: float) -> float:
    """jmm's settlement reaction at its last step (its reaction plateau)."""
    return float(mf.open_dataset(store / str(jmm.sel(settlement_center=x0).result_path.values)).step_reaction[-1])


def draw_damage(fdem, path: Path) -> None:
    """Damage category and widest crack against S_max, one line per trough axis."""
    figure = Figure(figsize=(7.5, 5.0), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True, height_ratios=(1.2, 1))
    names = mfp.flags("step_damage_category")
    for k, x0 in enumerate(AXES):
        row = fdem.sel(settlement_center=x0)
        s = 1e3 * row.option_settlement.values
        top.plot(s, row.damage_category.values + 0.06 * (k - 1.5), "o-", ms=4, label=f"x0 = {x0:g} m")
        bottom.plot(s, 1e3 * row.crack_width.values, "o-", ms=4)
    top.set_yticks(list(names.values()), [f"{v} {n.replace('_', ' ')}" for n, v in names.items()], fontsize=8)
    top.set_ylim(-0.4, 5.4)
    top.set_title("Facade 1 over a trough (i = 0.25 m): fdem, damage after Burland et al. (1977)", fontsize=10)
    top.legend(title="trough axis", fontsize=8, ncol=2)
    top.grid(alpha=0.3)
    bottom.set_yscale("log")
    for limit in mf.DAMAGE_LIMITS:
        bottom.axhline(1e3 * limit, color="0.75", lw=0.8, zorder=0)
    bottom.set_ylabel("widest crack [mm]")
    bottom.set_xlabel("S_max, the settlement over the trough axis [mm]")
    bottom.grid(alpha=0.3, which="both")
    figure.savefig(path, dpi=130)


def draw_reactions(la, fdem_minimum: dict, jmm_last: dict, path: Path) -> None:
    """la's collapse reaction, fdem's smallest and jmm's plateau reaction against the trough axis (all
    settlement reactions, ``mf.settlement_reaction``)."""
    figure = Figure(figsize=(7.5, 4.2), layout="constrained")
    ax = figure.subplots()
    x = la.settlement_center.values
    ax.plot(x, la.collapse_reaction.values, "o-", ms=3, label="la: (1 - alpha) R0 at collapse")
    ax.plot(x, la.collapse_reaction.values / (1 - la.alpha.values), "k:", lw=1, label="R0: dead reaction (la)")
    ax.plot(list(fdem_minimum), list(fdem_minimum.values()), "s", ms=6, label="fdem: smallest reaction to 20 mm")
    ax.plot(list(jmm_last), list(jmm_last.values()), "^", ms=6, label="jmm: reaction at its plateau stop")
    ax.set_xlabel("trough axis x0 [m]")
    ax.set_ylabel("settlement reaction [N]")
    ax.set_title("Facade 1 over a trough (i = 0.25 m): the reaction the settling ground keeps", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    figure.savefig(path, dpi=130)


def draw_cases(store: Path) -> None:
    """The fdem runs at S_max = 20 mm under the middle (sagging) and at the end (hogging), as mechanisms."""
    for name, x0 in (("sagging", 0.75), ("hogging", 1.5)):
        spec = trough_spec()
        spec["settlement"]["center"] = x0
        result = mf.solve(mf.build(spec), "fdem", {"settlement": 0.02, "plateau_tolerance": 0.0})
        result.attrs["title"] = f"Facade 1, trough axis x0 = {x0:g} m ({name}), S_max = 20 mm"
        mf.save(result, store / f"fdem-{name}.nc", command="docs/scripts/settlements_study.py")
        mf.save_figure(mf.render([result], "mechanism"), IMAGES / f"facade-1-{name}.png", dpi=130)
        mf.save_figure(mf.render([result], "history", {"quantity": "damage"}),
                       IMAGES / f"facade-1-{name}-damage.png", dpi=130)
        print(f"{name}: " + ", ".join(map(str, mf.key_numbers(result))))


def table(fdem, fdem_minimum: dict, jmm_last: dict, la) -> str:
    lines = ["| x0 [m] | la alpha | la (1 - alpha) R0 [N] | fdem smallest reaction [N] | "
             "jmm reaction at its stop [N] | "
             + " | ".join(f"fdem {1e3 * s:g} mm: crack [mm] / cat." for s in S_MAX) + " |",
             "|---:|---:|---:|---:|---:|" + "---:|" * len(S_MAX)]
    for x0 in AXES:
        row = fdem.sel(settlement_center=x0)
        l_row = la.sel(settlement_center=x0, method="nearest")
        cells = [f"{1e3 * w:.2f} / {int(c)}" for w, c in zip(row.crack_width.values, row.damage_category.values)]
        lines.append(f"| {x0:g} | {float(l_row.alpha):.4f} | {float(l_row.collapse_reaction):.1f} | "
                     f"{fdem_minimum[x0]:.1f} | {jmm_last[x0]:.1f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def segment_table(client, store: Path) -> str:
    """fdem at 20 mm over the sagging and the hogging axis against the segment length: the widest crack,
    where it is, its category, R0 and the smallest reaction."""
    plan = plan_sweep(trough_spec(), "fdem", [f"settlement.center={values(AXES[::3])}",
                                              f"settlement.segment={values(UNIT * u for u in SEGMENTS)}"],
                      {"plateau_tolerance": 0.0, "settlement": S_MAX[-1]})
    result = run_plan(client, store, "segments", plan)
    lines = ["| trough | segment [units] | widest crack [mm] | off the finest | at (x, y) [m] | category | "
             "base gap [mm] | R0 [N] | smallest reaction [N] |", "|---|---:|---:|---:|---|---:|---:|---:|---:|"]
    for x0, name in zip(AXES[::3], ("sagging", "hogging")):
        finest = float(result.sel(settlement_center=x0).crack_width.values[-1])
        for units in SEGMENTS:
            row = result.sel(settlement_center=x0, settlement_segment=UNIT * units, method="nearest")
            width = float(row.crack_width)
            lines.append(f"| {name} (x0 = {x0:g} m) | {units:g} | {1e3 * width:.3f} | {width / finest - 1:+.1%} | "
                         f"({float(row.crack_x):.3g}, {float(row.crack_y):.3g}) | {int(row.damage_category)} | "
                         f"{1e3 * float(row.base_gap):.3f} | {float(row.dead_reaction):.1f} | "
                         f"{float(row.minimum_reaction):.1f} |")
    return "\n".join(lines)


def facade_table() -> str:
    """The two-storey facade of the report that asked for a continuous ground, at three segment lengths."""
    lines = ["| segment [m] | widest crack [mm] | at (x, y) [m], settlement [mm] | category | base gap [mm] | "
             "R0 [kN] | smallest reaction [kN] | fdem wall time [s] |", "|---:|---:|---|---:|---:|---:|---:|---:|"]
    for segment in (0.25, 0.125, 0.0625):
        spec = mf.load_spec(ROOT / "docs" / "scripts" / "two-storey-facade.toml")
        spec["settlement"]["segment"] = segment
        result = mf.solve(mf.build(spec), "fdem", {"settlement": 0.015, "plateau_tolerance": 0.0})
        n = {k.name: k.value for k in mf.key_numbers(result)}
        lines.append(f"| {segment:g} | {1e3 * n['crack_width']:.3f} | ({n['crack_x']:.3g}, {n['crack_y']:.3g}), "
                     f"{1e3 * n['crack_settlement']:.1f} | {int(n['damage_category'])} | {1e3 * n['base_gap']:.3f} | "
                     f"{n['dead_reaction'] / 1e3:.2f} | {n['minimum_reaction'] / 1e3:.2f} | "
                     f"{float(result.attrs['wall_time_s']):.1f} |")
    return "\n".join(lines)


def main() -> None:
    args = arguments(__doc__.splitlines()[0], ROOT / "build" / "sweeps" / "settlements")
    IMAGES.mkdir(parents=True, exist_ok=True)
    with dask_client(workers=args.workers) as client:
        fdem = sweep(client, args.store, "fdem", [f"settlement.center={values(AXES)}",
                                                  f"option.settlement={values(S_MAX)}"],
                     {"plateau_tolerance": 0.0})
        la = sweep(client, args.store, "la", ["settlement.center=0.3:1.5:0.05"], {})
        jmm = sweep(client, args.store, "jmm", [f"settlement.center={values(AXES)}"], {})
        segments = segment_table(client, args.store)
    mf.save_figure(mf.render([mf.build(mf.bundled_spec_path("facade-1-trough"))], "model"),
                   IMAGES / "facade-1-trough-model.png", dpi=130)
    draw_damage(fdem, IMAGES / "facade-1-damage-vs-smax.png")
    fdem_minimum = {x0: reaction_minimum(args.store, fdem, x0) for x0 in AXES}
    jmm_last = {x0: reaction_last(args.store, jmm, x0) for x0 in AXES}
    draw_reactions(la, fdem_minimum, jmm_last, IMAGES / "facade-1-reactions-vs-axis.png")
    draw_cases(args.store)
    print(table(fdem, fdem_minimum, jmm_last, la))
    jmm_widths = ", ".join(f"{x0:g} m: {1e3 * float(w):.4f} mm at {1e3 * float(s):.3f} mm"
                           for x0, w, s in zip(jmm.settlement_center.values, jmm.crack_width.values,
                                               jmm.final_settlement.values))
    print(f"jmm widest crack at its plateau stop: {jmm_widths}")
    print(segments)
    print(facade_table())
    print(f"wrote {IMAGES.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
