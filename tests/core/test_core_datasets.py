"""The ten bundled walls against the paper's numbers (datasets/README.md) and closed-form reactions."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw
from masonryfw import ModelError, build, bundled_cases, bundled_spec_path, load_spec
from masonryfw.plugin_api import flags

ROLE = flags("block_role")

# name: (title, units + lintels in the paper) -- datasets/README.md, paper sec. 3
PAPER = {
    "test-8c": ("Test 8C", 48),
    "test-12c": ("Test 12C", 72),
    "panel-1": ("Panel 1", 55),
    "panel-2": ("Panel 2", 55),
    "panel-3": ("Panel 3", 73),
    "panel-4": ("Panel 4", 73),
    "panel-5": ("Panel 5", 105),
    "facade-1": ("Facade 1", 320),
    "facade-2": ("Facade 2", 320),
    "facade-3": ("Facade 3", 480),
}
# name: (width, height, thickness, unit length, opening count, opening w x h, settling length) [m]
PAPER_GEOMETRY = {
    "test-8c": (1.1, 0.4, 0.1, 0.2, 0, None, 0.6),
    "test-12c": (1.1, 0.6, 0.1, 0.2, 0, None, 0.6),
    "panel-1": (0.6, 0.55, 0.05, 0.1, 1, (0.3, 0.25), 0.2),
    "panel-2": (0.6, 0.55, 0.05, 0.1, 1, (0.3, 0.25), 0.3),
    "panel-3": (0.4, 0.9, 0.05, 0.1, 2, (0.1, 0.25), 0.15),
    "panel-4": (0.4, 0.9, 0.05, 0.1, 2, (0.1, 0.25), 0.25),
    "panel-5": (0.4, 1.3, 0.1, 0.1, 3, (0.1, 0.25), 0.25),
    "facade-1": (1.5, 1.2, 0.05, 0.1, 4, (0.2, 0.35), 0.3),
    "facade-2": (1.5, 1.2, 0.05, 0.1, 4, (0.2, 0.35), 0.3),
    "facade-3": (1.5, 1.8, 0.05, 0.1, 6, (0.2, 0.35), 0.3),
}
GAMMA = 12000.0


@pytest.fixture(scope="module")
def models():
    return {name: build(bundled_spec_path(name)) for name in PAPER}


def test_bundled_cases_are_the_papers_ten_walls_with_their_titles():
    assert bundled_cases() == {name: title for name, (title, _) in PAPER.items()}


def test_an_unknown_case_name_lists_the_valid_ones():
    with pytest.raises(ModelError, match="facade-3") as info:
        bundled_spec_path("facade-4")
    assert "'facade-4'" in str(info.value)


def test_spec_paths_are_package_files_named_after_the_case():
    for name in PAPER:
        path = bundled_spec_path(name)
        assert path.is_file() and path.name == f"{name}.toml"


@pytest.mark.parametrize("name", list(PAPER))
def test_wall_matches_the_paper(models, name):
    ds = models[name]
    width, height, thickness, unit_length, n_openings, opening, settling = PAPER_GEOMETRY[name]
    spec = load_spec(ds.attrs["source_spec"])
    assert spec["title"] == PAPER[name][0]
    assert (spec["wall"]["width"], spec["wall"]["height"], spec["wall"]["thickness"]) == (width, height, thickness)
    assert (spec["unit"]["length"], spec["unit"]["height"]) == (unit_length, 0.05)
    assert spec["material"]["unit_weight"] == GAMMA and spec["material"]["friction_angle"] == 21.8
    assert len(spec.get("openings", [])) == n_openings
    assert all((o["width"], o["height"]) == opening for o in spec.get("openings", []))
    moving = [s for s in spec["supports"].values() if s["kind"] == "moving"]
    assert len(moving) == 1 and moving[0]["end"] - moving[0]["start"] == pytest.approx(settling)
    # block count: units + lintels (supports not counted) within 10 % of the paper's
    masonry = int(np.sum(ds.block_role.values <= ROLE["lintel"]))
    assert abs(masonry - PAPER[name][1]) <= 0.1 * PAPER[name][1]
    assert np.all(ds.interface_friction.values == pytest.approx(0.4, rel=1e-4))


def base_contact(spec, support) -> float:
    """Length of wall base resting on a support range: the range minus the doors standing on it."""
    doors = [(o["x"], o["x"] + o["width"]) for o in spec.get("openings", []) if o["y"] == 0.0]
    overlap = sum(max(0.0, min(b, support["end"]) - max(a, support["start"])) for a, b in doors)
    return support["end"] - support["start"] - overlap


@pytest.mark.parametrize("name", list(PAPER))
def test_settlement_loads_follow_the_papers_convention(models, name):
    ds = models[name]
    spec = load_spec(ds.attrs["source_spec"])
    width, height, thickness, _, _, _, _ = PAPER_GEOMETRY[name]
    open_area = sum(o["width"] * o["height"] for o in spec.get("openings", []))
    weight = GAMMA * thickness * (width * height - open_area)  # closed form W
    masonry = ds.block_role.values <= ROLE["lintel"]
    assert -ds.dead_load.values[masonry, 1].sum() == pytest.approx(weight, rel=1e-12)

    total_contact = sum(base_contact(spec, s) for s in spec["supports"].values())
    moving = np.flatnonzero(ds.block_role.values == ROLE["moving_support"])
    specs_moving = [s for s in spec["supports"].values() if s["kind"] == "moving"]
    reactions = ds.dead_load.values[moving, 1]
    expected = [weight * base_contact(spec, s) / total_contact for s in specs_moving]
    assert reactions == pytest.approx(expected, rel=1e-12)
    assert np.array_equal(ds.live_load.values[moving], -ds.dead_load.values[moving])
    others = ds.block_role.values != ROLE["moving_support"]
    assert np.all(ds.live_load.values[others] == 0.0)


def test_every_case_has_its_picture():
    for name in PAPER:
        assert bundled_spec_path(name).parent.joinpath("img", f"{name}.png").is_file()


def test_bundled_models_pass_the_checks(models):
    for name, ds in models.items():
        assert masonryfw.check(ds) == [], name
