"""The held-out test set of docs/diagnose.md: surveys of walls cracked by fdem, fixed as data.

Made by another generator than the one the diagnosis was tuned on (``masonryfw_diagnose.synthetic.random_wall``
and ``random_truth``): facades 8 to 16 units wide and 8 to 14 courses high of four unit sizes, with up to three
openings of several shapes (rectangular with a lintel or a flat arch; arched, with an arch; a door from the base),
over a settlement of every family (a step at either end or under an inner stretch, a tilt about any hinge, a
Gaussian trough with its axis on the wall or up to half a wall beyond it, i from 0.2 to 1.2 wall lengths) of
2 to 20 mm, on ground segments of half a unit (the diagnosis cuts whole units). fdem runs each to its
magnitude; the joints open or slipping over 0.1 mm are drawn by one of four surveyors (offset lines, vertices
moved, joints and short cracks missed, spurious hairlines, widths written in 0.5 mm steps), and the second
course is levelled with 0.3 mm noise.

    python docs/scripts/diagnose_cases.py [--cases 48] [--cache DIR]

Writes datasets/surveys/study/case-NN/ (wall.toml, cracks.geojson, levelling.csv, truth.json). Even cases
are the tuning half, odd ones the held-back half (docs/diagnose.md).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np

import masonryfw as mf
from masonryfw_diagnose import synthetic as sy

ROOT = Path(__file__).resolve().parents[2]
FOLDER = ROOT / "datasets" / "surveys" / "study"
#: (length, height) of a unit with its joints [m]: brick, metric brick, stone, block.
UNITS = ((0.225, 0.075), (0.25, 0.065), (0.3, 0.1), (0.44, 0.215))
SURVEYORS = (
    sy.Surveyor(offset=0.2, gaps=0.1, missing=1.0, spurious=1, width_step=0.5),
    sy.Surveyor(offset=0.1, jitter=0.15, gaps=0.2, missing=2.0, spurious=0, width_step=0.5),
    sy.Surveyor(offset=0.35, gaps=0.05, missing=1.0, spurious=3, width_step=0.5),
    sy.Surveyor(offset=0.05, jitter=0.05, gaps=0.0, missing=0.5, spurious=2),
)
FDEM_WIDTH = 1e-4  # m: a joint open or slipping more is a crack the surveyor sees
LEVELLING_NOISE = 3e-4  # m


def wall(rng: np.random.Generator) -> dict:
    """A facade spec (module docstring), without its ground."""
    length, height = UNITS[rng.integers(len(UNITS))]
    columns = int(rng.integers(8, 17)) if height < 0.2 else int(rng.integers(8, 12))
    courses = int(rng.integers(8, 15)) if height < 0.2 else int(rng.integers(6, 9))
    width, tall = columns * length, courses * height
    spec = {"title": f"study facade {columns} x {courses} units", "length_unit": "m",
            "wall": {"width": round(width, 6), "height": round(tall, 6), "thickness": 0.2},
            "unit": {"length": length, "height": height},
            "bond": {"pattern": "running", "first_course": "full" if rng.random() < 0.5 else "half"},
            "material": {"unit_weight": 18000.0, "friction_angle": 30.0, "cohesion": 0.0, "tensile_strength": 0.0,
                         "young_modulus": 3e9, "poisson_ratio": 0.2}}
    openings: list[dict] = []
    for _ in range(int(rng.integers(0, 4))):
        kind = ("window", "arched", "door")[rng.integers(3)]
        span = int(rng.integers(2, 4)) * length
        rise_courses = int(rng.integers(3, max(4, courses // 2)))
        x = float(rng.uniform(1.5 * length, width - span - 1.5 * length))
        y = 0.0 if kind == "door" else 2 * height * int(rng.integers(1, max(2, courses // 4)))
        top = y + rise_courses * height + (span / 2 if kind == "arched" else 0.0) + 2 * height
        if top > tall - height or any(x < o["x"] + o["width"] + 2 * length and o["x"] < x + span + 2 * length
                                      for o in openings):
            continue
        opening = {"x": round(x, 4), "y": round(y, 4), "width": round(span, 4),
                   "height": round(rise_courses * height, 4)}
        if kind == "arched":
            opening["shape"] = "arched"
        else:
            opening["head"] = ("lintel", "flat_arch")[rng.integers(2)] if kind == "window" else "lintel"
        openings.append(opening)
    if openings:
        spec["openings"] = openings
    return spec


def truth(spec: dict, rng: np.random.Generator) -> dict:
    """A settlement of any family under ``spec``'s wall (module docstring), with its magnitude ``target`` [m]."""
    width = spec["wall"]["width"]
    family = ("step", "gaussian", "linear")[rng.integers(3)]
    target = float(math.exp(rng.uniform(math.log(0.002), math.log(0.02))))
    if family == "gaussian":
        table = {"profile": "gaussian", "center": float(rng.uniform(-0.5, 1.5) * width),
                 "width": float(rng.uniform(0.2, 1.2) * width)}
    elif family == "step":
        part = float(rng.uniform(0.2, 0.5)) * width
        where = rng.random()
        if where < 0.4:
            table = {"profile": "step", "start": -0.01 * width, "end": part}
        elif where < 0.8:
            table = {"profile": "step", "start": width - part, "end": 1.01 * width}
        else:
            start = float(rng.uniform(0.2, 0.8 - part / width)) * width if part < 0.6 * width else 0.2 * width
            table = {"profile": "step", "start": start, "end": start + part}
    else:
        hinge = float(rng.uniform(0.2, 0.8)) * width
        table = {"profile": "linear", "start": hinge, "end": 0.0 if rng.random() < 0.5 else width}
    return {**{k: round(v, 4) if isinstance(v, float) else v for k, v in table.items()}, "target": round(target, 5)}


def forward(spec: dict, table: dict, cache: Path, key: str):
    """fdem's run of ``spec``'s wall on ground of half-unit segments moved by ``table`` to its target."""
    path = cache / f"{key}.fdem.nc"
    if path.is_file():
        return mf.open_dataset(path)
    ground = mf.ground_model(mf.build({**spec, **mf.STAND_IN_GROUND}), 0.5 * spec["unit"]["length"])
    xs = ground.node_x.values
    profile = mf.settlement_profile({k: v for k, v in table.items() if k != "target"}, float(xs.min()),
                                    float(xs.max()), spec["unit"]["length"])
    model = mf.over_profile(ground, dataclasses.replace(profile, target=table["target"]))
    result = mf.solve(model, "fdem", {})
    mf.save(result, path)
    return result


def toml_text(spec: dict) -> str:
    """``spec`` as TOML (flat tables and one array of tables: what :func:`wall` makes)."""
    def value(v) -> str:
        return json.dumps(v)

    lines = [f"title = {value(spec['title'])}", f"length_unit = {value(spec['length_unit'])}"]
    for table in ("wall", "unit", "bond", "material"):
        lines += ["", f"[{table}]", *(f"{k} = {value(v)}" for k, v in spec[table].items())]
    for opening in spec.get("openings", []):
        lines += ["", "[[openings]]", *(f"{k} = {value(v)}" for k, v in opening.items())]
    return "\n".join(lines) + "\n"


def make(number: int, cache: Path) -> dict:
    rng = np.random.default_rng(5000 + number)
    spec = wall(rng)
    table = truth(spec, rng)
    started = time.perf_counter()
    result = forward(spec, table, cache, f"case-{number:02d}")
    seconds = time.perf_counter() - started
    joints = sy.visible_cracks(result, width=FDEM_WIDTH)
    opening = np.maximum(result.interface_opening.values, 0.0).max(axis=1)
    surveyor = SURVEYORS[number % len(SURVEYORS)]
    collection = sy.draw(result, joints, surveyor, rng, {int(j): 1e3 * float(opening[j]) for j in joints})
    for feature in collection["features"]:
        feature["geometry"]["coordinates"] = np.round(np.asarray(feature["geometry"]["coordinates"]), 4).tolist()
        if "width_mm" in feature["properties"]:
            feature["properties"]["width_mm"] = round(feature["properties"]["width_mm"], 2)
    course = 1.5 * spec["unit"]["height"]
    points = sy.levelling(result, course, 1.0, noise=LEVELLING_NOISE, rng=rng)
    folder = FOLDER / f"case-{number:02d}"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "wall.toml").write_text(toml_text(spec))
    (folder / "cracks.geojson").write_text(json.dumps(collection) + "\n")
    (folder / "levelling.csv").write_text("x,y,dy\n" + "".join(f"{x:.4f},{y:.4f},{dy:.5f}\n" for x, y, dy in points))
    reached = float(result.step_settlement.values[-1])
    about = {"truth": table, "settlement": reached, "half": "tuning" if number % 2 == 0 else "held-back",
             "surveyor": dataclasses.asdict(surveyor), "cracked_joints": int(joints.size),
             "lines": len(collection["features"]), "unbalanced_ratio": float(result.attrs.get("unbalanced_ratio", -1)),
             "blocks": int(result.sizes["block"]), "fdem_seconds": round(seconds, 1)}
    (folder / "truth.json").write_text(json.dumps(about, indent=1) + "\n")
    return about


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=48)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--cache", type=Path, default=Path("/tmp/masonryfw-diagnose-cases"))
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    for number in range(args.first, args.cases):
        try:
            about = make(number, args.cache)
        except mf.MasonryError as exc:
            print(number, "failed:", str(exc).splitlines()[0], flush=True)
            continue
        print(number, json.dumps(about["truth"]), about["blocks"], "blocks", about["lines"], "lines",
              about["fdem_seconds"], "s", flush=True)


if __name__ == "__main__":
    main()
