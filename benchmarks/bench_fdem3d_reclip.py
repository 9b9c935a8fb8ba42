"""What reusing a 3D face pair's clipped overlap (fdem's option ``reclip_ratio``) saves and changes.

A 3D step clips every face pair's two faces against each other (70 % of the pair pass on the bundled house,
measured with the kernels alone); a pair whose blocks have moved against each other by less than
``reclip_ratio`` of the smaller one's radius since its last clip keeps that overlap, its points carried by
block A. ``--reclip 0`` clips every pair every step (the kernel before the reuse).

Run: ``python benchmarks/bench_fdem3d_reclip.py MODEL [--reclip SHARE] [--option KEY=VALUE ...]`` solves one
model's 3D twin (a bundled wall's, or a 3D model itself: ``house-tunnel``, ``corner`` for the kit's corner
building, ``small-house`` for the building tests' house, ``house-5k`` for the bundled house in finer units, 5,430
blocks) and prints its key numbers and the estimate's seconds
(and steps) against the solve's: time it whole-process, A against B. ``--twins WALL,WALL`` solves each wall
in 2D and its twin under each ``--variant`` of the 3D options and prints the largest difference of their reaction
histories over R0, the minima, the widest cracks, the categories and the F1 of the cracked joints.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import command_line  # noqa: E402


def model_3d(name: str):
    """The kit's corner building, the building tests' small house, a bundled 3D model, or a bundled wall's twin."""
    if name == "corner":
        return mt.corner_building()
    if name == "house-5k":
        return mf.build(house_in_finer_units())
    if name == "small-house":
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "core"))
        from test_core_building import house_spec

        return mf.build(house_spec())
    model = mf.open_model(name)
    return model if mfp.space(model) == 3 else mf.checked_model(mfp.twin(model))


def house_in_finer_units(shorter: float = 2.5, lower: float = 2.0) -> dict:
    """``house-tunnel``'s spec in units ``shorter`` times shorter and ``lower`` times lower, its ground segments
    half as long: 5,430 blocks, 16,158 joints."""
    spec = dict(mf.load_spec(mf.bundled_spec_path("house-tunnel")))
    building = dict(spec["building"])
    unit = dict(building["unit"])
    building["unit"] = {**unit, "length": unit["length"] / shorter, "height": unit["height"] / lower}
    return {**spec, "building": building, "settlement": {**spec["settlement"],
                                                         "segment": spec["settlement"]["segment"] / 2}}


def settlement_records(result) -> tuple[np.ndarray, np.ndarray]:
    at = result.step_phase.values == 1
    return result.step_settlement.values[at], result.step_reaction.values[at]


def cracked_pairs(model, result) -> set[tuple[int, int]]:
    """The cracked joints by the block pair they join (a twin's interfaces are not the wall's)."""
    return {tuple(sorted(p)) for p in model.interface_blocks.values[mf.cracked_joints(result)].tolist()}


def twin_rows(walls: list[str], variants: list[dict]) -> list[str]:
    """Each wall in 2D and its twin under each variant (fdem options): the table's rows."""
    rows = ["| wall | 3D options | max diff / R0 | R min / R0 2D, 3D | crack [mm] 2D, 3D | category 2D, 3D | F1 | "
            "solve 3D [s] |", "|---|---|---|---|---|---|---|---|"]
    for name in walls:
        planar = mf.open_model(name)
        twin = mf.checked_model(mfp.twin(planar))
        flat = mf.solve(planar, "fdem")
        s2, r2 = settlement_records(flat)
        r0 = r2[0]
        for variant in variants:
            start = time.perf_counter()
            solid = mf.solve(twin, "fdem", variant)
            seconds = time.perf_counter() - start
            s3, r3 = settlement_records(solid)
            grid = np.linspace(0.0, min(s2[-1], s3[-1]), 200)
            diff = np.abs(np.interp(grid, s3, r3) - np.interp(grid, s2, r2)).max() / r0
            a, b = cracked_pairs(planar, flat), cracked_pairs(twin, solid)
            f1 = 2 * len(a & b) / (len(a) + len(b))
            rows.append(f"| {planar.attrs.get('title', name)} | {options_text(variant)} | {diff:.4f} | {r2.min() / r0:.4f}, "
                        f"{r3.min() / r0:.4f} | {1e3 * flat.step_crack_width_max.values[-1]:.2f}, "
                        f"{1e3 * solid.step_crack_width_max.values[-1]:.2f} | "
                        f"{int(flat.step_damage_category.values[-1])}, {int(solid.step_damage_category.values[-1])} "
                        f"| {f1:.2f} | {seconds:.1f} |")
            print(rows[-1], flush=True)
    return rows


def parsed_options(pairs: list[str]) -> dict:
    """``KEY=VALUE`` strings as fdem options, a number where the value reads as one."""
    def value(text: str):
        try:
            return float(text)
        except ValueError:
            return text

    return {key: value(text) for key, text in (pair.split("=", 1) for pair in pairs)}


def options_text(options: dict) -> str:
    return ", ".join(f"{key}={value}" for key, value in options.items()) or "defaults"


def main() -> None:
    parser = command_line(__doc__)
    parser.add_argument("model", nargs="?", default="corner")
    parser.add_argument("--reclip", type=float, default=None, help="fdem's reclip_ratio (default: the solver's)")
    parser.add_argument("--option", action="append", default=[], help="an fdem option KEY=VALUE")
    parser.add_argument("--twins", default="", help="walls whose 2D and 3D runs to compare, comma-separated")
    parser.add_argument("--variant", action="append", default=[],
                        help="the twins' 3D options, KEY=VALUE[;KEY=VALUE] (repeatable: one variant each; default: "
                             "reclip_ratio=0 and 1e-4)")
    args = parser.parse_args()
    if args.twins:
        variants = [parsed_options(v.split(";")) for v in args.variant] or [{"reclip_ratio": 0.0},
                                                                             {"reclip_ratio": 1e-4}]
        twin_rows(args.twins.split(","), variants)
        return
    options = parsed_options(args.option)
    if args.reclip is not None:
        options["reclip_ratio"] = args.reclip
    model = model_3d(args.model)
    guess = mf.estimate(model, "fdem", options)
    start = time.perf_counter()
    result = mf.solve(model, "fdem", options)
    print(f"solve {time.perf_counter() - start:.1f} s, {result.attrs['fdem_steps']} steps; the estimate "
          f"{guess.seconds:.1f} s ({guess.basis})" if guess else "no estimate")
    print(mf.headline_text(result))
    if "building_walls" in result.attrs:
        print(mf.walls_text(result))


if __name__ == "__main__":
    main()
