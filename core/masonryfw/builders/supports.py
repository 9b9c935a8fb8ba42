"""The supports of a wall the core lays (parametric or by its outline): the ranges of ``[supports.*]`` along its
base, or the segments of a ``[settlement]`` profile under its bottom course (:mod:`masonryfw.ground.profiles`); each
a rectangle one course high under the base (:func:`support_rectangles`)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..ground.profiles import Profile, profile_segments
from ..readers.spec import MOTION_KEYS, SpecTable, check_pivot, read_motion
from ..runtime.errors import SpecError
from .blocks import GroundEdge, Support

#: Position tolerance, relative to the wall size.
POSITION_TOLERANCE = 1.0e-9
_SUPPORT_KEYS = ("kind", "start", "end", *MOTION_KEYS)


def read_supports(top: SpecTable, x0: float, x1: float) -> tuple[Support, ...]:
    """The ``[supports.*]`` ranges of a wall whose base runs from ``x0`` to ``x1`` [m] (spec order)."""
    table = top.raw("supports")
    if not isinstance(table, dict) or not table:
        raise SpecError(f"spec key 'supports' = {table!r}: must hold at least one [supports.<name>] table")
    width = x1 - x0
    tol = POSITION_TOLERANCE * max(abs(x0), abs(x1), width)
    supports = []
    for name in table:
        entry = SpecTable(table[name], f"supports.{name}", _SUPPORT_KEYS, top.scale)
        kind = entry.choice("kind", ("fixed", "moving"))
        start = entry.number("start", length=True)
        end = entry.number("end", length=True)
        if start < x0 - tol:
            raise SpecError(f"spec key {entry.key('start')!r} = {entry.raw('start')!r}: before the wall's left end "
                            f"(x = {x0:.6g} m)")
        if end > x1 + tol:
            raise SpecError(f"spec key {entry.key('end')!r} = {entry.raw('end')!r}: beyond the wall's right end")
        if end <= start + tol:
            raise SpecError(f"spec key {entry.key('end')!r} = {entry.raw('end')!r}: must exceed start")
        motion, pivot, rate, direction = read_motion(entry, kind)
        check_pivot(entry, pivot, 0.5 * (start + end), tol)
        supports.append(Support(name, kind, motion, pivot, rate, direction=direction, extent=(max(start, x0), min(end, x1))))
    ordered = sorted(supports, key=lambda s: s.extent[0])
    for left, right in zip(ordered, ordered[1:]):
        if right.extent[0] < left.extent[1] - tol:
            raise SpecError(f"spec keys 'supports.{left.name}' and 'supports.{right.name}': the ranges overlap")
    return tuple(supports)


def profile_supports(profile: Profile, x0: float, x1: float, base: np.ndarray, y0: float = 0.0
                     ) -> tuple[Support, ...]:
    """The support segments of a ``[settlement]`` profile under a wall from ``x0`` to ``x1`` whose bottom course
    rests on the ``base`` intervals ``(n, 2)`` at height ``y0`` (a continuous ground: :mod:`masonryfw.ground.profiles`)."""
    segments = profile_segments(profile, x0, x1, base)
    return tuple(
        Support(f"segment {k} [{s.start:.6g}, {s.end:.6g}] m", "moving", "ground",
                ground=GroundEdge((s.start, s.end), y0, s.down, s.horizontal), extent=(s.start, s.end))
        if s.moving else Support(f"segment {k} [{s.start:.6g}, {s.end:.6g}] m", extent=(s.start, s.end))
        for k, s in enumerate(segments)
    )


def support_label(name: str) -> str:
    """How errors name a support: its spec key, or the profile segment."""
    return f"settlement {name}" if name.startswith("segment ") else f"spec key 'supports.{name}'"


def support_rectangles(supports: tuple[Support, ...], y0: float, height: float):
    """``(x0, x1, y0, y1)`` rectangles of the supports under a base at ``y0``, ``height`` deep, and their
    descriptions for :func:`masonryfw.builders.blocks.model_from_blocks`."""
    x0 = np.array([s.extent[0] for s in supports], dtype=float)
    x1 = np.array([s.extent[1] for s in supports], dtype=float)
    described = [replace(s, name=support_label(s.name)) for s in supports]
    return x0, x1, np.full(x0.size, y0 - height), np.full(x0.size, y0), described
