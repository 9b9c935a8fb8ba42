"""Run fdem and la on the bundled walls; draw the figures and tables of docs/fdem.md.

Writes ``docs/img/fdem/<case>.png`` (la and fdem mechanisms side by side with the
compare plugin's scores), ``docs/img/fdem/<case>-history.png`` (reaction against
settlement, the la collapse reaction as a line), ``docs/img/fdem/agreement.md``
(the agreement table).
Run from the project root: ``python docs/scripts/fdem_figures.py [case ...]``.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import masonryfw as mf  # noqa: E402
import masonryfw.plugin_api as mfp

OUT = Path(__file__).resolve().parents[1] / "img" / "fdem"
PAPER_MACRO_BLOCKS = {"test-8c": "3", "test-12c": "2", "panel-1": "many", "panel-2": "3", "panel-3": "2",
                      "panel-4": "3 (FEM/DEM: 4)", "panel-5": "3", "facade-1": "2+", "facade-2": "3+",
                      "facade-3": "7"}


def masonry_macro_blocks(result) -> int:
    return int({number.name: number.value for number in mf.key_numbers(result)}["macro_blocks"])


def largest_share(result, count: int) -> float:
    masonry = mfp.masonry_blocks(result.block_role.values)
    sizes = np.sort(np.bincount(result.macro_block.values[masonry]))[::-1]
    return float(sizes[:count].sum() / masonry.sum())


def history_figure(fdem, la, path: Path) -> None:
    figure = Figure(figsize=(6, 3.6), layout="constrained")
    ax = figure.add_subplot()
    phase = fdem.step_phase.values == 1
    ax.plot(fdem.step_settlement.values[phase] * 1e3, fdem.step_reaction.values[phase], label="fdem")
    dead = mf.dead_reaction(fdem)
    alpha = la.collapse_multiplier.item()
    ax.axhline((1 - alpha) * dead, color="k", ls="--", lw=0.8, label=f"la: (1 - alpha) R0, alpha = {alpha:.3f}")
    ax.axhline(dead, color="0.5", ls=":", lw=0.8, label="R0 (dead reaction of the model)")
    ax.set_xlabel("settlement [mm]")
    ax.set_ylabel("reaction on the moving support [N]")
    ax.set_title(str(fdem.attrs.get("title", "")))
    ax.legend(fontsize="small")
    figure.savefig(path, dpi=110)


def run_case(case: str, options: dict) -> dict:
    model = mf.open_model(case)
    la = mf.solve(model, "la", {})
    clock = time.perf_counter()
    fdem = mf.solve(model, "fdem", options)
    seconds = time.perf_counter() - clock
    scores = mf.compare(la, fdem)
    mf.render([la, fdem], "compare").savefig(OUT / f"{case}.png", dpi=100)
    history_figure(fdem, la, OUT / f"{case}-history.png")
    dead = mf.dead_reaction(model)
    settlement = fdem.step_settlement.values
    phase = fdem.step_phase.values == 1
    return {
        "case": case,
        "blocks": int(mfp.masonry_blocks(model.block_role.values).sum()),
        "time_s": seconds,
        "steps": int(fdem.attrs["fdem_steps"]),
        "stop": fdem.attrs["stop_reason"],
        "settlement_mm": 1e3 * float(settlement.max()),
        "r0_fdem": float(fdem.step_reaction.values[~phase][-1] / dead),
        "reaction_min_fdem": float(fdem.step_reaction.values[phase].min() / dead),
        "reaction_end_fdem": float(fdem.step_reaction.values[-1] / dead),
        "reaction_ratio_la": 1 - la.collapse_multiplier.item(),
        "macro_fdem": masonry_macro_blocks(fdem),
        "macro_la": masonry_macro_blocks(la),
        "macro_paper": PAPER_MACRO_BLOCKS.get(case, "?"),
        "top2_fdem": largest_share(fdem, 2), "top3_fdem": largest_share(fdem, 3),
        "top2_la": largest_share(la, 2), "top3_la": largest_share(la, 3),
        "crack_f1": scores.crack_f1.item(),
        "macro_block_ari": scores.macro_block_ari.item(),
        "mechanism_cosine": scores.mechanism_cosine.item(),
        "energy_error": float(np.abs(fdem.step_energy_error.values).max()),
    }


def table(rows: list[dict]) -> str:
    head = ("| case | units | time [s] | steps | stop | settlement [mm] | R0 fdem / R0 | R min / R0 | R end / R0 | "
            "1 - alpha (la) | macro-blocks fdem / la / paper | 2 largest hold (fdem / la) | crack F1 | ARI | "
            "mechanism cos | max energy error |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    body = "".join(
        f"| {r['case']} | {r['blocks']} | {r['time_s']:.1f} | {r['steps']} | {r['stop']} | {r['settlement_mm']:.2f} | "
        f"{r['r0_fdem']:.3f} | {r['reaction_min_fdem']:.3f} | {r['reaction_end_fdem']:.3f} | "
        f"{r['reaction_ratio_la']:.3f} | {r['macro_fdem']} / {r['macro_la']} / {r['macro_paper']} | "
        f"{r['top2_fdem']:.0%} / {r['top2_la']:.0%} | {r['crack_f1']:.2f} | {r['macro_block_ari']:.2f} | "
        f"{r['mechanism_cosine']:.3f} | {r['energy_error']:.1e} |\n" for r in rows)
    return head + body


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("cases", nargs="*", default=mf.bundled_cases())
    parser.add_argument("--option", action="append", default=[], help="fdem option name=value")
    args = parser.parse_args()
    options = dict(item.split("=", 1) for item in args.option)
    rows = []
    for case in args.cases:
        rows.append(run_case(case, options))
        print(json.dumps(rows[-1]), flush=True)
    (OUT / "agreement.md").write_text(table(rows))
    print(table(rows))


if __name__ == "__main__":
    main()
