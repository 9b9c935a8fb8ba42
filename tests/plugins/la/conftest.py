"""Walls of the la tests: rectangles through the kit's helper (:func:`masonryfw.testing.rectangles_model`)."""
from __future__ import annotations

from functools import partial

import numpy as np
import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

ROLE = mfp.flags("block_role")


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
    return mt.rectangles_model(rects, roles, friction=0.65, loading="tilt", length_unit=length_unit)


def static_alpha(model) -> float:
    """The largest multiplier of the live load that contact forces can equilibrate: the static (lower-bound)
    limit analysis LP, written here from the geometry alone, independently of the la plugin.

    Unknowns: per interface end a normal force N (compression positive) and a shear
    force T, and alpha. Every free block is in equilibrium under its dead load, alpha
    times its live load and the contact forces (forces and moment about its
    centroid); a moving support, which may move only along its settlement direction
    ``d``, is in equilibrium along ``d``. Every end obeys the joint's strength:
    ``N >= -a_t``, ``|T| <= a_c + mu N`` (``a_c = c A``, ``a_t = min(ft, c / mu) A``, A
    the end's half of the contact area). Interfaces between two supports carry nothing.
    Maximise alpha with HiGHS. By the static theorem (and LP duality) this is the
    collapse multiplier of the associative kinematic programme.
    """
    import scipy.sparse as sp
    from scipy.optimize import linprog

    blocks = model.interface_blocks.values.astype(int)
    n_if, n_block = blocks.shape[0], model.sizes["block"]
    role = model.block_role.values
    support = np.isin(role, [ROLE["fixed_support"], ROLE["moving_support"]])
    active = ~support[blocks].all(axis=1)
    nx, ny = model.interface_normal_x.values, model.interface_normal_y.values
    tx, ty = model.interface_tangent_x.values, model.interface_tangent_y.values
    cx, cy = model.block_centroid_x.values, model.block_centroid_y.values
    n_var = 4 * n_if + 1  # N0, N1, T0, T1 per interface, alpha last
    rows, cols, vals = [], [], []
    for i in np.flatnonzero(active):
        for end in (0, 1):
            px, py = model.interface_x.values[i, end], model.interface_y.values[i, end]
            for side, sign in ((0, -1.0), (1, 1.0)):
                b = blocks[i, side]
                for var, (fx, fy) in ((4 * i + end, (nx[i], ny[i])), (4 * i + 2 + end, (tx[i], ty[i]))):
                    moment = (px - cx[b]) * fy - (py - cy[b]) * fx
                    for dof, value in enumerate((fx, fy, moment)):
                        rows.append(3 * b + dof), cols.append(var), vals.append(sign * value)
    contact = sp.csr_matrix((vals, (rows, cols)), shape=(3 * n_block, n_var))
    # forces over the largest load, so that HiGHS's absolute tolerances (1e-7) are relative ones: unscaled,
    # the LACT3 portal's 7 kN blocks end 2e-5 short of the optimum
    force = max(np.abs(mfp.block_loads(model, "dead")).max(), np.abs(mfp.block_loads(model, "live")).max())
    dead = mfp.block_loads(model, "dead").ravel() / force
    live = mfp.block_loads(model, "live").ravel() / force
    total = (contact + sp.csr_matrix((live, (np.arange(3 * n_block), np.full(3 * n_block, n_var - 1))),
                                     shape=(3 * n_block, n_var))).tocsr()
    free = ((model.block_fixed.values == 0) & ~support[:, None]).ravel()
    moving = np.flatnonzero(role == ROLE["moving_support"])
    direction = model.settlement_direction.values
    equations = [total[free]]
    rhs = [-dead[free]]
    if moving.size:  # one shared settlement parameter: the moving supports together, along their directions
        weights = np.zeros(3 * n_block)
        for b in moving:
            weights[3 * b:3 * b + 3] = direction[b]
        equations.append(sp.csr_matrix(weights @ total))
        rhs.append([-(weights @ dead)])
    half_area = 0.5 * model.interface_length.values * model.block_thickness.values[blocks].min(axis=1)
    mu = model.interface_friction.values
    cohesion = model.interface_cohesion.values
    cap = np.where(mu > 0, cohesion / np.where(mu > 0, mu, 1.0), np.inf)
    a_c = cohesion * half_area / force
    a_t = np.minimum(model.interface_tensile_strength.values, cap) * half_area / force
    ends = np.array([(i, end) for i in np.flatnonzero(active) for end in (0, 1)]).reshape(-1, 2)
    k = np.arange(2 * len(ends))
    row_if, row_end = np.tile(ends[:, 0], 2), np.tile(ends[:, 1], 2)
    sign = np.repeat([1.0, -1.0], len(ends))  # sign T - mu N <= a_c
    upper = sp.csr_matrix((np.concatenate([sign, -mu[row_if]]), (np.concatenate([k, k]),
                           np.concatenate([4 * row_if + 2 + row_end, 4 * row_if + row_end]))), shape=(k.size, n_var))
    bounds = [(None, None)] * n_var
    for i in range(n_if):
        for end in (0, 1):
            bounds[4 * i + end] = (-a_t[i], None) if active[i] else (0.0, 0.0)
            bounds[4 * i + 2 + end] = (None, None) if active[i] else (0.0, 0.0)
    cost = np.zeros(n_var)
    cost[-1] = -1.0
    res = linprog(cost, A_ub=upper, b_ub=a_c[row_if], A_eq=sp.vstack(equations),
                  b_eq=np.concatenate(rhs), bounds=bounds, method="highs")
    assert res.status == 0, res.message
    return float(res.x[-1])


class Walls:
    """Factories shared by the la tests (pytest fixture ``walls``); ``rect_model`` loads by tilting by default."""

    rect_model = staticmethod(partial(mt.rectangles_model, loading="tilt"))
    running_bond = staticmethod(running_bond)
    ferris_tin_loi_wall = staticmethod(ferris_tin_loi_wall)
    static_alpha = staticmethod(static_alpha)
    ROLE = ROLE

    @staticmethod
    def solve(model, **given):
        """``mf.solve(model, "la", given)``: the result with the core's comparable fields."""
        return mf.solve(model, "la", given)


@pytest.fixture
def walls():
    return Walls


def first_nonassociative_lp(case: str):
    """The first LP of the non-associative sequence on a bundled wall: capacities from the associative normal
    forces (HiGHS's vertex)."""
    from masonryfw_la import assembly, backends, nonassociative

    model = mf.open_model(case)
    wall = assembly.Wall.from_model(model)
    scales = assembly.model_scales(model, wall)
    kin = assembly.interface_kinematics(wall, scales)
    lp = assembly.assemble(wall, scales, kin)
    first = backends.solve_lp("highs", lp.cost, lp.constraints, lp.live, 1e-10)
    normal = nonassociative.end_normal_forces(lp, first.y, wall.n_interface, scales)
    return assembly.assemble(wall, scales, kin, normal_force=normal)


@pytest.fixture
def nonassociative_lp():
    """:func:`first_nonassociative_lp`."""
    return first_nonassociative_lp
