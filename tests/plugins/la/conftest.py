"""Test-only construction of FORMAT.md models from axis-aligned rectangles, by hand.

Independent of the core builder on purpose: the closed-form tests need exact
control of the geometry, supports and loads.
"""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import masonryfw as mf

ROLE = mf.flags("block_role")
KIND = mf.flags("interface_kind")


def rectangle_contacts(rects: np.ndarray, tol: float = 1e-9):
    """Shared edges of axis-aligned rectangles ``(x0, y0, x1, y1)``: pairs, end points, horizontal?"""
    x0, y0, x1, y1 = (rects[:, k] for k in range(4))
    scale = np.ptp(rects) or 1.0
    pairs, xs, ys, horizontal = [], [], [], []
    # i below j: top of i on bottom of j
    touch = np.isclose(y1[:, None], y0[None, :], atol=tol * scale)
    lo = np.maximum(x0[:, None], x0[None, :])
    hi = np.minimum(x1[:, None], x1[None, :])
    i, j = np.nonzero(touch & (hi - lo > tol * scale))
    pairs.append(np.c_[i, j]); xs.append(np.c_[lo[i, j], hi[i, j]]); ys.append(np.c_[y1[i], y1[i]])
    horizontal.append(np.ones(i.size, bool))
    # i left of j: right of i on left of j
    touch = np.isclose(x1[:, None], x0[None, :], atol=tol * scale)
    lo = np.maximum(y0[:, None], y0[None, :])
    hi = np.minimum(y1[:, None], y1[None, :])
    i, j = np.nonzero(touch & (hi - lo > tol * scale))
    pairs.append(np.c_[i, j]); xs.append(np.c_[x1[i], x1[i]]); ys.append(np.c_[lo[i, j], hi[i, j]])
    horizontal.append(np.zeros(i.size, bool))
    return np.concatenate(pairs), np.concatenate(xs), np.concatenate(ys), np.concatenate(horizontal)


def rect_model(
    rects,
    roles,
    *,
    mu=0.4,
    unit_weight=12e3,
    thickness=0.1,
    loading="tilt",
    cohesion=0.0,
    tensile_strength=0.0,
    length_unit=1.0,
):
    """A model of rectangles in metres (times ``length_unit`` for the coordinates).

    ``loading="tilt"``: horizontal live load = weight on every unit, supports fixed.
    ``loading="settlement"``: the paper's convention (moving supports translate down,
    dead load up = W * contact length / total contact length, live load the same down).
    Loads are computed in metres and are the same whatever ``length_unit``; moments are zero.
    """
    rects = np.asarray(rects, dtype=float)
    roles = np.asarray(roles, dtype=np.int8)
    n = len(rects)
    x0, y0, x1, y1 = rects.T
    node_x = np.c_[x0, x1, x1, x0].ravel()
    node_y = np.c_[y0, y0, y1, y1].ravel()
    pairs, ix, iy, horizontal = rectangle_contacts(rects)
    support = np.isin(roles, [ROLE["fixed_support"], ROLE["moving_support"]])
    kind = np.where(horizontal, KIND["bed"], KIND["head"]).astype(np.int8)
    kind[support[pairs].any(axis=1)] = KIND["support"]
    weight = np.where(support, 0.0, unit_weight * (x1 - x0) * (y1 - y0) * thickness)
    dead = np.zeros((n, 3))
    live = np.zeros((n, 3))
    dead[:, 1] = -weight
    fixed = np.zeros((n, 3), np.int8)
    direction = np.zeros((n, 3))
    fixed[roles == ROLE["fixed_support"]] = 1
    moving = roles == ROLE["moving_support"]
    fixed[moving] = (1, 0, 1)
    direction[moving] = (0, -1, 0)
    if loading == "tilt":
        live[:, 0] = weight
    else:
        length = np.abs(ix[:, 1] - ix[:, 0]) + np.abs(iy[:, 1] - iy[:, 0])
        sup = support[pairs]
        wall_on_support = sup.any(axis=1) & ~sup.all(axis=1)
        support_block = np.where(sup[:, 0], pairs[:, 0], pairs[:, 1])[wall_on_support]
        contact = np.bincount(support_block, weights=length[wall_on_support], minlength=n)
        share = weight.sum() * contact / contact.sum()
        dead[moving, 1] = share[moving]
        live[moving, 1] = -share[moving]
    ds = xr.Dataset(
        {
            "node_x": ("node", node_x * length_unit),
            "node_y": ("node", node_y * length_unit),
            "block_node_count": ("block", np.full(n, 4, np.int32)),
            "block_role": ("block", roles),
            "block_thickness": ("block", np.full(n, thickness * length_unit)),
            "block_unit_weight": ("block", np.where(support, 0.0, unit_weight / length_unit**3)),
            "interface_blocks": (("interface", "side"), pairs.astype(np.int32)),
            "interface_x": (("interface", "end"), ix * length_unit),
            "interface_y": (("interface", "end"), iy * length_unit),
            "interface_kind": ("interface", kind),
            "interface_friction": ("interface", np.full(len(pairs), mu, dtype=float)),
            "interface_cohesion": ("interface", np.full(len(pairs), cohesion / length_unit**2)),
            "interface_tensile_strength": ("interface", np.full(len(pairs), tensile_strength / length_unit**2)),
            "dead_load": (("block", "dof"), dead),
            "live_load": (("block", "dof"), live),
            "block_fixed": (("block", "dof"), fixed),
            "settlement_direction": (("block", "dof"), direction),
        },
        coords={"dof": ["ux", "uy", "rz"]},
        attrs={"title": "test wall"},
    )
    return mf.derive_geometry(ds)


def running_bond(n_courses, width, unit_length, unit_height, *, half_first=True, y0=0.0):
    """Rectangles of a running-bond wall ``width`` wide, courses from ``y0`` up.

    Courses alternate between starting at the left with a half unit and with a
    full unit (the bottom course with a half unit when ``half_first``); a course
    ends wherever the width ends.
    """
    rects = []
    for course in range(n_courses):
        first = unit_length / 2 if (course % 2 == 0) == half_first else unit_length
        cuts = np.r_[0.0, np.arange(first, width - 1e-9 * width, unit_length), width]
        y = y0 + course * unit_height
        rects += [(a, y, b, y + unit_height) for a, b in zip(cuts[:-1], cuts[1:])]
    return np.array(rects)


def ferris_tin_loi_wall(length_unit=1.0):
    """Ferris & Tin-Loi (2001) wall 1: 6 courses of 0.4 x 0.175 m units in running bond (33 units),
    2.0 x 1.05 m on a fixed base, mu = 0.65, horizontal live load = weight; published lambda 0.643."""
    units = running_bond(6, 2.0, 0.4, 0.175, half_first=True)
    rects = np.vstack([(-0.2, -0.175, 2.2, 0.0), units])
    roles = [ROLE["fixed_support"]] + [ROLE["unit"]] * len(units)
    return rect_model(rects, roles, mu=0.65, length_unit=length_unit)


class Walls:
    """Factories shared by the la tests (pytest fixture ``walls``)."""

    rect_model = staticmethod(rect_model)
    running_bond = staticmethod(running_bond)
    ferris_tin_loi_wall = staticmethod(ferris_tin_loi_wall)
    ROLE = ROLE

    @staticmethod
    def options(**given):
        import masonryfw_la

        (solver,) = masonryfw_la.masonryfw_solvers()
        resolved = {o.name: o.default for o in solver.options}
        resolved.update(given)
        return resolved

    @staticmethod
    def solve(model, **given):
        """The plugin's solve function called directly; the model with the result variables."""
        import masonryfw_la

        (solver,) = masonryfw_la.masonryfw_solvers()
        result = solver.solve(model, Walls.options(**given), mf.no_progress)
        merged = model.assign(result.data_vars)
        merged.attrs = {**model.attrs, **result.attrs}
        return merged


@pytest.fixture
def walls():
    return Walls
