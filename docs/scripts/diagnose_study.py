"""The studies of docs/diagnose.md: forward then inverse, on walls and surveys the method was not tuned to.

1. ``cases``: the held-out surveys of datasets/surveys/study (docs/scripts/diagnose_cases.py: facades with
   openings cracked by fdem, drawn by four surveyors, levelled with 0.3 mm noise), each diagnosed from its
   cracks and from its cracks and its levelling, judged against its truth by ``synthetic.judged`` (what the
   answer determined: side, edge within two segments, sagging/hogging; the family where it claims one; the
   truth in the plausible set; the differential settlement against fdem's), before and after the default
   re-ranking by fdem. ``--half tuning`` or ``--half held-back`` runs one half (cases-<half>.json).
2. ``table``: the doc's table from the halves' numbers.
3. ``walls``: the paper's ten walls, the cracks of their own la and fdem results as the survey.
4. ``survey``: the bundled survey of the README tour (datasets/surveys/).

    python docs/scripts/diagnose_study.py [cases|table|walls|survey ...] [--half tuning] [--cache DIR]

Forward results of ``walls`` and the rows of ``cases`` are kept in the cache (default
/tmp/masonryfw-diagnose-study): a re-run only does what is missing. Prints the tables of the doc and writes docs/img/diagnose/*.json (the numbers) and the figures.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_diagnose import (
    DEFAULT_BUDGET,
    Survey,
    affordable,
    describe,
    diagnose,
    read_cracks,
    read_levelling,
    rerank,
    to_dataset,
    wall_model,
)
from masonryfw_diagnose import synthetic as sy

ROOT = Path(__file__).resolve().parents[2]
IMAGES = ROOT / "docs" / "img" / "diagnose"
CASES = ROOT / "datasets" / "surveys" / "study"
FDEM_WIDTH = 1e-4  # m: a joint open or slipping more is a crack the surveyor sees
TEN_WALLS = ("test-8c", "test-12c", "panel-1", "panel-2", "panel-3", "panel-4", "panel-5", "facade-1", "facade-2",
             "facade-3")


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


def study_cases() -> list[Path]:
    return sorted(p for p in CASES.iterdir() if (p / "truth.json").is_file())


def diagnose_case(folder: Path, levelled: bool) -> dict:
    """One case of the held-out set (docs/scripts/diagnose_cases.py) diagnosed from its cracks, or its cracks and
    its levelling, and judged against its truth."""
    about = json.loads((folder / "truth.json").read_text())
    survey = read_cracks(folder / "cracks.geojson")
    if levelled:
        survey = survey.with_levelling(read_levelling(folder / "levelling.csv", "m"), "levelling.csv")
    started = time.perf_counter()
    diagnosis = diagnose(wall_model(str(folder / "wall.toml")), survey)
    seconds = time.perf_counter() - started
    truth = {k: v for k, v in about["truth"].items() if k != "target"}
    by_la = sy.judged(diagnosis, truth, about["settlement"])
    started = time.perf_counter()
    rerank(diagnosis, affordable(diagnosis, DEFAULT_BUDGET))  # as the command does by default
    return {"case": folder.name, "half": about["half"], "levelled": levelled, "truth": truth,
            "settlement": about["settlement"], "best": describe(diagnosis.best.table),
            "score": diagnosis.best.score.total, "candidates": len(diagnosis.candidates), "seconds": seconds,
            "rerank_seconds": time.perf_counter() - started, "reranked": diagnosis.reranked,
            "family_probability": diagnosis.family_probability, "by_la": by_la,
            **sy.judged(diagnosis, truth, about["settlement"])}


def summary(rows: list[dict]) -> dict:
    """The shares of docs/diagnose.md's table for ``rows``."""
    ratios = [r["magnitude_ratio"] for r in rows if r["magnitude_ratio"] is not None]
    claimed = [r for r in rows if r["claims"]]
    determined = [r for r in rows if r["found_side"] is not None]
    return {"cases": len(rows), "side_determined": len(determined), "side": sum(r["side"] for r in rows),
            "edge": sum(r["edge"] for r in rows),
            "side_and_edge": sum(r["side_and_edge"] for r in rows), "mode": sum(r["mode"] for r in rows),
            "family": sum(r["family"] for r in rows), "place": sum(r["place"] for r in rows),
            "claims": len(claimed), "claimed_right": sum(r["family"] for r in claimed),
            "in_plausible": sum(r["in_plausible"] for r in rows),
            "median_plausible": float(np.median([r["plausible"] for r in rows])),
            "magnitude_within_25": sum(abs(q - 1) <= 0.25 for q in ratios), "magnitudes": len(ratios),
            "magnitude_quartiles": [float(v) for v in np.percentile(ratios, [25, 50, 75])] if ratios else None,
            "median_seconds": float(np.median([r["seconds"] for r in rows])),
            "median_rerank_seconds": float(np.median([r.get("rerank_seconds", 0.0) for r in rows]))}


def cases(cache: Path, halves: tuple[str, ...] = ("tuning", "held-back")) -> dict:
    """Every case of ``halves`` diagnosed (its row kept in ``cache``: a re-run reuses it); a case whose surveyor
    drew no crack is counted as skipped."""
    out: dict = {"rows": [], "skipped": []}
    for folder in study_cases():
        if json.loads((folder / "truth.json").read_text())["half"] not in halves:
            continue
        if not json.loads((folder / "cracks.geojson").read_text())["features"]:
            out["skipped"].append({"case": folder.name, "why": "no crack drawn (none over 0.1 mm, or all missed)"})
            continue
        for levelled in (False, True):
            kept = cache / "rows" / f"{folder.name}-{'levelling' if levelled else 'cracks'}.json"
            if kept.is_file():
                row = json.loads(kept.read_text())
            else:
                row = diagnose_case(folder, levelled)
                kept.parent.mkdir(parents=True, exist_ok=True)
                kept.write_text(json.dumps(row, default=float))
            out["rows"].append(row)
            print(json.dumps(row, default=float), flush=True)
    for half in halves:
        for levelled in (False, True):
            rows = [r for r in out["rows"] if r["half"] == half and r["levelled"] == levelled]
            out[f"{half}/{'levelling' if levelled else 'cracks'}"] = summary(rows)
            out[f"{half}/{'levelling' if levelled else 'cracks'}/la"] = summary([{**r, **r["by_la"]} for r in rows])
            print(half, levelled, summary(rows), flush=True)
    return out


def table() -> dict:
    """docs/diagnose.md's table of the held-out study, from the halves' numbers (docs/img/diagnose/cases-*.json)."""
    lines = ["| half | survey | ranked by | cases | side determined (right) | side and edge right | mode right | "
             "family right (claimed, right) | family and place right | truth plausible | median plausible | "
             "magnitude within 25 % | magnitude ratio quartiles |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    out = {}
    for half in ("tuning", "held-back"):
        numbers = json.loads((IMAGES / f"cases-{half}.json").read_text())
        for survey in ("cracks", "levelling"):
            for ranked, key in (("la", f"{half}/{survey}/la"), ("la + fdem", f"{half}/{survey}")):
                n = numbers[key]
                quartiles = ", ".join(f"{q:.2f}" for q in n["magnitude_quartiles"]) if n["magnitude_quartiles"] else "-"
                lines.append(f"| {half} | {survey} | {ranked} | {n['cases']} | {n['side_determined']} "
                             f"({n['side']}) | {n['side_and_edge']} | {n['mode']} | {n['family']} ({n['claims']}, "
                             f"{n['claimed_right']}) | {n['place']} | {n['in_plausible']} | {n['median_plausible']:g} | "
                             f"{n['magnitude_within_25']} of {n['magnitudes']} | {quartiles} |")
                out[key] = n
    print("\n".join(lines))
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
                   "side": diagnosis.determined().side}
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
    parser.add_argument("studies", nargs="*", default=["cases", "walls"])
    parser.add_argument("--half", action="append", choices=("tuning", "held-back"),
                        help="the halves of the held-out set the cases study runs [default: both]")
    parser.add_argument("--cache", type=Path, default=Path("/tmp/masonryfw-diagnose-study"))
    args = parser.parse_args()
    args.half = args.half or ["tuning", "held-back"]
    args.cache.mkdir(parents=True, exist_ok=True)
    IMAGES.mkdir(parents=True, exist_ok=True)
    for study in args.studies:
        numbers = {"cases": lambda: cases(args.cache, tuple(args.half)), "table": table, "walls": lambda: walls(args.cache),
                   "survey": lambda: survey(args.cache)}[study]()
        if study == "table":  # printed for the doc, from the numbers written
            continue
        name = f"cases-{args.half[0]}" if study == "cases" and len(args.half) == 1 else study
        (IMAGES / f"{name}.json").write_text(json.dumps(numbers, indent=1, default=float) + "\n")


if __name__ == "__main__":
    main()
