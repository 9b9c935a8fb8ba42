"""The greenfield ground in plan: a 2D profile across an axis, and a tunnel's face.

A building's ``[settlement]`` is a 2D profile (:mod:`masonryfw.ground.profiles`) over the coordinate ``u`` across an
axis in plan (the unit vector ``across``, from ``point``). A trough's tunnel may have a face: driven along the
axis (``v``, along ``axis``, ``across`` turned a quarter left), its face at ``v = face``. Behind the face the
ground has settled by the trough, ahead of it by less: the longitudinal profile is the cumulative normal
(Attewell & Woodman 1982)

    S(u, v) = S_max exp(-u^2 / (2 i^2)) Phi((face - v) / i),

half the trough at the face. The ground moves horizontally towards the tunnel: across it as in 2D
(O'Reilly & New 1982, ``-u / z0`` times the settlement) and along it, back towards the excavated length,

    u_v = -S_max i / (sqrt(2 pi) z0) exp(-u^2 / (2 i^2)) exp(-(v - face)^2 / (2 i^2))

(Attewell, Yeates & Selby 1986). Both are what point sinks along the excavated tunnel, each with its
displacements pointing at it, sum to; the tests check that by quadrature.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..readers.spec import SpecTable
from ..runtime.errors import SpecError
from .profiles import SETTLEMENT_KEYS, Profile, beyond_cutoff, model_profile, read_profile

#: A 3D profile's keys: the 2D ones, its axis in plan through a point instead of ``center``, a tunnel's face.
SETTLEMENT_3D_KEYS = tuple(k for k in SETTLEMENT_KEYS if k != "center") + ("axis_angle", "center_x", "center_y",
                                                                             "face")


class GroundInPlan(NamedTuple):
    """A 2D ``profile`` across the axis through ``point`` (the unit vector ``across``), and the position of a
    tunnel's ``face`` along the axis (None: the face has passed long ago, the 2D trough everywhere)."""

    profile: Profile
    point: np.ndarray  # (2,) [m]
    across: np.ndarray  # (2,)
    face: float | None = None

    @property
    def axis(self) -> np.ndarray:
        """The direction the tunnel is driven: ``across`` turned a quarter left."""
        return np.array([-self.across[1], self.across[0]])

    def axis_attr(self) -> str:
        """The model's ``settlement_axis`` attribute (docs/format.md): JSON of the point, the direction across the
        axis and the face, if any."""
        return json.dumps({"point": self.point.tolist(), "direction": self.across.tolist(),
                           **({} if self.face is None else {"face": self.face})})

    def greenfield(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(settlement rate, horizontal motion (n, 2))`` of the ground at the points ``xy`` (n, 2) in plan, per
        unit of the settlement parameter (module docstring)."""
        u = (xy - self.point) @ self.across
        rate = self.profile.rate(u)
        horizontal = self.profile.horizontal(u)[:, None] * self.across
        if self.face is None:
            return rate, horizontal
        from scipy.special import ndtr  # here: building a wall need not import scipy.special

        v = (xy - self.point) @ self.axis
        width = self.profile.width
        behind = ndtr((self.face - v) / width)
        horizontal = horizontal * behind[:, None]
        if self.profile.depth is not None and self.profile.sideways:
            along = -width / (math.sqrt(2.0 * math.pi) * self.profile.depth) * rate * np.exp(
                -0.5 * ((v - self.face) / width) ** 2)
            horizontal = horizontal + along[:, None] * self.axis
        return rate * behind, horizontal

    def motion(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(down, horizontal (n, 2))``: the greenfield less the profile's cutoff, as the 2D ground's nodes
        (:func:`masonryfw.ground.profiles.beyond_cutoff`)."""
        rate, horizontal = self.greenfield(xy)
        down, share = beyond_cutoff(self.profile, rate)
        return down, horizontal * share[:, None]


def profile_in_plan(table: SpecTable, unit_length: float, ground: float) -> GroundInPlan:
    """The ``[settlement]`` profile over the coordinate across its axis in plan: ``axis_angle`` degrees from x (90:
    the axis along y, the profile along x) through (``center_x``, ``center_y``); a trough's tunnel ``face`` along
    the axis from that point, driven towards ``axis_angle`` (:mod:`masonryfw.ground.ground_plan`). Its ``segment`` is
    checked against the ``ground`` it cuts [m] (a building's longest wall, a drawing's extent in plan)."""
    angle = math.radians(table.number("axis_angle", 90.0))
    point = np.array([table.number("center_x", 0.0, length=True), table.number("center_y", 0.0, length=True)])
    plain = {k: v for k, v in table.table.items() if k not in ("axis_angle", "center_x", "center_y", "face")}
    if plain.get("profile") in ("gaussian", "tunnel"):
        plain["center"] = 0.0
    elif table.has("face"):
        raise SpecError(f"spec key {table.key('face')!r}: a tunnel's face bounds a trough; profile = "
                        f"{plain.get('profile')!r} has none (use 'tunnel' or 'gaussian')")
    profile = read_profile(SpecTable(plain, table.path, SETTLEMENT_KEYS, table.scale), 0.0, 1.0, unit_length, ground)
    face = table.number("face", length=True) if table.has("face") else None
    return GroundInPlan(profile, point, np.array([math.sin(angle), -math.cos(angle)]), face)


def ground_in_plan(model) -> GroundInPlan | None:
    """The ground in plan a 3D model was built over (its ``settlement_profile`` and ``settlement_axis``
    attributes), None for a model without them."""
    profile = model_profile(model)
    if profile is None or "settlement_axis" not in model.attrs:
        return None
    axis = json.loads(model.attrs["settlement_axis"])
    return GroundInPlan(profile, np.array(axis["point"]), np.array(axis["direction"]), axis.get("face"))


@dataclass(frozen=True)
class SurfaceCut:
    """The greenfield surface along a wall's base line from ``start`` in the unit direction ``along``: the
    settlement rate and the horizontal motion along the wall at ``s`` from its start, what the engineers'
    stages read of a profile (:mod:`masonryfw.ground.assessment`); its inflection points found on the curve."""

    ground: GroundInPlan
    start: np.ndarray
    along: np.ndarray
    kind: str = "cut"

    def _points(self, s) -> np.ndarray:
        return self.start + np.atleast_1d(np.asarray(s, dtype=float))[:, None] * self.along

    def rate(self, s) -> np.ndarray:
        return self.ground.greenfield(self._points(s))[0]

    def horizontal(self, s) -> np.ndarray:
        return self.ground.greenfield(self._points(s))[1] @ self.along

    def inflections(self, a: float, b: float, samples: int) -> list[float]:
        """Where the settlement's curvature changes sign on ``(a, b)`` (linear between ``samples`` points)."""
        s = np.linspace(a, b, samples)
        curvature = np.diff(self.rate(s), 2)
        curvature[np.abs(curvature) < 1e-12 * np.abs(curvature).max(initial=0.0)] = 0.0
        change = np.flatnonzero(curvature[:-1] * curvature[1:] < 0)
        mid = s[1:-1]
        return [float(mid[k] + (mid[k + 1] - mid[k]) * curvature[k] / (curvature[k] - curvature[k + 1]))
                for k in change]
