"""Polyhedra in 3D: volumes, centroids and contacts against closed forms."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw.plugin_api as mfp


def rotated(poly: mfp.Polyhedra, angle: float, shift=(0.0, 0.0, 0.0)) -> mfp.Polyhedra:
    """``poly`` turned by ``angle`` about z and moved by ``shift``."""
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return poly._replace(vertices=poly.vertices @ turn.T + np.asarray(shift))


def test_boxes_volume_centroid_and_outward_faces():
    lower, upper = np.array([[0.0, 0.0, 0.0], [1.0, -2.0, 3.0]]), np.array([[2.0, 1.0, 0.5], [1.5, 0.0, 7.0]])
    poly = mfp.boxes(lower, upper)
    volume, centroid = mfp.volumes_centroids(poly)
    assert volume == pytest.approx(np.prod(upper - lower, axis=1), rel=1e-14)
    assert centroid == pytest.approx(0.5 * (lower + upper), rel=1e-14)
    normal, area, face_centre = mfp.face_normals_areas(poly)
    outward = np.einsum("ij,ij->i", normal, face_centre - np.repeat(centroid, 6, axis=0))
    assert (outward > 0).all()
    size = upper - lower
    assert area[:6] == pytest.approx([size[0, 0] * size[0, 1]] * 2 + [size[0, 0] * size[0, 2]] * 2
                                     + [size[0, 1] * size[0, 2]] * 2)


def test_prism_of_a_non_convex_polygon():
    """An L-shaped polygon (area 3, centroid (5/6, 5/6)) stood 0.4 deep: volume 1.2, centroid (5/6, 0, 5/6)."""
    x, y = np.array([0.0, 2.0, 2.0, 1.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0, 2.0, 2.0])
    poly = mfp.prisms(x, y, np.array([6]), np.array([0.4]))
    volume, centroid = mfp.volumes_centroids(poly)
    assert volume == pytest.approx([1.2], rel=1e-14)
    assert centroid[0] == pytest.approx([5 / 6, 0.0, 5 / 6], abs=1e-14)
    normal, area, _ = mfp.face_normals_areas(poly)
    assert area.sum() == pytest.approx(2 * 3.0 + 0.4 * 8.0)
    assert normal[0] == pytest.approx([0, -1, 0]) and normal[1] == pytest.approx([0, 1, 0])


def test_contacts_of_offset_boxes_are_the_common_rectangles():
    """A box on a base, shifted so that they share 0.6 x 0.5; a second beside the first (head joint 1 x 1)."""
    poly = mfp.boxes([[0, 0, -1], [0.4, 0.5, 0], [1.4, 0.5, 0]], [[1, 1, 0], [1.4, 1.5, 1], [2.4, 1.5, 1]])
    contacts = mfp.find_contacts(poly, 1e-9)
    found = {tuple(s): i for i, s in enumerate(contacts.sides)}
    assert set(found) == {(0, 1), (1, 2)}
    bed, head = found[(0, 1)], found[(1, 2)]
    assert contacts.area[bed] == pytest.approx(0.6 * 0.5) and contacts.area[head] == pytest.approx(1.0)
    assert contacts.normal[bed] == pytest.approx([0, 0, 1]) and contacts.normal[head] == pytest.approx([1, 0, 0])
    for i in (bed, head):
        t = contacts.tangent[i]
        assert np.cross(t[0], t[1]) == pytest.approx(contacts.normal[i])
    start = contacts.point_count[:bed].sum()
    corners = contacts.points[start:start + contacts.point_count[bed]]
    assert sorted(map(tuple, np.round(corners, 12))) == [(0.4, 0.5, 0.0), (0.4, 1.0, 0.0), (1.0, 0.5, 0.0),
                                                         (1.0, 1.0, 0.0)]


def test_contacts_do_not_depend_on_the_frame_or_the_order_of_blocks():
    """The same stack turned by 0.3 rad and moved, and listed backwards: the same contact areas per pair."""
    poly = mfp.boxes([[0, 0, -1], [0.2, 0.1, 0], [0.3, 0.2, 1]], [[2, 1, 0], [1.2, 0.9, 1], [1.0, 0.8, 1.5]])
    reference = mfp.find_contacts(poly, 1e-9)
    moved = mfp.find_contacts(rotated(poly, 0.3, (5.0, -2.0, 1.0)), 1e-9)
    backwards = mfp.boxes(poly.vertices.reshape(-1, 8, 3)[::-1, 0], poly.vertices.reshape(-1, 8, 3)[::-1, 7])
    reordered = mfp.find_contacts(backwards, 1e-9)

    def areas(contacts, relabel=lambda b: b):
        return {tuple(sorted(relabel(s))): a for s, a in zip(contacts.sides.tolist(), contacts.area)}

    expected = areas(reference)
    assert expected == pytest.approx({(0, 1): 0.8, (1, 2): 0.42})
    assert areas(moved) == pytest.approx(expected)
    assert areas(reordered, lambda s: [2 - b for b in s]) == pytest.approx(expected)


def test_faces_that_only_touch_along_a_line_or_within_the_tolerance_are_no_contact():
    """Edge to edge (a line), a sliver thinner than the tolerance, and a gap wider than it: no interface."""
    poly = mfp.boxes([[0, 0, 0], [1, 1, 0], [0, 0.9999995, 1], [1.5, 0, 0], [2.6, 0, 0]],
                     [[1, 1, 1], [2, 2, 1], [1, 2, 2], [2.5, 1, 1], [3.6, 1, 1]])
    contacts = mfp.find_contacts(poly, 1e-6)
    pairs = {tuple(sorted(s)) for s in contacts.sides.tolist()}
    assert (0, 1) not in pairs and (0, 2) not in pairs and (3, 4) not in pairs


def test_second_moments_of_a_non_convex_prism_add_up_from_its_boxes():
    """The L-shaped prism against its two boxes moved to its centroid (the parallel-axis theorem)."""
    x, y = np.array([0.0, 2.0, 2.0, 1.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0, 2.0, 2.0])
    prism = mfp.prisms(x, y, np.array([6]), np.array([0.4]))
    parts = mfp.boxes([[0, -0.2, 0], [0, -0.2, 1]], [[2, 0.2, 1], [1, 0.2, 2]])
    volume, centre = mfp.volumes_centroids(parts)
    whole = (volume[:, None] * centre).sum(axis=0) / volume.sum()
    arm = centre - whole
    expected = (mfp.second_moments(parts) + volume[:, None, None] * np.einsum("bi,bj->bij", arm, arm)).sum(axis=0)
    np.testing.assert_allclose(mfp.second_moments(prism)[0], expected, atol=1e-14)
    box = mfp.boxes([[1, 2, 3]], [[1.5, 2.4, 4]])
    np.testing.assert_allclose(mfp.second_moments(box)[0], np.diag(0.2 * np.array([0.5, 0.4, 1.0]) ** 2 / 12),
                               atol=1e-15)
