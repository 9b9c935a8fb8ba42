"""Buildings in English and Flemish bond and in leaves: laid once, the bonds' rules on every course, unbound leaves
the planar wall."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from tests.core.test_core_building import MATERIAL, UNIT, box_bounds, house_spec, wall

LENGTH, HEIGHT, DEPTH = UNIT["length"], UNIT["height"], 0.12
BONDS = [{"bond": "running"}, {"bond": "english"}, {"bond": "english", "header_every": 4}, {"bond": "flemish"}]


def two_leaf(spec: dict, **bond) -> dict:
    """``spec`` with every wall two leaves (0.24 m) of units 0.12 m deep, in ``bond``."""
    spec["building"].update(bond, unit={**UNIT, "depth": DEPTH})
    for entry in spec["building"]["walls"]:
        entry["thickness"] = 2 * DEPTH
    return spec


@pytest.mark.parametrize("bond", BONDS, ids=lambda b: "-".join(map(str, b.values())))
def test_a_house_in_each_bond_is_laid_once_over_its_walls_and_loaded_once(bond):
    """The masonry fills the walls' footprint (centre lines 2.4 x 1.8 m, 0.24 m thick) times 1.2 m less the door
    and the window, exactly; no two blocks overlap; the floor on the top (odd) course carries its line load times
    the lengths the toothing leaves south (short of both corners, 2.4 - t) and north (2.4 m) once, whatever the
    leaves it is laid in."""
    model = mf.build(two_leaf(house_spec(), **bond))
    masonry = mfp.masonry_blocks(model.block_role.values)
    t = 2 * DEPTH
    expected = 2 * t * (2.4 + 1.8) * 1.2 - t * (0.48 * 0.72 + 0.48 * 0.36)
    assert model.block_volume.values[masonry].sum() == pytest.approx(expected, rel=1e-12)
    low, high = box_bounds(model)
    common = np.clip(np.minimum(high[:, None], high[None]) - np.maximum(low[:, None], low[None]), 0, None).prod(-1)
    np.fill_diagonal(common, 0.0)
    assert common.max() < 1e-12
    weight = MATERIAL["unit_weight"] * expected
    assert -model.dead_load.values[masonry, 2].sum() == pytest.approx(weight + 2000.0 * ((2.4 - t) + 2.4), rel=1e-12)
    mf.check(model)


def face_courses(model, length: float) -> list[list[tuple[float, float, bool]]]:
    """Course by course, the blocks showing on the wall's face (y = -t/2) of a wall along x: (x0, x1, whether it
    runs through the wall's thickness), left to right."""
    low, high = box_bounds(model)
    masonry = mfp.masonry_blocks(model.block_role.values)
    thickness = 2 * DEPTH
    courses = []
    for k in range(round(1.2 / HEIGHT)):
        on_face = masonry & np.isclose(low[:, 1], -0.5 * thickness) & np.isclose(low[:, 2], k * HEIGHT)
        order = np.argsort(low[on_face, 0])
        courses.append([(float(a), float(b), bool(np.isclose(c - d, thickness)))
                        for a, b, c, d in zip(low[on_face, 0][order], high[on_face, 0][order],
                                              high[on_face, 1][order], low[on_face, 1][order])])
        assert courses[-1][0][0] == pytest.approx(0.0) and courses[-1][-1][1] == pytest.approx(length)
    return courses


def inner_joints(course, length: float) -> np.ndarray:
    return np.array([b for _, b, _ in course[:-1] if LENGTH < b < length - LENGTH])


@pytest.mark.parametrize("bond", BONDS, ids=lambda b: "-".join(map(str, b.values())))
def test_every_course_follows_its_bonds_rules_on_the_face(bond):
    """A free-standing wall 4.8 m long, read off its face: English, a course of headers (through the wall, a
    header long) every ``header_every`` courses and stretchers (a unit long, one per leaf) between; Flemish,
    header and stretcher alternating and every header centred on a stretcher below; running, stretchers only.
    Away from the ends, head joints of courses one above the other are a quarter unit apart or more (half a unit
    in running bond): the lap that makes a bond."""
    length = 4.8
    spec = {"title": "wall", "building": {"unit": UNIT, "walls": [wall("w", (0, 0), (length, 0))]},
            "material": MATERIAL, "settlement": {"profile": "gaussian", "width": 0.8, "center_x": 1.9}}
    courses = face_courses(mf.build(two_leaf(spec, **bond)), length)
    every = bond.get("header_every", 2)
    for k, course in enumerate(courses):
        inner = [(a, b, through) for a, b, through in course if LENGTH < a and b < length - LENGTH]
        sizes = {round((b - a) / DEPTH, 9) for a, b, _ in inner}
        if bond["bond"] == "flemish":
            assert [through for *_, through in inner[:-1]] != [through for *_, through in inner[1:]]
            assert all((b - a == pytest.approx(DEPTH)) == through for a, b, through in inner)
        elif bond["bond"] == "english" and k % every == every - 1:
            assert all(through for *_, through in course) and sizes == {1.0}
        else:
            assert not any(through for *_, through in course) and sizes == {LENGTH / DEPTH}
    lap = LENGTH / (2 if bond["bond"] == "running" else 4)
    for below, above in zip(courses[:-1], courses[1:]):
        apart = np.abs(inner_joints(above, length)[:, None] - inner_joints(below, length)[None]).min()
        assert apart >= lap * (1 - 1e-9)
        if bond["bond"] == "flemish":
            stretchers = [0.5 * (a + b) for a, b, through in below if not through and b - a == pytest.approx(LENGTH)]
            for a, b, through in above:
                if through and LENGTH < a and b < length - LENGTH:
                    assert np.abs(np.array(stretchers) - 0.5 * (a + b)).min() == pytest.approx(0.0, abs=1e-12)


def test_two_unbound_leaves_in_running_bond_are_the_planar_wall():
    """Two leaves side by side with their joints in line and nothing but collar joints between them, under a trough
    whose axis runs across the wall: the planar wall's alpha. Each leaf carrying its own half of the planar wall's
    stresses is statically admissible (a lower bound), and the planar mechanism in both leaves kinematically
    admissible (an upper bound)."""
    planar = mf.build({"title": "wall", "wall": {"width": 2.4, "height": 1.2, "thickness": 0.24}, "unit": UNIT,
                       "bond": {"pattern": "running", "first_course": "full"}, "material": MATERIAL,
                       "settlement": {"profile": "gaussian", "width": 0.8, "center": 1.9, "segment": 0.06},
                       "loading": {"type": "settlement"}})
    spec = {"title": "wall", "building": {"unit": UNIT, "segment": 0.06, "walls": [wall("w", (0, 0), (2.4, 0))]},
            "material": MATERIAL, "settlement": {"profile": "gaussian", "width": 0.8, "center_x": 1.9}}
    leaves = mf.build(two_leaf(spec, bond="running"))
    assert int(mfp.masonry_blocks(leaves.block_role.values).sum()) == 2 * int(
        mfp.masonry_blocks(planar.block_role.values).sum())
    a, b = mf.solve(planar, "la"), mf.solve(leaves, "la")
    assert float(b.collapse_multiplier) == pytest.approx(float(a.collapse_multiplier), rel=1e-7)


@pytest.mark.parametrize("change, message", [
    (lambda s: s["building"].update(bond="english"), "wall 'south' in english bond is one leaf"),
    (lambda s: s["building"].update(bond="herringbone"), "'building.bond' = 'herringbone': must be one of"),
    (lambda s: two_leaf(s, bond="english", header_every=1), "'building.header_every' = 1: must be at least 2"),
    (lambda s: two_leaf(s, bond="flemish").update(), None),
    (lambda s: s["building"]["walls"][2].update(bond="flemish", thickness=0.3),
     "wall 'north' is 0.3 m thick, not a whole number of leaves of units 0.12 m deep"),
    (lambda s: two_leaf(s, bond="english")["building"]["walls"][1].update(header_every=2.5),
     "'building.walls\\[1\\].header_every' = 2.5: must be a whole number"),
])
def test_a_bad_bond_names_the_key_and_the_wall(change, message):
    spec = house_spec()
    change(spec)
    if message is None:  # the control: the same house two leaves thick in Flemish bond builds
        assert mf.build(spec).sizes["block"] > 0
        return
    with pytest.raises(mf.SpecError, match=message):
        mf.build(spec)


def test_headers_longer_than_a_unit_are_said():
    spec = two_leaf(house_spec(), bond="english")
    spec["building"]["unit"]["depth"] = 0.08
    for entry in spec["building"]["walls"]:
        entry["thickness"] = 0.32
    notes = mf.build(spec).attrs["laying_notes"]
    assert "wall 'south': its headers run through its 0.32 m thickness (units 0.24 m long)" in notes
