"""What a survey determines: the features every plausible candidate agrees on, and where they disagree.

Cracks tie down less than a scenario: a step at 3.3 m, a tilt about 3.3 m and the edge of a trough centred
beyond the wall crack the same joints. What they share is the answer a survey supports:

- the **side**: which part of the wall settled relative to the rest, ``left`` or ``right`` (an end part, the
  rest held; of a trough, the end settling more), or ``middle`` (an inner stretch, both ends held; of a
  trough, both ends settling less than half its deepest point under the wall);
- the **edge**: where the ground breaks under the wall, the hinge the cracks rise from: a step's inner edge
  (an inner stretch: its middle), a tilt's hinge, a trough's point of greatest ground curvature under the
  wall (its axis when that is on the wall, the hogging peak ``centre +/- sqrt(3) i``, or an end);
- the **mode**: ``sagging`` (the wall bridges a settled inner stretch, or lies within ``i`` of a trough's
  axis) or ``hogging`` (an end part cantilevers off the rest, a trough's flank);
- the **magnitude**: the largest differential settlement under the wall (between the ends of a tilted part,
  a step's two sides, a trough's deepest and shallowest points under the wall: what a survey can see; a
  trough's S_max beyond the wall is not), the plausible candidates' estimates, their spread as the interval.

:func:`determine` gathers them over the plausible set: a feature every plausible candidate shares is
*determined*, one they split on is not, and the families among them are named as indistinguishable.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Feature:
    """One candidate's reading of the wall (module docstring)."""

    side: str  # left, right or middle
    edge: float  # x [m]
    mode: str  # sagging or hogging
    differential: float  # the largest differential settlement under the wall per unit of the table's rate


def feature(table: dict, extent: tuple[float, float]) -> Feature:
    """The side, edge, mode and differential settlement of a ``[settlement]`` table under a wall spanning
    ``extent`` (module docstring)."""
    x_a, x_b = extent
    tiny = 1e-9 * (x_b - x_a)
    if table["profile"] == "step":
        left, right = table["start"] <= x_a + tiny, table["end"] >= x_b - tiny
        if left:
            return Feature("left", float(table["end"]), "hogging", 1.0)
        if right:
            return Feature("right", float(table["start"]), "hogging", 1.0)
        return Feature("middle", 0.5 * (table["start"] + table["end"]), "sagging", 1.0)
    if table["profile"] == "linear":
        start, end = float(table["start"]), float(table["end"])
        reach = (x_a if end < start else x_b) - start  # the wall's end on the settling side, from the hinge
        return Feature("left" if end < start else "right", start, "hogging", float(np.clip(reach / (end - start), 0, 1)))
    return _trough(float(table["center"]), float(table["width"]), extent)


def _trough(centre: float, width: float, extent: tuple[float, float]) -> Feature:
    """A Gaussian trough's reading: the edge where the ground's curvature under the wall is greatest (its sign the
    mode: sagging within ``i`` of the axis, hogging beyond), the side (module docstring)."""
    x = np.linspace(*extent, 401)
    u = (x - centre) / width
    settlement = np.exp(-0.5 * u**2)
    curvature = (1.0 - u**2) * settlement  # of the ground, concave up (sagging) positive; times S / i^2
    at = int(np.argmax(np.abs(curvature)))
    ends = settlement[[0, -1]] / settlement.max()
    side = "middle" if ends.max() < 0.5 else ("left" if ends[0] > ends[1] else "right")
    return Feature(side, float(x[at]), "sagging" if curvature[at] > 0 else "hogging",
                   float(settlement.max() - settlement.min()))


@dataclass(frozen=True)
class Determined:
    """What the plausible set agrees on (module docstring); ``None`` where it splits."""

    side: str | None
    sides: tuple[str, ...]
    edge: tuple[float, float]  # the interval of the plausible edges [m]
    edge_best: float
    mode: str | None
    modes: tuple[str, ...]
    families: tuple[str, ...]  # the families in the plausible set, best first
    magnitude: tuple[float, float] | None  # the interval of the plausible differential settlements [m]
    magnitude_best: float | None  # the best candidate's differential settlement under the wall [m]

    def as_json(self) -> dict:
        """The ``determined`` object of the ``--json`` contract (lengths in metres)."""
        def rounded(values):
            return None if values is None else [round(float(v), 6) for v in values]

        return {"side": self.side, "sides": list(self.sides), "edge": round(self.edge_best, 6),
                "edge_interval": rounded(self.edge), "mode": self.mode, "modes": list(self.modes),
                "families": list(self.families), "family": self.families[0] if len(self.families) == 1 else None,
                "magnitude": None if self.magnitude_best is None else round(self.magnitude_best, 7),
                "magnitude_interval": rounded(self.magnitude)}


def determine(tables: list[dict], magnitudes: list[float | None], extent: tuple[float, float],
              spreads: list[float] | None = None) -> Determined:
    """The features of the plausible ``tables`` (best first) with their ``magnitudes`` [m] (their ``target``
    scales; each one's own standard error in ``spreads``: the interval is then the plausible estimates +/- two of
    theirs); the magnitude determined is the differential settlement under the wall."""
    features = [feature(t, extent) for t in tables]
    sides = tuple(dict.fromkeys(f.side for f in features))
    modes = tuple(dict.fromkeys(f.mode for f in features))
    edges = [f.edge for f in features]
    spreads = spreads or [0.0] * len(magnitudes)
    magnitudes = [None if m is None else m * f.differential for m, f in zip(magnitudes, features)]
    known = [(m, spreads[k] * features[k].differential) for k, m in enumerate(magnitudes)
             if m is not None and math.isfinite(m) and m > 0]
    interval = None
    if known:
        interval = (max(0.0, min(m - 2 * s for m, s in known)), max(m + 2 * s for m, s in known))
    best_magnitude = magnitudes[0] if magnitudes and magnitudes[0] is not None else (known[0][0] if known else None)
    return Determined(sides[0] if len(sides) == 1 else None, sides, (min(edges), max(edges)), edges[0],
                      modes[0] if len(modes) == 1 else None, modes,
                      tuple(dict.fromkeys(t["profile"] for t in tables)), interval, best_magnitude)


FAMILY_WORDS = {"step": "a step", "linear": "a tilt", "gaussian": "a trough"}


def sentence(determined: Determined, levelled: bool) -> str:
    """The determined features in words, naming what the data cannot tell apart and what would."""
    parts = []
    where = (f"{determined.edge_best:.2f} m" if determined.edge[1] - determined.edge[0] < 1e-6
             else f"{determined.edge_best:.2f} m ({determined.edge[0]:.2f} to {determined.edge[1]:.2f})")
    if determined.side is None:
        parts.append(f"the settled part is not determined ({' or '.join(determined.sides)}); "
                     f"the ground breaks at {where}")
    elif determined.side == "middle":
        parts.append(f"an inner stretch settled relative to both ends, about {where}")
    else:
        parts.append(f"the {determined.side} part settled relative to the rest, the ground breaking at {where}")
    parts.append(f"the wall {determined.mode}" if determined.mode else "sagging or hogging is not determined")
    if determined.magnitude is not None:
        low, high = determined.magnitude
        parts.append(f"a differential settlement of {1e3 * (determined.magnitude_best or low):.3g} mm under the wall "
                     f"({1e3 * low:.3g} to {1e3 * high:.3g})")
    text = "; ".join(parts)
    if len(determined.families) > 1:
        names = ", ".join(FAMILY_WORDS[f] for f in determined.families[:-1])
        text += (f". {names[0].upper()}{names[1:]} or {FAMILY_WORDS[determined.families[-1]]} explain the data "
                 "equally")
        if not levelled:
            text += "; a levelling of one course would tell them apart"
    return text
