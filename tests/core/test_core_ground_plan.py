"""The ground in plan with a tunnel's face: the closed forms against point sinks summed along the excavated tunnel,
the plane trough far behind the face, and the engineers' stages on the surface it leaves."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import trapezoid

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.ground.assessment import ltsm_parts, wall_profile
from masonryfw.ground.ground_plan import GroundInPlan, SurfaceCut
from masonryfw.ground.profiles import Profile
from tests.core.test_core_building import house_spec

WIDTH, DEPTH = 3.0, 6.0  # i and z0 [m]
TROUGH = Profile("tunnel", 0.1, 0.01, center=0.0, width=WIDTH, depth=DEPTH)
ANGLE = math.radians(60.0)
ACROSS = np.array([math.sin(ANGLE), -math.cos(ANGLE)])
POINT = np.array([1.0, -2.0])


def sinks(u: np.ndarray, v: np.ndarray, face: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Settlement and horizontal motion (across, along the axis) per unit S_max summed over point sinks at every
    station eta behind the face, each settling the surface by a Gaussian bell of width i about it (volume
    S_max sqrt(2 pi) i per metre of tunnel) and moving it horizontally towards it by (distance / z0) times that:
    the quadrature of the model the closed forms integrate."""
    eta = np.linspace(face - 14 * WIDTH, face, 40001)
    bell = np.exp(-0.5 * (u[:, None] ** 2 + (v[:, None] - eta) ** 2) / WIDTH**2) / (math.sqrt(2 * math.pi) * WIDTH)
    far = np.exp(-0.5 * u**2 / WIDTH**2) * (1 - 0.5 * math.erfc(-14 / math.sqrt(2)))  # sinks beyond 14 i
    settlement = trapezoid(bell, eta, axis=1) + far
    across = -u / DEPTH * settlement
    along = trapezoid(-(v[:, None] - eta) / DEPTH * bell, eta, axis=1)
    return settlement, across, along


@pytest.mark.parametrize("face", [-4.0, 0.0, 2.5])
def test_the_face_closed_forms_are_point_sinks_summed_along_the_excavated_tunnel(face):
    ground = GroundInPlan(TROUGH, POINT, ACROSS, face)
    rng = np.random.default_rng(7)
    u, v = rng.uniform(-8, 8, 60), rng.uniform(face - 9, face + 9, 60)
    xy = POINT + u[:, None] * ACROSS + v[:, None] * ground.axis
    rate, horizontal = ground.greenfield(xy)
    settlement, across, along = sinks(u, v, face)
    np.testing.assert_allclose(rate, settlement, atol=1e-9)
    np.testing.assert_allclose(horizontal @ ACROSS, across, atol=1e-9)
    np.testing.assert_allclose(horizontal @ ground.axis, along, atol=1e-9)


def test_at_the_face_half_the_trough_far_behind_it_all_far_ahead_none():
    ground = GroundInPlan(TROUGH, POINT, ACROSS, 3.0)
    u = np.array([0.0, 1.5, -4.0])
    for v, share in ((3.0, 0.5), (3.0 - 40 * WIDTH, 1.0), (3.0 + 40 * WIDTH, 0.0)):
        rate, _ = ground.greenfield(POINT + u[:, None] * ACROSS + v * ground.axis)
        np.testing.assert_allclose(rate, share * TROUGH.rate(u), atol=1e-15)


def test_a_walls_cut_is_the_trough_far_behind_the_face_and_turns_at_the_face_along_the_axis():
    """Far behind the face a wall's cut (sampled, inflections found on the curve) gives the closed-form wall
    profile's LTSM parts; a wall along the axis over the tunnel bends only at the face (Phi'' = 0 there)."""
    start, along = POINT + 1.0 * ACROSS, np.array([1.0, 0.0])
    behind = SurfaceCut(GroundInPlan(TROUGH, POINT, ACROSS, 1e4), start, along)
    closed = wall_profile(TROUGH, float((start - POINT) @ ACROSS), float(along @ ACROSS))
    for a, b in zip(ltsm_parts(behind, -6.0, 9.0, 3.0), ltsm_parts(closed, -6.0, 9.0, 3.0)):
        assert (a.start, a.end, a.sagging) == pytest.approx((b.start, b.end, b.sagging), abs=1e-4)
        assert a.strain == pytest.approx(b.strain, rel=1e-6)
    ground = GroundInPlan(TROUGH, POINT, ACROSS, 2.0)
    on_axis = SurfaceCut(ground, POINT, ground.axis)
    assert on_axis.inflections(-8.0, 10.0, 2001) == pytest.approx([2.0], abs=1e-3 * WIDTH)


def house_with_face(face):
    spec = house_spec()
    if face is not None:
        spec["settlement"]["face"] = face
    return mf.build(spec)


def test_a_face_far_ahead_is_the_plane_trough_and_the_house_feels_it_as_it_nears():
    """The house with the face 1 km ahead of the axis point is the house over the plane trough (its segments'
    motions to 1e-12, alpha); with the face under it, its ground moves along the axis too and settles less."""
    plane, far = house_with_face(None), house_with_face(1000.0)
    np.testing.assert_allclose(far.settlement_direction.values, plane.settlement_direction.values, atol=1e-12)
    assert float(mf.solve(far, "la").collapse_multiplier) == pytest.approx(
        float(mf.solve(plane, "la").collapse_multiplier), rel=1e-9)
    near = house_with_face(0.5)
    moving = near.block_role.values == mfp.flags("block_role")["moving_support"]
    assert -near.settlement_direction.values[moving, 2].sum() < -plane.settlement_direction.values[moving, 2].sum()
    axis = np.array([math.cos(math.radians(60.0)), math.sin(math.radians(60.0))])
    assert (near.settlement_direction.values[moving, :2] @ axis).max() < 0  # back towards the excavated tunnel
    assert mfp.assess(near, 0.01).greenfield_settlement < mfp.assess(plane, 0.01).greenfield_settlement


def test_a_face_needs_a_trough():
    spec = house_spec(profile="linear", start=0.0, end=3.0, axis_angle=60.0, face=1.0)
    with pytest.raises(mf.SpecError, match="'settlement.face': a tunnel's face bounds a trough"):
        mf.build(spec)
