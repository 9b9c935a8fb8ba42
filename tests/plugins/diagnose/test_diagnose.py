"""``masonryfw diagnose``: from a crack survey (and a levelling) back to the settlement that caused it.

References, none of them the diagnosis's own output: the scenario that made the survey (a forward solve
of a known support or profile, drawn by ``masonryfw_diagnose.synthetic``), the settlement the data were
scaled by (levelling, widths), the mirror image of the wall, and random lines that nothing explains.
"""
from __future__ import annotations

import csv
import json

import ezdxf
import numpy as np
import pytest
from click.testing import CliRunner

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.cli import cli
from masonryfw_diagnose import synthetic as sy
from masonryfw_diagnose.dataset import to_dataset
from masonryfw_diagnose.diagnosis import EXPLAINED, diagnose, verify
from masonryfw_diagnose.scoring import SCALE, weight
from masonryfw_diagnose.survey import Survey, read_cracks

WIDTH_12C = 1.1  # Test 12C: 1.1 m x 0.6 m, the right 0.6 m (x = 0.5 .. 1.1) settles
SEGMENT = 0.1


def survey(lines, widths=None) -> Survey:
    lines = tuple(np.asarray(line, dtype=float) for line in lines)
    return Survey(lines, tuple(widths or [None] * len(lines)), tuple(f"line {k}" for k in range(len(lines))),
                  sources={"cracks": "test", "unit": "m"})


def joint_lines(result, joints) -> list[np.ndarray]:
    return [np.c_[result.interface_x.values[j], result.interface_y.values[j]] for j in joints]


def write_geojson(path, lines, widths=None):
    features = [{"type": "Feature", "properties": {"name": f"c{k}", **({"width_mm": widths[k]} if widths else {})},
                 "geometry": {"type": "LineString", "coordinates": np.asarray(line).tolist()}}
                for k, line in enumerate(lines)]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.fixture(scope="module")
def la_12c():
    return mf.solve(mf.open_model("test-12c"), "la", {})


@pytest.fixture(scope="module")
def cracks_12c(la_12c):
    return joint_lines(la_12c, sy.visible_cracks(la_12c))


@pytest.fixture(scope="module")
def diagnosis_12c(cracks_12c):
    return diagnose(mf.open_model("test-12c"), survey(cracks_12c), segment=SEGMENT)


def near(value, targets, tolerance):
    return any(abs(value - t) <= tolerance + 1e-9 for t in targets)


def test_the_weights_are_the_documented_ones():
    h = 0.05
    assert weight(np.array([0.0, h / 2, h, 2 * h]), h) == pytest.approx(
        np.exp(-0.5 * (np.array([0.0, 0.5, 1.0, 2.0]) / SCALE) ** 2), rel=1e-12)
    assert weight(np.array([h]), h)[0] == pytest.approx(0.36, abs=0.005)  # one joint off: docs/diagnose.md


def test_own_la_cracks_point_to_the_settling_support(diagnosis_12c):
    best = diagnosis_12c.best
    assert best.table["profile"] == "step"
    assert near(best.table["start"], [0.5], SEGMENT) or near(best.table["end"], [0.5, 0.6], SEGMENT)
    assert best.score.total > 0.95
    plausible = [c.table for c in diagnosis_12c.plausible]
    assert {"profile": "step", "start": pytest.approx(0.5), "end": pytest.approx(1.1), "segment": SEGMENT} in plausible
    assert diagnosis_12c.explained


def test_cracks_alone_do_not_say_which_side_went_down(cracks_12c):
    """On a grid that holds both edges of the staircase (0.5 and 0.55 m), the right part dropping and the left
    part dropping open the same cracks: both are plausible, and the verdict says a levelling would tell."""
    diagnosis = diagnose(mf.open_model("test-12c"), survey(cracks_12c), segment=0.05, families=("step",))
    plausible = [c.table for c in diagnosis.plausible]
    assert {"profile": "step", "start": 0.0, "end": pytest.approx(0.55), "segment": 0.05} in plausible
    assert {"profile": "step", "start": pytest.approx(0.5), "end": pytest.approx(1.1), "segment": 0.05} in plausible
    assert diagnosis.determined().side is None and set(diagnosis.determined().sides) == {"left", "right"}
    assert "the settled part is not determined" in diagnosis.verdict()


def test_a_levelling_picks_the_side_and_the_settlement(la_12c, cracks_12c):
    settlement = 4e-3
    points = sy.levelling(la_12c, 0.525, settlement, noise=5e-5, rng=np.random.default_rng(3))
    diagnosis = diagnose(mf.open_model("test-12c"), survey(cracks_12c).with_levelling(points, "levels.csv"),
                         segment=SEGMENT)
    best = diagnosis.best
    assert best.table["profile"] == "step" and best.table["end"] == pytest.approx(WIDTH_12C)
    assert near(best.table["start"], [0.5], SEGMENT)
    assert best.score.magnitude == pytest.approx(settlement, rel=0.05)
    assert "left" not in diagnosis.determined().sides  # the levelling rules the mirror image out
    mirror = [c for c in diagnosis.candidates if c.table["profile"] == "step" and c.table["start"] == 0.0
              and near(c.table["end"], [0.5, 0.6], SEGMENT)]
    assert mirror and all(c.score.levelling < 0.01 and c.score.magnitude == 0.0 and not c.plausible for c in mirror)


def test_verify_runs_the_best_forward_to_its_settlement(la_12c, cracks_12c):
    """fdem from rest to the levelling's settlement (4 mm) under the best step: it gets there, and the part
    over the settling ground opens a crack no wider than that settlement (a translation of 4 mm)."""
    points = sy.levelling(la_12c, 0.525, 4e-3)
    diagnosis = diagnose(mf.open_model("test-12c"), survey(cracks_12c).with_levelling(points, "levels.csv"),
                         segment=SEGMENT, families=("step",))
    verify(diagnosis, "fdem", count=1)
    best, second = diagnosis.candidates[:2]
    assert second.verified is None and diagnosis.verified_with == "fdem"
    assert best.verified["final_settlement"] >= 0.999 * best.score.magnitude
    assert 0.2 * best.score.magnitude < best.verified["crack_width"] <= 1.01 * best.score.magnitude
    assert best.verified["damage_category"] >= 1


def test_surveyed_widths_give_the_settlement(la_12c, cracks_12c):
    """Widths of la's own openings at a known settlement: the estimate is that settlement."""
    settlement = 3e-3
    joints = sy.visible_cracks(la_12c)
    opening = np.maximum(la_12c.interface_opening.values, 0.0).max(axis=1)
    widths = [1e3 * settlement * float(opening[j]) for j in joints]
    diagnosis = diagnose(mf.open_model("test-12c"), survey(cracks_12c, widths), segment=SEGMENT)
    step = next(c for c in diagnosis.candidates if c.table["profile"] == "step"
                and c.table["start"] == pytest.approx(0.5) and c.table["end"] == pytest.approx(WIDTH_12C))
    assert step.score.magnitude == pytest.approx(settlement, rel=0.02)


def mirrored(model, width):
    """``model``'s polygons mirrored about x = width / 2, each one's vertices reversed (still counter-clockwise);
    the diagnosis builds its joints anew from them."""
    counts = model.block_node_count.values
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    order = np.concatenate([s + np.arange(c)[::-1] for s, c in zip(starts, counts)])
    return model.assign(node_x=model.node_x.copy(data=width - model.node_x.values[order]),
                        node_y=model.node_y.copy(data=model.node_y.values[order]))


@pytest.mark.slow  # 13 s: a second search
def test_a_mirrored_wall_with_mirrored_cracks_gives_the_mirrored_candidates(diagnosis_12c, cracks_12c):
    mirror_model = mirrored(mf.open_model("test-12c"), WIDTH_12C)
    lines = [np.c_[WIDTH_12C - line[:, 0], line[:, 1]] for line in cracks_12c]
    mirror = diagnose(mirror_model, survey(lines), segment=SEGMENT)
    scores = {(c.table["profile"], round(c.table.get("start", c.table.get("center")), 6),
               round(c.table.get("end", c.table.get("width")), 6)): c.score.total for c in mirror.candidates}

    def flipped(table):
        if table["profile"] == "gaussian":
            return ("gaussian", round(WIDTH_12C - table["center"], 6), round(table["width"], 6))
        if table["profile"] == "step":
            return ("step", round(WIDTH_12C - table["end"], 6), round(WIDTH_12C - table["start"], 6))
        return ("linear", round(WIDTH_12C - table["start"], 6), round(WIDTH_12C - table["end"], 6))

    for candidate in diagnosis_12c.candidates[:10]:
        assert scores[flipped(candidate.table)] == pytest.approx(candidate.score.total, abs=0.02), candidate.table
    assert mirror.best.score.total == pytest.approx(diagnosis_12c.best.score.total, abs=1e-3)


@pytest.mark.parametrize("seed", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_random_lines_are_not_explained(seed):
    model = mf.open_model("facade-1")
    rng = np.random.default_rng(seed)
    h = 0.05
    lines = []
    for _ in range(8):
        start = np.array([rng.uniform(0.0, 1.5), rng.uniform(0.0, 1.2)])
        angle = rng.uniform(0.0, np.pi)
        lines.append(np.clip([start, start + 3 * h * np.array([np.cos(angle), np.sin(angle)])], 0.0, [1.5, 1.2]))
    diagnosis = diagnose(model, survey(lines), families=("step", "gaussian"))
    assert diagnosis.best.score.total < EXPLAINED
    assert not diagnosis.explained
    assert diagnosis.verdict().startswith("nothing tried explains these cracks well")


def test_the_same_cracks_read_alike_from_geojson_csv_and_dxf(tmp_path, cracks_12c):
    lines = cracks_12c[:6]
    write_geojson(tmp_path / "c.geojson", lines, [0.5] * len(lines))
    with open(tmp_path / "c.csv", "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["crack", "x", "y", "width_mm"])
        for k, line in enumerate(lines):
            for x, y in line:
                writer.writerow([f"c{k}", 1e3 * x, 1e3 * y, 0.5])
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4  # mm
    for k, line in enumerate(lines):
        pts = [(1e3 * x, 1e3 * y) for x, y in line]
        if k % 2:
            doc.modelspace().add_lwpolyline(pts, dxfattribs={"layer": "CRACKS"})
        else:
            doc.modelspace().add_line(*pts, dxfattribs={"layer": "CRACKS"})
    doc.modelspace().add_line((0, 0), (1100, 600), dxfattribs={"layer": "WALL"})
    doc.saveas(tmp_path / "c.dxf")
    from_geojson = read_cracks(tmp_path / "c.geojson")
    from_csv = read_cracks(tmp_path / "c.csv", unit="mm")
    from_dxf = read_cracks(tmp_path / "c.dxf", layer="CRACKS")
    assert from_dxf.sources["unit"] == "mm" and len(read_cracks(tmp_path / "c.dxf").cracks) == len(lines) + 1
    for other in (from_csv, from_dxf):
        assert len(other.cracks) == len(lines)
        for a, b in zip(from_geojson.cracks, other.cracks):
            np.testing.assert_allclose(a, b, atol=1e-12)
    assert from_csv.widths_mm == from_geojson.widths_mm == (0.5,) * len(lines)


def cli_run(args, cwd):
    import os

    here = os.getcwd()
    os.chdir(cwd)
    try:
        return CliRunner().invoke(cli, args, catch_exceptions=False)
    finally:
        os.chdir(here)


def bad_geojson(tmp_path, name, geometry):
    path = tmp_path / name
    features = [] if geometry is None else [{"type": "Feature", "properties": {}, "geometry": geometry}]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.mark.parametrize("case, expected", [
    ("off", ["crack '0'", "off the wall", "x 0..1.1, y 0..0.6 m", "--unit"]),
    ("millimetres", ["passes (200, 100) m", "off the wall", "--unit"]),
    ("empty", ["no crack in it"]),
    ("point", ["feature 0: a Point, not a LineString or MultiLineString"]),
    ("csv", ["needs the columns crack, x, y", "y missing"]),
    ("levelling-off", ["levelling 'levels.csv' row 3", "(5, 0.3) m is off the wall"]),
    ("levelling-short", ["levelling 'levels.csv': 2 point(s); a levelling needs at least three"]),
    ("suffix", ["unknown file type '.txt'"]),
])
def test_bad_input_is_named_and_nothing_is_written(tmp_path, case, expected):
    good = bad_geojson(tmp_path, "good.geojson", {"type": "LineString", "coordinates": [[0.5, 0.1], [0.6, 0.2]]})
    args = ["diagnose", "test-12c", "--cracks", str(good), "-o", "out.nc", "--no-progress"]
    if case == "off":
        args[3] = str(bad_geojson(tmp_path, "c.geojson", {"type": "LineString", "coordinates": [[0.5, 0.1],
                                                                                                [3.0, 0.2]]}))
    elif case == "millimetres":
        args[3] = str(bad_geojson(tmp_path, "c.geojson", {"type": "LineString", "coordinates": [[200, 100],
                                                                                                [300, 200]]}))
    elif case == "empty":
        args[3] = str(bad_geojson(tmp_path, "c.geojson", None))
    elif case == "point":
        args[3] = str(bad_geojson(tmp_path, "c.geojson", {"type": "Point", "coordinates": [0.5, 0.1]}))
    elif case == "csv":
        (tmp_path / "c.csv").write_text("crack,x\na,0.1\n")
        args[3] = str(tmp_path / "c.csv")
    elif case.startswith("levelling"):
        rows = "x,y,dy\n0.1,0.3,0\n5,0.3,-0.001\n0.9,0.3,-0.002\n" if case == "levelling-off" else "x,y,dy\n0.1,0.3,0\n0.3,0.3,0\n"
        (tmp_path / "levels.csv").write_text(rows)
        args += ["--levelling", str(tmp_path / "levels.csv")]
    elif case == "suffix":
        (tmp_path / "c.txt").write_text("0.1 0.2\n")
        args[3] = str(tmp_path / "c.txt")
    run = cli_run(args, tmp_path)
    assert run.exit_code == 1, run.output
    assert "Traceback" not in run.output
    for fragment in expected:
        assert fragment in run.output
    assert not (tmp_path / "out.nc").exists()


def test_a_wall_without_a_ground_to_cut_is_refused():
    model = mf.open_model("test-12c")
    support = mfp.support_blocks(model.block_role.values)
    lowered = np.where(np.repeat(support, model.block_node_count.values), model.node_y.values - 1.0,
                       model.node_y.values)
    with pytest.raises(mf.SpecError, match="no masonry rests on the wall's ground"):
        mf.ground_model(model.assign(node_y=model.node_y.copy(data=lowered)), SEGMENT)


@pytest.fixture(scope="module")
def cli_diagnosis(tmp_path_factory, la_12c, cracks_12c):
    """``masonryfw diagnose test-12c --json`` on its own la cracks with widths, and one stray line in the middle of
    a unit (further than ``--tolerance 0.01`` m from every joint)."""
    folder = tmp_path_factory.mktemp("cli")
    joints = sy.visible_cracks(la_12c)
    opening = np.maximum(la_12c.interface_opening.values, 0.0).max(axis=1)
    lines = [*cracks_12c, np.array([[0.3, 0.3245], [0.3, 0.3255]])]  # in the unit 0.2..0.4 x 0.3..0.35
    widths = [1e3 * 2e-3 * float(opening[j]) for j in joints] + [0.1]
    write_geojson(folder / "cracks.geojson", lines, widths)
    run = cli_run(["diagnose", "test-12c", "--cracks", "cracks.geojson", "--segment", str(SEGMENT), "--json",
                   "--top", "3", "--tolerance", "0.01", "-o", "d.nc", "--no-progress", "--rerank", "0"], folder)
    assert run.exit_code == 0, run.output
    return folder, json.loads(run.stdout), run


def test_the_json_contract(cli_diagnosis, cracks_12c):
    folder, data, _ = cli_diagnosis
    assert {"candidates", "observed_joints", "unmatched_cracks"} <= set(data)
    candidates = data["candidates"]
    assert [c["rank"] for c in candidates] == list(range(1, len(candidates) + 1))
    assert len(candidates) == max(3, sum(c["plausible"] for c in candidates))
    scores = [c["score"] for c in candidates]
    assert all(0.0 <= s <= 1.0 for s in scores) and scores == sorted(scores, reverse=True)
    families = data["determined"]["families"]
    best_of = {f: max(c["score"] for c in candidates if c["settlement"]["profile"] == f) for f in families}
    assert candidates[0]["plausible"] and candidates[0]["settlement"]["profile"] == families[0]
    for c in candidates:  # plausible: in a family the data allow, within 0.05 of its best
        family = c["settlement"]["profile"]
        assert c["plausible"] == (family in families and c["score"] >= best_of[family] - 0.05 - 1e-6), c
    keys = {"step": {"start", "end"}, "gaussian": {"center", "width"}, "linear": {"start", "end"}}
    for c in candidates:
        settlement = c["settlement"]
        assert set(settlement) == {"profile", "segment"} | keys[settlement["profile"]]
        assert settlement["segment"] == SEGMENT
        assert isinstance(c["magnitude"], float) and c["magnitude"] > 0
    assert data["unmatched_cracks"] == 1 and data["unmatched_crack_names"] == [f"c{len(cracks_12c)}"]
    ds = mf.open_dataset(folder / "d.nc")
    assert mf.check(ds) == []
    assert data["observed_joints"] == int(ds.observed_joint.sum())
    np.testing.assert_allclose(ds.candidate_score.values[:len(scores)], scores, atol=1e-6)
    assert int(ds.survey_crack_matched.values.sum()) == ds.sizes["survey_crack"] - 1


def test_a_survey_without_widths_or_levelling_has_no_magnitude(tmp_path, cracks_12c):
    write_geojson(tmp_path / "c.geojson", cracks_12c)
    run = cli_run(["diagnose", "test-12c", "--cracks", "c.geojson", "--profiles", "step", "--json", "-o", "d.nc",
                   "--no-progress", "--rerank", "0"], tmp_path)
    assert run.exit_code == 0, run.output
    data = json.loads(run.stdout)
    assert all(c["magnitude"] is None and c["settlement"]["profile"] == "step" for c in data["candidates"])


def test_the_plot_and_the_report_show_the_diagnosis(cli_diagnosis):
    from html.parser import HTMLParser

    folder, data, _ = cli_diagnosis
    ds = mf.open_dataset(folder / "d.nc")
    figure = mf.render([ds], "diagnosis")
    assert len(figure.axes) >= 1 + ds.sizes["kept"] + 2  # survey, mechanisms, scores, troughs (+ colour bar)
    run = cli_run(["report", "d.nc", "-o", "r.html"], folder)
    assert run.exit_code == 0, run.output

    class Cells(HTMLParser):
        def __init__(self):
            super().__init__()
            self.cells = []

        def handle_starttag(self, tag, attrs):
            self.cells.append(dict(attrs))

    parser = Cells()
    parser.feed((folder / "r.html").read_text())
    first = [c for c in parser.cells if c.get("data-row") == "1" and c.get("data-column") == "score"]
    assert float(first[0]["data-value"]) == pytest.approx(float(ds.candidate_score[0]), rel=1e-12)
    assert 'data-kind="diagnosis"' in (folder / "r.html").read_text()


def test_an_interrupted_search_keeps_what_was_ranked(cracks_12c):
    calls = []

    def progress(fraction, message=""):
        calls.append(message)
        if len(calls) == 11:
            raise KeyboardInterrupt

    diagnosis = diagnose(mf.open_model("test-12c"), survey(cracks_12c), segment=SEGMENT, progress=progress)
    assert diagnosis.interrupted and len(diagnosis.candidates) + len(diagnosis.failed) == 10
    assert [c.rank for c in diagnosis.candidates] == list(range(1, len(diagnosis.candidates) + 1))


def test_an_interrupted_command_writes_the_ranking_and_exits_130(tmp_path, cracks_12c, monkeypatch):
    import masonryfw_diagnose.diagnosis as module

    solved, calls = module.solved, []

    def interrupted(*args):
        calls.append(1)
        if len(calls) == 8:
            raise KeyboardInterrupt
        return solved(*args)

    monkeypatch.setattr(module, "solved", interrupted)
    write_geojson(tmp_path / "c.geojson", cracks_12c)
    run = cli_run(["diagnose", "test-12c", "--cracks", "c.geojson", "-o", "d.nc", "--no-progress"], tmp_path)
    assert run.exit_code == 130
    assert "interrupted after 7 scenario(s)" in run.output
    assert mf.open_dataset(tmp_path / "d.nc").sizes["candidate"] == 7


def test_a_drawn_wall_with_a_dxf_crack_map(tmp_path):
    """Stepped units (a drawn wall, non-convex blocks) settling from x = 0.7 m: its la cracks drawn on a CRACKS
    layer of a DXF in mm beside the wall's outline; and the same wall's spec without its loading (its drawn
    supports kept as the ground to cut: a drawing's base blocks are masonry unless the spec says otherwise)."""
    result = mf.solve(mf.open_model("stepped-units"), "la", {})
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    for line in joint_lines(result, sy.visible_cracks(result)):
        doc.modelspace().add_lwpolyline([tuple(1e3 * p) for p in line], dxfattribs={"layer": "CRACKS"})
    doc.modelspace().add_lwpolyline([(0, 0), (1200, 0), (1200, 600), (0, 600)], close=True,
                                    dxfattribs={"layer": "OUTLINE"})
    doc.saveas(tmp_path / "survey.dxf")
    run = cli_run(["diagnose", "stepped-units", "--cracks", "survey.dxf", "--cracks-layer", "CRACKS", "--json",
                   "-o", "d.nc", "--no-progress", "--rerank", "0"], tmp_path)
    assert run.exit_code == 0, run.output
    best = json.loads(run.stdout)["candidates"][0]["settlement"]
    segment = best["segment"]
    assert best["profile"] == "step" and near(best["start"], [0.7], segment) or near(best["end"], [0.7], segment)
    spec = mf.load_spec(mf.bundled_spec_path("stepped-units"))
    bare = {k: v for k, v in spec.items() if k != "loading"}
    (tmp_path / "bare.toml").write_text(mf.dump_toml(bare))
    again = cli_run(["diagnose", "bare.toml", "--cracks", "survey.dxf", "--cracks-layer", "CRACKS", "--json",
                     "-o", "e.nc", "--no-progress", "--rerank", "0"], tmp_path)
    assert again.exit_code == 0, again.output
    assert json.loads(again.stdout)["candidates"][0]["settlement"] == best


def test_the_stand_in_ground_of_a_bare_spec_is_replaced():
    spec = mf.load_spec(mf.bundled_spec_path("test-12c"))
    bare = {k: v for k, v in spec.items() if k not in ("supports", "loading")}
    built = mf.build({**bare, **mf.STAND_IN_GROUND})
    a, b = mf.ground_model(built, SEGMENT), mf.ground_model(mf.open_model("test-12c"), SEGMENT)

    def boxes(model):
        bounds = np.c_[mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)]
        return bounds[np.lexsort(bounds[::-1])]

    np.testing.assert_allclose(boxes(a), boxes(b), atol=1e-12)
    assert a.sizes == b.sizes


def test_the_dataset_round_trips_its_candidates(diagnosis_12c, tmp_path):
    ds = to_dataset(diagnosis_12c, "test-12c")
    mf.save(ds, tmp_path / "d.nc")
    back = mf.open_dataset(tmp_path / "d.nc")
    assert mf.check(back) == []
    for k, candidate in enumerate(diagnosis_12c.candidates[:20]):
        assert str(back.candidate_profile.values[k]) == candidate.table["profile"]
        for key in ("start", "end", "center", "width"):
            value = float(back[f"candidate_{key}"].values[k])
            assert value == pytest.approx(candidate.table[key]) if key in candidate.table else np.isnan(value)
