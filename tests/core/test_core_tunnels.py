"""Tunnels and the engineers' stages 1 and 2: the trough from the tunnel's parameters (closed forms), the
LTSM strains against a Timoshenko deep beam solved numerically, and the assessment every result carries."""
from __future__ import annotations

import math

import numpy as np
import pytest

import masonryfw as mf
from masonryfw.assessment import E_OVER_G, deep_beam_strains, ltsm_category, ltsm_parts
from masonryfw.profiles import Profile


def timoshenko_midspan_deflection(load: float, length: float, bending_stiffness: float, shear_stiffness: float,
                                  elements: int = 8) -> float:
    """Midspan deflection of a simply supported Timoshenko beam under a central point load, from a finite-
    element model of two-node elements with the exact (interdependent interpolation) stiffness: a second
    formulation of the beam, solved numerically."""
    h = length / elements
    phi = 12.0 * bending_stiffness / (shear_stiffness * h**2)
    k = bending_stiffness / (h**3 * (1.0 + phi)) * np.array([
        [12.0, 6.0 * h, -12.0, 6.0 * h],
        [6.0 * h, (4.0 + phi) * h**2, -6.0 * h, (2.0 - phi) * h**2],
        [-12.0, -6.0 * h, 12.0, -6.0 * h],
        [6.0 * h, (2.0 - phi) * h**2, -6.0 * h, (4.0 + phi) * h**2]])
    n = 2 * (elements + 1)
    stiffness = np.zeros((n, n))
    for e in range(elements):
        dofs = slice(2 * e, 2 * e + 4)
        stiffness[dofs, dofs] += k
    force = np.zeros(n)
    force[2 * (elements // 2)] = load
    free = np.setdiff1d(np.arange(n), [0, n - 2])  # the ends held vertically, free to turn
    w = np.zeros(n)
    w[free] = np.linalg.solve(stiffness[np.ix_(free, free)], force[free])
    return float(w[2 * (elements // 2)])


@pytest.mark.parametrize("sagging", [True, False])
@pytest.mark.parametrize(("length", "height"), [(10.0, 6.0), (4.0, 8.0), (25.0, 3.0)])
def test_ltsm_strains_are_those_of_the_timoshenko_deep_beam(sagging, length, height):
    """The beam of Burland & Wroth: neutral axis at mid-height (sagging) or at the bottom (hogging), E/G = 2.6,
    shear area 2/3 H (the 1.5 peak of the parabolic shear stress), bent by a central load to a deflection
    ratio: its extreme fibre bending strain M t / (E I) and its diagonal strain at the supports (half the
    peak shear strain) equal the LTSM's closed forms to 1e-9."""
    young = 1.0e9
    shear = young / E_OVER_G
    t, inertia = (height / 2, height**3 / 12) if sagging else (height, height**3 / 3)
    ratio = 1.0e-3
    unit = timoshenko_midspan_deflection(1.0, length, young * inertia, shear * 2.0 / 3.0 * height)
    load = ratio * length / unit
    bending = load * length / 4.0 * t / (young * inertia)
    diagonal = 0.5 * 1.5 * (load / 2.0) / height / shear
    eps_b, eps_d = deep_beam_strains(ratio, length, height, sagging)
    assert eps_b == pytest.approx(bending, rel=1e-9)
    assert eps_d == pytest.approx(diagonal, rel=1e-9)


def gaussian(center: float, width: float, depth: float | None = None) -> Profile:
    return Profile("gaussian", 0.25, 0.0, center=center, width=width, depth=depth)


def test_ltsm_parts_split_at_the_inflection_points_and_read_the_trough():
    """A wall from x = 0 to 20 m under a trough centred at 12 m with i = 5 m: parts [0, 7] hogging, [7, 17]
    sagging, [17, 20] hogging. Each part's deflection ratio is the largest gap between the Gaussian and its
    chord (found here by a second route, a dense evaluation); its horizontal strain the O'Reilly & New
    motion's difference over its length."""
    profile = gaussian(12.0, 5.0, depth=10.0)
    parts = ltsm_parts(profile, 0.0, 20.0, 6.0)
    assert [(p.start, p.end, p.sagging) for p in parts] == [(0.0, 7.0, False), (7.0, 17.0, True), (17.0, 20.0, False)]
    for part in parts:
        x = np.linspace(part.start, part.end, 1_000_001)
        s = np.exp(-0.5 * ((x - 12.0) / 5.0) ** 2)
        chord = s[0] + (s[-1] - s[0]) * (x - x[0]) / (x[-1] - x[0])
        assert part.deflection_ratio == pytest.approx(np.abs(s - chord).max() / (part.end - part.start), rel=1e-9)
        h = -(np.array([part.start, part.end]) - 12.0) / 10.0 * np.exp(-0.5 * ((np.array([part.start, part.end]) - 12.0) / 5.0) ** 2)
        assert part.horizontal_strain == pytest.approx((h[1] - h[0]) / (part.end - part.start), rel=1e-12)
    assert parts[1].horizontal_strain < 0 < parts[0].horizontal_strain  # compression in sagging, tension beyond


def test_ltsm_category_counts_the_limits_reached():
    np.testing.assert_array_equal(ltsm_category([0.0, 4.99e-4, 5e-4, 7.5e-4, 1.49e-3, 1.5e-3, 3e-3, 0.1]),
                                  [0, 0, 1, 2, 2, 3, 4, 4])


TUNNEL = {"profile": "tunnel", "volume_loss": 1.0, "diameter": 6.0, "depth": 15.0, "trough_width_factor": 0.5,
          "center": 10.0}
FACADE = {"title": "facade", "length_unit": "m", "wall": {"width": 8.0, "height": 3.0, "thickness": 0.25},
          "unit": {"length": 0.25, "height": 0.125}, "material": {"unit_weight": 18000.0, "friction_angle": 30.0},
          "loading": {"type": "settlement"}}


def test_tunnel_trough_is_the_closed_form():
    """i = K z0, S_max = V_L pi D^2 / 4 / (sqrt(2 pi) i), S_v and S_h: the model records S_max as its
    settlement_target and the greenfield profile it was built over; the ground follows S_v / S_max per unit t."""
    model = mf.build({**FACADE, "settlement": TUNNEL})
    i = 0.5 * 15.0
    s_max = 0.01 * math.pi * 6.0**2 / 4.0 / (math.sqrt(2.0 * math.pi) * i)
    assert float(model.settlement_target) == pytest.approx(s_max, rel=1e-12)
    profile = mf.model_profile(model)
    assert (profile.kind, profile.center, profile.width, profile.depth) == ("tunnel", 10.0, i, 15.0)
    x = np.linspace(-5.0, 25.0, 31)
    np.testing.assert_allclose(profile.rate(x), np.exp(-(x - 10.0) ** 2 / (2 * i**2)), rtol=1e-12)
    np.testing.assert_allclose(profile.horizontal(x), -(x - 10.0) / 15.0 * np.exp(-(x - 10.0) ** 2 / (2 * i**2)),
                               rtol=1e-12, atol=1e-15)
    no_sideways = mf.model_profile(mf.build({**FACADE, "settlement": {**TUNNEL, "horizontal": False}}))
    np.testing.assert_array_equal(no_sideways.horizontal(x), 0.0)


@pytest.mark.parametrize(("change", "message"), [
    ({"volume_loss": -0.5}, "'settlement.volume_loss' = -0.5: must be positive"),
    ({"diameter": 0.0}, "'settlement.diameter' = 0.0: must be positive"),
    ({"depth": 2.0}, "'settlement.depth' = 2.0: the tunnel's crown would be above the ground"),
    ({"trough_width_factor": 0.0}, "'settlement.trough_width_factor' = 0.0: must be positive"),
    ({"center": 200.0}, "nothing settles under the wall"),
    ({"width": 5.0}, "'settlement.width' only applies to profile = 'gaussian'"),
    ({"horizontal": "yes"}, "'settlement.horizontal' = 'yes': must be true or false"),
])
def test_bad_tunnels_are_named(change, message):
    with pytest.raises(mf.SpecError, match=message.replace("(", r"\(").replace(")", r"\)")):
        mf.build({**FACADE, "settlement": {**TUNNEL, **change}})
