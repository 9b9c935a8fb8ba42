"""The settlement scenarios a diagnosis tries: every one a ``[settlement]`` table that can be pasted into a spec.

On the wall's ground pieces (their ends, the *nodes*, from ``x_a`` to ``x_b``):

- ``step``: the ground under ``[start, end]`` drops (the paper's loading), every contiguous run of pieces
  but the whole base (which would move the wall as one body), from its first piece's start to its last
  one's end;
- ``gaussian``: a trough (Peck) with its axis at every node and every other node's distance beyond
  either end (half the wall each side), its width ``i`` from an eighth to two wall lengths in steps
  of sqrt(2): sagging where the wall lies within ``i`` of the axis, hogging beyond;
- ``linear``: a tilt rising from a node to either end of the wall.
"""
from __future__ import annotations

import numpy as np

FAMILIES = ("step", "gaussian", "linear")
#: Trough widths i, in wall lengths: an eighth to two, in steps of sqrt(2).
WIDTHS = tuple(float(w) for w in 0.125 * np.sqrt(2.0) ** np.arange(9))
#: How far the axis may lie beyond the wall's ends, in wall lengths.
BEYOND = 0.5


def steps(pieces: np.ndarray) -> list[tuple[float, float]]:
    """``(start, end)`` of every step that moves a different set of ground ``pieces`` (``(n, 2)`` x-extents), a
    contiguous run of them but not all: the run's outer ends (a step over a door's bare ground moves what
    the step to the door's far side moves, and is tried once)."""
    found = []
    for first in range(len(pieces)):
        for last in range(first, len(pieces)):
            if not (first == 0 and last == len(pieces) - 1):
                found.append((float(pieces[first, 0]), float(pieces[last, 1])))
    return list(dict.fromkeys(found))  # pieces stacked over one stretch of ground give a run twice


def _centres(nodes: np.ndarray) -> np.ndarray:
    """The troughs' axes: every node, and every other node's distance beyond either end."""
    x_a, x_b = float(nodes[0]), float(nodes[-1])
    spacing = float(np.diff(nodes).mean())
    length = x_b - x_a
    beyond = np.arange(spacing, BEYOND * length + 1e-9 * length, 2 * spacing)
    return np.concatenate([x_a - beyond[::-1], nodes, x_b + beyond])


def count(pieces: np.ndarray, families: tuple[str, ...]) -> int:
    """How many scenarios :func:`candidates` makes at most (without making them: the steps grow with the square of
    the pieces, 600,000 of them at a millimetre's segment under a 1.5 m wall)."""
    nodes = np.unique(np.asarray(pieces, dtype=float))
    n = len(pieces)
    return ((n * (n + 1) // 2 - 1 if "step" in families else 0)
            + (len(WIDTHS) * len(_centres(nodes)) if "gaussian" in families else 0)
            + (2 * (len(nodes) - 1) if "linear" in families else 0))


def candidates(pieces: np.ndarray, families: tuple[str, ...], segment: float) -> list[dict]:
    """The ``[settlement]`` tables of ``families`` on the ground ``pieces`` (``(n, 2)`` x-extents, left to right;
    lengths in metres)."""
    pieces = np.asarray(pieces, dtype=float)
    nodes = np.unique(pieces)
    x_a, x_b = float(nodes[0]), float(nodes[-1])
    length = x_b - x_a
    tables: list[dict] = []
    if "step" in families:
        tables += [{"profile": "step", "start": a, "end": b, "segment": segment} for a, b in steps(pieces)]
    if "gaussian" in families:
        centres = _centres(nodes)
        for width in WIDTHS:
            for centre in centres:
                tables.append({"profile": "gaussian", "center": float(centre), "width": width * length,
                               "segment": segment})
    if "linear" in families:
        for start in nodes[:-1]:
            tables.append({"profile": "linear", "start": float(start), "end": x_b, "segment": segment})
        for start in nodes[1:]:
            tables.append({"profile": "linear", "start": float(start), "end": x_a, "segment": segment})
    return tables


def describe(table: dict) -> str:
    """A candidate in a few words: ``step 0.5..1.1 m``, ``gaussian at 0.75 m, i 0.25 m``, ``tilt from 0.4 m down to
    1.1 m`` (linear: the ground still at ``start``, settling most at ``end``)."""
    if table["profile"] == "step":
        return f"step {table['start']:.4g}..{table['end']:.4g} m"
    if table["profile"] == "gaussian":
        return f"gaussian at {table['center']:.4g} m, i {table['width']:.4g} m"
    return f"tilt from {table['start']:.4g} m down to {table['end']:.4g} m"


def shape(table: dict, x_a: float, x_b: float) -> str:
    """How a trough bends the wall: sagging (the wall within ``i`` of the axis), hogging (beyond), or both."""
    if table["profile"] != "gaussian":
        return ""
    near = abs(np.array([x_a, x_b]) - table["center"]) < table["width"]
    inside = x_a < table["center"] < x_b
    if near.all():
        return "sagging"
    if not near.any() and not inside:
        return "hogging"
    return "sagging and hogging"
