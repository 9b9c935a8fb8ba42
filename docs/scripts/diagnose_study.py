"""The studies of docs/diagnose.md: forward then inverse, on walls the method was not tuned to.

1. ``generator``: random walls (size, unit, bond, openings; ``masonryfw_diagnose.synthetic``) over a random
   known scenario (a step at one end, a Gaussian trough, a tilt), solved forward by fdem (to 2 % of the wall
   height) and by la; the cracked joints (fdem: open or slipping over 0.1 mm at the end; la: crack
   indicator over 0.1) drawn as a surveyor would (lines offset 0.2 h, 10 % of the joints left out, cracks
   shorter than h missed, one spurious hairline), widths from fdem's openings; diagnosed with la. Success:
   the family right, a step's or tilt's ends within two segments, a trough's centre within 10 % of the wall,
   sagging/hogging right, the truth in the plausible set; the magnitude against fdem's settlement.
2. ``noise``: the la cases again, one surveyor error at a time (offset, missing cracks, spurious lines).
3. ``walls``: the paper's ten walls, the cracks of their own la and fdem results as the survey.

4. ``survey``: the bundled survey of the README tour (datasets/surveys/).

    python docs/scripts/diagnose_study.py [generator|noise|walls|survey ...] [--cases 30] [--cache DIR]

Forward results are kept in the cache (default /tmp/masonryfw-diagnose-study): a re-run only diagnoses.
Prints the tables of the doc and writes docs/img/diagnose/*.json (the numbers) and the example figure.
"""
from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_diagnose import Survey, describe, diagnose, to_dataset
from masonryfw_diagnose import synthetic as sy

ROOT = Path(__file__).resolve().parents[2]
IMAGES = ROOT / "docs" / "img" / "diagnose"
SURVEYOR = sy.Surveyor(offset=0.2, gaps=0.1, missing=1.0, spurious=1)
FDEM_WIDTH = 1e-4  # m: a joint open or slipping more is a crack the surveyor sees
TEN_WALLS = ("test-8c", "test-12c", "panel-1", "panel-2", "panel-3", "panel-4", "panel-5", "facade-1", "facade-2",
             "facade-3")
NOISE = {"offset": (0.0, 0.25, 0.5, 1.0), "missing": (0.0, 2.0, 4.0), "spurious": (0, 3, 6)}


def survey_of(collection: dict) -> Survey:
    """A GeoJSON FeatureCollection of :func:`synthetic.draw` as a survey (what ``read_cracks`` would give)."""
    lines, widths, names = [], [], []
    for feature in collection["features"]:
        geometry = feature["geometry"]
        parts = [geometry["coordinates"]] if geometry["type"] == "LineString" else geometry["coordinates"]
        for k, part in enumerate(parts):
            lines.append(np.asarray(part, dtype=float))
            widths.append(feature["properties"].get("width_mm"))
            names.append(f"{feature['properties']['name']}.{k}")
    return Survey(tuple(lines), tuple(widths), tuple(names), sources={"cracks": "synthetic", "unit": "m"})


def forward(cache: Path, key: str, model, solver: str):
    """``model`` solved by ``solver``, from the cache when it was solved before."""
    path = cache / f"{key}.{solver}.nc"
    if path.is_file():
        return mf.open_dataset(path)
    result = mf.solve(model, solver, {})
    mf.save(result, path)
    return result


def case(seed: int):
    rng = np.random.default_rng(seed)
    spec = sy.random_wall(rng)
    truth = sy.random_truth(spec, rng)
    return spec, truth


def run_case(spec: dict, truth: dict, result, joints, surveyor: sy.Surveyor, seed: int, widths=None) -> dict:
    collection = sy.draw(result, joints, surveyor, np.random.default_rng(1000 + seed), widths)
    if not collection["features"]:
        return {"seed": seed, "skipped": "no crack drawn"}
    started = time.perf_counter()
    diagnosis = diagnose(mf.build({**spec, **mf.STAND_IN_GROUND}), survey_of(collection))
    seconds = time.perf_counter() - started
    judged = sy.judged([c.table for c in diagnosis.candidates], [c.table for c in diagnosis.plausible], truth,
                       diagnosis.extent, diagnosis.segment)
    return {"seed": seed, "wall": spec["title"], "openings": len(spec.get("openings", [])), "truth": truth,
            "best": diagnosis.best.table, "score": diagnosis.best.score.total, "plausible": len(diagnosis.plausible),
            "candidates": len(diagnosis.candidates), "seconds": seconds, "magnitude": diagnosis.best.score.magnitude,
            "lines": len(collection["features"]), **judged}


def rates(rows: list[dict]) -> dict:
    done = [r for r in rows if "family" in r]
    troughs = [r for r in done if r["truth"]["profile"] == "gaussian"]
    return {"cases": len(done), "family": np.mean([r["family"] for r in done]),
            "place": np.mean([r["place"] for r in done]), "in_plausible": np.mean([r["in_plausible"] for r in done]),
            "shape": np.mean([r["shape"] for r in troughs]) if troughs else float("nan"),
            "troughs": len(troughs), "median_plausible": float(np.median([r["plausible"] for r in done])),
            "median_seconds": float(np.median([r["seconds"] for r in done]))}


def generator(cases: int, cache: Path) -> dict:
    out = {}
    for solver in ("la", "fdem"):
        rows = []
        for seed in range(cases):
            spec, truth = case(seed)
            model = mf.build({**spec, "settlement": truth, "loading": {"type": "settlement"}})
            try:
                result = forward(cache, f"case{seed}", model, solver)
            except mf.MasonryError as exc:
                rows.append({"seed": seed, "skipped": str(exc).splitlines()[0]})
                continue
            if solver == "la":
                row = run_case(spec, truth, result, sy.visible_cracks(result), SURVEYOR, seed)
            else:
                joints = sy.visible_cracks(result, width=FDEM_WIDTH)
                opening = np.maximum(result.interface_opening.values, 0.0).max(axis=1)
                row = run_case(spec, truth, result, joints, SURVEYOR, seed,
                               {int(j): 1e3 * float(opening[j]) for j in joints})
                row["settlement"] = float(result.step_settlement.values[-1])
            rows.append(row)
            print(solver, json.dumps(row, default=float), flush=True)
        out[solver] = {"rows": rows, "rates": rates(rows)}
        print(solver, out[solver]["rates"], flush=True)
    return out


def noise(cases: int, cache: Path) -> dict:
    out = {}
    for factor, levels in NOISE.items():
        for level in levels:
            surveyor = replace(sy.Surveyor(), **{factor: level})
            rows = []
            for seed in range(cases):
                spec, truth = case(seed)
                model = mf.build({**spec, "settlement": truth, "loading": {"type": "settlement"}})
                result = forward(cache, f"case{seed}", model, "la")
                rows.append(run_case(spec, truth, result, sy.visible_cracks(result), surveyor, seed))
            out[f"{factor}={level}"] = rates(rows)
            print(factor, level, out[f"{factor}={level}"], flush=True)
    return out


def walls(cache: Path) -> dict:
    out = {}
    for name in TEN_WALLS:
        model = mf.open_model(name)
        role = model.block_role.values
        moving = np.flatnonzero(role == mfp.flags("block_role")["moving_support"])
        xmin, xmax, _, _ = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
        settling = (float(xmin[moving].min()), float(xmax[moving].max()))
        for solver in ("la", "fdem"):
            result = forward(cache, name, model, solver)
            joints = sy.visible_cracks(result) if solver == "la" else sy.visible_cracks(result, width=FDEM_WIDTH)
            started = time.perf_counter()
            diagnosis = diagnose(model, survey_of(sy.draw(result, joints, sy.Surveyor(), np.random.default_rng(0))))
            best = diagnosis.best.table
            edges = [e for e in (settling[0], settling[1]) if diagnosis.extent[0] + 1e-9 < e < diagnosis.extent[1] - 1e-9]
            found = best["profile"] == "step" and all(
                min(abs(best["start"] - e), abs(best["end"] - e)) <= diagnosis.segment + 1e-9 for e in edges)
            row = {"wall": name, "solver": solver, "settling": settling, "best": describe(best),
                   "score": diagnosis.best.score.total, "plausible": len(diagnosis.plausible),
                   "candidates": len(diagnosis.candidates), "joints": int(joints.size), "segment": diagnosis.segment,
                   "edge_found": bool(found), "seconds": time.perf_counter() - started,
                   "either_end": diagnosis.either_end()}
            out[f"{name}/{solver}"] = row
            print(json.dumps(row, default=float), flush=True)
            if name == "facade-1" and solver == "fdem":
                figure = mf.render([to_dataset(diagnosis, name)], "diagnosis")
                mf.save_figure(figure, IMAGES / "facade-1-fdem.png")
    return out


def survey(cache: Path) -> dict:
    """The bundled survey of the README tour (datasets/surveys/README.md): facade-1's fdem cracks and a levelling."""
    result = forward(cache, "facade-1", mf.open_model("facade-1"), "fdem")
    joints = sy.visible_cracks(result, width=FDEM_WIDTH)
    opening = np.maximum(result.interface_opening.values, 0.0).max(axis=1)
    collection = sy.draw(result, joints, sy.Surveyor(offset=0.15, gaps=0.1, missing=1.0, spurious=1),
                         np.random.default_rng(7), {int(j): 1e3 * float(opening[j]) for j in joints})
    for feature in collection["features"]:
        geometry = feature["geometry"]
        geometry["coordinates"] = np.round(np.asarray(geometry["coordinates"], dtype=float), 4).tolist()
        if "width_mm" in feature["properties"]:
            feature["properties"]["width_mm"] = round(feature["properties"]["width_mm"], 2)
    folder = ROOT / "datasets" / "surveys"
    (folder / "facade-1-cracks.geojson").write_text(json.dumps(collection, indent=1) + "\n")
    points = sy.levelling(result, 0.125, 1.0, noise=2e-4, rng=np.random.default_rng(8))
    (folder / "facade-1-levelling.csv").write_text(
        "x,y,dy\n" + "".join(f"{x:.3f},{y:.3f},{dy:.5f}\n" for x, y, dy in points))
    return {"settlement": float(result.step_settlement.values[-1]), "cracked_joints": int(joints.size)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="*", default=["generator", "noise", "walls"])
    parser.add_argument("--cases", type=int, default=30)
    parser.add_argument("--cache", type=Path, default=Path("/tmp/masonryfw-diagnose-study"))
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    IMAGES.mkdir(parents=True, exist_ok=True)
    for study in args.studies:
        numbers = {"generator": lambda: generator(args.cases, args.cache), "noise": lambda: noise(args.cases, args.cache),
                   "walls": lambda: walls(args.cache), "survey": lambda: survey(args.cache)}[study]()
        (IMAGES / f"{study}.json").write_text(json.dumps(numbers, indent=1, default=float) + "\n")


if __name__ == "__main__":
    main()
