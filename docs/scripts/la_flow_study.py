"""The numbers of docs/la.md, section "Non-associative friction": la with both flow rules against fdem.

- the ten bundled walls: alpha associative and non-associative, LPs, time; the reaction at
  collapse ``(1 - alpha) R0`` beside fdem's smallest reaction over R0 (docs/fdem.md's table,
  regenerated here for Test 8C and Test 12C);
- Test 8C and Test 12C: fdem at its defaults, and the crack-pattern scores of each la result
  against it (the compare plugin);
- Ferris & Tin-Loi's wall 1 (tilting, mu = 0.65): la both ways against fdem's load-factor search.

    python docs/scripts/la_flow_study.py
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

ROLE = mfp.flags("block_role")


def ferris_tin_loi_wall():
    """Ferris & Tin-Loi (2001) wall 1 (as in tests/plugins/la/conftest.py): 6 courses of 0.4 x 0.175 m units
    in running bond, 2.0 x 1.05 m on a fixed base, mu = 0.65, horizontal live load = weight."""
    rects = [(-0.2, -0.175, 2.2, 0.0)]
    for course in range(6):
        first = 0.2 if course % 2 == 0 else 0.4
        cuts = np.r_[0.0, np.arange(first, 2.0 - 1e-9, 0.4), 2.0]
        y = course * 0.175
        rects += [(a, y, b, y + 0.175) for a, b in zip(cuts[:-1], cuts[1:])]
    roles = [ROLE["fixed_support"]] + [ROLE["unit"]] * (len(rects) - 1)
    return mt.rectangles_model(np.array(rects), roles, friction=0.65, loading="tilt")


def timed(model, options):
    start = time.perf_counter()
    result = mf.solve(model, "la", options)
    return result, time.perf_counter() - start


def walls_table() -> dict:
    print("| wall | alpha assoc. | alpha non-assoc. | LPs | 1 - alpha assoc. | 1 - alpha non-assoc. | time assoc. [s] | time non-assoc. [s] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    results = {}
    for case in mf.CASE_NAMES:
        model = mf.open_model(case)
        assoc, t_a = timed(model, {})
        non, t_n = timed(model, {"flow": "nonassociative"})
        a, n = float(assoc.collapse_multiplier), float(non.collapse_multiplier)
        results[case] = (assoc, non)
        print(f"| {case} | {a:.4f} | {n:.4f} | {non.attrs['la_flow_iterations']} | {1 - a:.3f} | {1 - n:.3f} "
              f"| {t_a:.2f} | {t_n:.2f} |")
    return results


def fdem_comparison(results: dict) -> None:
    print("\n| wall | fdem R min / R0 | fdem R end / R0 | la assoc.: F1 / ARI / cos | la non-assoc.: F1 / ARI / cos |")
    print("|---|---:|---:|---|---|")
    for case in ("test-8c", "test-12c"):
        fdem = mf.solve(mf.open_model(case), "fdem")
        numbers = {k.name: k.value for k in mf.key_numbers(fdem)}
        r0 = mf.dead_reaction(fdem)
        cells = []
        for la in results[case]:
            scores = mf.compare(la, fdem, "crack")
            cells.append(f"{float(scores.crack_f1):.2f} / {float(scores.macro_block_ari):.2f} / "
                         f"{float(scores.mechanism_cosine):.2f}")
        print(f"| {case} | {numbers['minimum_reaction'] / r0:.3f} | "
              f"{float(fdem.step_reaction.values[-1]) / r0:.3f} | {cells[0]} | {cells[1]} |")


def ferris_tin_loi() -> None:
    model = ferris_tin_loi_wall()
    assoc, _ = timed(model, {})
    non, _ = timed(model, {"flow": "nonassociative"})
    fdem = mf.solve(model, "fdem")
    print(f"\nFerris & Tin-Loi wall 1: la associative {float(assoc.collapse_multiplier):.4f} (published 0.643), "
          f"non-associative {float(non.collapse_multiplier):.4f} ({non.attrs['la_flow_iterations']} LPs), "
          f"fdem load-factor search: stable {float(fdem.collapse_multiplier):.4f}, "
          f"unstable {fdem.attrs['fdem_unstable_load_factor']:.4f}")


def main() -> None:
    results = walls_table()
    fdem_comparison(results)
    ferris_tin_loi()


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
